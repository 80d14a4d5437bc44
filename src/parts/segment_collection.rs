//! [`segment_collection`]: the whole collection stage in one call (shape graph →
//! [`cosegment`] → heat smoothers → [`refine_cosegmentation`]), as `coseg segment` runs it.

use super::adaptive_cosegment::{
    AdaptiveCosegmentation, AdaptiveOptions, StopReason, adaptive_cosegment,
};
use super::choose_features::{
    ChooseFeaturesOptions, FeatureChoice, SharedAlignment, choose_features,
};
use super::choose_part_count::{PartCount, choose_part_count};
use super::geometric_part_tree::geometric_part_tree_linked;
use super::mirror_pairs::{Likeness, mirror_pairs};
use super::part_cues::collection_cues;
use super::parts_report::PartsReport;
use super::snap_part_boundaries::{check_band, snap_part_boundaries};
use super::split_disconnected_leaves::split_disconnected_leaves;
use super::start_score::start_score;
use crate::graph::{
    CosegmentOptions, Cosegmentation, GraphError, GraphOptions, RefineSizes, ShapeGraph, ShapeNode,
    cosegment, refine_cosegmentation_sized,
};
use crate::mesh::TriMesh;
use crate::spectral::HeatSmoother;
use crate::stable::RefineOptions;
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Options of [`segment_collection`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct SegmentCollectionOptions {
    /// How the shape graph is built (default: [`GraphOptions::default`]).
    pub graph: GraphOptions,
    /// The co-segmentation (default: [`CosegmentOptions::default`]).
    pub cosegment: CosegmentOptions,
    /// Boundary refinement after the co-segmentation; `None` keeps the raw region tuples.
    /// Default: 30 sweeps at smoothing time `3e-3` (more than a pair's 10: see `DEFAULT_REFINE`).
    pub refine: Option<RefineOptions>,
    /// Per-feature affinity weights on every edge (`None`: equal weights), e.g. the feature
    /// families' weights ([`crate::pipeline::ShapePipelineOptions::feature_weights`]).
    pub feature_weights: Option<Vec<f64>>,
    /// `Some`: parts of their own size by [`super::adaptive_cosegment`] (then cut at
    /// [`AdaptiveOptions::parts`] parts when set) instead of [`cosegment`]'s equal areas;
    /// `cosegment` is ignored. Default `None`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub parts: Option<AdaptiveOptions>,
    /// Starts of the equal-area co-segmentation (default 1). Start 0 is
    /// [`CosegmentOptions::seed`] as given; start `s ≥ 1` seeds each tuple from a seeded random
    /// half of the root (seed `s`, or `seed + s` when a seed is given). Every start is
    /// co-segmented and refined; the one whose tuples have the highest mean confidence wins
    /// (ties: the earliest). Why: the co-segmentation is a fixed point reached from a start,
    /// and some collections have several (measured on COSEG chairs with spectral + extrinsic
    /// features: 63 % or 85 % of the area right depending on the start, the better one with the
    /// higher confidence; docs/PARTS.md). Costs `starts` co-segmentations and refinements (the
    /// smoothers are factored once). Only for the equal-area mode: with [`Self::parts`] more
    /// than one start is an error ([`GraphError::BadOption`]).
    #[serde(skip_serializing_if = "is_one")]
    pub starts: usize,
    /// How the refinement treats region sizes (default [`RefineSizes::Free`], the classic
    /// best response, which drifts towards equal areas). With [`Self::parts`],
    /// [`RefineSizes::Keep`] (`coseg segment --parts … --refine-sizes keep`, tolerance
    /// [`AdaptiveOptions::size_tolerance`]) moves boundaries but keeps the sizes the adaptive
    /// stage read from the data (measured on both sides in docs/PARTS.md).
    #[serde(skip_serializing_if = "is_free")]
    pub refine_sizes: RefineSizes,
    /// With [`Self::parts`]: merge mirror pairs of leaves ([`super::mirror_pairs`], left and
    /// right copies of a part) first in the part tree, so every cut (`--parts N`) keeps the
    /// two sides of a part together. Needs the meshes; without them nothing changes.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub group_mirrors: bool,
    /// The collection's up direction in file coordinates when it is aligned (`coseg segment
    /// --up` with the extrinsic family: [`crate::pipeline::ShapePipelineOptions::up_direction`]);
    /// the mirror-pair test then uses vertical planes ([`super::mirror_pairs`]). Default `None`.
    /// Not serialised: the feature options that imply it are recorded with them.
    #[serde(skip)]
    pub up: Option<[f64; 3]>,
    /// Feature columns a mirror image leaves unchanged
    /// ([`crate::pipeline::ShapePipelineOptions::mirror_invariant_columns`]): mirror pairs
    /// must look alike on them ([`super::Likeness`]). Empty (the default): not compared. Not
    /// serialised, like [`Self::up`].
    #[serde(skip)]
    pub mirror_columns: Vec<usize>,
    /// With [`Self::parts`] and a number of parts ([`AdaptiveOptions::parts`]): where the
    /// finest parts come from and how they are grouped (default [`PartsFrom::Adaptive`]).
    #[serde(skip_serializing_if = "PartsFrom::is_adaptive")]
    pub parts_from: PartsFrom,
    /// With [`PartsFrom::Geometry`]: the per-shape cache directory where each shape's
    /// [`super::PartCues`] are kept ([`super::load_or_compute_part_cues`]; `coseg segment` passes
    /// its `--cache`). `None` (the default): computed every run. Not serialised: it does not
    /// change the result.
    #[serde(skip)]
    pub cue_cache: Option<PathBuf>,
    /// Which feature families the collection is co-segmented with (default
    /// [`FeatureSelection::Chosen`]: chosen from the data by [`super::choose_features`] when the
    /// nodes hold the intrinsic family alone). Not serialised: `summary.json` records the
    /// choice itself ([`SegmentedCollection::features`]).
    #[serde(skip)]
    pub features: FeatureSelection,
}

/// Whether [`segment_collection`] chooses the feature families (`coseg segment` without
/// `--features`) or takes the nodes' columns as they are (`--features F`).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum FeatureSelection {
    /// The nodes' columns as given, weighted by [`SegmentCollectionOptions::feature_weights`].
    Given,
    /// The intrinsic family alone or with the extrinsic family in the collection frame,
    /// whichever co-segments the collection more consistently ([`super::choose_features`]).
    /// Applies when the nodes hold one family (no [`SegmentCollectionOptions::feature_weights`],
    /// no [`SegmentCollectionOptions::up`]) and one mesh per node is given; otherwise the
    /// columns are taken as given.
    Chosen(ChooseFeaturesOptions),
}

