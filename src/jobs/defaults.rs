//! [`defaults`]: every default the front ends expose, by command and keyword, read from the
//! options' `Default`s — what the command line's flag defaults and the Python package's keyword
//! defaults are compared with.

use super::{AlignJob, PairJob, PropagateJob, SegmentJob};
use crate::generate::GenerateOptions;
use crate::graph::RefineSizes;
use crate::maps::{MapPreset, MapStep};
use crate::pipeline::{FamilyFlags, ShapePipelineOptions};
use crate::propagate::PartScore;
use crate::render::RenderOptions;
use crate::spectral::SpectrumOptions;
use crate::stable::{AreaReference, Init, RefineOptions, TSearch, Threshold};
use serde_json::{Value, json};

/// The library's default of every option the command line and the Python package expose, as a
/// JSON object `{command: {keyword: value}}`: keywords are the flags' names in snake case
/// (`--complete-limit` → `complete_limit`), which the Python keywords share; `"pipeline"`
/// holds the per-shape options every command that computes per-shape data takes. A `null`
/// value: the option is unset by default (the library chooses, or the feature is off); a
/// switch's value is its state without the flag. Read from the jobs' and the stages' `Default`s,
/// so it cannot drift from them.
///
/// ```
/// let d = coseg::jobs::defaults();
/// assert_eq!(d["pipeline"]["eigenpairs"], 200);
/// assert_eq!(d["segment"]["regions"], serde_json::Value::Null); // parts, chosen from the data
/// ```
pub fn defaults() -> Value {
    json!({
        "pipeline": pipeline(),
        "segment": segment(),
        "pair": pair(),
        "propagate": propagate(),
        "align": align(),
        "spectrum": spectrum(),
        "render": { "cell_size": RenderOptions::default().cell_size },
        "generate": {
            "seed": GenerateOptions::default().seed,
            "count": GenerateOptions::default().count,
        },
    })
}

fn pipeline() -> Value {
    let p = ShapePipelineOptions::default();
    let f = FamilyFlags::default();
    json!({
        "eigenpairs": p.spectrum.eigenpairs,
        "hks": p.descriptors.hks_count,
        "wks": p.descriptors.wks_count,
        "curvature": p.descriptors.curvature_count,
        "bands": p.bands.bands,
        "area_bands": p.bands.weighting == crate::bands::BandWeighting::Area,
        "features": f.features,
        "up": f.up,
        "directions": f.directions,
        "normals": f.normals,
        "family_weights": f.family_weights,
        "laplacian": p.spectrum.laplacian.to_string(),
    })
}

fn segment() -> Value {
    let j = SegmentJob::default();
    let c = &j.collection;
    let (refine_rounds, smoothing_time) = RefineOptions::rounds_of(c.refine.as_ref());
    json!({
        "regions": j.regions,
        "parts": j.parts.map(|p| match p {
            crate::parts::PartsRequest::Auto => "auto".to_string(),
            crate::parts::PartsRequest::Count(k) => k.to_string(),
        }),
        "parts_from": j.parts_from.map(|p| match p {
            crate::parts::PartsFrom::Adaptive => "adaptive",
            crate::parts::PartsFrom::Geometry { .. } => "geometry",
        }),
        "snap_band": j.snap_band,
        "area_fraction": c.cosegment.area_fraction,
        "seed": c.cosegment.seed,
        "starts": c.starts,
        "complete_limit": c.graph.complete_limit,
        "neighbours": c.graph.neighbours,
        "refine_rounds": refine_rounds,
        "smoothing_time": smoothing_time,
        "refine_sizes": match c.refine_sizes {
            RefineSizes::Free => "free".to_string(),
            RefineSizes::Keep { tolerance } => format!("keep:{tolerance}"),
        },
    })
}

fn pair() -> Value {
    let j = PairJob::default();
    let r = &j.pair.regions;
    let alpha = match r.p {
        Threshold::AreaFraction(a) => Some(a),
        _ => None,
    };
    let (preset, overrides) = match &j.pair.map_step {
        MapStep::Auto(o) => ("auto", Some(o)),
        MapStep::Preset(MapPreset::General, o) => ("general", Some(o)),
        MapStep::Preset(MapPreset::NearIsometric, o) => ("near-isometric", Some(o)),
        _ => ("auto", None),
    };
    let refine = j.pair.refine.clone();
    json!({
        "algorithm": match r.algorithm {
            crate::stable::Algorithm::Fixed => "fixed",
            crate::stable::Algorithm::Auto => "auto",
        },
        "pairs": r.pairs,
        "alpha": alpha,
        "alpha_of_remaining": r.area_reference == AreaReference::Remaining,
        "delta_t": r.delta_t,
        "t_max": r.t_max,
        "linear_t": r.t_search == TSearch::Linear,
        "init": match r.init {
            Init::Extreme => "extreme",
            Init::Random => "random",
        },
        "seed": r.seed,
        "max_iterations": r.max_iterations,
        "refine_rounds": refine.as_ref().map_or(0, |r| r.max_rounds),
        "smoothing_time": refine.map(|r| r.smoothing_time),
        "map_preset": preset,
        "map_weight": overrides.and_then(|o| o.map_weight),
        "map_size": overrides.and_then(|o| o.final_size),
        "map_smoothing_time": overrides.and_then(|o| o.smoothing_time),
    })
}

fn propagate() -> Value {
    let j = PropagateJob::default();
    let (g, p) = (&j.propagation.graph, &j.propagation.propagate);
    json!({
        "complete_limit": g.complete_limit,
        "neighbours": g.neighbours,
        "smoothing_time": p.smoothing_time,
        "max_sweeps": p.max_sweeps,
        "network_weight": p.network_weight,
        "similarity_power": p.similarity_power,
        "size_prior": p.size_prior,
        "part_score": match p.part_score {
            PartScore::Affinity => "affinity",
            PartScore::Geometric => "geometric",
        },
        "area_weighted": p.area_weighted,
        "refit_rounds": p.refit_rounds,
        "refit_weight": p.refit_weight,
        "map_step": j.propagation.map_step.is_some(),
        "map_agreement": crate::propagate::MapStepOptions::default().min_agreement,
    })
}

fn align() -> Value {
    let j = AlignJob::default();
    json!({
        "neighbours": j.align.neighbours,
        "write_meshes": j.write_meshes,
    })
}

fn spectrum() -> Value {
    let s = SpectrumOptions::default();
    json!({
        "eigenpairs": s.eigenpairs,
        "shift": s.shift,
        "tolerance": s.tolerance,
        "block_size": s.block_size,
        "seed": s.seed,
        "solver_threads": s.threads,
        "basis_size": s.basis_size,
        "laplacian": s.laplacian.to_string(),
    })
}
