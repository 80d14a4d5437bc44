//! Running the `coseg` binary from integration tests.

use std::ffi::OsStr;
use std::path::Path;
use std::process::{Command, Output};

/// Small per-shape settings so that debug builds finish in seconds: 20 eigenpairs, 6 of each
/// descriptor, 6 bands.
#[rustfmt::skip]
pub const FAST_PIPELINE: [&str; 10] = [
    "--eigenpairs", "20", "--hks", "6", "--wks", "6", "--curvature", "6", "--bands", "6",
];

/// `coseg ARGS`, run to completion with its output captured.
pub fn coseg<S: AsRef<OsStr>>(args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_coseg"))
        .args(args)
        .output()
        .expect("run coseg")
}

/// Bytes of a captured stream as text (invalid UTF-8 replaced).
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A path as a command-line argument (test paths are UTF-8).
pub fn arg(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `coseg ARGS`, which must succeed: the failure message names the command and holds its
/// standard error.
pub fn coseg_ok<S: AsRef<OsStr>>(args: &[S]) -> Output {
    let run = coseg(args);
    assert!(
        run.status.success(),
        "coseg {}: {}",
        args.iter()
            .map(|a| a.as_ref().to_string_lossy())
            .collect::<Vec<_>>()
            .join(" "),
        text(&run.stderr)
    );
    run
}
