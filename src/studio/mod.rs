//! The labelling studio's operations as library calls (`coseg studio` serves them to a browser
//! page; the server only translates).
//!
//! - [`crease_patches`]: a fine over-segmentation of a shape whose boundaries follow its
//!   creases, so that one click labels a leg.
//! - [`Palette`]: the parts, with names and colours (add, rename, recolour).
//! - [`Studio`]: a labelling session on a folder of meshes: open (resuming a saved session),
//!   label a patch, brush vertices, erase, undo/redo, propagate through the library's
//!   incremental update ([`Propagation::update`](crate::propagate::Propagation::update)), save
//!   and export atomically, thumbnails.
//!
//! Files of a session, in its labels folder (default `FOLDER/labels`): `<stem>.labels.txt`
//! (per vertex) and `<stem>.seg` (per face) for every shape, `parts.json` (`{label: name}`, as
//! `coseg propagate --part-names` reads it) and `summary.json` (the sources, part colours and
//! confidences; `coseg eval` reads its `sources`), so the folder is also what `coseg eval
//! LABELS --truth GT` scores.

mod crease_patches;
mod palette;
mod studio_session;

pub use crease_patches::{PatchOptions, crease_patches};
pub use palette::{Palette, Part};
pub use studio_session::{
    EditSummary, PropagateProgress, PropagateReport, ShapeInfo, Studio, StudioOptions,
};

use thiserror::Error;

/// Errors of the studio; each names the shape, part or file concerned.
#[derive(Debug, Error)]
pub enum StudioError {
    /// A request names a shape, patch, vertex or part that does not exist, or an option is out
    /// of range; nothing was changed.
    #[error("{0}")]
    BadRequest(String),
    /// A path names a place outside the session's folder; nothing was read or written.
    #[error("{path}: outside the studio's folder {folder}")]
    OutsideFolder {
        /// The path as given.
        path: String,
        /// The session's folder.
        folder: String,
    },
    /// A file could not be read or written.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// The collection could not be loaded.
    #[error(transparent)]
    Graph(#[from] crate::graph::GraphError),
    /// Propagation failed.
    #[error(transparent)]
    Propagate(#[from] crate::propagate::PropagateError),
    /// A label file is unreadable or does not fit its mesh.
    #[error(transparent)]
    Labels(#[from] crate::labels::LabelError),
}
