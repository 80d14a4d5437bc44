//! Keyword options: a dict from the Python half, read key by key into the library's option
//! structs (starting from their `Default`s, so an absent key keeps the library's default), with
//! unknown keys rejected so that a typo never passes silently.

use coseg::bands::BandWeighting;
use coseg::features::{
    ExtrinsicOptions, FamilyWeights, FeatureError, parse_alignment, parse_families,
    parse_family_weights,
};
use coseg::graph::{GraphError, GraphOptions, RefineSizes};
use coseg::maps::{MapGuidedOptions, MapOverrides, MapPreset, MapStep, ZoomOutOptions};
use coseg::parts::{PartsFrom, PartsRequest, SegmentCollectionOptions};
use coseg::pipeline::ShapePipelineOptions;
use coseg::propagate::{MapStepOptions, PropagateOptions};
use coseg::stable::{
    Algorithm, AreaReference, Init, RefineOptions, SegmentPairOptions, StableRegionsOptions,
    TSearch, Threshold,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The CLI's `--features` default.
const DEFAULT_FEATURES: &str = "spectral";
/// The CLI's `--up` default.
const DEFAULT_UP: &str = "y";

/// The options dict, consumed key by key.
pub struct Opts<'py>(Option<Bound<'py, PyDict>>);

impl<'py> Opts<'py> {
    pub fn new(d: Option<Bound<'py, PyDict>>) -> Self {
        Self(d)
    }

