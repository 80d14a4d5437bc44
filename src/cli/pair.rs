//! `coseg pair A B -o OUT`: stable region correspondences between two meshes.

use anyhow::Result;
use clap::{Args, ValueEnum};
use coseg::jobs::{CacheChoice, JobShape, PairJob, PairOutcome, run_pair};
use coseg::maps::{MapOverrides, MapPreset, MapStep};
use coseg::stable::{
    Algorithm, AreaReference, Init, RefineOptions, SegmentPairOptions, StableRegionsOptions,
    TSearch, Threshold, VertexMap,
};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Clone, Copy, ValueEnum)]
enum AlgorithmArg {
    /// Algorithm 2: fixed area thresholds.
    Fixed,
    /// Algorithm 3: automatic thresholds.
    Auto,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum InitArg {
    /// Most extreme band signature (deterministic).
    Extreme,
    /// Random half of the remaining vertices (seeded).
    Random,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum MapPresetArg {
    /// `near-isometric` when the two spectra agree, else `general`.
    Auto,
    /// For different bodies (`MapGuidedOptions::default`).
    General,
    /// For two poses of one body (`MapGuidedOptions::near_isometric`).
    NearIsometric,
}

#[derive(Debug, Args)]
pub struct PairArgs {
    /// Mesh A (.obj, .off, .ply).
    a: PathBuf,
    /// Mesh B.
    b: PathBuf,
    /// Output directory (created if missing); files listed in docs/OUTPUTS.md.
    #[arg(short, long, visible_alias = "out")]
    output: PathBuf,
    /// Per-shape cache directory (spectrum, features, bands; read if valid, written
    /// otherwise). Default: `<OUTPUT>/.cache`.
    #[arg(long)]
    cache: Option<PathBuf>,
    /// Compute the per-shape data without reading or writing a cache.
    #[arg(long, conflicts_with = "cache")]
    no_cache: bool,
    /// Do not draw `preview.png`, `<name>.png` and `index.html`.
    #[arg(long)]
    no_pictures: bool,
    /// Algorithm 2 (fixed) or 3 (auto). [default: fixed]
    #[arg(long, value_enum)]
    algorithm: Option<AlgorithmArg>,
    /// Number of region pairs K (the last one is the leftovers).
    #[arg(long, default_value_t = StableRegionsOptions::default().pairs)]
    pairs: usize,
    /// Algorithm 2's area cutoff α (fraction of each shape's total area per pair).
    /// [default: 0.1]
    #[arg(long)]
    alpha: Option<f64>,
    /// Algorithm 2: α is a fraction of the remaining area instead of the total.
    #[arg(long)]
    alpha_of_remaining: bool,
    /// Algorithm 3's step δt.
    #[arg(long, default_value_t = StableRegionsOptions::default().delta_t)]
    delta_t: f64,
    /// Algorithm 3's largest t.
    #[arg(long, default_value_t = StableRegionsOptions::default().t_max)]
    t_max: f64,
    /// Algorithm 3: step t linearly as the paper does (slower) instead of bisecting.
    #[arg(long)]
    linear_t: bool,
    /// Initial indicators. [default: random]
    #[arg(long, value_enum)]
    init: Option<InitArg>,
    /// Seed of the random initial indicators.
    #[arg(long, default_value_t = StableRegionsOptions::default().seed)]
    seed: u64,
    /// Algorithm 1's iteration cap.
    #[arg(long, default_value_t = StableRegionsOptions::default().max_iterations)]
    max_iterations: usize,
    /// Rounds of boundary refinement after the algorithm (smoothed best responses between the
    /// two partitions, see `coseg::stable::refine_regions`); 0 keeps the algorithm's raw
    /// regions.
    #[arg(long, default_value_t = RefineOptions::default().max_rounds)]
    refine_rounds: usize,
    /// Heat-smoothing time of the refinement (unit-area surface; 0 = no smoothing).
    #[arg(long, default_value_t = RefineOptions::default().smoothing_time)]
    smoothing_time: f64,
    /// Weight of the point map's vote in the last step, which re-assigns B's vertices by band
    /// affinity plus a functional-map point map fitted to the region pairs (see
    /// `coseg::stable::map_guided_refinement`); 0 skips the step.
    /// [default: 0.5, or 2 with the near-isometric preset]
    #[arg(long)]
    map_weight: Option<f64>,
    /// Options of the map step: `near-isometric` (two poses of one body: a stronger vote and
    /// descriptors in the point map's last match; TOSCA within-class 95.7 % against 94.3 %,
    /// but worse on different bodies), `general`, or `auto`, which picks `near-isometric`
    /// when the two spectra agree (eigenvalue discrepancy below 0.03, see
    /// `coseg::maps::map_preset`). [default: auto]
    #[arg(long, value_enum)]
    map_preset: Option<MapPresetArg>,
    /// Same as `--map-preset near-isometric`.
    #[arg(long, conflicts_with = "map_preset")]
    near_isometric: bool,
    /// Size of the last functional map of that step (capped by the eigenpairs computed).
    /// [default: the preset's, 150]
    #[arg(long)]
    map_size: Option<usize>,
    /// Heat-smoothing time of that step's blended scores (0 = no smoothing).
    /// [default: the preset's, 0.001]
    #[arg(long)]
    map_smoothing_time: Option<f64>,
    /// Fit that step's point map to the refined regions, after the refinement, instead of to
    /// the algorithm's regions alongside it (slower: about 12 % on the 50k-vertex TOSCA pair,
    /// for 0.1 point of TOSCA correspondence ratio; see `SegmentPairOptions::map_after_refine`)
    #[arg(long)]
    map_after_refine: bool,
    /// Ground truth for the correspondence ratio: `identity`, or a file with one B index per
    /// vertex of A (negative = none).
    #[arg(long)]
    ground_truth: Option<String>,
    #[command(flatten)]
    pipeline: super::pipeline_args::PipelineArgs,
}

/// Algorithm 2's default area cut-off α, as the library sets it.
/// The algorithm's options the flags select.
fn region_options(args: &PairArgs) -> StableRegionsOptions {
    let mut opts = StableRegionsOptions::default();
    if let Some(a) = args.algorithm {
        opts.algorithm = match a {
            AlgorithmArg::Fixed => Algorithm::Fixed,
            AlgorithmArg::Auto => Algorithm::Auto,
        };
    }
    opts.pairs = args.pairs;
    if let Some(alpha) = args.alpha {
        opts.p = Threshold::AreaFraction(alpha);
        opts.q = Threshold::AreaFraction(alpha);
    }
    opts.area_reference = if args.alpha_of_remaining {
        AreaReference::Remaining
    } else {
        AreaReference::Total
    };
    opts.delta_t = args.delta_t;
    opts.t_max = args.t_max;
    opts.t_search = if args.linear_t {
        TSearch::Linear
    } else {
        TSearch::Bisect
    };
    if let Some(init) = args.init {
        opts.init = match init {
            InitArg::Extreme => Init::Extreme,
            InitArg::Random => Init::Random,
        };
    }
    opts.seed = args.seed;
    opts.max_iterations = args.max_iterations;
    opts
}

/// The map step the flags select: `--map-preset` (`auto`: resolved by the library from the
/// spectra) with the flags' overrides.
fn map_step(args: &PairArgs) -> MapStep {
    let overrides = MapOverrides {
        map_weight: args.map_weight,
        final_size: args.map_size,
        smoothing_time: args.map_smoothing_time,
    };
    let preset = match (args.near_isometric, args.map_preset) {
        (true, _) | (false, Some(MapPresetArg::NearIsometric)) => Some(MapPreset::NearIsometric),
        (false, Some(MapPresetArg::General)) => Some(MapPreset::General),
        (false, Some(MapPresetArg::Auto) | None) => None,
    };
    MapStep::with_preset(preset, overrides)
}

pub fn run(args: PairArgs) -> Result<ExitCode> {
    let job = pair_job(&args)?;
    let spin = super::spinner("per-shape data, stable regions, refinement and map step");
    let outcome = run_pair(
        [
            JobShape::File(args.a.clone()),
            JobShape::File(args.b.clone()),
        ],
        &job,
    );
    if let Some(b) = spin {
        b.finish_and_clear();
    }
    let outcome = outcome?;
    for w in &outcome.warnings {
        super::warn(w);
    }
    if !super::quiet() {
        report(&args, &outcome);
    }
    Ok(ExitCode::SUCCESS)
}

/// The job the flags select: the flag-to-option translation kept in one place.
fn pair_job(args: &PairArgs) -> Result<PairJob> {
    let mut job = PairJob::default();
    job.pipeline = args.pipeline.options()?;
    job.pair = segment_pair_options(args);
    job.cache = match (&args.cache, args.no_cache) {
        (_, true) => CacheChoice::Off,
        (Some(dir), false) => CacheChoice::Dir(dir.clone()),
        (None, false) => CacheChoice::Auto,
    };
    job.output = Some(args.output.clone());
    job.pictures = !args.no_pictures;
    job.ground_truth = match &args.ground_truth {
        None => None,
        Some(s) if s == "identity" => Some(VertexMap::Identity),
        Some(file) => Some(VertexMap::read(file)?),
    };
    Ok(job)
}

/// The whole pair stage's options the flags select: the flag-to-option translation kept in one
/// place, next to [`region_options`] and [`map_step`] which it combines; the affinity's
/// per-feature weights are left to the job (the families' shares over the band table).
fn segment_pair_options(args: &PairArgs) -> SegmentPairOptions {
    let mut opts = SegmentPairOptions::default();
    opts.regions = region_options(args);
    opts.refine = RefineOptions::rounds(args.refine_rounds, args.smoothing_time);
    opts.map_step = map_step(args);
    opts.map_after_refine = args.map_after_refine;
    opts
}

/// The lines `coseg pair` prints when not quiet: only reads the run's results, so it is kept
/// out of `run`.
fn report(args: &PairArgs, outcome: &PairOutcome) {
    if let Some(choice) = outcome.pair.map_preset {
        println!(
            "map step: {} preset (eigenvalue discrepancy {:.4})",
            match choice.preset {
                MapPreset::General => "general",
                MapPreset::NearIsometric => "near-isometric",
            },
            choice.discrepancy
        );
    }
    println!(
        "{} x {}: {} region pairs in {:.3} s{} -> {} files in {}",
        args.a.display(),
        args.b.display(),
        outcome.pair.regions.pairs.len(),
        outcome.seconds,
        outcome
            .correspondence_ratio
            .map_or(String::new(), |r| format!(
                ", correspondence ratio {:.2} %",
                100.0 * r
            )),
        outcome.written.len(),
        args.output.display()
    );
    let times = &outcome.pair.times;
    println!(
        "stages: algorithm {:.2} s, smoothers {:.2} s, refinement {:.2} s, map step {:.2} s",
        times.algorithm.as_secs_f64(),
        times.smoothers.as_secs_f64(),
        times.refine.as_secs_f64(),
        times.map_guided.as_secs_f64()
    );
    if !args.no_pictures {
        let out = args.output.display();
        println!("pictures: {out}/preview.png; viewer: {out}/index.html");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Debug, Parser)]
    struct Wrapper {
        #[command(flatten)]
        pair: PairArgs,
    }

    /// With no option given, `coseg pair` runs the library's defaults: the algorithm's
    /// options, the refinement's, the map step's size and smoothing, the per-shape pipeline.
    #[test]
    fn default_flags_select_the_library_defaults() {
        let w = Wrapper::try_parse_from(["coseg", "a.off", "b.off", "-o", "out"]).unwrap();
        assert_eq!(region_options(&w.pair), StableRegionsOptions::default());
        assert_eq!(
            w.pair.pipeline.options().unwrap(),
            coseg::pipeline::ShapePipelineOptions::default()
        );
        let refine = RefineOptions::default();
        assert_eq!(w.pair.refine_rounds, refine.max_rounds);
        assert_eq!(w.pair.smoothing_time, refine.smoothing_time);
        assert_eq!(map_step(&w.pair), MapStep::default());
        // The whole job: `coseg pair A B -o OUT` is `PairJob::default()` writing to OUT.
        let mut expected = PairJob::default();
        expected.output = Some(PathBuf::from("out"));
        assert_eq!(pair_job(&w.pair).unwrap(), expected);
        // The help's stated defaults are the presets' own.
        for preset in [MapPreset::General, MapPreset::NearIsometric] {
            let o = preset.options();
            assert_eq!(o.point_map.zoomout.final_size, 150);
            assert_eq!(o.smoothing_time, 0.001);
        }
        let near =
            Wrapper::try_parse_from(["coseg", "a", "b", "-o", "o", "--near-isometric"]).unwrap();
        assert_eq!(
            map_step(&near.pair),
            MapStep::Preset(MapPreset::NearIsometric, MapOverrides::default())
        );
    }
}