impl Default for FeatureSelection {
    fn default() -> Self {
        Self::Chosen(ChooseFeaturesOptions::default())
    }
}

/// Where `--parts N` takes its finest parts from, and how it groups them
/// (`coseg segment --parts-from adaptive|geometry`; measured side by side in docs/PARTS.md).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum PartsFrom {
    /// Tuples of their own size ([`adaptive_cosegment`]), grouped by what the affinity
    /// transports between them ([`AdaptiveCosegmentation::regroup`]); refined after the cut.
    #[default]
    Adaptive,
    /// `leaves` equal-area regions ([`cosegment`], refined freely: `refine_sizes` does not
    /// apply, equal areas carry no sizes to keep), split into their kinds of pieces
    /// ([`super::split_disconnected_leaves`]) and grouped by
    /// [`super::geometric_part_tree_linked`]: touching regions (and mirror pairs and siblings
    /// facing the same way, then the other siblings) of one thickness across convex
    /// boundaries merge first. Needs the meshes and
    /// a number of parts. After
    /// the cut, no refinement (it would drift the grouped parts back towards equal areas) but
    /// [`super::snap_part_boundaries`]: each boundary moves, within `band`, onto the cut of
    /// least weight, concave creases being cheap.
    Geometry {
        /// Number of equal-area regions (the finest parts; `coseg segment --regions`,
        /// default 12).
        leaves: usize,
        /// How far a part boundary may move, × √(shape area) (`coseg segment --snap-band`,
        /// default 0.1); 0 keeps the regions' boundaries.
        band: f64,
    },
}

/// The default number of leaves of [`PartsFrom::Geometry`] (a heuristic, hence private: the
/// default reaches callers through [`SegmentCollectionOptions::default`]): enough that each
/// region lies mostly in one part of a body or a chair (measured: 84–92 % of their area on the
/// generated families), few enough that each is a sizeable piece of a part.
pub(crate) const GEOMETRY_LEAVES: usize = 12;

/// The default band of [`PartsFrom::Geometry`], × √(shape area) (a heuristic, private like
/// [`GEOMETRY_LEAVES`]): about a third of the radius of a disc of one leaf's area (1/12 of the
/// shape). Measured on the 36 generated sets of seeds 1–9 (docs/PARTS.md, "Boundaries snapped
/// to creases"): 0.06 and 0.1 lift the sets meeting the bar from 15 to 23 and 24, 0.15 moves
/// boundaries too far.
pub(crate) const GEOMETRY_BAND: f64 = 0.1;

/// The collection's default refinement (a heuristic, private: callers read it from
/// [`SegmentCollectionOptions::default`]): 30 sweeps at smoothing time `3e-3`. More sweeps
/// than a pair's default (10) because a sweep over a collection moves each boundary by about
/// one smoothing length, and the measured agreement with the ground truth keeps rising to about
/// 30 sweeps (8 TOSCA cats, 6 regions: 88.8 % at 10, 90.8 % at 30; docs/RESULTS.md).
const DEFAULT_REFINE: RefineOptions = RefineOptions {
    max_rounds: 30,
    smoothing_time: 3e-3,
};

impl PartsFrom {
    fn is_adaptive(&self) -> bool {
        *self == Self::Adaptive
    }
}

impl std::str::FromStr for PartsFrom {
    type Err = GraphError;

    /// `adaptive` or `geometry` (12 leaves, band 0.1: the
    /// defaults of [`SegmentCollectionOptions::default`]).
    ///
    /// ```
    /// use coseg::parts::PartsFrom;
    /// assert_eq!("geometry".parse::<PartsFrom>().unwrap(), PartsFrom::Geometry { leaves: 12, band: 0.1 });
    /// assert!("size".parse::<PartsFrom>().is_err());
    /// ```
    fn from_str(s: &str) -> Result<Self, GraphError> {
        match s {
            "adaptive" => Ok(Self::Adaptive),
            "geometry" => Ok(Self::Geometry {
                leaves: GEOMETRY_LEAVES,
                band: GEOMETRY_BAND,
            }),
            _ => Err(GraphError::BadOption(format!(
                "{s:?}: expected `adaptive` or `geometry`"
            ))),
        }
    }
}

// Here rather than beside `RefineSizes`: `keep` takes the tolerance of parts of their own
// size, a later stage than the refinement.
impl std::str::FromStr for RefineSizes {
    type Err = GraphError;

