//! `coseg segment FOLDER -o OUT`: consistent co-segmentation of every mesh in a folder.

use anyhow::{Context, Result, bail};
use clap::Args;
use coseg::cache::CacheOutcome;
use coseg::graph::{GraphError, GraphOptions, LoadedCollection, RefineSizes, load_collection};
use coseg::output::{CollectionSummary, ShapeRegions, SkippedInput, write_regions, write_visuals};
use coseg::parts::{
    PartsFrom, PartsRequest, SegmentCollectionOptions, SegmentedCollection, segment_collection,
};
use coseg::pipeline::ShapePipelineOptions;
use coseg::render::{RenderOptions, RenderShape};
use coseg::stable::RefineOptions;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

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
    #[arg(long, default_value_t = SegmentCollectionOptions::default().starts)]
    starts: usize,
    /// Collections up to this size use a complete shape graph; larger ones a nearest-neighbour
    /// graph.
    #[arg(long, default_value_t = GraphOptions::default().complete_limit)]
    complete_limit: usize,
    /// Neighbours per shape of the nearest-neighbour graph.
    #[arg(long, default_value_t = GraphOptions::default().neighbours)]
    neighbours: usize,
    /// Sweeps of boundary refinement after the co-segmentation (smoothed best responses over
    /// every graph edge, see `coseg::graph::refine_cosegmentation`); 0 keeps the raw regions.
    #[arg(long, default_value_t = SegmentCollectionOptions::DEFAULT_REFINE.max_rounds)]
    refine_rounds: usize,
    /// How the refinement treats part sizes: `free` (default: the classic best response,
    /// which drifts towards equal areas), `keep` (each part's area on each shape stays within
    /// the adaptive size tolerance, a factor 1.5, of its area before refinement; meant for
    /// `--parts`, whose sizes come from the data) or `keep:TOL` (within a factor 1 + TOL).
    /// See docs/PARTS.md.
    #[arg(long, value_parser = parse_refine_sizes)]
    refine_sizes: Option<RefineSizes>,
    /// Heat-smoothing time of the refinement (unit-area surface; 0 = no smoothing).
    #[arg(long, default_value_t = SegmentCollectionOptions::DEFAULT_REFINE.smoothing_time)]
    smoothing_time: f64,
    #[command(flatten)]
    pipeline: super::pipeline_args::PipelineArgs,
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

pub fn run(args: SegmentArgs) -> Result<ExitCode> {
    let cache = args
        .cache
        .clone()
        .unwrap_or_else(|| args.out.join(".cache"));
    let pipeline = args.pipeline.options()?;
    let t0 = Instant::now();
    let bar = super::progress_bar(0);
    let loaded = load_collection(&args.folder, &pipeline, &cache, |i, total, path| {
        if let Some(b) = &bar {
            b.set_length(total as u64);
            b.set_position(i as u64);
            b.set_message(path.display().to_string());
        }
    })
    .with_context(|| format!("reading {}", args.folder.display()))?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    for s in &loaded.skipped {
        eprintln!("error: {} (skipped)", s.error);
    }
    for w in &loaded.warnings {
        super::warn(w);
    }
    super::check_strict(loaded.skipped.len())?;
    let total_files = loaded.nodes.len() + loaded.skipped.len();
    if total_files == 0 {
        bail!(
            "{}: no mesh files (.obj, .off, .ply)",
            args.folder.display()
        );
    }
    if loaded.nodes.len() < 2 {
        bail!(
            "{}: co-segmentation needs at least 2 readable shapes, got {}",
            args.folder.display(),
            loaded.nodes.len()
        );
    }
    let options = collection_options(&args, &pipeline, &loaded, &cache)?;
    let spin = super::spinner("co-segmentation and refinement");
    let result = segment_collection(loaded.nodes.clone(), &loaded.meshes, &options)?;
    if let Some(b) = spin {
        b.finish_and_clear();
    }
    for w in &result.warnings {
        super::warn(w);
    }
    if !super::quiet() {
        if let Some(f) = &result.features {
            println!("{}", f.reason);
        }
        if let Some(c) = &result.part_count {
            println!("{}", c.reason);
        }
    }
    let seg = &result.segmentation;
    let t_write = Instant::now();
    let files: Vec<String> = loaded
        .paths
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    let skipped = loaded.skipped.iter().map(SkippedInput::from).collect();
    let mut summary = CollectionSummary::new(&result, &files, &options, skipped);
    if let (Some(a), Some(report)) = (&result.adaptive, result.parts_report(&loaded.meshes)) {
        if !super::quiet() {
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
                seg.tuples.len(),
                report.mirror_candidates,
                report
                    .mirror_pairs
                    .iter()
                    .map(|m| (m.a, m.b))
                    .collect::<Vec<_>>()
            );
        }
        if let Some(w) = report.warning() {
            super::warn(w);
        }
        summary.parts = Some(report);
    }
    let labels: Vec<Vec<i32>> = (0..seg.names.len()).map(|i| seg.labels(i)).collect();
    let shapes = ShapeRegions::collection(&seg.names, &loaded.meshes, &labels);
    let mut written = write_regions(&args.out, &shapes, &summary)?;
    if !args.no_pictures {
        written.extend(draw(&args.out, &shapes, &summary)?);
    }
    let write_time = t_write.elapsed();
    if !super::quiet() {
        report(
            &args,
            &loaded,
            &result,
            &options,
            written.len(),
            write_time,
            t0,
        );
    }
    Ok(super::exit_code(loaded.skipped.len(), total_files))
}

