//! `coseg propagate FOLDER --labels DIR-OR-FILES -o OUT`: part labels from a few annotated
//! shapes to every mesh of a folder.

use anyhow::{Result, bail};
use clap::Args;
use coseg::jobs::{PropagateInput, PropagateJob, run_propagate};
use coseg::propagate::{MapStepOptions, PartScore, PropagateOptions};
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
    #[arg(long, default_value_t = PropagateJob::default().propagation.graph.complete_limit)]
    complete_limit: usize,
    /// Neighbours per shape of the nearest-neighbour graph.
    #[arg(long, default_value_t = PropagateJob::default().propagation.graph.neighbours)]
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
    /// [default: affinity]
    #[arg(long)]
    part_score: Option<String>,
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

/// The job `coseg propagate` runs with these flags (the flags translated, nothing else).
fn propagate_job(args: &PropagateArgs) -> Result<PropagateJob> {
    let mut job = PropagateJob::default();
    let options = &mut job.propagation;
    options.pipeline = args.pipeline.options()?;
    options.graph.complete_limit = args.complete_limit;
    options.graph.neighbours = args.neighbours;
    options.propagate.smoothing_time = args.smoothing_time;
    options.propagate.max_sweeps = args.max_sweeps;
    options.propagate.network_weight = args.network_weight;
    options.propagate.similarity_power = args.similarity_power;
    options.propagate.size_prior = args.size_prior;
    if let Some(score) = &args.part_score {
        options.propagate.part_score = match score.as_str() {
            "affinity" => PartScore::Affinity,
            "geometric" => PartScore::Geometric,
            o => bail!("--part-score {o}: expected affinity or geometric"),
        };
    }
    options.propagate.area_weighted = args.area_weighted;
    options.propagate.refit_rounds = args.refit_rounds;
    options.propagate.refit_weight = args.refit_weight;
    if args.map_step {
        let mut m = MapStepOptions::default();
        m.min_agreement = args.map_agreement;
        options.map_step = Some(m);
    }
    options.part_names = args.part_names.clone();
    job.cache = super::cache_or_auto(&args.cache);
    job.output = Some(args.out.clone());
    job.pictures = !args.no_pictures;
    Ok(job)
}

pub fn run(args: PropagateArgs) -> Result<ExitCode> {
    let t0 = Instant::now();
    let job = propagate_job(&args)?;
    let spin = super::spinner("propagating");
    let outcome = run_propagate(
        PropagateInput::Folder {
            folder: args.folder.clone(),
            labels: args.labels.clone(),
        },
        &job,
    );
    if let Some(b) = spin {
        b.finish_and_clear();
    }
    let outcome = outcome?;
    let result = &outcome.result;
    for s in &result.skipped {
        eprintln!("error: {} (skipped)", s.error);
    }
    for w in &result.warnings {
        super::warn(w);
    }
    super::check_strict(result.skipped.len())?;
    let n = result.graph.node_count();
    let written = &outcome.written;
    let p = &result.propagation;
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
    println!("time: total {:.2} s", t0.elapsed().as_secs_f64());
    Ok(super::exit_code(
        result.skipped.len(),
        n + result.skipped.len(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bare command runs the job's default: the CLI chooses no default of its own.
    #[test]
    fn the_bare_command_runs_the_default_job() {
        let args: PropagateArgs =
            super::super::parse_args(&["coseg", "shapes", "--labels", "a.seg", "-o", "out"]);
        let job = propagate_job(&args).unwrap();
        let mut want = PropagateJob::default();
        want.output = Some(PathBuf::from("out"));
        want.pictures = true;
        assert_eq!(format!("{job:?}"), format!("{want:?}"));
    }
}
