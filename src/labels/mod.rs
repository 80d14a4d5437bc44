//! Part labels of shapes: reading and writing annotation files, and converting between
//! per-vertex and per-face labels.
//!
//! A label is any integer; `-1` (any negative value) means *unlabelled*, so partial annotations
//! are allowed. Two file formats, both one integer per line (blank lines skipped):
//!
//! - **per-vertex** text (`<name>.labels.txt`, or any other extension): line `i` is vertex `i`
//!   in the mesh file's vertex order;
//! - **per-face** `.seg` (Princeton segmentation benchmark / COSEG): line `f` is face `f` in
//!   the mesh file's face order. PSB files are 0-based and COSEG files 1-based: labels are kept
//!   as they are, they only have to mean the same part on every shape.
//!
//! [`faces_to_vertices`] and [`vertices_to_faces`] convert between the two;
//! [`read_shape_labels`] reads either against a mesh (checking the count);
//! [`match_label_files`] pairs label files with meshes by file stem; [`read_part_names`] reads the
//! optional `{label: name}` JSON.
//!
//! ```
//! use coseg::labels::{faces_to_vertices, vertices_to_faces};
//! use coseg::mesh::TriMesh;
//! // A unit square of two triangles, face 0 labelled 1 and face 1 labelled 2.
//! let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
//!     vec![[0, 1, 2], [0, 2, 3]]).unwrap();
//! let v = faces_to_vertices(&m, &[1, 2]).unwrap();
//! assert_eq!(v, vec![1, 1, 1, 2]); // shared vertices 0, 2 take the lower label on a tie
//! assert_eq!(vertices_to_faces(&m, &v).unwrap(), vec![1, 1]);
//! ```

mod convert;
mod files;

pub use convert::{faces_to_vertices, label_set, vertices_to_faces};
pub use files::{
    LabelKind, MatchedLabels, PartNames, ShapeLabels, label_file_stem, match_label_files,
    parse_label_file, parse_shape_labels, read_label_file, read_part_names, read_shape_labels,
    write_face_labels, write_vertex_labels,
};

use thiserror::Error;

/// Errors of label input and conversion; each names the file concerned when there is one.
#[derive(Debug, Error)]
pub enum LabelError {
    /// A file could not be read or written.
    #[error(transparent)]
    Io(#[from] crate::FileError),
    /// A line is not an integer (`line` is 1-based).
    #[error("{path}:{line}: {text:?} is not an integer label")]
    BadLabel {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// The offending text.
        text: String,
    },
    /// The file has a different number of labels than the mesh has vertices (or faces).
    #[error("{path}: {got} labels, but the mesh {mesh} has {expected} {what}")]
    Count {
        /// The label file.
        path: String,
        /// The mesh it was matched with.
        mesh: String,
        /// `"vertices"` or `"faces"`.
        what: &'static str,
        /// Vertex or face count of the mesh.
        expected: usize,
        /// Labels in the file.
        got: usize,
    },
    /// Label files that carry no label `≥ 0` (every line negative: unlabelled), when no other
    /// annotation is left to propagate.
    #[error(
        "{paths}: no label ≥ 0 (every line is negative, i.e. unlabelled): nothing to propagate"
    )]
    Unlabelled {
        /// The files, comma-separated.
        paths: String,
    },
    /// A label vector given in memory does not match the mesh.
    #[error("{got} labels for a mesh of {expected} {what}")]
    Length {
        /// `"vertices"` or `"faces"`.
        what: &'static str,
        /// Vertex or face count.
        expected: usize,
        /// Labels given.
        got: usize,
    },
    /// A label file matches no mesh, or two files match the same mesh.
    #[error("{path}: {message}")]
    Match {
        /// The label file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// The part-names file is not a JSON object `{label: name}` with integer keys.
    #[error("{path}: {message}")]
    BadNames {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
}
