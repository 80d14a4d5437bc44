//! Output files of a segmentation or a propagation: per-vertex region ids or labels, coloured
//! meshes and a JSON summary ([`write_regions`], [`write_propagation`], [`write_visuals`]).
//!
//! Generic over the stage that produced the regions (two-shape stable regions or a collection):
//! a shape is a name, its mesh and one region id per vertex (`-1` = none); the summary is any
//! serialisable value. Every file is written atomically (temporary file + rename), so a crash
//! never leaves a half-written output.
//!
//! - `OUT/<name>.regions.txt`: one integer region id per line, in the input file's vertex order.
//! - `OUT/<name>.regions.ply`: the mesh with `red`/`green`/`blue` colours by region and an
//!   integer `region` vertex property.
//! - `OUT/summary.json`: the summary, pretty-printed.
//! - `OUT/index.html`: [`write_viewer`], a self-contained interactive 3D view of the shapes.
//! - `OUT/preview.png`, `OUT/<name>.png`: pictures ([`crate::render`]); [`write_visuals`]
//!   writes them and the viewer in one call.

mod collection_summary;
mod export_features;
mod pair_summary;
mod viewer;
mod visuals;
mod write_propagation;
mod write_regions;

/// Re-exported from [`crate::render`], where the palette lives: PLY colours and pictures agree.
pub use crate::render::region_colors;
pub use collection_summary::{
    CollectionEdge, CollectionRegion, CollectionShape, CollectionSummary, SkippedInput,
    StartsReport,
};
pub use export_features::{ExportFormat, ExportOptions, export_features};
pub use pair_summary::{PairSummary, RegionSummary, ShapeSummary};
pub use viewer::write_viewer;
pub use visuals::write_visuals;
pub use write_propagation::{
    PropagatedPart, PropagatedShape, PropagationSummary, write_propagation,
};
pub use write_regions::{
    ShapeRegions, write_region_ids, write_region_mesh, write_regions, write_summary,
};

use thiserror::Error;

/// Errors of the output stage; each names the file concerned.
#[derive(Debug, Error)]
pub enum OutputError {
    /// Writing a file failed.
    #[error(transparent)]
    Io(#[from] crate::FileError),
    /// Writing a mesh failed.
    #[error(transparent)]
    Mesh(#[from] crate::mesh::MeshError),
    /// Arrays to be written together do not fit each other (a bug of the caller).
    #[error("inconsistent tables: {0}")]
    Inconsistent(String),
    /// The region ids do not match the mesh.
    #[error("{name}: {ids} region ids for a mesh of {vertices} vertices")]
    Length {
        /// Shape name.
        name: String,
        /// Number of ids given.
        ids: usize,
        /// Vertex count.
        vertices: usize,
    },
    /// A shape name that cannot be a file name.
    #[error("invalid shape name {0:?}: must be non-empty without path separators")]
    BadName(String),
    /// Drawing or writing a picture failed.
    #[error(transparent)]
    Render(#[from] crate::render::RenderError),
    /// Label files could not be written or converted.
    #[error(transparent)]
    Labels(#[from] crate::labels::LabelError),
    /// The summary could not be serialised.
    #[error("summary.json: {0}")]
    Json(String),
}
