//! `coseg segment FOLDER -o OUT`: consistent co-segmentation of every mesh in a folder.

use anyhow::{Result, bail};
use clap::Args;
use coseg::cache::CacheOutcome;
use coseg::graph::{GraphError, RefineSizes};
use coseg::jobs::{
    JobError, SegmentInput, SegmentJob, SegmentOutcome, SegmentProgress, run_segment_with_progress,
};
use coseg::parts::{PartsFrom, PartsRequest};
use coseg::stable::RefineOptions;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, Args)]
pub struct SegmentArgs {
    /// Folder of meshes (.obj, .off, .ply); every mesh file directly in it is used.
    folder: PathBuf,
    /// Output folder: `<name>.regions.txt`, `<name>.regions.ply` (coloured) and `<name>.png`
    /// per shape, `summary.json`, `preview.png`, `index.html` (docs/OUTPUTS.md).
    #[arg(short, long, visible_alias = "output")]
    out: PathBuf,
    /// Do not draw `preview.png`, `<name>.png` and `index.html`.
    #[arg(long)]
    no_pictures: bool,
    /// Per-shape cache folder (default: `<OUT>/.cache`).
    #[arg(long)]
    cache: Option<PathBuf>,
    /// Alone: the paper's equal-area stable regions instead of parts, this many per shape, the
    /// last being the leftovers. With `--parts`: the number of equal-area regions grouped into
    /// parts (default 12); with `--parts-from adaptive`, the upper bound on the number of parts
    /// (default 8).
    #[arg(long)]
    regions: Option<usize>,
    /// How many parts (default `auto`): `auto` = the number the part tree's cut criterion
    /// chooses (docs/PARTS.md), `N` = cut the tree of parts at N. summary.json records the
    /// tree, the chosen count and why, and the mirror pairs (left/right copies).
    #[arg(long, value_parser = parse_parts)]
    parts: Option<PartsRequest>,
    /// Where the parts come from: `geometry` (default; `--regions` equal-area regions, 12,
    /// grouped first where they touch or are left/right copies, have one thickness and meet
    /// over convex surface) or `adaptive` (tuples of their own size, grouped by what the
    /// affinity transports); docs/PARTS.md.
    #[arg(long, value_parser = parse_parts_from)]
    parts_from: Option<PartsFrom>,
    /// With `--parts-from geometry`: how far each part boundary may move onto a concave
    /// crease, × √(shape area) (default 0.1; 0 keeps the regions' boundaries; docs/PARTS.md).
    #[arg(long)]
    snap_band: Option<f64>,
    /// Area of each region as a fraction of its shape (default: 1 / regions).
    #[arg(long)]
    area_fraction: Option<f64>,
    /// Start each region from a seeded random half of the root shape instead of its most
    /// distinctive vertex.
    #[arg(long)]
    seed: Option<u64>,
    /// Co-segment from this many starts (the default start, then seeded ones) and keep the one
    /// with the highest mean region confidence; equal-area mode only (an error with
    /// `--parts`). See docs/PARTS.md.
    #[arg(long, default_value_t = SegmentJob::default().collection.starts)]
    starts: usize,
    /// Collections up to this size use a complete shape graph; larger ones a nearest-neighbour
    /// graph.
    #[arg(long, default_value_t = SegmentJob::default().collection.graph.complete_limit)]
    complete_limit: usize,
    /// Neighbours per shape of the nearest-neighbour graph.
    #[arg(long, default_value_t = SegmentJob::default().collection.graph.neighbours)]
    neighbours: usize,
    /// Sweeps of boundary refinement after the co-segmentation (smoothed best responses over
    /// every graph edge, see `coseg::graph::refine_cosegmentation`); 0 keeps the raw regions.
    #[arg(long, default_value_t = default_refine().0)]
    refine_rounds: usize,
    /// How the refinement treats part sizes: `free` (default: the classic best response,
    /// which drifts towards equal areas), `keep` (each part's area on each shape stays within
    /// the adaptive size tolerance, a factor 1.5, of its area before refinement; meant for
    /// `--parts`, whose sizes come from the data) or `keep:TOL` (within a factor 1 + TOL).
    /// See docs/PARTS.md.
    #[arg(long, value_parser = parse_refine_sizes)]
    refine_sizes: Option<RefineSizes>,
    /// Heat-smoothing time of the refinement (unit-area surface; 0 = no smoothing).
    #[arg(long, default_value_t = default_refine().1)]
    smoothing_time: f64,
    #[command(flatten)]
    pipeline: super::pipeline_args::PipelineArgs,
}

