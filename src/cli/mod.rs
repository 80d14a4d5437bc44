//! Subcommands of the `coseg` binary, one file each.

mod convert;
mod features;
mod generate;
mod info;
mod pair;
mod pipeline_args;
mod propagate;
mod segment;
mod spectrum;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Exit code when the command failed as a whole.
pub const EXIT_FAILURE: u8 = 1;
/// Exit code when some input files were reported and skipped but the rest succeeded.
pub const EXIT_PARTIAL: u8 = 3;

/// coseg: stable region correspondences and co-segmentation of 3D shape collections.
#[derive(Debug, Parser)]
#[command(name = "coseg", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Load meshes, validate them and print their counts and warnings.
    Info(info::InfoArgs),
    /// Print the k smallest Laplace–Beltrami eigenvalues of a mesh scaled to unit area.
    Spectrum(spectrum::SpectrumArgs),
    /// Convert a mesh between OBJ, OFF and PLY (format by extension), keeping vertex order.
    Convert(convert::ConvertArgs),
    /// Compute a mesh's descriptors and band table and export them (.npy or .csv).
    Features(features::FeaturesArgs),
    /// Generate a synthetic shape family with ground-truth part labels.
    Generate(generate::GenerateArgs),
    /// Stable region correspondences between two meshes (Algorithm 2 or 3).
    Pair(pair::PairArgs),
    /// Co-segment every mesh of a folder into corresponding regions (same id = same part).
    Segment(segment::SegmentArgs),
    /// Carry part labels from a few annotated meshes to every mesh of a folder.
    Propagate(propagate::PropagateArgs),
}

/// Runs a parsed command line; the exit code tells success, partial success or failure.
pub fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Info(args) => info::run(args),
        Command::Spectrum(args) => spectrum::run(args),
        Command::Convert(args) => convert::run(args),
        Command::Features(args) => features::run(args),
        Command::Generate(args) => generate::run(args),
        Command::Pair(args) => pair::run(args),
        Command::Segment(args) => segment::run(args),
        Command::Propagate(args) => propagate::run(args),
    }
}

/// The error and its causes on one line, `outer: inner: …`, each cause shown once: a library
/// error whose message already includes its source (`path: No such file or directory`) is
/// not followed by that source again.
pub fn error_message(err: &anyhow::Error) -> String {
    let mut parts: Vec<String> = Vec::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if parts.iter().any(|p| p.contains(&text)) {
            continue;
        }
        // A context that only names the file the cause names too: keep the cause.
        match parts.last_mut() {
            Some(last) if text.starts_with(last.as_str()) => *last = text,
            _ => parts.push(text),
        }
    }
    parts.join(": ")
}

/// 0 when nothing failed, [`EXIT_FAILURE`] when everything failed, [`EXIT_PARTIAL`] otherwise.
fn exit_code(failed: usize, total: usize) -> ExitCode {
    if failed == 0 {
        ExitCode::SUCCESS
    } else if failed == total {
        ExitCode::from(EXIT_FAILURE)
    } else {
        ExitCode::from(EXIT_PARTIAL)
    }
}
