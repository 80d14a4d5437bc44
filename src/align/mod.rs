//! Alignment: similarity transforms (rotation, uniform scale, translation) that put shapes in
//! one frame, and labels carried by nearest surface points (docs/ALIGN.md).
//!
//! Pairwise (the rigid route of label transfer and the evaluation baseline):
//! - [`Similarity`]: `x ↦ s R x + t`; [`Similarity::apply`], [`Similarity::compose`],
//!   [`Similarity::inverse`], [`Similarity::rotation_angle_to`];
//! - [`register_pair`]`(source, target, &`[`RegisterOptions`]`) -> Result<`[`Registration`]`, `[`AlignError`]`>`:
//!   the similarity taking `target` onto `source`, its residual (symmetric trimmed chamfer in
//!   source RMS radii), inlier share, and the runner-up pose of a symmetric shape;
//! - [`closest_surface_points`]`(mesh, points) -> Vec<`[`SurfacePoint`]`>` (face, barycentric,
//!   distance), exact, through a [`SurfaceIndex`] (build once, query many);
//! - [`nearest_point_labels`]`(source, source_face_labels, target, &transform)` and
//!   [`nearest_point_vertex_labels`] (per-vertex source labels): `(Vec<i32>, Vec<f64>)`, a
//!   label and a distance per target vertex.
//!
//! Collections:
//! - [`align_collection`]`(meshes, &`[`AlignOptions`]`) -> Result<`[`CollectionAlignment`]`, `[`AlignError`]`>`:
//!   a similarity per shape into one collection frame (registrations over a shape graph,
//!   synchronised), a confidence per shape, the already-aligned case kept exactly, the up and
//!   forward axes; `coseg align FOLDER -o OUT` is the job
//!   [`run_align`](crate::jobs::run_align).

mod align_collection;
mod closest_surface_points;
mod nearest_point_labels;
mod register_pair;
mod similarity;
mod surface_samples;

pub use align_collection::{
    AlignOptions, CollectionAlignment, FrameCase, ShapeAlignment, align_collection,
};
pub use closest_surface_points::{SurfaceIndex, SurfacePoint, closest_surface_points};
pub use nearest_point_labels::{nearest_point_labels, nearest_point_vertex_labels};
pub use register_pair::{Candidate, RegisterOptions, Registration, register_pair};
pub use similarity::Similarity;

pub(crate) use nearest_point_labels::{nearest_corner, nearest_point_vertex_labels_in};
pub(crate) use register_pair::register_onto_from;
pub(crate) use surface_samples::Prepared;
use thiserror::Error;

/// Errors of the alignment stage.
#[derive(Debug, Error)]
pub enum AlignError {
    /// An option is out of range.
    #[error("invalid option: {0}")]
    BadOption(String),
    /// A shape cannot be registered (no area, no extent).
    #[error("{0}")]
    Degenerate(String),
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder concerned.
        path: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A mesh could not be read or written.
    #[error("{path}: {source}")]
    Mesh {
        /// The file concerned.
        path: String,
        /// The mesh error.
        #[source]
        source: crate::mesh::MeshError,
    },
    /// Labels do not match the mesh they are given for.
    #[error("{found} {kind} labels for a mesh with {expected} {kind}s")]
    LabelCount {
        /// Faces or vertices of the mesh.
        expected: usize,
        /// Labels given.
        found: usize,
        /// "face" or "vertex".
        kind: &'static str,
    },
}
