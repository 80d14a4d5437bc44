//! [`segment_pair`]: the whole pair stage in one call (Algorithm 2 or 3 →
//! [`refine_regions`] → [`map_guided_refinement`](super::map_guided_refinement), all on one
//! affinity), as `coseg pair` runs it.

use super::map_guided_refinement::region_map;
use super::stable_regions::{pair_affinity, stable_regions_with};
use super::{
    RefineOptions, StableError, StableRegions, StableRegionsOptions, point_map_refinement,
    refine_regions,
};
use crate::affinity::BandAffinity;
use crate::bands::BandTable;
use crate::maps::ShapeGeometry;
use crate::maps::{MapGuidedOptions, MapStep, PresetChoice};
use crate::mesh::TriMesh;
use crate::option_range::non_negative;
use crate::spectral::{HeatSmoother, Spectrum};
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};

/// Options of [`segment_pair`]. The defaults are `coseg pair`'s with no flags: the map step's
/// options are those [`map_preset`](crate::maps::map_preset) picks from the two spectra
/// ([`MapStep::Auto`]), which on two poses of one body is the configuration that scores
/// best on the TOSCA within-class pairs (README, "Correspondence ratio").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct SegmentPairOptions {
    /// Algorithm 2 or 3 and their options (default: Algorithm 2 at a 10 % area cutoff,
    /// 10 pairs, random initial indicators with seed 0).
    pub regions: StableRegionsOptions,
    /// Boundary refinement of both partitions; `None` keeps the algorithm's regions
    /// (default: [`RefineOptions::default`]).
    pub refine: Option<RefineOptions>,
    /// The last step, B's regions re-assigned by band affinity and a point map: its options,
    /// resolved for the pair ([`MapStep::resolve`]); [`MapStep::Off`] skips it (default:
    /// [`MapStep::Auto`]).
    pub map_step: MapStep,
    /// Weight of each feature (column of the band tables) in the affinity of every stage, as
    /// [`pair_affinity`](super::pair_affinity) takes them; `None` = equal weights (default).
    /// `coseg pair` sets the feature families' shares,
    /// [`ShapePipelineOptions::feature_weights`](crate::pipeline::ShapePipelineOptions::feature_weights),
    /// as `coseg segment` and `coseg propagate` do: `None` when the table has one family.
    #[serde(default)]
    pub feature_weights: Option<Vec<f64>>,
    /// Fit the map step's point map to the refined regions, after the refinement, instead of
    /// to the algorithm's regions alongside it (default `false`). The overlap saves the
    /// refinement's time where the map's assignment leaves a core idle: 12 % of `coseg pair`'s
    /// wall time on victoria0 × david0, for 0.09–0.12 points of TOSCA correspondence ratio
    /// (95.55 / 95.61 % against 95.64 / 95.73 %, seeds 0 / 1; docs/PERFORMANCE.md, "Fourth
    /// pass").
    #[serde(default)]
    pub map_after_refine: bool,
}

impl Default for SegmentPairOptions {
    fn default() -> Self {
        SegmentPairOptions {
            regions: StableRegionsOptions::default(),
            refine: Some(RefineOptions::default()),
            map_step: MapStep::default(),
            feature_weights: None,
            map_after_refine: false,
        }
    }
}

/// One shape as [`segment_pair`] needs it: the mesh, and the spectrum and band table computed
/// from it (e.g. [`compute_shape_data`](crate::pipeline::compute_shape_data)).
#[derive(Debug, Clone, Copy)]
pub struct PairShape<'a> {
    /// The mesh (vertex areas, positions, and the heat smoothers' Laplacian).
    pub mesh: &'a TriMesh,
    /// Its unit-area Laplace–Beltrami spectrum (used by the map step).
    pub spectrum: &'a Spectrum,
    /// Its `d × N` band table.
    pub bands: &'a BandTable,
    /// Its descriptors, feature-major (`Descriptors::values`); optional, they sharpen the map
    /// step's point map (see [`ZoomOutOptions::descriptor_weight`](crate::maps::ZoomOutOptions)).
    pub descriptors: Option<&'a [f64]>,
}

