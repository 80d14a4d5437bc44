//! Label propagation: part labels from a few annotated shapes to a whole collection
//! (docs/PROPAGATION.md argues the design).
//!
//! - [`propagate_collection`] and [`propagate_loaded`] run, by default, every correspondence
//!   route and fuse them ([`fuse_propagation`]): the band-affinity transport
//!   ([`propagate_labels`]), the collection's own parts named from the sources
//!   ([`parts_route`]); each route is trusted on each shape as far as the others agree with it
//!   ([`fuse_routes`]) and the fused boundaries move onto concave creases ([`snap_labels`]).
//! - [`propagate_labels`]: the band-affinity solver on a [`ShapeGraph`](crate::graph::ShapeGraph):
//!   annotated parts are fixed regions on their sources, transported through the band affinity
//!   onto every shape, relayed by labelled neighbours over the graph, smoothed and sized.
//! - [`Propagation::update`]: add or correct one annotation and re-propagate from the previous
//!   state, reusing every transport whose voter did not change.
//! - [`propagate_collection`]: a folder of meshes and a folder (or list) of label files in
//!   one call, as `coseg propagate` runs it; [`crate::output::write_propagation`] writes its files.
//!   [`propagate_loaded`] is its collection stage alone, for shapes already in memory (the
//!   Python package's `coseg.propagate` on arrays).
//! - [`map_step`]: for near-isometric collections, a target's labels carried point by point
//!   from its nearest source through a point map, kept when they agree with the propagation
//!   ([`PropagateCollectionOptions::map_step`], `coseg propagate --map-step`);
//!   [`map_step_collection`] runs it on every unlabelled shape of a propagation.

mod classifier_route;
mod collection;
mod fuse_propagation;
mod fuse_routes;
mod held_out;
mod map_route;
mod map_step;
mod map_step_collection;
mod options;
mod part_scores;
mod parts_route;
mod point_map_store;
mod refine_affine;
mod refine_nonrigid;
mod rigid_pair_store;
mod rigid_route;
mod snap_labels;
mod solve;

pub use classifier_route::{ClassifierReport, ClassifierShape, classifier_route};
pub use collection::{
    PropagateCollectionOptions, PropagatedCollection, PropagatedShapes, SourceFile,
    propagate_collection, propagate_loaded,
};
pub use fuse_propagation::{CollectionParts, FusionReport, RouteOptions, fuse_propagation};
pub use fuse_routes::{FusedRoutes, RoundTrip, Route, RouteLabels, fuse_routes, fuse_routes_with};
pub use held_out::{HeldOutInputs, HeldOutRoutes, held_out_accuracy, held_out_routes};
pub use map_route::{fuse_with_map, map_route, map_route_on};
pub use map_step::{MapStepOptions, MapStepReport, map_step};
pub use map_step_collection::map_step_collection;
pub use options::PropagateOptions;
pub use part_scores::PartScore;
pub use parts_route::parts_route;
pub use refine_affine::{AffineFit, AffineMap, refine_affine};
pub use refine_nonrigid::{NonrigidFit, refine_nonrigid};
pub use rigid_route::{
    RigidAlternative, RigidSteps, choose_rigid_alternative, rigid_alternatives,
    rigid_choice_is_outlier, rigid_route,
};
pub use snap_labels::snap_labels;
pub use solve::{Propagation, UpdateStats, propagate_labels};

use thiserror::Error;

/// Errors of label propagation; each names the shape or file concerned.
#[derive(Debug, Error)]
pub enum PropagateError {
    /// An option or argument is out of range.
    #[error("invalid option: {0}")]
    BadOption(String),
    /// No shape carries a label.
    #[error("no labelled shape: at least one annotation with a label ≥ 0 is needed")]
    NoLabels,
    /// A shape's annotation does not fit it.
    #[error("shape {name}: {message}")]
    Shape {
        /// The shape's name.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// A heat smoother failed.
    #[error("shape {name}: heat smoothing: {message}")]
    Smoothing {
        /// The shape's name.
        name: String,
        /// The spectral-stage error.
        message: String,
    },
    /// The affinity operator rejected its input.
    #[error(transparent)]
    Affinity(#[from] crate::affinity::AffinityError),
    /// The stable-region stage rejected its input.
    #[error(transparent)]
    Stable(#[from] crate::stable::StableError),
    /// The collection stage (loading, graph) failed.
    #[error(transparent)]
    Graph(#[from] crate::graph::GraphError),
    /// A label file is unreadable or does not fit its mesh.
    #[error(transparent)]
    Labels(#[from] crate::labels::LabelError),
}