    /// `free`, `keep` (tolerance [`AdaptiveOptions::size_tolerance`],
    /// the sizes' own tolerance) or `keep:TOL` (`TOL` ≥ 0), as `coseg segment --refine-sizes`.
    ///
    /// ```
    /// use coseg::graph::RefineSizes;
    /// assert_eq!("free".parse::<RefineSizes>().unwrap(), RefineSizes::Free);
    /// assert_eq!("keep:0.25".parse::<RefineSizes>().unwrap(), RefineSizes::Keep { tolerance: 0.25 });
    /// assert_eq!("keep".parse::<RefineSizes>().unwrap(), RefineSizes::Keep { tolerance: 0.5 });
    /// assert!("keep:-1".parse::<RefineSizes>().is_err());
    /// ```
    fn from_str(s: &str) -> Result<Self, GraphError> {
        let bad = || {
            GraphError::BadOption(format!(
                "{s:?}: expected `free`, `keep` or `keep:TOL` (TOL ≥ 0)"
            ))
        };
        match s {
            "free" => Ok(Self::Free),
            "keep" => Ok(Self::Keep {
                tolerance: AdaptiveOptions::default().size_tolerance,
            }),
            _ => match s.strip_prefix("keep:").map(str::parse::<f64>) {
                Some(Ok(tolerance)) if tolerance.is_finite() && tolerance >= 0.0 => {
                    Ok(Self::Keep { tolerance })
                }
                _ => Err(bad()),
            },
        }
    }
}

fn is_free(r: &RefineSizes) -> bool {
    *r == RefineSizes::Free
}

fn is_one(n: &usize) -> bool {
    *n == 1
}

/// How many parts of their own size to ask for (`coseg segment --parts auto|N`).
///
/// ```
/// use coseg::parts::PartsRequest;
/// assert_eq!("auto".parse::<PartsRequest>().unwrap(), PartsRequest::Auto);
/// assert_eq!("4".parse::<PartsRequest>().unwrap(), PartsRequest::Count(4));
/// assert!("0".parse::<PartsRequest>().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PartsRequest {
    /// As many as are stable, consistent and separated (the finest consistent parts).
    Auto,
    /// This many (≥ 1): the tree of parts is cut there.
    Count(usize),
}

impl std::str::FromStr for PartsRequest {
    type Err = GraphError;

    fn from_str(s: &str) -> Result<Self, GraphError> {
        match s {
            "auto" => Ok(Self::Auto),
            _ => match s.parse::<usize>() {
                Ok(k) if k >= 1 => Ok(Self::Count(k)),
                _ => Err(GraphError::BadOption(format!(
                    "{s:?}: expected `auto` or a number of parts ≥ 1"
                ))),
            },
        }
    }
}

impl SegmentCollectionOptions {
    /// Switches to parts of their own size ([`Self::parts`]): [`AdaptiveOptions::default`]
    /// with `request`'s number of parts, at most `upper_bound` parts when given (`coseg
    /// segment --regions` with `--parts`; default [`AdaptiveOptions::max_parts`], raised to a
    /// requested count above it), and each tuple started as [`CosegmentOptions::seed`] says.
    ///
    /// ```
    /// use coseg::parts::{PartsRequest, SegmentCollectionOptions};
    /// let mut o = SegmentCollectionOptions::default();
    /// o.request_parts(PartsRequest::Count(10), None);
    /// let p = o.parts.unwrap();
    /// assert_eq!((p.parts, p.max_parts), (Some(10), 10));
    /// o.request_parts(PartsRequest::Auto, Some(5));
    /// assert_eq!(o.parts.unwrap().max_parts, 5);
    /// ```
    pub fn request_parts(&mut self, request: PartsRequest, upper_bound: Option<usize>) {
        let mut o = AdaptiveOptions::default();
        if let PartsRequest::Count(k) = request {
            o.parts = Some(k);
            o.max_parts = o.max_parts.max(k);
        }
        if let Some(r) = upper_bound {
            o.max_parts = r;
        }
        o.seed = self.cosegment.seed;
        self.parts = Some(o);
    }
}

impl SegmentCollectionOptions {
    /// Takes the feature families from the per-shape `pipeline` the nodes were computed with
    /// (`columns` columns per node): when the families were `given` (`--features F`), the
    /// nodes' columns as they are ([`FeatureSelection::Given`]) with the pipeline's family
    /// weights, up axis and mirror-invariant columns; otherwise the families are chosen from
    /// the data ([`FeatureSelection::Chosen`]), the extrinsic columns cut into bands as
    /// `pipeline` cuts its own.
    ///
    /// ```
    /// use coseg::parts::{FeatureSelection, SegmentCollectionOptions};
    /// use coseg::pipeline::ShapePipelineOptions;
    /// let mut o = SegmentCollectionOptions::default();
    /// o.set_pipeline(&ShapePipelineOptions::default(), true, 300);
    /// assert_eq!(o.features, FeatureSelection::Given);
    /// ```
    pub fn set_pipeline(
        &mut self,
        pipeline: &crate::pipeline::ShapePipelineOptions,
        given: bool,
        columns: usize,
    ) {
        if given {
            self.features = FeatureSelection::Given;
            self.feature_weights = pipeline.feature_weights(columns);
            self.up = pipeline.up_direction();
            self.mirror_columns = pipeline.mirror_invariant_columns(columns);
        } else {
            let mut c = match &self.features {
                FeatureSelection::Chosen(c) => c.clone(),
                FeatureSelection::Given => ChooseFeaturesOptions::default(),
            };
            c.weighting = pipeline.bands.weighting;
            self.features = FeatureSelection::Chosen(c);
        }
    }

