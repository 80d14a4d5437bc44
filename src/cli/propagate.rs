//! `coseg propagate FOLDER --labels DIR-OR-FILES -o OUT`: part labels from a few annotated
//! shapes to every mesh of a folder.

use anyhow::{Context, Result, bail};
use clap::Args;
use coseg::graph::GraphOptions;
use coseg::labels::PartNames;
use coseg::output::{PropagationSummary, write_propagation, write_visuals};
use coseg::propagate::{
    MapStepOptions, PartScore, PropagateCollectionOptions, PropagateOptions, propagate_collection,
};
use coseg::render::{RenderOptions, RenderShape};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, Args)]
pub struct PropagateArgs {
    /// Folder of meshes (.obj, .off, .ply); every mesh file directly in it is used.
    folder: PathBuf,
    /// Annotations: folders (label files matched to meshes by stem: `<stem>.seg` per face,
    /// `<stem>.labels.txt` per vertex) or label files; repeat or separate by commas.
    /// `-1` = unlabelled.
    #[arg(long, required = true, value_delimiter = ',')]
    labels: Vec<PathBuf>,
    /// Output folder: `<name>.labels.txt`, `<name>.seg`, `<name>.labels.ply` per shape,
    /// `summary.json`.
    #[arg(short, long)]
    out: PathBuf,
    /// Part names, a JSON object `{label: name}`, carried into summary.json and the pictures.
    #[arg(long)]
    part_names: Option<PathBuf>,
    /// Do not write preview.png, <name>.png and index.html.
    #[arg(long)]
    no_pictures: bool,
    /// Per-shape cache folder (default: `<OUT>/.cache`).
    #[arg(long)]
    cache: Option<PathBuf>,
    /// Collections up to this size use a complete shape graph; larger ones a nearest-neighbour
    /// graph.
    #[arg(long, default_value_t = GraphOptions::default().complete_limit)]
    complete_limit: usize,
    /// Neighbours per shape of the nearest-neighbour graph.
    #[arg(long, default_value_t = GraphOptions::default().neighbours)]
    neighbours: usize,
    /// Heat-smoothing time of the part scores (unit-area surface; 0 = no smoothing).
    #[arg(long, default_value_t = PropagateOptions::default().smoothing_time)]
    smoothing_time: f64,
    /// Largest number of sweeps over the unlabelled shapes.
    #[arg(long, default_value_t = PropagateOptions::default().max_sweeps)]
    max_sweeps: usize,
    /// Vote weight of labelled neighbours that are not sources (0 = sources only).
    #[arg(long, default_value_t = PropagateOptions::default().network_weight)]
    network_weight: f64,
    /// How much more a source like the target counts than an unlike one, when several vote
    /// (weight `(d_min / d)^p` by summary distance; 0 = all alike).
    #[arg(long, default_value_t = PropagateOptions::default().similarity_power)]
    similarity_power: f64,
    /// How strongly part sizes follow the sources' area shares (0 … 1).
    #[arg(long, default_value_t = PropagateOptions::default().size_prior)]
    size_prior: f64,
    /// Part score: affinity (mean of the per-feature histogram values, the band affinity's
    /// transport) or geometric (their geometric mean). See docs/PROPAGATION.md.
    #[arg(long, default_value = "affinity")]
    part_score: String,
    /// Weigh the parts' band histograms by vertex area (true) or vertex count (false).
    #[arg(long, default_value_t = PropagateOptions::default().area_weighted, action = clap::ArgAction::Set)]
    area_weighted: bool,
    /// Rounds of the label-aware refit of every target on its own parts (0 = off).
    #[arg(long, default_value_t = PropagateOptions::default().refit_rounds)]
    refit_rounds: usize,
    /// Weight of the target's own parts in the refit, relative to the votes.
    #[arg(long, default_value_t = PropagateOptions::default().refit_weight)]
    refit_weight: f64,
    /// For near-isometric collections (posed scans, TOSCA, FAUST): carry each unlabelled
    /// shape's labels point by point from its nearest source through a point map, kept where
    /// they agree with the propagation on at least --map-agreement of the area. Not for
    /// man-made collections (docs/PROPAGATION.md, "Map step").
    #[arg(long)]
    map_step: bool,
    /// Smallest agreement, in [0, 1], for the map step's labels to be kept.
    #[arg(long, default_value_t = MapStepOptions::default().min_agreement)]
    map_agreement: f64,
    #[command(flatten)]
    pipeline: super::pipeline_args::PipelineArgs,
}

