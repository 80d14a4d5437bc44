//! Mesh readers and writers: OBJ and OFF (our own parsers), PLY ASCII and binary (via ply-rs-bw).
//!
//! Readers keep the file's vertex order exactly: they never merge, drop or reorder vertices, and
//! vertex `i` of the mesh is the `i`-th vertex record of the file. Polygons are fan-triangulated
//! (`v0 v1 … vn-1` → `(v0, vk, vk+1)` for `k = 1..n-2`), in file order. Every error names the file.
//!
//! Writers write `f64` coordinates losslessly (shortest round-trip decimal in OBJ/OFF, `double`
//! in PLY), so `read_mesh(write_mesh(m)) == m` bit for bit, and write atomically through
//! [`write_atomic`].

mod atomic;
mod obj;
mod off;
mod ply;
mod text;

pub use atomic::write_atomic;

use super::{IN_MEMORY, MeshError, MeshReport, MeshWarning, TriMesh};
use std::path::Path;

/// A file format coseg reads and writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (positions and faces only).
    Obj,
    /// Object File Format (ASCII).
    Off,
    /// Stanford PLY (ASCII, binary little- or big-endian on read; binary little-endian on write).
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

/// A per-vertex property written into a PLY file beside the positions. Each vector has one
/// entry per vertex, in vertex order.
#[derive(Debug, Clone, PartialEq)]
pub enum PlyVertexProperty {
    /// RGB colour, written as `red`, `green`, `blue` uchar properties.
    Color(Vec<[u8; 3]>),
    /// A named integer property (written as PLY `int`).
    Int(String, Vec<i32>),
    /// A named float property (written as PLY `float`).
    Float(String, Vec<f32>),
}

/// Positions and triangles as a parser found them, before [`TriMesh::new`] validates them.
/// Indices are already checked against the vertex count.
pub(crate) struct RawMesh {
    pub positions: Vec<[f64; 3]>,
    pub faces: Vec<[u32; 3]>,
    /// What the parser skipped but the user should hear of.
    pub warnings: Vec<MeshWarning>,
}

/// Reads a mesh, choosing the format by extension. See [`read_mesh_with_report`] to also get the
/// warnings.
///
/// ```
/// # fn main() -> Result<(), coseg::mesh::MeshError> {
/// use coseg::mesh::{read_mesh, write_mesh, TriMesh};
/// let dir = std::env::temp_dir().join(format!("coseg-doc-read-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("tri.off");
/// std::fs::write(&path, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").unwrap();
/// let mesh = read_mesh(&path)?;
/// assert_eq!((mesh.vertex_count(), mesh.face_count()), (3, 1));
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok(()) }
/// ```
pub fn read_mesh(path: impl AsRef<Path>) -> Result<TriMesh, MeshError> {
    read_mesh_with_report(path).map(|(m, _)| m)
}

/// Reads a mesh (format chosen by extension) and checks it; returns the mesh and its
/// [`MeshReport`] of warnings (degenerate triangles, duplicate faces, unreferenced vertices,
/// non-manifold edges, boundary, several components).
///
/// Parser warnings come first (an OFF file's data after its declared elements,
/// [`MeshWarning::IgnoredData`]), then the mesh's own.
///
/// Errors ([`MeshError`], always naming `path`): the file cannot be read, unknown extension,
/// wrong header, unsupported element or encoding, truncated file, malformed record, index out of
/// range, non-finite coordinate, empty mesh, zero total area.
///
/// ```
/// # fn main() -> Result<(), coseg::mesh::MeshError> {
/// use coseg::mesh::{read_mesh_with_report, MeshWarning};
/// let dir = std::env::temp_dir().join(format!("coseg-doc-report-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("tri.obj");
/// std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
/// let (mesh, report) = read_mesh_with_report(&path)?;
/// assert_eq!(mesh.face_count(), 1);
/// assert!(report.warnings.contains(&MeshWarning::Boundary { edges: 3 }));
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok(()) }
/// ```
pub fn read_mesh_with_report(path: impl AsRef<Path>) -> Result<(TriMesh, MeshReport), MeshError> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let format = MeshFormat::from_path(path)
        .ok_or_else(|| MeshError::UnsupportedFormat { path: name.clone() })?;
    let bytes = std::fs::read(path).map_err(|source| {
        MeshError::Io(crate::FileError {
            path: name.clone(),
            source,
        })
    })?;
    let (mesh, mut parse_warnings) = parse(&bytes, format).map_err(|e| e.with_path(&name))?;
    let mut report = mesh.report();
    parse_warnings.append(&mut report.warnings);
    report.warnings = parse_warnings;
    Ok((mesh, report))
}