    /// Removes `key` and converts it; `None` when absent or `None`.
    pub fn take<T: for<'a> FromPyObject<'a, 'py>>(&mut self, key: &str) -> PyResult<Option<T>> {
        let Some(d) = &self.0 else { return Ok(None) };
        let Some(v) = d.get_item(key)? else {
            return Ok(None);
        };
        d.del_item(key)?;
        if v.is_none() {
            return Ok(None);
        }
        v.extract::<T>().map(Some).map_err(|e| {
            let e: PyErr = e.into();
            super::input_err(format!("option {key}: {e}"))
        })
    }

    /// Errors on any key not consumed.
    pub fn finish(self) -> PyResult<()> {
        match &self.0 {
            Some(d) if !d.is_empty() => {
                let keys: Vec<String> = d.keys().iter().map(|k| k.to_string()).collect();
                Err(pyo3::exceptions::PyTypeError::new_err(format!(
                    "unknown option(s): {}",
                    keys.join(", ")
                )))
            }
            _ => Ok(()),
        }
    }

    /// `eigenpairs`, `hks`, `wks`, `curvature`, `bands`, `area_bands`, and the feature
    /// families: `features` (`spectral,extrinsic,sdf,user:DIR`), `up`, `directions`,
    /// `normals`, `family_weights` (`NAME=W,...`), as the CLI's `--features`, `--up`,
    /// `--directions`, `--normals`, `--family-weights` (same parsers, same defaults).
    pub fn pipeline(&mut self) -> PyResult<ShapePipelineOptions> {
        let mut p = ShapePipelineOptions::default();
        let features: Option<String> = self.take("features")?;
        let up: Option<String> = self.take("up")?;
        let directions: Option<usize> = self.take("directions")?;
        let normals: Option<usize> = self.take("normals")?;
        let weights: Option<String> = self.take("family_weights")?;
        let lib = |e: FeatureError| super::lib_err(&e);
        let alignment = parse_alignment(up.as_deref().unwrap_or(DEFAULT_UP)).map_err(lib)?;
        let (spectral, mut families) =
            parse_families(features.as_deref().unwrap_or(DEFAULT_FEATURES), alignment)
                .map_err(lib)?;
        if let Some(e) = families.extrinsic.as_mut() {
            if let Some(n) = directions {
                e.directions = n;
            }
            if let Some(n) = normals {
                e.normal_directions = n;
            }
        }
        parse_family_weights(weights.as_deref().unwrap_or(""), &mut families.weights)
            .map_err(lib)?;
        p.families = families;
        if let Some(k) = self.take("eigenpairs")? {
            p.spectrum.eigenpairs = k;
        }
        if let Some(k) = self.take("hks")? {
            p.descriptors.hks_count = k;
        }
        if let Some(k) = self.take("wks")? {
            p.descriptors.wks_count = k;
        }
        if let Some(k) = self.take("curvature")? {
            p.descriptors.curvature_count = k;
        }
        if let Some(k) = self.take("bands")? {
            p.bands.bands = k;
        }
        if self.take::<bool>("area_bands")? == Some(true) {
            p.bands.weighting = BandWeighting::Area;
        }
        if !spectral {
            p.descriptors.hks_count = 0;
            p.descriptors.wks_count = 0;
            p.descriptors.curvature_count = 0;
        }
        Ok(p)
    }

    /// The propagation's graph and solver options, as `coseg propagate` sets them.
    pub fn propagate(&mut self) -> PyResult<(GraphOptions, PropagateOptions)> {
        let mut graph = GraphOptions::default();
        if let Some(v) = self.take("complete_limit")? {
            graph.complete_limit = v;
        }
        if let Some(v) = self.take("neighbours")? {
            graph.neighbours = v;
        }
        let mut p = PropagateOptions::default();
        if let Some(v) = self.take("smoothing_time")? {
            p.smoothing_time = v;
        }
        if let Some(v) = self.take("max_sweeps")? {
            p.max_sweeps = v;
        }
        if let Some(v) = self.take("network_weight")? {
            p.network_weight = v;
        }
        if let Some(v) = self.take("similarity_power")? {
            p.similarity_power = v;
        }
        if let Some(v) = self.take("size_prior")? {
            p.size_prior = v;
        }
        if let Some(v) = self.take("area_weighted")? {
            p.area_weighted = v;
        }
        Ok((graph, p))
    }

    /// The propagation's map step, as `coseg propagate --map-step --map-agreement` sets it:
    /// `map_step` (bool) and `map_agreement`.
    pub fn map_step(&mut self) -> PyResult<Option<MapStepOptions>> {
        let on = self.take::<bool>("map_step")?.unwrap_or(false);
        let agreement: Option<f64> = self.take("map_agreement")?;
        Ok(on.then(|| {
            let mut m = MapStepOptions::default();
            if let Some(a) = agreement {
                m.min_agreement = a;
            }
            m
        }))
    }

    /// The collection stage's options, as `coseg segment` sets them.
    pub fn segment(&mut self) -> PyResult<SegmentCollectionOptions> {
        let lib = |e: GraphError| super::lib_err(&e);
        let regions: Option<usize> = self.take("regions")?;
        let parts = self
            .take::<String>("parts")?
            .map(|p| p.parse::<PartsRequest>())
            .transpose()
            .map_err(lib)?;
        let from = self
            .take::<String>("parts_from")?
            .map(|f| f.parse::<PartsFrom>())
            .transpose()
            .map_err(lib)?;
        // The mode as `coseg segment` reads it (the library's policy): parts by default,
        // `regions` alone for equal-area regions.
        let mut o2 = SegmentCollectionOptions::for_request(regions, parts, from);
        o2.cosegment.area_fraction = self.take("area_fraction")?;
        o2.cosegment.seed = self.take("seed")?;
        if let Some(p) = o2.parts.as_mut() {
            p.seed = o2.cosegment.seed;
        }
        if let Some(v) = self.take("complete_limit")? {
            o2.graph.complete_limit = v;
        }
        if let Some(v) = self.take("neighbours")? {
            o2.graph.neighbours = v;
        }
        let base = o2
            .refine
            .clone()
            .unwrap_or(SegmentCollectionOptions::DEFAULT_REFINE);
        let rounds = self.take("refine_rounds")?.unwrap_or(base.max_rounds);
        let time = self.take("smoothing_time")?.unwrap_or(base.smoothing_time);
        o2.refine = (rounds > 0).then_some({
            let mut opts = RefineOptions::default();
            opts.max_rounds = rounds;
            opts.smoothing_time = time;
            opts
        });
        if let Some(n) = self.take("starts")? {
            o2.starts = n;
        }
        if let Some(r) = self.take::<String>("refine_sizes")? {
            o2.refine_sizes = r.parse::<RefineSizes>().map_err(lib)?;
        }
        if let Some(b) = self.take::<f64>("snap_band")? {
            o2.set_snap_band(b).map_err(lib)?;
        }
        Ok(o2)
    }

    /// The pair stage's options, as `coseg pair` sets them.
    pub fn pair(&mut self) -> PyResult<PairOpts> {
        let mut r = StableRegionsOptions::default();
        if let Some(a) = self.take::<String>("algorithm")? {
            r.algorithm = match a.as_str() {
                "fixed" => Algorithm::Fixed,
                "auto" => Algorithm::Auto,
                _ => return Err(bad("algorithm", &a, "fixed, auto")),
            };
        }
        if let Some(v) = self.take("pairs")? {
            r.pairs = v;
        }
        if let Some(a) = self.take::<f64>("alpha")? {
            r.p = Threshold::AreaFraction(a);
            r.q = Threshold::AreaFraction(a);
        }
        if self.take::<bool>("alpha_of_remaining")? == Some(true) {
            r.area_reference = AreaReference::Remaining;
        }
        if let Some(v) = self.take("delta_t")? {
            r.delta_t = v;
        }
        if let Some(v) = self.take("t_max")? {
            r.t_max = v;
        }
        if self.take::<bool>("linear_t")? == Some(true) {
            r.t_search = TSearch::Linear;
        }
        if let Some(a) = self.take::<String>("init")? {
            r.init = match a.as_str() {
                "extreme" => Init::Extreme,
                "random" => Init::Random,
                _ => return Err(bad("init", &a, "extreme, random")),
            };
        }
        if let Some(v) = self.take("seed")? {
            r.seed = v;
        }
        if let Some(v) = self.take("max_iterations")? {
            r.max_iterations = v;
        }
        let base = RefineOptions::default();
        let rounds = self.take("refine_rounds")?.unwrap_or(base.max_rounds);
        let time = self.take("smoothing_time")?.unwrap_or(base.smoothing_time);
        let preset = match self.take::<String>("map_preset")?.as_deref() {
            None | Some("auto") => None,
            Some("general") => Some(MapPreset::General),
            Some("near-isometric") | Some("near_isometric") => Some(MapPreset::NearIsometric),
            Some(other) => return Err(bad("map_preset", other, "auto, general, near-isometric")),
        };
        Ok(PairOpts {
            regions: r,
            refine: (rounds > 0).then_some({
                let mut opts = RefineOptions::default();
                opts.max_rounds = rounds;
                opts.smoothing_time = time;
                opts
            }),
            preset,
            map_weight: self.take("map_weight")?,
            map_size: self.take("map_size")?,
            map_smoothing_time: self.take("map_smoothing_time")?,
        })
    }
}