    /// The options `coseg segment`'s (and `coseg.segment`'s) mode flags select, everything else
    /// at its default:
    /// - nothing: the default, parts from geometry, their number chosen from the part tree;
    /// - `regions` alone: [`Self::equal_areas`] (the paper's equal-area stable regions);
    /// - `parts` and/or `parts_from`: parts ([`Self::request_parts`], default
    ///   [`PartsRequest::Auto`]) from `parts_from` (default [`PartsFrom::Geometry`]);
    ///   `regions` is then the number of equal-area leaves of parts from geometry, or the
    ///   upper bound on the number of adaptive parts.
    ///
    /// ```
    /// use coseg::parts::{PartsFrom, PartsRequest, SegmentCollectionOptions};
    /// assert_eq!(
    ///     SegmentCollectionOptions::for_request(None, None, None),
    ///     SegmentCollectionOptions::default()
    /// );
    /// let regions = SegmentCollectionOptions::for_request(Some(6), None, None);
    /// assert_eq!((regions.parts.is_none(), regions.cosegment.regions), (true, 6));
    /// let four = SegmentCollectionOptions::for_request(Some(16), Some(PartsRequest::Count(4)), None);
    /// assert_eq!(four.parts.unwrap().parts, Some(4));
    /// assert_eq!(four.parts_from, PartsFrom::Geometry { leaves: 16, band: 0.1 });
    /// let adaptive = "adaptive".parse().unwrap();
    /// let a = SegmentCollectionOptions::for_request(Some(5), None, Some(adaptive));
    /// assert_eq!((a.parts.unwrap().max_parts, a.parts_from), (5, PartsFrom::Adaptive));
    /// ```
    pub fn for_request(
        regions: Option<usize>,
        parts: Option<PartsRequest>,
        parts_from: Option<PartsFrom>,
    ) -> Self {
        if let (Some(r), None, None) = (regions, parts, parts_from) {
            return Self::equal_areas(r);
        }
        let mut o = Self::default();
        let from = parts_from.unwrap_or(o.parts_from);
        // `regions` bounds the number of adaptive parts; parts from geometry take it as their
        // leaves.
        let bound = match from {
            PartsFrom::Adaptive => regions,
            PartsFrom::Geometry { .. } => None,
        };
        o.request_parts(parts.unwrap_or(PartsRequest::Auto), bound);
        o.set_parts_from(from, regions);
        o
    }

    /// Sets [`Self::parts_from`]; `regions` (`coseg segment --regions`), when given, is the
    /// number of leaves of [`PartsFrom::Geometry`].
    ///
    /// ```
    /// use coseg::parts::{PartsFrom, SegmentCollectionOptions};
    /// let mut o = SegmentCollectionOptions::default();
    /// o.set_parts_from("geometry".parse().unwrap(), Some(16));
    /// assert_eq!(o.parts_from, PartsFrom::Geometry { leaves: 16, band: 0.1 });
    /// o.set_snap_band(0.05).unwrap();
    /// assert_eq!(o.parts_from, PartsFrom::Geometry { leaves: 16, band: 0.05 });
    /// ```
    pub fn set_parts_from(&mut self, from: PartsFrom, regions: Option<usize>) {
        self.parts_from = match (from, regions) {
            (PartsFrom::Geometry { band, .. }, Some(leaves)) => {
                PartsFrom::Geometry { leaves, band }
            }
            (f, _) => f,
        };
    }

    /// Sets the band of [`PartsFrom::Geometry`] (`coseg segment --snap-band`).
    ///
    /// Errors: [`GraphError::BadOption`] when the parts do not come from geometry or the band
    /// is negative or not finite.
    ///
    /// ```
    /// use coseg::parts::{PartsFrom, SegmentCollectionOptions};
    /// let mut o = SegmentCollectionOptions::equal_areas(6);
    /// assert!(o.set_snap_band(0.1).is_err()); // equal-area regions have no band
    /// o.set_parts_from("geometry".parse().unwrap(), None);
    /// o.set_snap_band(0.0).unwrap(); // the regions' boundaries as they are
    /// assert_eq!(o.parts_from, PartsFrom::Geometry { leaves: 12, band: 0.0 });
    /// assert!(o.set_snap_band(-1.0).is_err());
    /// ```
    pub fn set_snap_band(&mut self, band: f64) -> Result<(), GraphError> {
        check_band(band)?;
        match &mut self.parts_from {
            PartsFrom::Geometry { band: b, .. } => {
                *b = band;
                Ok(())
            }
            PartsFrom::Adaptive => Err(GraphError::BadOption(
                "a snap band is for parts from geometry (--parts-from geometry)".into(),
            )),
        }
    }
}

/// The default is `coseg segment FOLDER`: parts from geometry ([`PartsFrom::Geometry`]: 12
/// refined equal-area regions grouped by the geometric part tree), as many as the tree's cut
/// criterion chooses ([`super::choose_part_count`]), on the feature families chosen from the
/// data ([`FeatureSelection::Chosen`]). [`SegmentCollectionOptions::equal_areas`] gives the
/// paper's equal-area regions (`coseg segment --regions N`).
impl Default for SegmentCollectionOptions {
    fn default() -> Self {
        Self {
            parts: Some(AdaptiveOptions::default()),
            parts_from: PartsFrom::Geometry {
                leaves: GEOMETRY_LEAVES,
                band: GEOMETRY_BAND,
            },
            ..Self::equal_areas(CosegmentOptions::default().regions)
        }
    }
}

impl SegmentCollectionOptions {
    /// `regions` equal-area regions ([`cosegment`] then the refinement; the paper's fixed
    /// cutoff, `coseg segment --regions N`), the feature families chosen from the data as by
    /// default.
    ///
    /// ```
    /// use coseg::parts::SegmentCollectionOptions;
    /// let o = SegmentCollectionOptions::equal_areas(6);
    /// assert_eq!((o.parts.is_none(), o.cosegment.regions), (true, 6));
    /// assert!(SegmentCollectionOptions::default().parts.is_some());
    /// ```
    pub fn equal_areas(regions: usize) -> Self {
        let cosegment = CosegmentOptions {
            regions,
            ..CosegmentOptions::default()
        };
        Self {
            graph: GraphOptions::default(),
            cosegment,
            refine: Some(DEFAULT_REFINE),
            feature_weights: None,
            parts: None,
            starts: 1,
            refine_sizes: RefineSizes::Free,
            group_mirrors: false,
            up: None,
            mirror_columns: Vec::new(),
            parts_from: PartsFrom::Adaptive,
            cue_cache: None,
            features: FeatureSelection::default(),
        }
    }
}