/// Parses a mesh held in memory in the given format. Errors name `<memory>`; use
/// [`MeshError::with_path`] to name a file instead. Never panics, whatever the bytes.
///
/// ```
/// use coseg::mesh::{read_mesh_from_bytes, MeshFormat};
/// let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
/// let mesh = read_mesh_from_bytes(obj, MeshFormat::Obj).unwrap();
/// assert_eq!(mesh.faces(), &[[0, 1, 2], [0, 2, 3]]); // quad fan-triangulated
/// ```
pub fn read_mesh_from_bytes(bytes: &[u8], format: MeshFormat) -> Result<TriMesh, MeshError> {
    parse(bytes, format).map(|(mesh, _)| mesh)
}

/// The mesh in `bytes` and the parser's own warnings (data it skipped).
fn parse(bytes: &[u8], format: MeshFormat) -> Result<(TriMesh, Vec<MeshWarning>), MeshError> {
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(MeshError::Empty {
            path: IN_MEMORY.to_string(),
            vertices: 0,
            faces: 0,
        });
    }
    let raw = match format {
        MeshFormat::Obj => obj::parse(bytes)?,
        MeshFormat::Off => off::parse(bytes)?,
        MeshFormat::Ply => ply::parse(bytes)?,
    };
    Ok((TriMesh::new(raw.positions, raw.faces)?, raw.warnings))
}

/// Writes a mesh, choosing the format by extension, atomically (see [`write_atomic`]).
/// `properties` are written only to PLY (other formats ignore them); each must have one entry
/// per vertex and a name that is a single word distinct from `x`, `y`, `z`, the colour names
/// and the other properties.
///
/// ```
/// # fn main() -> Result<(), coseg::mesh::MeshError> {
/// use coseg::mesh::{read_mesh, write_mesh, PlyVertexProperty, TriMesh};
/// let mesh = TriMesh::new(
///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.1, 0.0]],
///     vec![[0, 1, 2]],
/// )?;
/// let dir = std::env::temp_dir().join(format!("coseg-doc-write-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("tri.ply");
/// write_mesh(&path, &mesh, &[PlyVertexProperty::Int("label".into(), vec![0, 1, 1])])?;
/// assert_eq!(read_mesh(&path)?, mesh); // bit-for-bit round trip
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok(()) }
/// ```
pub fn write_mesh(
    path: impl AsRef<Path>,
    mesh: &TriMesh,
    properties: &[PlyVertexProperty],
) -> Result<(), MeshError> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let format = MeshFormat::from_path(path)
        .ok_or_else(|| MeshError::UnsupportedFormat { path: name.clone() })?;
    if format == MeshFormat::Ply {
        ply::check_properties(mesh, properties).map_err(|e| e.with_path(&name))?;
    }
    write_atomic(path, |w| match format {
        MeshFormat::Obj => obj::write(w, mesh),
        MeshFormat::Off => off::write(w, mesh),
        MeshFormat::Ply => ply::write(w, mesh, properties),
    })
    .map_err(|source| MeshError::Io(crate::FileError { path: name, source }))
}

/// Builds a [`MeshError::Parse`] for an in-memory source, with an optional 1-based line number.
pub(crate) fn parse_error(line: Option<usize>, message: impl std::fmt::Display) -> MeshError {
    let message = match line {
        Some(l) => format!("line {l}: {message}"),
        None => message.to_string(),
    };
    MeshError::Parse {
        path: IN_MEMORY.to_string(),
        message,
    }
}

/// Fan-triangulates polygon `poly` (indices already checked), appending to `faces`.
pub(crate) fn fan(poly: &[u32], faces: &mut Vec<[u32; 3]>) {
    for k in 1..poly.len().saturating_sub(1) {
        faces.push([poly[0], poly[k], poly[k + 1]]);
    }
}

/// A capacity hint that a lying header cannot turn into a huge allocation.
pub(crate) fn capacity_hint(
    declared: usize,
    available_bytes: usize,
    min_bytes_each: usize,
) -> usize {
    declared.min(available_bytes / min_bytes_each.max(1) + 1)
}

/// Builds a [`MeshError::Truncated`] for an in-memory source.
pub(crate) fn truncated(message: impl std::fmt::Display) -> MeshError {
    MeshError::Truncated {
        path: IN_MEMORY.to_string(),
        message: message.to_string(),
    }
}

/// Builds a [`MeshError::Header`] for an in-memory source.
pub(crate) fn header_error(message: impl std::fmt::Display) -> MeshError {
    MeshError::Header {
        path: IN_MEMORY.to_string(),
        message: message.to_string(),
    }
}

/// Builds a [`MeshError::IndexOutOfRange`] for an in-memory source.
pub(crate) fn out_of_range(face: usize, index: u64, vertices: usize) -> MeshError {
    MeshError::IndexOutOfRange {
        path: IN_MEMORY.to_string(),
        face,
        index,
        vertices,
    }
}