impl<'a> PairShape<'a> {
    fn geometry(&self) -> ShapeGeometry<'a> {
        ShapeGeometry {
            spectrum: self.spectrum,
            positions: self.mesh.positions(),
            descriptors: self.descriptors,
        }
    }
}

/// Wall time of each stage of [`segment_pair`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PairTimes {
    /// Building the affinity ([`pair_affinity`]) and
    /// [`stable_regions_with`](super::stable_regions_with).
    pub algorithm: Duration,
    /// Factorising the heat smoothers.
    pub smoothers: Duration,
    /// [`refine_regions`].
    pub refine: Duration,
    /// [`map_guided_refinement`](super::map_guided_refinement). Unless
    /// [`SegmentPairOptions::map_after_refine`], its point map is computed alongside the
    /// refinement, so the two times overlap.
    pub map_guided: Duration,
}

/// The result of [`segment_pair`].
#[derive(Debug, Clone)]
pub struct SegmentedPair {
    /// The corresponding regions after every requested stage.
    pub regions: StableRegions,
    /// Per-stage wall times.
    pub times: PairTimes,
    /// The optional stages that could not run on these shapes (each kept the previous
    /// stage's regions), in stage order; empty when every requested stage ran.
    pub fallbacks: Vec<StageFallback>,
    /// The map step's options as resolved for this pair ([`MapStep::resolve`]); `None` when
    /// it was off.
    pub map_guided: Option<MapGuidedOptions>,
    /// The preset the map step used and the pair's eigenvalue discrepancy, when it ran with a
    /// preset.
    pub map_preset: Option<PresetChoice>,
}