/// The collection stage's options the flags select.
fn collection_options(
    args: &SegmentArgs,
    pipeline: &ShapePipelineOptions,
    loaded: &LoadedCollection,
    cache: &Path,
) -> Result<SegmentCollectionOptions> {
    let mut o2 = SegmentCollectionOptions::for_request(args.regions, args.parts, args.parts_from);
    o2.graph = {
        let mut opts = GraphOptions::default();
        opts.complete_limit = args.complete_limit;
        opts.neighbours = args.neighbours;
        opts
    };
    o2.cosegment = {
        let mut opts = o2.cosegment;
        opts.area_fraction = args.area_fraction;
        opts.seed = args.seed;
        opts
    };
    o2.refine = (args.refine_rounds > 0).then_some({
        let mut opts = RefineOptions::default();
        opts.max_rounds = args.refine_rounds;
        opts.smoothing_time = args.smoothing_time;
        opts
    });
    o2.starts = args.starts;
    o2.refine_sizes = args.refine_sizes.unwrap_or_default();
    o2.set_pipeline(
        pipeline,
        args.pipeline.features_given(),
        loaded.nodes[0].bands.features,
    );
    if let Some(p) = o2.parts.as_mut() {
        p.seed = args.seed;
    }
    if let Some(band) = args.snap_band {
        o2.set_snap_band(band)?;
    }
    o2.cue_cache = Some(cache.to_path_buf());
    Ok(o2)
}

/// preview.png, <name>.png and index.html, legends naming each region by its confidence.
fn draw(
    out: &std::path::Path,
    shapes: &[ShapeRegions],
    summary: &CollectionSummary,
) -> Result<Vec<PathBuf>> {
    let spin = super::spinner("pictures");
    let pictures: Vec<RenderShape> = shapes.iter().map(ShapeRegions::picture).collect();
    let names: Vec<String> = summary
        .regions
        .iter()
        .map(|r| {
            if r.leftover {
                "leftovers".to_string()
            } else {
                format!("({:.0}%)", 100.0 * r.confidence)
            }
        })
        .collect();
    let paths = write_visuals(out, &pictures, Some(&names), &RenderOptions::default())?;
    if let Some(b) = spin {
        b.finish_and_clear();
    }
    Ok(paths)
}

/// The one-screen summary on stdout: shapes, regions, times, where the results are.
fn report(
    args: &SegmentArgs,
    loaded: &LoadedCollection,
    result: &SegmentedCollection,
    options: &SegmentCollectionOptions,
    written: usize,
    write_time: Duration,
    t0: Instant,
) {
    let seg = &result.segmentation;
    let total_files = loaded.nodes.len() + loaded.skipped.len();
    let hits = loaded
        .outcomes
        .iter()
        .filter(|o| **o == CacheOutcome::Hit)
        .count();
    println!(
        "{} shapes co-segmented into {} regions; {} files in {}",
        loaded.nodes.len(),
        seg.tuples.len(),
        written,
        args.out.display()
    );
    let times = &result.times;
    println!(
        "time: read {:.2} s, per-shape data {:.2} s ({hits} cached), {}graph {:.2} s, co-segmentation {:.2} s{}, refinement {:.2} s{}, write {:.2} s, total {:.2} s",
        loaded.read_time.as_secs_f64(),
        loaded.shape_time.as_secs_f64(),
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
        write_time.as_secs_f64(),
        t0.elapsed().as_secs_f64()
    );
    if !loaded.skipped.is_empty() {
        println!(
            "skipped {} of {total_files} files (listed above and in summary.json)",
            loaded.skipped.len()
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
