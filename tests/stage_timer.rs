//! `coseg::stage_timer`: stage timings for profiling, off unless `COSEG_TIMINGS` is set.

use coseg::stage_timer::{cpu_seconds, memory_mb, stage};

#[test]
fn memory_is_read_from_the_process_status() {
    let (rss, peak) = memory_mb();
    if std::path::Path::new("/proc/self/status").exists() {
        assert!(rss > 0 && peak >= rss, "rss {rss} MB, peak {peak} MB");
    } else {
        assert_eq!((rss, peak), (0, 0));
    }
}

#[test]
fn a_stage_runs_and_ends_whether_or_not_timings_are_on() {
    let t = stage("a stage");
    let x: u64 = (0..1000).sum();
    drop(t);
    assert_eq!(x, 499_500);
}

#[test]
fn cpu_time_grows_with_work() {
    let before = cpu_seconds();
    let mut x = 0u64;
    let start = std::time::Instant::now();
    while start.elapsed().as_millis() < 300 {
        x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
    }
    std::hint::black_box(x);
    if std::path::Path::new("/proc/self/stat").exists() {
        assert!(
            cpu_seconds() > before,
            "{before} s before, {} s after",
            cpu_seconds()
        );
    }
}