/// Stable region correspondences between two shapes: Algorithm 2 or 3
/// ([`stable_regions_with`](super::stable_regions_with)), then (by default) [`refine_regions`]
/// and [`map_guided_refinement`](super::map_guided_refinement), with heat smoothers built on
/// the meshes at the stages' smoothing times. Every stage runs on one affinity, [`pair_affinity`] with
/// [`SegmentPairOptions::feature_weights`] (equal weights by default). The map step's point
/// map is fitted to the algorithm's regions and computed alongside the refinement, then
/// blended into the refined regions ([`point_map_refinement`]); with
/// [`SegmentPairOptions::map_after_refine`] it is fitted to the refined regions, after them,
/// exactly [`map_guided_refinement`](super::map_guided_refinement) of the refined regions.
///
/// The two later stages are optional: one that cannot run on these shapes (a smoother that
/// cannot be factored, a map that cannot be fitted) leaves the previous stage's regions and is
/// listed in [`SegmentedPair::fallbacks`] with the reason. Errors are the algorithm's and
/// invalid options only.
///
/// Deterministic: the same shapes and options give the same regions, bit for bit.
///
/// ```no_run
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use coseg::pipeline::{compute_shape_data, ShapePipelineOptions};
/// use coseg::mesh::read_mesh;
/// use coseg::stable::{segment_pair, PairShape, SegmentPairOptions};
/// let (ma, mb) = (read_mesh("cat0.off")?, read_mesh("cat1.off")?);
/// let pipe = ShapePipelineOptions::default();
/// let (da, db) = (compute_shape_data(&ma, &pipe)?, compute_shape_data(&mb, &pipe)?);
/// let a = PairShape { mesh: &ma, spectrum: &da.spectrum, bands: &da.bands, descriptors: None };
/// let b = PairShape { mesh: &mb, spectrum: &db.spectrum, bands: &db.bands, descriptors: None };
/// let out = segment_pair(a, b, &SegmentPairOptions::default())?;
/// println!("{} region pairs in {:?}", out.regions.pairs.len(), out.times.algorithm);
/// # Ok(()) }
/// ```
pub fn segment_pair(
    a: PairShape<'_>,
    b: PairShape<'_>,
    options: &SegmentPairOptions,
) -> Result<SegmentedPair, StableError> {
    check_sizes(a, b)?;
    let resolved = options.map_step.resolve(a.spectrum, b.spectrum)?;
    let (mut map_guided_options, map_preset) = (resolved.options, resolved.preset);
    // The map step's descriptor term weighs the columns as the affinity does.
    if let Some(m) = map_guided_options.as_mut() {
        m.point_map.zoomout.descriptor_weights = options.feature_weights.clone();
    }
    check_stage_options(options.refine.as_ref(), map_guided_options.as_ref())?;
    let mut times = PairTimes::default();
    let mut fallbacks = Vec::new();
    let (areas_a, areas_b) = (a.mesh.vertex_areas(), b.mesh.vertex_areas());
    let t = Instant::now();
    // One operator for every stage: the algorithm, the refinement and the map step all weigh
    // the features alike.
    let w = pair_affinity(a.bands, b.bands, options.feature_weights.as_deref())?;
    let mut regions = stable_regions_with(&w, &areas_a, &areas_b, &options.regions)?;
    times.algorithm = t.elapsed();
    let refine = options.refine.as_ref().filter(|r| r.max_rounds > 0);
    let map_guided = map_guided_options.as_ref();
    if refine.is_none() && map_guided.is_none() {
        return Ok(SegmentedPair {
            regions,
            times,
            fallbacks,
            map_guided: map_guided_options,
            map_preset,
        });
    }
    let t = Instant::now();
    let (refine_smoothers, map_smoother) = smoothers(a, b, refine, map_guided);
    times.smoothers = t.elapsed();
    // By default the map step's point map is fitted to the algorithm's regions and computed
    // alongside the refinement: the map's assignment is sequential, and the refinement fills
    // the other core meanwhile. Only the map's first functional map depends on the regions,
    // through their low frequencies, which the refinement moves little.
    let map_options = map_guided.map(|m| fit_map_sizes(m, a.spectrum.len().min(b.spectrum.len())));
    let run_refine = |regions: &StableRegions| {
        refine.map(|refine| {
            let areas = (&areas_a[..], &areas_b[..]);
            let t = Instant::now();
            let out = refine_stage(&w, regions, refine_smoothers, areas, refine);
            (out, t.elapsed())
        })
    };
    let run_map = |regions: &StableRegions| {
        map_options.as_ref().map(|m| {
            let t = Instant::now();
            let out = region_map(regions, a.geometry(), b.geometry(), m);
            (out, t.elapsed())
        })
    };
    let (refined, map) = if options.map_after_refine {
        let refined = run_refine(&regions);
        let fitted_to = match &refined {
            Some((Ok(r), _)) => r,
            _ => &regions,
        };
        let map = run_map(fitted_to);
        (refined, map)
    } else {
        rayon::join(|| run_refine(&regions), || run_map(&regions))
    };
    if let Some((out, time)) = refined {
        times.refine = time;
        match out {
            Ok(r) => regions = r,
            Err(e) => fallbacks.push(StageFallback::new(PairStage::Refine, &e.to_string())),
        }
    }
    if let (Some(m), Some((map, time))) = (map_options.as_ref(), map) {
        let t = Instant::now();
        let out = map.and_then(|map| {
            point_map_refinement(
                &w,
                &regions,
                &map,
                &a.spectrum.vertex_areas,
                &b.spectrum.vertex_areas,
                map_smoother?.as_ref().filter(|_| m.smoothing_time > 0.0),
                m.map_weight,
            )
        });
        times.map_guided = time + t.elapsed();
        match out {
            Ok(r) => regions = r,
            Err(e) => fallbacks.push(StageFallback::new(PairStage::MapGuided, &e.to_string())),
        }
    }
    Ok(SegmentedPair {
        regions,
        times,
        fallbacks,
        map_guided: map_guided_options,
        map_preset,
    })
}

/// The shapes' mesh, band table and spectrum must describe the same vertices; checked first so
/// that a mismatch is reported as the caller's error rather than failing inside a stage.
fn check_sizes(a: PairShape<'_>, b: PairShape<'_>) -> Result<(), StableError> {
    for (s, name) in [(a, "A"), (b, "B")] {
        let d = s.mesh.vertex_count();
        if s.bands.vertices != d || s.spectrum.vertex_count() != d {
            return Err(StableError::BadOption(format!(
                "shape {name}: a mesh of {d} vertices with a band table of {} and a spectrum \
                 of {}",
                s.bands.vertices,
                s.spectrum.vertex_count()
            )));
        }
    }
    Ok(())
}

