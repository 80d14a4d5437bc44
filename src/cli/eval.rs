//! `coseg eval RESULT_DIR --truth DIR`: scores a result folder against ground truth.

use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct EvalArgs {
    /// Folder written by `coseg segment`, `pair` or `propagate` (`<name>.regions.txt`).
    result: PathBuf,
    /// Ground-truth folder: `<name>.labels.txt` (per vertex) or `<name>.seg` (per face).
    #[arg(long)]
    truth: PathBuf,
}

pub fn run(args: EvalArgs) -> Result<ExitCode> {
    let _ = (&args.result, &args.truth);
    anyhow::bail!("eval: not built yet")
}
