//! Shared test fixtures, one file per area.
#![allow(dead_code)]

pub mod adversarial;
pub mod cli;
pub mod features;
pub mod generate;
pub mod graph;
pub mod mesh;
pub mod motion;
pub mod outputs;
pub mod shapes;
pub mod stable;
pub mod studio;

/// The evaluation data folder (`../shared/data`: TOSCA, FAUST, COSEG chairs) from the
/// environment variable `COSEG_DATA`, or `None` after saying that `test` is skipped: no test CI
/// needs depends on it.
pub fn shared_data(test: &str) -> Option<std::path::PathBuf> {
    match std::env::var_os("COSEG_DATA") {
        Some(dir) if std::path::Path::new(&dir).is_dir() => Some(dir.into()),
        _ => {
            eprintln!("{test}: skipped (set COSEG_DATA to the evaluation data folder to run it)");
            None
        }
    }
}

/// A fresh, empty scratch folder `area/name` under Cargo's per-target temporary directory
/// (kept after the run for inspection, emptied at the next).
pub fn scratch(area: &str, name: &str) -> std::path::PathBuf {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(area)
        .join(name);
    if dir.exists() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `f` run on a rayon pool of `threads` threads (results must not depend on the count).
pub fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// A proptest configuration of `cases` cases from the fixed `seed` (the same cases on every
/// run) that writes no failure-persistence files.
pub fn fixed_cases(cases: u32, seed: u64) -> proptest::test_runner::Config {
    proptest::test_runner::Config {
        cases,
        rng_seed: proptest::test_runner::RngSeed::Fixed(seed),
        failure_persistence: None,
        ..proptest::test_runner::Config::default()
    }
}