pub fn run(args: PropagateArgs) -> Result<ExitCode> {
    let t0 = Instant::now();
    let mut options = PropagateCollectionOptions::default();
    options.pipeline = args.pipeline.options()?;
    options.graph.complete_limit = args.complete_limit;
    options.graph.neighbours = args.neighbours;
    options.propagate.smoothing_time = args.smoothing_time;
    options.propagate.max_sweeps = args.max_sweeps;
    options.propagate.network_weight = args.network_weight;
    options.propagate.similarity_power = args.similarity_power;
    options.propagate.size_prior = args.size_prior;
    options.propagate.part_score = match args.part_score.as_str() {
        "affinity" => PartScore::Affinity,
        "geometric" => PartScore::Geometric,
        o => bail!("--part-score {o}: expected affinity or geometric"),
    };
    options.propagate.area_weighted = args.area_weighted;
    options.propagate.refit_rounds = args.refit_rounds;
    options.propagate.refit_weight = args.refit_weight;
    if args.map_step {
        let mut m = MapStepOptions::default();
        m.min_agreement = args.map_agreement;
        options.map_step = Some(m);
    }
    options.cache_dir = Some(
        args.cache
            .clone()
            .unwrap_or_else(|| args.out.join(".cache")),
    );
    options.part_names = args.part_names.clone();
    let result = propagate_collection(&args.folder, &args.labels, &options)
        .with_context(|| format!("propagating labels over {}", args.folder.display()))?;
    for s in &result.skipped {
        eprintln!("error: {} (skipped)", s.error);
    }
    for w in &result.warnings {
        super::warn(w);
    }
    super::check_strict(result.skipped.len())?;
    let n = result.graph.node_count();
    if n == 0 {
        bail!("{}: no readable mesh", args.folder.display());
    }
    let t_solve = t0.elapsed();
    let summary = PropagationSummary::of(&result, &options.graph, &options.propagate);
    let mut written = write_propagation(&args.out, &result, &summary)?;
    let p = &result.propagation;
    if !args.no_pictures {
        let spin = super::spinner("pictures");
        let pictures: Vec<RenderShape> = (0..n)
            .map(|i| RenderShape {
                name: &result.graph.node(i).name,
                mesh: &result.meshes[i],
                labels: &p.labels[i],
                confidence: Some(p.shape_confidence[i]),
            })
            .collect();
        // The legends index names by label value; labels are the annotation's own integers.
        let names = legend_names(&p.parts, &result.part_names);
        written.extend(write_visuals(
            &args.out,
            &pictures,
            (!result.part_names.is_empty()).then_some(names.as_slice()),
            &RenderOptions::default(),
        )?);
        if let Some(b) = spin {
            b.finish_and_clear();
        }
    }
    if super::quiet() {
        return Ok(super::exit_code(
            result.skipped.len(),
            n + result.skipped.len(),
        ));
    }
    println!(
        "{} shapes labelled from {} source(s) with {} parts ({} sweeps{}); {} files in {}",
        n,
        result.sources.len(),
        p.parts.len(),
        p.sweeps,
        if p.converged { ", converged" } else { "" },
        written.len(),
        args.out.display()
    );
    let mut order: Vec<usize> = (0..n).filter(|&i| !p.sources[i]).collect();
    order.sort_by(|&a, &b| p.shape_confidence[a].total_cmp(&p.shape_confidence[b]));
    if let Some(&low) = order.first() {
        println!(
            "lowest confidence: {} ({:.2}); mean over unlabelled shapes {:.2}",
            result.graph.node(low).name,
            p.shape_confidence[low],
            order.iter().map(|&i| p.shape_confidence[i]).sum::<f64>() / order.len() as f64
        );
    }
    println!(
        "time: load + propagate {:.2} s, total {:.2} s",
        t_solve.as_secs_f64(),
        t0.elapsed().as_secs_f64()
    );
    Ok(super::exit_code(
        result.skipped.len(),
        n + result.skipped.len(),
    ))
}

/// Legend text per label value `0..=max`: the part's name when given, else empty (the legend
/// then shows the bare label).
fn legend_names(parts: &[i32], names: &PartNames) -> Vec<String> {
    let max = parts.iter().copied().max().unwrap_or(-1).max(-1);
    (0..=max)
        .map(|l| names.get(&l).cloned().unwrap_or_default())
        .collect()
}