fn bad(key: &str, value: &str, allowed: &str) -> PyErr {
    super::input_err(format!("option {key}: {value:?} is not one of {allowed}"))
}

/// The pair options before the map preset is chosen from the two spectra.
#[derive(Clone)]
pub struct PairOpts {
    regions: StableRegionsOptions,
    refine: Option<RefineOptions>,
    preset: Option<MapPreset>,
    map_weight: Option<f64>,
    map_size: Option<usize>,
    map_smoothing_time: Option<f64>,
}

impl PairOpts {
    /// The library's options (the map step resolved by `segment_pair`, as in `coseg pair`).
    pub fn options(&self) -> SegmentPairOptions {
        let overrides = MapOverrides {
            map_weight: self.map_weight,
            final_size: self.map_size,
            smoothing_time: self.map_smoothing_time,
        };
        {
            let mut opts = SegmentPairOptions::default();
            opts.regions = self.regions.clone();
            opts.refine = self.refine.clone();
            opts.map_step = match self.preset {
                None => MapStep::Auto(overrides),
                Some(p) => MapStep::Preset(p, overrides),
            };
            opts
        }
    }
}

/// Library defaults of every keyword the package exposes.
pub fn defaults(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    let p = ShapePipelineOptions::default();
    d.set_item("eigenpairs", p.spectrum.eigenpairs)?;
    d.set_item("hks", p.descriptors.hks_count)?;
    d.set_item("wks", p.descriptors.wks_count)?;
    d.set_item("curvature", p.descriptors.curvature_count)?;
    d.set_item("bands", p.bands.bands)?;
    d.set_item("area_bands", p.bands.weighting == BandWeighting::Area)?;
    d.set_item("features", DEFAULT_FEATURES)?;
    d.set_item("up", DEFAULT_UP)?;
    d.set_item("directions", ExtrinsicOptions::default().directions)?;
    d.set_item("normals", ExtrinsicOptions::default().normal_directions)?;
    let w = FamilyWeights::default();
    let weights = PyDict::new(py);
    weights.set_item("spectral", w.spectral)?;
    weights.set_item("extrinsic", w.extrinsic)?;
    weights.set_item("normals", w.normals)?;
    weights.set_item("sdf", w.sdf)?;
    weights.set_item("user", w.user)?;
    d.set_item("family_weights", weights)?;
    let s = SegmentCollectionOptions::default();
    let refine = s
        .refine
        .clone()
        .unwrap_or(SegmentCollectionOptions::DEFAULT_REFINE);
    d.set_item("regions", s.cosegment.regions)?;
    d.set_item("area_fraction", s.cosegment.area_fraction)?;
    d.set_item("segment_seed", s.cosegment.seed)?;
    d.set_item("complete_limit", s.graph.complete_limit)?;
    d.set_item("neighbours", s.graph.neighbours)?;
    d.set_item("segment_refine_rounds", refine.max_rounds)?;
    d.set_item("segment_smoothing_time", refine.smoothing_time)?;
    d.set_item("starts", s.starts)?;
    d.set_item("refine_sizes", "free")?;
    d.set_item(
        "parts_from",
        match s.parts_from {
            PartsFrom::Adaptive => "adaptive",
            PartsFrom::Geometry { .. } => "geometry",
        },
    )?;
    d.set_item(
        "parts",
        match s.parts.as_ref().and_then(|p| p.parts) {
            Some(k) => k.to_string(),
            None => "auto".to_string(),
        },
    )?;
    let a = coseg::parts::AdaptiveOptions::default();
    d.set_item("max_parts", a.max_parts)?;
    let r = StableRegionsOptions::default();
    d.set_item(
        "algorithm",
        match r.algorithm {
            Algorithm::Fixed => "fixed",
            Algorithm::Auto => "auto",
        },
    )?;
    d.set_item("pairs", r.pairs)?;
    if let Threshold::AreaFraction(a) = r.p {
        d.set_item("alpha", a)?;
    }
    d.set_item(
        "alpha_of_remaining",
        r.area_reference == AreaReference::Remaining,
    )?;
    d.set_item("delta_t", r.delta_t)?;
    d.set_item("t_max", r.t_max)?;
    d.set_item("linear_t", r.t_search == TSearch::Linear)?;
    d.set_item(
        "init",
        match r.init {
            Init::Extreme => "extreme",
            Init::Random => "random",
        },
    )?;
    d.set_item("pair_seed", r.seed)?;
    d.set_item("max_iterations", r.max_iterations)?;
    let pr = RefineOptions::default();
    d.set_item("pair_refine_rounds", pr.max_rounds)?;
    d.set_item("pair_smoothing_time", pr.smoothing_time)?;
    let po = PropagateOptions::default();
    d.set_item("propagate_smoothing_time", po.smoothing_time)?;
    d.set_item("max_sweeps", po.max_sweeps)?;
    d.set_item("network_weight", po.network_weight)?;
    d.set_item("similarity_power", po.similarity_power)?;
    d.set_item("size_prior", po.size_prior)?;
    d.set_item("area_weighted", po.area_weighted)?;
    d.set_item("map_agreement", MapStepOptions::default().min_agreement)?;
    d.set_item("map_preset", "auto")?;
    d.set_item("map_size", ZoomOutOptions::default().final_size)?;
    d.set_item(
        "map_smoothing_time",
        MapGuidedOptions::default().smoothing_time,
    )?;
    Ok(d)
}
