//! Mesh readers and writers: OBJ (via tobj), OFF (our own), PLY ASCII and binary (via ply-rs-bw).
//!
//! Readers keep the file's vertex order exactly: they never merge, drop or reorder vertices.
//! Polygons are fan-triangulated. Every error names the file.

use super::{MeshError, MeshReport, TriMesh};
use std::path::Path;

/// A file format coseg reads and writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (positions and faces only).
    Obj,
    /// Object File Format (ASCII).
    Off,
    /// Stanford PLY (ASCII or binary little-endian on read; binary on write).
    Ply,
}

impl MeshFormat {
    /// The format named by a file's extension (case-insensitive), if any.
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(MeshFormat::Obj),
            "off" => Some(MeshFormat::Off),
            "ply" => Some(MeshFormat::Ply),
            _ => None,
        }
    }
}

/// A per-vertex property written into a PLY file beside the positions.
#[derive(Debug, Clone, PartialEq)]
pub enum PlyVertexProperty {
    /// RGB colour, written as `red`, `green`, `blue` uchar properties.
    Color(Vec<[u8; 3]>),
    /// A named integer property (written as PLY `int`).
    Int(String, Vec<i32>),
    /// A named float property (written as PLY `float`).
    Float(String, Vec<f32>),
}

/// Reads a mesh, choosing the format by extension. See [`read_mesh_with_report`] to also get the
/// warnings.
pub fn read_mesh(path: impl AsRef<Path>) -> Result<TriMesh, MeshError> {
    read_mesh_with_report(path).map(|(m, _)| m)
}

/// Reads a mesh and checks it; returns the mesh and its [`MeshReport`].
pub fn read_mesh_with_report(path: impl AsRef<Path>) -> Result<(TriMesh, MeshReport), MeshError> {
    let _ = path;
    todo!("issue 2")
}

/// Writes a mesh, choosing the format by extension. `properties` are written only to PLY
/// (other formats ignore them).
pub fn write_mesh(
    path: impl AsRef<Path>,
    mesh: &TriMesh,
    properties: &[PlyVertexProperty],
) -> Result<(), MeshError> {
    let _ = (path, mesh, properties);
    todo!("issue 2")
}