/// Wall time of each stage of [`segment_collection`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SegmentTimes {
    /// Building the shape graph.
    pub graph: Duration,
    /// [`cosegment`].
    pub cosegment: Duration,
    /// Factorising the heat smoothers (one per shape, in parallel).
    pub smoothers: Duration,
    /// [`refine_cosegmentation`](crate::graph::refine_cosegmentation).
    pub refine: Duration,
    /// Reading or computing the [`super::PartCues`] (`None`: not needed, only
    /// [`PartsFrom::Geometry`] reads them).
    pub part_cues: Option<Duration>,
    /// Choosing the feature families (alignment, extrinsic columns, the two probe
    /// co-segmentations and the graph; `None` when the columns were given).
    pub features: Option<Duration>,
}

/// The result of [`segment_collection`].
#[derive(Debug, Clone)]
pub struct SegmentedCollection {
    /// The shape graph the segmentation was computed on.
    pub graph: ShapeGraph,
    /// The final segmentation (refined unless `options.refine` is `None`).
    pub segmentation: Cosegmentation,
    /// Per-stage wall times.
    pub times: SegmentTimes,
    /// The adaptive run (finest parts, thresholds, tree) when `options.parts` was set.
    pub adaptive: Option<AdaptiveCosegmentation>,
    /// Which start won ([`SegmentCollectionOptions::starts`]; 0 with one start).
    pub start: usize,
    /// The selection score of every start: the mean confidence of its final tuples.
    pub start_scores: Vec<f64>,
    /// [`SegmentCollectionOptions::up`], for the mirror pairs of [`Self::parts_report`].
    pub up: Option<[f64; 3]>,
    /// [`SegmentCollectionOptions::mirror_columns`], likewise.
    pub mirror_columns: Vec<usize>,
    /// Warnings for the user: part-cue cache entries that were not trusted or not written
    /// (the run's results do not depend on them), an alignment or extrinsic family that could
    /// not be computed (the intrinsic family was used).
    pub warnings: Vec<String>,
    /// The feature families chosen from the data, and why ([`FeatureSelection::Chosen`]);
    /// `None` when the columns were taken as given.
    pub features: Option<FeatureChoice>,
    /// The number of parts chosen from the part tree, and why (parts from geometry without a
    /// number of parts); `None` otherwise.
    pub part_count: Option<PartCount>,
}

impl SegmentedCollection {
    /// What `summary.json` records of the adaptive run (`coseg segment --parts`): the
    /// [`PartsReport`] of [`Self::adaptive`] for the final segmentation, its pieces counted on
    /// `meshes` (graph order; empty: no piece counts). `None` without `--parts`.
    pub fn parts_report(&self, meshes: &[TriMesh]) -> Option<PartsReport> {
        self.adaptive.as_ref().map(|a| {
            let likeness = Likeness {
                graph: &self.graph,
                columns: &self.mirror_columns,
            };
            PartsReport::new(a, &self.segmentation, meshes, self.up, Some(likeness))
        })
    }
}

/// The mirror pairs among `coseg`'s tuples as leaf pairs, under `options`' up direction and
/// mirror-invariant columns.
fn mirror_links(
    graph: &ShapeGraph,
    meshes: &[TriMesh],
    coseg: &Cosegmentation,
    options: &SegmentCollectionOptions,
) -> Vec<(usize, usize)> {
    let likeness = Likeness {
        graph,
        columns: &options.mirror_columns,
    };
    mirror_pairs(meshes, coseg, options.up, Some(likeness))
        .iter()
        .map(|m| (m.a, m.b))
        .collect()
}

/// Co-segments a collection: builds the shape graph over `nodes`, extracts consistent region
/// tuples with [`cosegment`], and (by default) refines their boundaries with
/// [`refine_cosegmentation`](crate::graph::refine_cosegmentation), heat-smoothing on each shape's `meshes[i]` (same order as
/// `nodes`; only needed when refining with a positive smoothing time).
///
/// With the default options (`coseg segment FOLDER`) the feature families are first chosen
/// from the data ([`FeatureSelection::Chosen`]: the nodes' intrinsic columns alone or with the
/// extrinsic family in the collection frame), and the result is parts: twelve refined
/// equal-area regions grouped by the geometric part tree, cut where the tree's merge costs
/// jump most ([`super::choose_part_count`]). [`SegmentedCollection::features`] and
/// [`SegmentedCollection::part_count`] say what was chosen and why.
///
/// Deterministic: the same nodes and options give the same segmentation, bit for bit.
///
/// ```
/// use coseg::bands::equal_count_bands;
/// use coseg::graph::{ShapeNode};
/// use coseg::parts::{segment_collection, FeatureSelection, SegmentCollectionOptions};
/// use coseg::mesh::TriMesh;
/// // Three identical 4-vertex shapes (a tetrahedron) with one feature in 4 bands.
/// let mesh = TriMesh::new(
///     vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
///     vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
/// ).unwrap();
/// let t = equal_count_bands(&[0.0, 1.0, 2.0, 3.0], 1, 4, 4).unwrap();
/// let nodes: Vec<ShapeNode> = (0..3)
///     .map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &mesh.vertex_areas()).unwrap())
///     .collect();
/// // Two equal-area regions over the nodes' columns as given.
/// let mut opts = SegmentCollectionOptions::equal_areas(2);
/// opts.features = FeatureSelection::Given;
/// let out = segment_collection(nodes, &[mesh.clone(), mesh.clone(), mesh], &opts).unwrap();
/// assert_eq!(out.segmentation.labels(0), out.segmentation.labels(2));
/// ```
pub fn segment_collection(
    nodes: Vec<ShapeNode>,
    meshes: &[TriMesh],
    options: &SegmentCollectionOptions,
) -> Result<SegmentedCollection, GraphError> {
    segment_collection_sharing(nodes, meshes, options, None, None)
}