/// The default job's refinement as `--refine-rounds` and `--smoothing-time` show it.
fn default_refine() -> (usize, f64) {
    RefineOptions::rounds_of(SegmentJob::default().collection.refine.as_ref())
}

/// `--refine-sizes free|keep[:TOL]`.
fn parse_refine_sizes(s: &str) -> Result<RefineSizes, String> {
    s.parse().map_err(|e: GraphError| e.to_string())
}

/// `--parts-from adaptive|geometry`.
fn parse_parts_from(s: &str) -> Result<PartsFrom, String> {
    s.parse().map_err(|e: GraphError| e.to_string())
}

/// `--parts auto|N`.
fn parse_parts(s: &str) -> Result<PartsRequest, String> {
    s.parse().map_err(|e: GraphError| e.to_string())
}

/// The job `coseg segment` runs with these flags (the flags translated, nothing else).
fn segment_job(args: &SegmentArgs) -> Result<SegmentJob> {
    let mut job = SegmentJob::default();
    job.pipeline = args.pipeline.options()?;
    job.choose_features = !args.pipeline.features_given();
    job.regions = args.regions;
    job.parts = args.parts;
    job.parts_from = args.parts_from;
    job.snap_band = args.snap_band;
    let c = &mut job.collection;
    c.cosegment.area_fraction = args.area_fraction;
    c.cosegment.seed = args.seed;
    c.starts = args.starts;
    c.graph.complete_limit = args.complete_limit;
    c.graph.neighbours = args.neighbours;
    c.refine = RefineOptions::rounds(args.refine_rounds, args.smoothing_time);
    if let Some(r) = args.refine_sizes {
        c.refine_sizes = r;
    }
    job.cache = super::cache_or_auto(&args.cache);
    job.output = Some(args.out.clone());
    job.pictures = !args.no_pictures;
    job.strict = super::strict();
    Ok(job)
}

pub fn run(args: SegmentArgs) -> Result<ExitCode> {
    let t0 = Instant::now();
    let job = segment_job(&args)?;
    let bar = super::progress_bar(0);
    let mut spin = None;
    let outcome =
        run_segment_with_progress(
            SegmentInput::Folder(args.folder.clone()),
            &job,
            |p| match p {
                SegmentProgress::Shape { done, total, file } => {
                    if let Some(b) = &bar {
                        b.set_length(total as u64);
                        b.set_position(done as u64);
                        b.set_message(file.display().to_string());
                    }
                }
                SegmentProgress::Stage(stage) => {
                    if let Some(b) = &bar {
                        b.finish_and_clear();
                    }
                    if let Some(b) = spin.replace(super::spinner(stage)).flatten() {
                        b.finish_and_clear();
                    }
                }
                _ => {}
            },
        );
    if let Some(b) = spin.flatten() {
        b.finish_and_clear();
    }
    let outcome = match outcome {
        Err(JobError::Skipped(skipped)) => {
            for s in &skipped {
                eprintln!("error: {} (skipped)", s.error);
            }
            bail!(
                "{} input file(s) could not be used (--strict)",
                skipped.len()
            );
        }
        o => o?,
    };
    for s in &outcome.skipped {
        eprintln!("error: {} (skipped)", s.error);
    }
    for w in &outcome.warnings {
        super::warn(w);
    }
    if !super::quiet() {
        print_result(&args, &outcome, t0);
    }
    Ok(super::exit_code(
        outcome.skipped.len(),
        outcome.total_files(),
    ))
}

