//! Shared test fixtures, one file per area.
#![allow(dead_code)]

pub mod adversarial;
pub mod cli;
pub mod features;
pub mod generate;
pub mod graph;
pub mod mesh;
pub mod motion;
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
