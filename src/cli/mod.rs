//! Subcommands of the `coseg` binary, one file each, and the flags they share.

mod align;
mod convert;
mod eval;
mod features;
mod generate;
mod info;
mod pair;
mod pipeline_args;
mod propagate;
mod render;
mod segment;
mod spectrum;
mod studio;

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::process::ExitCode;
use std::sync::OnceLock;
use std::time::Duration;

/// Exit code when the command failed as a whole.
pub const EXIT_FAILURE: u8 = 1;
/// Exit code when some input files were reported and skipped but the rest succeeded.
pub const EXIT_PARTIAL: u8 = 3;

const AFTER_HELP: &str = "\
Examples:
  coseg generate quadrupeds -o shapes/           # a synthetic family with ground truth
  coseg segment shapes/ -o out/                  # co-segment a folder; out/preview.png, out/index.html
  coseg pair a.off b.off -o out/ --ground-truth identity
  coseg render out/*.regions.ply -o sheet.png    # pictures; labels from X.regions.txt or --labels
  coseg eval out/ --truth shapes/                # accuracy, IoU, Rand index against ground truth
  coseg info a.off b.obj                         # counts and warnings
Exit codes: 0 success, 1 failure, 3 some inputs were skipped (use --strict to make that fatal).
Run `coseg help SUBCOMMAND` for each subcommand's options and example.";

/// coseg: stable region correspondences and co-segmentation of 3D shape collections.
#[derive(Debug, Parser)]
#[command(name = "coseg", version, about, long_about = None, after_help = AFTER_HELP)]
pub struct Cli {
    #[command(flatten)]
    global: GlobalArgs,
    #[command(subcommand)]
    command: Command,
}

/// Flags every subcommand accepts.
#[derive(Debug, Clone, Args)]
struct GlobalArgs {
    /// Print nothing on success: no progress, warnings or summary (errors still go to stderr;
    /// `info` and `spectrum` still print their answer).
    #[arg(short, long, global = true)]
    quiet: bool,
    /// Fail (exit 1) when an input file cannot be used instead of skipping it (exit 3).
    #[arg(long, global = true)]
    strict: bool,
    /// Worker threads (default: one per core).
    #[arg(long, global = true, value_parser = clap::value_parser!(u16).range(1..))]
    threads: Option<u16>,
}

/// One subcommand's flags parsed alone from `argv`: its tests check what they translate into.
#[cfg(test)]
fn parse_args<A: Args>(argv: &[&str]) -> A {
    let command = A::augment_args(clap::Command::new("coseg"));
    clap::FromArgMatches::from_arg_matches(&command.get_matches_from(argv)).unwrap()
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Load meshes, validate them and print their counts and warnings.
    #[command(after_help = "Example:\n  coseg info shapes/*.off")]
    Info(info::InfoArgs),
    /// Print the k smallest Laplace–Beltrami eigenvalues of a mesh scaled to unit area.
    #[command(after_help = "Example:\n  coseg spectrum cat0.off -k 20")]
    Spectrum(spectrum::SpectrumArgs),
    /// Convert a mesh between OBJ, OFF and PLY (format by extension), keeping vertex order.
    #[command(after_help = "Example:\n  coseg convert cat0.off cat0.ply")]
    Convert(convert::ConvertArgs),
    /// Put every mesh of a folder in one collection frame (rotation, scale, translation).
    #[command(
        after_help = "Example:\n  coseg align shapes/ -o aligned/ --write-meshes\n\
        Writes aligned/transforms.json (see docs/ALIGN.md) and, on request, the aligned meshes."
    )]
    Align(align::AlignArgs),
    /// Compute a mesh's descriptors and band table and export them (.npy or .csv).
    #[command(after_help = "Example:\n  coseg features cat0.off -o cat0_features/")]
    Features(features::FeaturesArgs),
    /// Generate a synthetic shape family with ground-truth part labels.
    #[command(after_help = "Example:\n  coseg generate quadrupeds -o shapes/ --count 6")]
    Generate(generate::GenerateArgs),
    /// Stable region correspondences between two meshes (Algorithm 2 or 3).
    #[command(
        after_help = "Example:\n  coseg pair cat0.off cat1.off -o out/ --ground-truth identity\n\
        Writes out/<name>.regions.{txt,ply}, summary.json, preview.png, <name>.png, index.html \
        (see docs/OUTPUTS.md); per-shape data is cached in out/.cache unless --no-cache."
    )]
    Pair(pair::PairArgs),
    /// Co-segment every mesh of a folder into corresponding regions (same id = same part).
    #[command(after_help = "Example:\n  coseg segment shapes/ -o out/ --regions 6\n\
        Writes out/<name>.regions.{txt,ply}, summary.json, preview.png, <name>.png, index.html \
        (see docs/OUTPUTS.md); an interrupted run resumes from out/.cache.")]
    Segment(segment::SegmentArgs),
    /// Draw meshes coloured by regions or labels into one PNG contact sheet.
    #[command(
        after_help = "Example:\n  coseg render out/cat0.regions.ply out/cat1.regions.ply -o cats.png\n  \
        coseg render cat0.off --labels cat0.labels.txt -o cat0.png"
    )]
    Render(render::RenderArgs),
    /// Score a result folder against ground truth: accuracy, per-part IoU, Rand index,
    /// correspondence ratio.
    #[command(after_help = "Example:\n  coseg eval out/ --truth shapes/ --json scores.json")]
    Eval(eval::EvalArgs),
    /// Carry part labels from a few annotated meshes to every mesh of a folder.
    #[command(
        after_help = "Example:\n  coseg propagate shapes/ --labels labelled/ -o out/\n\
        Reads <stem>.seg (per face) or <stem>.labels.txt (per vertex) from --labels; writes \
        out/<name>.labels.{txt,ply}, <name>.seg, summary.json."
    )]
    Propagate(propagate::PropagateArgs),
    /// Label a folder of meshes in the browser: click patches, propagate, correct, save.
    #[command(after_help = "Example:\n  coseg studio shapes/ --open\n\
        Serves a page on 127.0.0.1 only; the printed address carries the session's token. \
        Saves <stem>.labels.txt, <stem>.seg, parts.json and summary.json into --labels \
        (default FOLDER/labels), and reopening the folder resumes from them.")]
    Studio(studio::StudioArgs),
}

static GLOBAL: OnceLock<GlobalArgs> = OnceLock::new();

fn global() -> &'static GlobalArgs {
    GLOBAL.get_or_init(|| GlobalArgs {
        quiet: false,
        strict: false,
        threads: None,
    })
}

/// True with `--quiet`: print nothing but errors.
pub fn quiet() -> bool {
    global().quiet
}

/// True with `--strict`: fail when an input file cannot be used.
pub fn strict() -> bool {
    global().strict
}

/// The cache of a command writing to an output folder: `--cache DIR` when given, otherwise
/// `<OUT>/.cache` ([`coseg::jobs::CacheChoice::Auto`]).
pub fn cache_or_auto(cache: &Option<std::path::PathBuf>) -> coseg::jobs::CacheChoice {
    cache.clone().map_or(
        coseg::jobs::CacheChoice::Auto,
        coseg::jobs::CacheChoice::Dir,
    )
}

/// Fails under `--strict` when `skipped` input files could not be used.
pub fn check_strict(skipped: usize) -> anyhow::Result<()> {
    if global().strict && skipped > 0 {
        anyhow::bail!("{skipped} input file(s) could not be used (--strict)");
    }
    Ok(())
}

/// A progress bar of `len` steps on stderr, or `None` when stderr is not a terminal or with
/// `--quiet`.
pub fn progress_bar(len: u64) -> Option<ProgressBar> {
    (!quiet() && std::io::stderr().is_terminal()).then(|| {
        let b = ProgressBar::new(len);
        b.set_style(
            ProgressStyle::with_template("{bar:30} {pos}/{len} {elapsed} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    })
}

/// A ticking spinner with `msg` for a stage without steps (same conditions as
/// [`progress_bar`]); finish it with `finish_and_clear`.
pub fn spinner(msg: &str) -> Option<ProgressBar> {
    (!quiet() && std::io::stderr().is_terminal()).then(|| {
        let b = ProgressBar::new_spinner();
        b.set_style(
            ProgressStyle::with_template("{spinner} {msg} {elapsed}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        b.set_message(msg.to_string());
        b.enable_steady_tick(Duration::from_millis(120));
        b
    })
}

/// Prints a warning on stderr unless `--quiet`.
pub fn warn(msg: impl std::fmt::Display) {
    if !quiet() {
        eprintln!("warning: {msg}");
    }
}

/// Runs a parsed command line; the exit code tells success, partial success or failure.
pub fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    if let Some(n) = cli.global.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n.into())
            .build_global()
            .map_err(|e| anyhow::anyhow!("--threads {n}: {e}"))?;
    }
    let _ = GLOBAL.set(cli.global.clone());
    match cli.command {
        Command::Info(args) => info::run(args),
        Command::Spectrum(args) => spectrum::run(args),
        Command::Convert(args) => convert::run(args),
        Command::Align(args) => align::run(args),
        Command::Features(args) => features::run(args),
        Command::Generate(args) => generate::run(args),
        Command::Pair(args) => pair::run(args),
        Command::Segment(args) => segment::run(args),
        Command::Render(args) => render::run(args),
        Command::Eval(args) => eval::run(args),
        Command::Propagate(args) => propagate::run(args),
        Command::Studio(args) => studio::run(args),
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

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{ArgAction, CommandFactory};
    use serde_json::Value;

    /// Every flag default of every subcommand is the library's ([`coseg::jobs::defaults`]: the
    /// subcommand's own, else the per-shape one). Generated from clap's description of the
    /// command line, so a flag given a default of its own (or one the library does not
    /// export) fails here.
    #[test]
    fn every_flag_default_is_the_librarys() {
        let lib = coseg::jobs::defaults();
        let mut checked = 0;
        let mut wrong = Vec::new();
        for sub in Cli::command().get_subcommands() {
            for arg in sub.get_arguments() {
                // A switch's "default" is its absence, not a value of the library's.
                if !matches!(arg.get_action(), ArgAction::Set | ArgAction::Append) {
                    continue;
                }
                let shown: Vec<String> = arg
                    .get_default_values()
                    .iter()
                    .map(|v| v.to_string_lossy().into_owned())
                    .collect();
                if shown.is_empty() {
                    continue;
                }
                let id = arg.get_id().as_str();
                let value = lib[sub.get_name()]
                    .get(id)
                    .or_else(|| lib["pipeline"].get(id));
                match value {
                    Some(v) if same(v, &shown.join(",")) => checked += 1,
                    _ => wrong.push(format!(
                        "{} --{id}: flag default {shown:?}, library {value:?}",
                        sub.get_name()
                    )),
                }
            }
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
        assert!(checked > 40, "only {checked} defaults checked");
    }

    /// A JSON value and the text clap shows for it: equal as numbers, switches or words.
    fn same(v: &Value, shown: &str) -> bool {
        match v {
            Value::String(s) => s == shown,
            Value::Bool(b) => shown.parse::<bool>() == Ok(*b),
            Value::Number(n) => n.as_f64().is_some() && n.as_f64() == shown.parse::<f64>().ok(),
            _ => false,
        }
    }
}