/// What the run chose and found, then the one-screen summary.
fn print_result(args: &SegmentArgs, outcome: &SegmentOutcome, t0: Instant) {
    let result = &outcome.result;
    if let Some(f) = &result.features {
        println!("{}", f.reason);
    }
    if let Some(c) = &result.part_count {
        println!("{}", c.reason);
    }
    if let (Some(a), Some(report)) = (&result.adaptive, &outcome.summary.parts) {
        println!(
            "parts: {} finest{} ({:?}), {} written; mirror candidates (several pieces, both sides?): {:?}; mirror pairs (left/right copies): {:?}",
            a.leaves.tuples.len(),
            match report
                .leaf_origin
                .iter()
                .enumerate()
                .filter(|&(i, &o)| i != o)
                .count()
            {
                0 => String::new(),
                n => format!(
                    ", {n} of them pieces split off their regions{}",
                    match report.leaf_copies.len() {
                        0 => String::new(),
                        c => format!(", {c} pairs of those copies of one part"),
                    }
                ),
            },
            a.stop,
            result.segmentation.tuples.len(),
            report.mirror_candidates,
            report
                .mirror_pairs
                .iter()
                .map(|m| (m.a, m.b))
                .collect::<Vec<_>>()
        );
    }
    report(args, outcome, t0);
}

/// The one-screen summary on stdout: shapes, regions, times, where the results are.
fn report(args: &SegmentArgs, outcome: &SegmentOutcome, t0: Instant) {
    let (result, options) = (&outcome.result, &outcome.options);
    let seg = &result.segmentation;
    let total_files = outcome.total_files();
    let hits = outcome
        .cache_outcomes
        .iter()
        .filter(|o| **o == Some(CacheOutcome::Hit))
        .count();
    println!(
        "{} shapes co-segmented into {} regions; {} files in {}",
        outcome.files.len(),
        seg.tuples.len(),
        outcome.written.len(),
        args.out.display()
    );
    if outcome.part_tree_cache == Some(CacheOutcome::Hit) {
        println!(
            "collection stage: re-cut from the cache (the part tree of an earlier run on these shapes and options, cut at {} parts)",
            seg.tuples.len()
        );
    }
    let times = &result.times;
    println!(
        "time: read {:.2} s, per-shape data {:.2} s ({hits} cached), {}graph {:.2} s, co-segmentation {:.2} s{}, refinement {:.2} s{}, write {:.2} s, total {:.2} s",
        outcome.load_times.0.as_secs_f64(),
        outcome.load_times.1.as_secs_f64(),
        match times.features {
            Some(t) => format!("feature choice {:.2} s, ", t.as_secs_f64()),
            None => String::new(),
        },
        times.graph.as_secs_f64(),
        times.cosegment.as_secs_f64(),
        match times.part_cues {
            Some(t) => format!(" (part cues {:.2} s)", t.as_secs_f64()),
            None => String::new(),
        },
        (times.smoothers + times.refine).as_secs_f64(),
        match (&options.refine, seg.tuples.first()) {
            (Some(_), Some(t)) => format!(
                " ({} sweeps{})",
                t.sweeps,
                if t.converged { ", converged" } else { "" }
            ),
            _ => String::new(),
        },
        outcome.write_time.as_secs_f64(),
        t0.elapsed().as_secs_f64()
    );
    if !outcome.skipped.is_empty() {
        println!(
            "skipped {} of {total_files} files (listed above and in summary.json)",
            outcome.skipped.len()
        );
    }
    let out = args.out.display();
    if args.no_pictures {
        println!("results: {out}/summary.json, {out}/<name>.regions.{{txt,ply}}");
    } else {
        println!(
            "results: {out}/summary.json; pictures: {out}/preview.png; viewer: {out}/index.html"
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bare command runs the job's default: the CLI chooses no default of its own.
    #[test]
    fn the_bare_command_runs_the_default_job() {
        let args: SegmentArgs = super::super::parse_args(&["coseg", "shapes", "-o", "out"]);
        let mut want = SegmentJob::default();
        want.output = Some(PathBuf::from("out"));
        want.pictures = true;
        assert_eq!(segment_job(&args).unwrap(), want);
    }
}
