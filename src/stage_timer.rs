//! [`stage`]: wall time, CPU time and memory of the long stages of a run, printed to stderr when the
//! environment variable `COSEG_TIMINGS` is set (to anything but `0`), for profiling large
//! collections (docs/SCALING.md). Off by default: nothing is measured or printed.

use std::sync::OnceLock;
use std::time::Instant;

/// Whether `COSEG_TIMINGS` asks for stage timings (read once).
pub fn enabled() -> bool {
    static ON: OnceLock<bool> = OnceLock::new();
    *ON.get_or_init(|| std::env::var_os("COSEG_TIMINGS").is_some_and(|v| v != "0"))
}

/// A running stage: prints `[timing] NAME: S s wall, C s cpu (rss R MB, peak P MB)` to stderr
/// when dropped, if timings are [`enabled`]. The CPU time is the whole process's (every
/// thread) over the stage: on a loaded machine it is the figure to compare, not the wall time.
#[derive(Debug)]
pub struct Stage {
    name: Option<(String, Instant, f64)>,
}

/// Starts timing the stage `name` (a no-op unless [`enabled`]).
///
/// ```
/// let _t = coseg::stage_timer::stage("reading");
/// // … the stage's work; the line is printed when `_t` is dropped.
/// ```
pub fn stage(name: impl Into<String>) -> Stage {
    Stage {
        name: enabled().then(|| (name.into(), Instant::now(), cpu_seconds())),
    }
}

impl Drop for Stage {
    fn drop(&mut self) {
        if let Some((name, start, cpu)) = &self.name {
            let (rss, peak) = memory_mb();
            eprintln!(
                "[timing] {name}: {:.2} s wall, {:.2} s cpu (rss {rss} MB, peak {peak} MB)",
                start.elapsed().as_secs_f64(),
                cpu_seconds() - cpu
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

/// The process's CPU time so far (user + system, all threads) in seconds, from
/// `/proc/self/stat` (0 where it cannot be read).
pub fn cpu_seconds() -> f64 {
    // Clock ticks per second of `/proc/*/stat` on Linux (USER_HZ; fixed at 100 by the ABI).
    const TICKS_PER_SECOND: f64 = 100.0;
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which may hold spaces, so split after its `)`):
    // utime and stime are the 14th and 15th fields, the 12th and 13th after the name.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<u64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|x| x.parse().ok())
        .collect();
    if f.len() == 2 {
        (f[0] + f[1]) as f64 / TICKS_PER_SECOND
    } else {
        0.0
    }
}
