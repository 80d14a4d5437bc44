//! Shape collections: the shape graph, the cycle solver and consistent co-segmentation of a
//! whole collection (docs/METHOD.md §5).
//!
//! - [`stable_cycle`]: fixed points of `P_0 ∘ W_{0,m−1} ∘ … ∘ P_1 ∘ W_10` around a cycle of any
//!   length `m ≥ 2`; the 2-cycle is exactly Algorithm 1.
//! - [`cycle_consistency`]: how much of a region carried around a cycle of thresholded
//!   transports comes back to itself.
//! - [`ShapeGraph`]: nodes hold each shape's band table and unit-area vertex areas, edges the
//!   feature pairing and a weight; pairwise affinities exist only as band-table operators.
//! - [`cosegment`]: consistent region tuples across every shape of the graph (design argued
//!   in that function's module).
//! - [`adaptive_cosegment`]: the same with each tuple's size found from the data
//!   (Algorithm 3 across the graph), the number of parts from the data and a tree of parts.
//! - [`mirror_pairs`]: which tuples are left/right copies of each other (each shape's own
//!   plane of mirror symmetry, [`mirror_plane`]); the part tree merges them first.
//! - [`geometric_part_tree`]: a part tree over equal-area regions that merges touching regions
//!   (and mirror pairs) of one thickness (`--parts N --parts-from geometry`), after
//!   [`split_disconnected_leaves`] has split regions made of pieces of different parts, and
//!   before [`snap_part_boundaries`] moves the parts' boundaries onto creases.
//! - [`refine_cosegmentation`]: smoothed best-response refinement of a co-segmentation's
//!   boundaries over every edge of the graph.
//! - [`segment_collection`]: graph, co-segmentation and refinement in one call, as
//!   `coseg segment` runs them.
//! - [`load_collection`]: a folder of meshes to graph nodes through the per-shape cache.

mod adaptive_cosegment;
mod cosegment;
mod cycle_consistency;
mod geometric_part_tree;
mod load_collection;
mod mirror_pairs;
mod part_cues;
mod refine_cosegmentation;
mod segment_collection;
mod shape_graph;
mod snap_part_boundaries;
mod split_disconnected_leaves;
mod stable_cycle;

pub use adaptive_cosegment::{
    AdaptiveCosegmentation, AdaptiveOptions, AutoTuple, PartMerge, PartTree, PartsReport, Sizing,
    StopReason, adaptive_cosegment, adaptive_update,
};
pub use cosegment::{CosegmentOptions, Cosegmentation, RegionTuple, cosegment, cosegment_update};
pub use cycle_consistency::{CycleConsistency, cycle_consistency};
pub use geometric_part_tree::{
    SIBLING_COST, geometric_part_tree, geometric_part_tree_linked, geometric_part_tree_with_cues,
};
pub use load_collection::{
    LoadedCollection, SkippedFile, is_coseg_output, load_collection, mesh_files, shape_names,
};
pub use mirror_pairs::{
    Likeness, MIRROR_AREA_BALANCE, MIRROR_LIKENESS, MIRROR_PAIR_RATIO, MirrorPair, MirrorPlane,
    mirror_pairs, mirror_plane,
};
pub use part_cues::{PartCues, PartCuesResult, load_or_compute_part_cues};
pub use refine_cosegmentation::{
    MIN_KEPT_SHARE, RefineSizes, refine_cosegmentation, refine_cosegmentation_sized,
};
pub use segment_collection::{
    PartsFrom, PartsRequest, SegmentCollectionOptions, SegmentTimes, SegmentedCollection,
    segment_collection, start_score,
};
pub use shape_graph::{GraphKind, GraphOptions, ShapeEdge, ShapeGraph, ShapeNode, shape_summary};
pub use snap_part_boundaries::snap_part_boundaries;
pub use split_disconnected_leaves::{
    SPLIT_PIECE_SHARE, SPLIT_SAME_DIRECTION, SplitLeaves, split_disconnected_leaves,
};
pub use stable_cycle::{
    CycleShape, CycleStep, StableCycle, StableCycleOptions, stable_cycle, stable_cycle_with,
};

use crate::affinity::AffinityError;
use thiserror::Error;

/// Errors of the collection stage.
#[derive(Debug, Error)]
pub enum GraphError {
    /// An affinity operator rejected its input.
    #[error(transparent)]
    Affinity(#[from] AffinityError),
    /// An option or argument is out of range.
    #[error("invalid option: {0}")]
    BadOption(String),
    /// Shapes that must share a band count or feature count do not.
    #[error("shape {name}: {reason}")]
    Incompatible {
        /// The shape's name.
        name: String,
        /// What does not match.
        reason: String,
    },
    /// A shape's heat smoother (for the refinement) could not be built.
    #[error("shape {name}: heat smoothing: {source}")]
    Smoothing {
        /// The shape's name.
        name: String,
        /// The spectral-stage error.
        #[source]
        source: crate::spectral::SpectralError,
    },
    /// A shape's thickness (shape diameter function) for [`geometric_part_tree`] could not be
    /// computed.
    #[error("shape {name}: thickness (SDF): {source}")]
    Thickness {
        /// The shape's name.
        name: String,
        /// The feature-stage error.
        #[source]
        source: crate::features::FeatureError,
    },
    /// The collection folder could not be listed.
    #[error("{path}: {source}")]
    Io {
        /// The folder.
        path: String,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
}
