//! Keyword options: a dict from the Python half, read key by key into the library's option
//! structs (starting from their `Default`s, so an absent key keeps the library's default), with
//! unknown keys rejected so that a typo never passes silently.

use coseg::bands::BandWeighting;
use coseg::features::FeatureError;
use coseg::graph::GraphOptions;
use coseg::jobs::SegmentJob;
use coseg::maps::{MapOverrides, MapPreset, MapStep};
use coseg::pipeline::{FamilyFlags, ShapePipelineOptions};
use coseg::propagate::{MapStepOptions, PropagateOptions};
use coseg::stable::{
    AreaReference, RefineOptions, SegmentPairOptions, StableRegionsOptions, TSearch, Threshold,
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

    /// Removes `key`, a string, and parses it with the library's parser (`FromStr`, the names
    /// the CLI's flags take); `None` when absent or `None`.
    pub fn parse<T: std::str::FromStr>(&mut self, key: &str) -> PyResult<Option<T>>
    where
        T::Err: std::fmt::Display,
    {
        self.take::<String>(key)?
            .map(|v| v.parse::<T>())
            .transpose()
            .map_err(|e| super::input_err(format!("option {key}: {e}")))
    }

    /// Removes `key` and, when present and not `None`, converts it into `field`; an absent key
    /// keeps the field's value (the library's default).
    pub fn set<T: for<'a> FromPyObject<'a, 'py>>(
        &mut self,
        key: &str,
        field: &mut T,
    ) -> PyResult<()> {
        if let Some(v) = self.take(key)? {
            *field = v;
        }
        Ok(())
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
        self.set("features", &mut flags.features)?;
        self.set("up", &mut flags.up)?;
        self.set("directions", &mut flags.directions)?;
        self.set("normals", &mut flags.normals)?;
        self.set("family_weights", &mut flags.family_weights)?;
        self.set("eigenpairs", &mut p.spectrum.eigenpairs)?;
        self.set("hks", &mut p.descriptors.hks_count)?;
        self.set("wks", &mut p.descriptors.wks_count)?;
        self.set("curvature", &mut p.descriptors.curvature_count)?;
        self.set("bands", &mut p.bands.bands)?;
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
        self.set("complete_limit", &mut graph.complete_limit)?;
        self.set("neighbours", &mut graph.neighbours)?;
        let mut p = PropagateOptions::default();
        self.set("smoothing_time", &mut p.smoothing_time)?;
        self.set("max_sweeps", &mut p.max_sweeps)?;
        self.set("network_weight", &mut p.network_weight)?;
        self.set("similarity_power", &mut p.similarity_power)?;
        self.set("size_prior", &mut p.size_prior)?;
        self.set("area_weighted", &mut p.area_weighted)?;
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
        let mut job = SegmentJob::default();
        job.choose_features = match &self.0 {
            Some(d) => !d.get_item("features")?.is_some_and(|v| !v.is_none()),
            None => true,
        };
        job.pipeline = self.pipeline()?;
        job.regions = self.take("regions")?;
        job.parts = self.parse("parts")?;
        job.parts_from = self.parse("parts_from")?;
        job.snap_band = self.take("snap_band")?;
        let c = &mut job.collection;
        c.cosegment.area_fraction = self.take("area_fraction")?;
        c.cosegment.seed = self.take("seed")?;
        self.set("complete_limit", &mut c.graph.complete_limit)?;
        self.set("neighbours", &mut c.graph.neighbours)?;
        let (mut rounds, mut time) = RefineOptions::rounds_of(c.refine.as_ref());
        self.set("refine_rounds", &mut rounds)?;
        self.set("smoothing_time", &mut time)?;
        c.refine = RefineOptions::rounds(rounds, time);
        self.set("starts", &mut c.starts)?;
        if let Some(r) = self.parse("refine_sizes")? {
            c.refine_sizes = r;
        }
        Ok(job)
    }

    /// The pair stage's options, as `coseg pair` sets them.
    pub fn pair(&mut self) -> PyResult<PairOpts> {
        let mut r = StableRegionsOptions::default();
        if let Some(a) = self.parse("algorithm")? {
            r.algorithm = a;
        }
        self.set("pairs", &mut r.pairs)?;
        if let Some(a) = self.take::<f64>("alpha")? {
            r.p = Threshold::AreaFraction(a);
            r.q = Threshold::AreaFraction(a);
        }
        if self.take::<bool>("alpha_of_remaining")? == Some(true) {
            r.area_reference = AreaReference::Remaining;
        }
        self.set("delta_t", &mut r.delta_t)?;
        self.set("t_max", &mut r.t_max)?;
        if self.take::<bool>("linear_t")? == Some(true) {
            r.t_search = TSearch::Linear;
        }
        if let Some(a) = self.parse("init")? {
            r.init = a;
        }
        self.set("seed", &mut r.seed)?;
        self.set("max_iterations", &mut r.max_iterations)?;
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
            refine: RefineOptions::rounds(rounds, time),
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