/// The collection stage of parts from geometry up to the cut ([`part_tree`]): the shape graph,
/// the leaves and the part tree over them, and what the feature choice decided. Cut at any
/// number of parts by [`cut_part_tree`]; `coseg segment` keeps it in its cache
/// ([`super::segment_collection_cached`]) so that another `--parts N` only re-cuts.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct PartTreeStage {
    /// The shape graph the leaves were co-segmented on.
    pub graph: ShapeGraph,
    /// The leaves (the refined equal-area regions split into their kinds of pieces) and the
    /// part tree over them ([`StopReason::EqualAreaLeaves`], no adaptive tuples).
    pub tree: AdaptiveCosegmentation,
    /// The feature families chosen from the data, and why (`None`: the columns as given).
    pub features: Option<FeatureChoice>,
    /// The up direction the co-segmentation's options held after the feature choice
    /// ([`SegmentCollectionOptions::up`]).
    pub up: Option<[f64; 3]>,
    /// Likewise, the mirror-invariant columns ([`SegmentCollectionOptions::mirror_columns`]).
    pub mirror_columns: Vec<usize>,
    /// Likewise, the per-feature weights ([`SegmentCollectionOptions::feature_weights`]).
    pub feature_weights: Option<Vec<f64>>,
    /// Warnings about the result (an alignment or extrinsic family that could not be
    /// computed), for the user with every cut.
    pub warnings: Vec<String>,
    /// Warnings about this run alone (part-cue cache entries not trusted or not written).
    pub run_warnings: Vec<String>,
    /// Per-stage wall times so far.
    pub times: SegmentTimes,
}

/// The shape graph, the options after the feature choice, and what the stages before the
/// co-segmentation made.
struct Prepared<'a> {
    graph: ShapeGraph,
    options: SegmentCollectionOptions,
    features: Option<FeatureChoice>,
    warnings: Vec<String>,
    /// How many of `warnings` are the feature choice's (about the result); the rest are the
    /// part cues' (about the run).
    feature_warnings: usize,
    times: SegmentTimes,
    shared: Option<&'a [HeatSmoother]>,
    made: Option<Vec<HeatSmoother>>,
    cues: Option<Vec<super::PartCues>>,
    geometry: Option<GeometryMode>,
}

/// Parts from geometry: `(leaves, Ok(parts) or Err(upper bound on the chosen number), band)`.
type GeometryMode = (usize, Result<usize, usize>, f64);

/// With parts from geometry: `(leaves, Ok(parts) or Err(upper bound on the chosen number),
/// band)`, the options checked; `None` in the other modes.
fn geometry_mode(options: &SegmentCollectionOptions) -> Result<Option<GeometryMode>, GraphError> {
    match (&options.parts, options.parts_from) {
        (None, PartsFrom::Geometry { .. }) => Err(GraphError::BadOption(
            "parts from geometry need a number of parts (--parts N)".into(),
        )),
        (Some(p), PartsFrom::Geometry { leaves, band }) => {
            if let Some(parts) = p.parts
                && leaves < parts
            {
                return Err(GraphError::BadOption(format!(
                    "parts from geometry: {leaves} regions cannot make {parts} parts"
                )));
            }
            check_band(band)?;
            // Without a number of parts, the tree's cut criterion chooses one, at most the
            // upper bound (`--regions` with `--parts auto`).
            Ok(Some((leaves, p.parts.ok_or(p.max_parts), band)))
        }
        _ => Ok(None),
    }
}

/// The stages before the co-segmentation: options checked, feature families chosen (or the
/// graph built over the columns as given), heat smoothers, part cues.
fn prepare<'a>(
    nodes: Vec<ShapeNode>,
    meshes: &[TriMesh],
    options: &SegmentCollectionOptions,
    shared: Option<&'a [HeatSmoother]>,
    alignment: Option<SharedAlignment<'_>>,
) -> Result<Prepared<'a>, GraphError> {
    let smoothing = options
        .refine
        .as_ref()
        .is_some_and(|r| r.max_rounds > 0 && r.smoothing_time > 0.0);
    if smoothing
        && (meshes.len() != nodes.len()
            || meshes
                .iter()
                .zip(&nodes)
                .any(|(m, n)| m.vertex_count() != n.bands.vertices))
    {
        return Err(GraphError::BadOption(
            "refinement with smoothing needs one mesh per shape, with the shape's vertex count"
                .into(),
        ));
    }
    let mut times = SegmentTimes::default();
    let mut warnings = Vec::new();
    let t = Instant::now();
    let choose = match &options.features {
        FeatureSelection::Chosen(c)
            if options.feature_weights.is_none()
                && options.up.is_none()
                && !meshes.is_empty()
                && meshes.len() == nodes.len() =>
        {
            Some(c)
        }
        _ => None,
    };
    let (graph, options, features) = match choose {
        Some(c) => {
            let _t = crate::stage_timer::stage("parts: choose features");
            let chosen = choose_features(
                nodes,
                meshes,
                &options.graph,
                &options.cosegment,
                c,
                alignment,
                &mut warnings,
            )?;
            let mut o = options.clone();
            o.feature_weights = chosen.feature_weights;
            o.up = chosen.up;
            o.mirror_columns = chosen.mirror_columns;
            times.features = Some(t.elapsed());
            (chosen.graph, o, Some(chosen.choice))
        }
        None => {
            let mut graph = ShapeGraph::build(nodes, &options.graph)?;
            if options.feature_weights.is_some() {
                graph.set_feature_weights(options.feature_weights.clone())?;
            }
            times.graph = t.elapsed();
            (graph, options.clone(), None)
        }
    };
    let feature_warnings = warnings.len();
    if options.starts == 0 {
        return Err(GraphError::BadOption("starts must be at least 1".into()));
    }
    if options.starts > 1 && options.parts.is_some() {
        return Err(GraphError::BadOption(format!(
            "starts = {}: several starts apply to the equal-area co-segmentation, not to parts of their own size (--parts)",
            options.starts
        )));
    }
    let refine = options.refine.as_ref().filter(|r| r.max_rounds > 0);
    let geometry = geometry_mode(&options)?;
    let t = Instant::now();
    let timer = crate::stage_timer::stage("parts: heat smoothers");
    let fits = |r: &RefineOptions, s: &[HeatSmoother]| {
        s.len() == meshes.len()
            && s.iter()
                .zip(meshes)
                .all(|(h, m)| h.time() == r.smoothing_time && h.vertex_count() == m.vertex_count())
    };
    let shared = match refine {
        Some(r) if smoothing => shared.filter(|s| fits(r, s)),
        _ => None,
    };
    let made = match refine {
        Some(r) if smoothing && shared.is_none() => Some(
            meshes
                .par_iter()
                .enumerate()
                .map(|(i, m)| {
                    HeatSmoother::new(m, r.smoothing_time).map_err(|source| GraphError::Smoothing {
                        name: graph.node(i).name.clone(),
                        source,
                    })
                })
                .collect::<Result<Vec<_>, _>>()?,
        ),
        _ => None,
    };
    times.smoothers = t.elapsed();
    drop(timer);
    let cues = match geometry {
        Some(_) => {
            let t = Instant::now();
            if meshes.len() != graph.node_count() {
                return Err(GraphError::BadOption(
                    "parts from geometry need one mesh per shape".into(),
                ));
            }
            let name = |i: usize| graph.node(i).name.clone();
            let _t = crate::stage_timer::stage("parts: cues");
            let cues = collection_cues(meshes, name, options.cue_cache.as_deref(), &mut warnings)?;
            times.part_cues = Some(t.elapsed());
            Some(cues)
        }
        None => None,
    };
    Ok(Prepared {
        graph,
        options,
        features,
        warnings,
        feature_warnings,
        times,
        shared,
        made,
        cues,
        geometry,
    })
}

