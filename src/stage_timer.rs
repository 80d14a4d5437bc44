//! [`stage`]: wall time and memory of the long stages of a run, printed to stderr when the
//! environment variable `COSEG_TIMINGS` is set (to anything but `0`), for profiling large
//! collections (docs/SCALING.md). Off by default: nothing is measured or printed.

use std::sync::OnceLock;
use std::time::Instant;

/// Whether `COSEG_TIMINGS` asks for stage timings (read once).
pub fn enabled() -> bool {
    static ON: OnceLock<bool> = OnceLock::new();
    *ON.get_or_init(|| std::env::var_os("COSEG_TIMINGS").is_some_and(|v| v != "0"))
}

/// A running stage: prints `[timing] NAME: S s (rss R MB, peak P MB)` to stderr when dropped,
/// if timings are [`enabled`].
#[derive(Debug)]
pub struct Stage {
    name: Option<(String, Instant)>,
}

/// Starts timing the stage `name` (a no-op unless [`enabled`]).
///
/// ```
/// let _t = coseg::stage_timer::stage("reading");
/// // … the stage's work; the line is printed when `_t` is dropped.
/// ```
pub fn stage(name: impl Into<String>) -> Stage {
    Stage {
        name: enabled().then(|| (name.into(), Instant::now())),
    }
}

impl Drop for Stage {
    fn drop(&mut self) {
        if let Some((name, start)) = &self.name {
            let (rss, peak) = memory_mb();
            eprintln!(
                "[timing] {name}: {:.2} s (rss {rss} MB, peak {peak} MB)",
                start.elapsed().as_secs_f64()
            );
        }
    }
}

/// The process's resident and peak resident memory in MB (`VmRSS`, `VmHWM` of
/// `/proc/self/status`; 0 where it cannot be read).
pub fn memory_mb() -> (u64, u64) {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let field = |key: &str| {
        status
            .lines()
            .find_map(|l| l.strip_prefix(key))
            .and_then(|v| v.split_whitespace().next())
            .and_then(|v| v.parse::<u64>().ok())
            .map_or(0, |kb| kb / 1024)
    };
    (field("VmRSS:"), field("VmHWM:"))
}
