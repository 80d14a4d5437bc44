//! Keyword options: a dict from the Python half, read key by key into the library's option
//! structs (starting from their `Default`s, so an absent key keeps the library's default), with
//! unknown keys rejected so that a typo never passes silently.

use coseg::bands::BandWeighting;
use coseg::features::FeatureError;
use coseg::graph::{GraphError, GraphOptions, RefineSizes};
use coseg::jobs::SegmentJob;
use coseg::maps::{MapOverrides, MapPreset, MapStep};
use coseg::parts::{PartsFrom, PartsRequest};
use coseg::pipeline::{FamilyFlags, ShapePipelineOptions};
use coseg::propagate::{MapStepOptions, PropagateOptions};
use coseg::stable::{
    Algorithm, AreaReference, Init, RefineOptions, SegmentPairOptions, StableRegionsOptions,
    TSearch, Threshold,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

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
    /// `--directions`, `--normals`, `--family-weights` (same parsers, the library's
    /// [`FamilyFlags`] defaults).
    pub fn pipeline(&mut self) -> PyResult<ShapePipelineOptions> {
        let mut p = ShapePipelineOptions::default();
        let mut flags = FamilyFlags::default();
        if let Some(f) = self.take("features")? {
            flags.features = f;
        }
        if let Some(u) = self.take("up")? {
            flags.up = u;
        }
        if let Some(n) = self.take("directions")? {
            flags.directions = n;
        }
        if let Some(n) = self.take("normals")? {
            flags.normals = n;
        }
        if let Some(w) = self.take("family_weights")? {
            flags.family_weights = w;
        }
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
        p.set_family_flags(&flags)
            .map_err(|e: FeatureError| super::lib_err(&e))?;
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

    /// The segment job, as `coseg segment` sets it: the per-shape options, and the families
    /// chosen from the data unless `features` is given.
    pub fn segment(&mut self) -> PyResult<SegmentJob> {
        let lib = |e: GraphError| super::lib_err(&e);
        let mut job = SegmentJob::default();
        job.choose_features = match &self.0 {
            Some(d) => !d.get_item("features")?.is_some_and(|v| !v.is_none()),
            None => true,
        };
        job.pipeline = self.pipeline()?;
        job.regions = self.take("regions")?;
        job.parts = self
            .take::<String>("parts")?
            .map(|p| p.parse::<PartsRequest>())
            .transpose()
            .map_err(lib)?;
        job.parts_from = self
            .take::<String>("parts_from")?
            .map(|f| f.parse::<PartsFrom>())
            .transpose()
            .map_err(lib)?;
        job.snap_band = self.take("snap_band")?;
        job.area_fraction = self.take("area_fraction")?;
        job.seed = self.take("seed")?;
        if let Some(v) = self.take("complete_limit")? {
            job.graph.complete_limit = v;
        }
        if let Some(v) = self.take("neighbours")? {
            job.graph.neighbours = v;
        }
        if let Some(v) = self.take("refine_rounds")? {
            job.refine_rounds = v;
        }
        if let Some(v) = self.take("smoothing_time")? {
            job.smoothing_time = v;
        }
        if let Some(n) = self.take("starts")? {
            job.starts = n;
        }
        if let Some(r) = self.take::<String>("refine_sizes")? {
            job.refine_sizes = r.parse::<RefineSizes>().map_err(lib)?;
        }
        Ok(job)
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