/// A heat smoother on `mesh` at `time`, or none at time 0 (which means no smoothing).
fn smoother(mesh: &TriMesh, time: f64) -> Result<Option<HeatSmoother>, StableError> {
    Ok((time > 0.0)
        .then(|| HeatSmoother::new(mesh, time))
        .transpose()?)
}

/// A smoother, or why it could not be built.
type SmootherResult = Result<Option<HeatSmoother>, StableError>;

/// The heat smoothers of the requested stages: A's and B's at the refinement's time, B's at
/// the map step's. Factorised side by side: each factorisation is sequential, and the three
/// took half a second one after another on the 50k-vertex TOSCA pair.
fn smoothers(
    a: PairShape<'_>,
    b: PairShape<'_>,
    refine: Option<&RefineOptions>,
    map_guided: Option<&MapGuidedOptions>,
) -> ((SmootherResult, SmootherResult), SmootherResult) {
    let at = |s: PairShape<'_>, time: Option<f64>| time.map_or(Ok(None), |t| smoother(s.mesh, t));
    let refine_time = refine.map(|r| r.smoothing_time);
    rayon::join(
        || rayon::join(|| at(a, refine_time), || at(b, refine_time)),
        || at(b, map_guided.map(|m| m.smoothing_time)),
    )
}

/// The boundary-refinement stage with its smoothers; its error (or a smoother's) becomes a
/// fallback in [`segment_pair`], so it is returned rather than propagated there.
fn refine_stage(
    w: &BandAffinity<'_>,
    regions: &StableRegions,
    (sa, sb): (SmootherResult, SmootherResult),
    (areas_a, areas_b): (&[f64], &[f64]),
    refine: &RefineOptions,
) -> Result<StableRegions, StableError> {
    refine_regions(
        w,
        regions,
        areas_a,
        areas_b,
        sa?.as_ref(),
        sb?.as_ref(),
        refine,
    )
}

/// The options' own ranges, checked before any stage runs: a wrong option is the caller's
/// error, not a reason for a stage to fall back.
fn check_stage_options(
    refine: Option<&RefineOptions>,
    map_guided: Option<&MapGuidedOptions>,
) -> Result<(), StableError> {
    let non_negative = |name: &str, x: f64| non_negative(name, x).map_err(StableError::BadOption);
    if let Some(r) = refine {
        non_negative("refine smoothing_time", r.smoothing_time)?;
    }
    if let Some(m) = map_guided {
        non_negative("map_weight", m.map_weight)?;
        non_negative("map smoothing_time", m.smoothing_time)?;
        let z = &m.point_map.zoomout;
        if z.initial_size == 0 || z.step == 0 || z.initial_size > z.final_size {
            return Err(StableError::BadOption(format!(
                "map sizes: initial {} and step {} must be positive, and the initial size at \
                 most the final size {}",
                z.initial_size, z.step, z.final_size
            )));
        }
    }
    Ok(())
}

/// The map step's options with its first map no larger than the eigenpairs both shapes have
/// (`available`): a small mesh has fewer eigenpairs than the default first size, and a
/// smaller first map is what the step can fit there.
fn fit_map_sizes(options: &MapGuidedOptions, available: usize) -> MapGuidedOptions {
    let mut options = options.clone();
    let z = &mut options.point_map.zoomout;
    z.initial_size = z.initial_size.min(available).max(1);
    options
}

/// An optional stage of [`segment_pair`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PairStage {
    /// [`refine_regions`].
    Refine,
    /// [`map_guided_refinement`](super::map_guided_refinement).
    MapGuided,
}

/// An optional stage that could not run on these shapes: the result is the previous stage's,
/// and `reason` (a sentence for the user) says why.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct StageFallback {
    /// The stage that was skipped.
    pub stage: PairStage,
    /// Why it could not run.
    pub reason: String,
}

impl StageFallback {
    fn new(stage: PairStage, reason: &str) -> Self {
        Self {
            stage,
            reason: reason.to_string(),
        }
    }
}

impl std::fmt::Display for StageFallback {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let stage = match self.stage {
            PairStage::Refine => "boundary refinement",
            PairStage::MapGuided => "map step",
        };
        write!(
            f,
            "{stage} skipped, the previous stage's regions are kept: {}",
            self.reason
        )
    }
}
