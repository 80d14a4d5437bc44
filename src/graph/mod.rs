//! Shape collections: the shape graph, the cycle solver and consistent co-segmentation of a
//! whole collection (docs/METHOD.md §5). What turns the co-segmentation's regions into parts
//! (parts of their own size, the part trees, mirror pairs) is the next stage, [`crate::parts`].
//!
//! - [`stable_cycle`]: fixed points of `P_0 ∘ W_{0,m−1} ∘ … ∘ P_1 ∘ W_10` around a cycle of any
//!   length `m ≥ 2`; the 2-cycle is exactly Algorithm 1.
//! - [`cycle_consistency`]: how much of a region carried around a cycle of thresholded
//!   transports comes back to itself.
//! - [`ShapeGraph`]: nodes hold each shape's band table and unit-area vertex areas, edges the
//!   feature pairing and a weight; pairwise affinities exist only as band-table operators.
//! - [`cosegment`]: consistent region tuples across every shape of the graph (design argued
//!   in that function's module).
//! - [`shape_confidences`]: each shape's share of a co-segmentation's confidence.
//! - [`refine_cosegmentation`]: smoothed best-response refinement of a co-segmentation's
//!   boundaries over every edge of the graph.
//! - [`load_collection`]: a folder of meshes to graph nodes through the per-shape cache.

mod cosegment;
mod cycle_consistency;
mod load_collection;
mod refine_cosegmentation;
mod shape_confidences;
mod shape_graph;
mod stable_cycle;

pub use cosegment::{CosegmentOptions, Cosegmentation, RegionTuple, cosegment, cosegment_update};
pub(crate) use cosegment::{
    Engine, Extraction, area, area_fractions, check_extraction, seed_region, tuple_hash,
};
pub use cycle_consistency::{CycleConsistency, cycle_consistency};
pub use load_collection::{
    LoadedCollection, SkippedFile, is_coseg_output, load_collection, mesh_files, shape_names,
};
pub use refine_cosegmentation::{RefineSizes, refine_cosegmentation, refine_cosegmentation_sized};
pub use shape_confidences::shape_confidences;
pub use shape_graph::{GraphKind, GraphOptions, ShapeEdge, ShapeGraph, ShapeNode, shape_summary};
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
    /// A shape's thickness (shape diameter function) for
    /// [`geometric_part_tree`](crate::parts::geometric_part_tree) could not be
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
    #[error(transparent)]
    Io(#[from] crate::FileError),
}