/// [`segment_collection`] reading the refinement's heat smoothers from `shared` (one per mesh,
/// as [`HeatSmoother::new`] makes them) where they have the refinement's smoothing time: the
/// same result without factorising and holding a second smoother per shape. Smoothers that do
/// not fit (another time, another vertex count) are ignored and made afresh. `alignment`: the
/// collection alignment of `meshes` under the default options, made by the caller
/// ([`SharedAlignment`]), read instead of aligning again when the feature choice aligns with
/// those options.
pub(crate) fn segment_collection_sharing(
    nodes: Vec<ShapeNode>,
    meshes: &[TriMesh],
    options: &SegmentCollectionOptions,
    shared: Option<&[HeatSmoother]>,
    alignment: Option<SharedAlignment<'_>>,
) -> Result<SegmentedCollection, GraphError> {
    let prepared = prepare(nodes, meshes, options, shared, alignment)?;
    if prepared.geometry.is_some() {
        let stage = grow_part_tree(prepared, meshes)?;
        return cut_part_tree(stage, meshes, options);
    }
    let Prepared {
        graph,
        options,
        features,
        warnings,
        mut times,
        shared,
        made,
        ..
    } = prepared;
    let smoothers = shared.or(made.as_deref());
    let graph = &graph;
    let refine = options.refine.as_ref().filter(|r| r.max_rounds > 0);
    let mut best: Option<(f64, usize, Cosegmentation, Option<AdaptiveCosegmentation>)> = None;
    let mut start_scores = Vec::with_capacity(options.starts);
    for start in 0..options.starts {
        let t = Instant::now();
        let timer = crate::stage_timer::stage("parts: cosegment");
        let (mut segmentation, adaptive) = match &options.parts {
            None => {
                let mut o = options.cosegment;
                if start > 0 {
                    o.seed = Some(o.seed.unwrap_or(0) + start as u64);
                }
                (cosegment(graph, &o)?, None)
            }
            Some(p) => {
                let mut a = adaptive_cosegment(graph, p)?;
                if options.group_mirrors {
                    let pairs = mirror_links(graph, meshes, &a.leaves, &options);
                    if !pairs.is_empty() {
                        a.regroup(graph, &pairs);
                    }
                }
                (a.cut(p.parts.unwrap_or(usize::MAX)), Some(a))
            }
        };
        times.cosegment += t.elapsed();
        drop(timer);
        if let Some(refine) = refine {
            let t = Instant::now();
            let _t = crate::stage_timer::stage("parts: refine");
            segmentation = refine_cosegmentation_sized(
                graph,
                &segmentation,
                smoothers,
                refine,
                options.refine_sizes,
            )?;
            times.refine += t.elapsed();
        }
        let score = start_score(&segmentation);
        start_scores.push(score);
        if best.as_ref().is_none_or(|b| score > b.0) {
            best = Some((score, start, segmentation, adaptive));
        }
    }
    let (_, start, segmentation, adaptive) = best.expect("at least one start");
    Ok(SegmentedCollection {
        graph: graph.clone(),
        segmentation,
        times,
        adaptive,
        start,
        start_scores,
        up: options.up,
        mirror_columns: options.mirror_columns,
        warnings,
        features,
        part_count: None,
    })
}

