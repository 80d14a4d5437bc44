//! `coseg eval RESULT_DIR --truth DIR`: scores a result folder against ground truth.

use anyhow::Result;
use clap::Args;
use coseg::evaluate::{CorrespondenceMap, FolderScores, ResultKind};
use coseg::jobs::{EvalJob, run_eval};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct EvalArgs {
    /// Folder written by `coseg segment` or `pair` (`<name>.regions.txt`, `<name>.regions.ply`)
    /// or by `coseg propagate` (`<name>.labels.txt`, `<name>.labels.ply`).
    result: PathBuf,
    /// Ground-truth folder: `<name>.labels.txt` (one label per vertex) or `<name>.seg` (one
    /// label per face).
    #[arg(long)]
    truth: PathBuf,
    /// Correspondence ratio of a two-shape result: `identity` (same triangulation) or a file
    /// with one index into the second shape per vertex of the first (negative = none).
    #[arg(long)]
    map: Option<String>,
    /// Also write the scores as JSON to this file.
    #[arg(long)]
    json: Option<PathBuf>,
}

pub fn run(args: EvalArgs) -> Result<ExitCode> {
    let mut job = EvalJob::default();
    job.evaluate.map = args.map.as_deref().map(|m| match m {
        "identity" => CorrespondenceMap::Identity,
        file => CorrespondenceMap::File(file.into()),
    });
    job.json = args.json.clone();
    let scores = run_eval(&args.result, &args.truth, &job)?;
    if !super::quiet() {
        print_table(&scores);
    }
    Ok(ExitCode::SUCCESS)
}

fn print_table(scores: &FolderScores) {
    let labels = scores.kind == ResultKind::Labels;
    println!("{:<24} {:>9} {:>11}", "shape", "accuracy", "rand index");
    for s in &scores.shapes {
        println!(
            "{:<24} {:>8.2}% {:>11.4}{}",
            s.name,
            100.0 * s.accuracy,
            s.rand_index,
            if s.source { "  (source)" } else { "" }
        );
    }
    println!(
        "{:<24} {:>8.2}% {:>11.4}",
        if labels { "mean (non-sources)" } else { "all" },
        100.0 * scores.accuracy,
        scores.mean_rand_index
    );
    if labels {
        println!("part IoU (mean over the non-source shapes; accuracy weighted by area):");
    } else {
        println!("part IoU (region ids mapped to their majority part):");
    }
    for (part, iou) in &scores.part_iou {
        println!("  part {part:<4} {:>6.2}%", 100.0 * iou);
    }
    println!("  mean      {:>6.2}%", 100.0 * scores.mean_iou);
    if let Some(r) = scores.correspondence_ratio {
        println!("correspondence ratio {:.2}%", 100.0 * r);
    }
}