/// Parts from geometry up to the cut: the equal-area leaves, refined, split into their kinds
/// of pieces, and the part tree over them.
fn grow_part_tree(prepared: Prepared<'_>, meshes: &[TriMesh]) -> Result<PartTreeStage, GraphError> {
    let Prepared {
        graph,
        options,
        features,
        mut warnings,
        feature_warnings,
        mut times,
        shared,
        made,
        cues,
        geometry,
    } = prepared;
    let (leaves, _, _) = geometry.expect("parts from geometry");
    let smoothers = shared.or(made.as_deref());
    let t = Instant::now();
    let timer = crate::stage_timer::stage("parts: cosegment");
    let mut o = options.cosegment;
    o.regions = leaves;
    let mut segmentation = cosegment(&graph, &o)?;
    times.cosegment += t.elapsed();
    drop(timer);
    if let Some(refine) = options.refine.as_ref().filter(|r| r.max_rounds > 0) {
        let t = Instant::now();
        let _t = crate::stage_timer::stage("parts: refine");
        // Equal-area leaves have no sizes from the data to keep.
        segmentation = refine_cosegmentation_sized(
            &graph,
            &segmentation,
            smoothers,
            refine,
            RefineSizes::Free,
        )?;
        times.refine += t.elapsed();
    }
    // The refined equal-area regions, split into their kinds of pieces, are the leaves, cut
    // after their refinement (a refinement of the grouped parts would drift them back to equal
    // areas); then [`cut_part_tree`] moves the parts' boundaries, still the leaves', onto the
    // creases between parts.
    let t = Instant::now();
    let _t = crate::stage_timer::stage("parts: geometric tree");
    let regions = segmentation.tuples.len();
    let split = split_disconnected_leaves(meshes, &segmentation)?;
    let siblings = split.siblings();
    // Recorded only when a region was split: otherwise every leaf is its own.
    let leaf_origin = if split.origin.len() > regions {
        split.origin
    } else {
        Vec::new()
    };
    let segmentation = split.segmentation;
    // Siblings facing the same way are copies of one part (a chair's front and back legs):
    // linked like mirror pairs, at no extra cost.
    let mut links = mirror_links(&graph, meshes, &segmentation, &options);
    links.extend_from_slice(&split.alike);
    let cues = cues
        .as_deref()
        .expect("computed above with parts from geometry");
    let tree = geometric_part_tree_linked(meshes, cues, &segmentation, &links, &siblings)?;
    times.cosegment += t.elapsed();
    let run_warnings = warnings.split_off(feature_warnings);
    Ok(PartTreeStage {
        graph,
        tree: AdaptiveCosegmentation {
            leaves: segmentation,
            auto: Vec::new(),
            stop: StopReason::EqualAreaLeaves,
            tree,
            leaf_origin,
            leaf_copies: split.alike,
        },
        features,
        up: options.up,
        mirror_columns: options.mirror_columns,
        feature_weights: options.feature_weights,
        warnings,
        run_warnings,
        times,
    })
}

/// Parts from geometry (the default of [`segment_collection`]) up to the cut: the collection
/// stage's costly part, whatever the number of parts. [`cut_part_tree`] then cuts it;
/// [`segment_collection`] is the two in a row.
///
/// Errors: those of [`segment_collection`], and [`GraphError::BadOption`] when the options do
/// not ask for parts from geometry.
pub fn part_tree(
    nodes: Vec<ShapeNode>,
    meshes: &[TriMesh],
    options: &SegmentCollectionOptions,
) -> Result<PartTreeStage, GraphError> {
    part_tree_sharing(nodes, meshes, options, None, None)
}

/// [`part_tree`] reading the caller's heat smoothers and collection alignment, as
/// [`segment_collection_sharing`] does: the same tree.
pub(crate) fn part_tree_sharing(
    nodes: Vec<ShapeNode>,
    meshes: &[TriMesh],
    options: &SegmentCollectionOptions,
    shared: Option<&[HeatSmoother]>,
    alignment: Option<SharedAlignment<'_>>,
) -> Result<PartTreeStage, GraphError> {
    let prepared = prepare(nodes, meshes, options, shared, alignment)?;
    if prepared.geometry.is_none() {
        return Err(GraphError::BadOption(
            "a part tree is grown for parts from geometry (--parts-from geometry)".into(),
        ));
    }
    grow_part_tree(prepared, meshes)
}

/// Cuts `stage` as `options` ask: at [`AdaptiveOptions::parts`], or where
/// [`super::choose_part_count`] chooses (at most [`AdaptiveOptions::max_parts`]), then moves
/// the parts' boundaries onto creases within the band of [`PartsFrom::Geometry`]
/// ([`super::snap_part_boundaries`]). `meshes`: the shapes `stage` was grown on (graph order).
/// The result is [`segment_collection`]'s for the same nodes and options, bit for bit.
///
/// Errors: [`GraphError::BadOption`] when `options` do not ask for parts from geometry or ask
/// for more parts than leaves; those of [`super::snap_part_boundaries`].
pub fn cut_part_tree(
    stage: PartTreeStage,
    meshes: &[TriMesh],
    options: &SegmentCollectionOptions,
) -> Result<SegmentedCollection, GraphError> {
    let Some((_, parts, band)) = geometry_mode(options)? else {
        return Err(GraphError::BadOption(
            "a part tree is cut for parts from geometry (--parts-from geometry)".into(),
        ));
    };
    let PartTreeStage {
        graph,
        tree,
        features,
        up,
        mirror_columns,
        mut warnings,
        run_warnings,
        mut times,
        ..
    } = stage;
    let t = Instant::now();
    let _t = crate::stage_timer::stage("parts: cut and snapping");
    let (parts, part_count) = match parts {
        Ok(k) => (k, None),
        Err(max_parts) => {
            let c = choose_part_count(&tree.tree, max_parts);
            (c.count, Some(c))
        }
    };
    let segmentation = snap_part_boundaries(meshes, &tree.cut(parts), band)?;
    times.cosegment += t.elapsed();
    warnings.extend(run_warnings);
    let score = start_score(&segmentation);
    Ok(SegmentedCollection {
        graph,
        segmentation,
        times,
        adaptive: Some(tree),
        start: 0,
        start_scores: vec![score],
        up,
        mirror_columns,
        warnings,
        features,
        part_count,
    })
}
