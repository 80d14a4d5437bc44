//! Triangle meshes: the validated [`TriMesh`] type, its per-vertex and per-face quantities,
//! topology queries, and readers/writers for OBJ, OFF and PLY.
//!
//! Conventions used everywhere in coseg:
//! - positions are `f64`, in the units of the input file;
//! - faces are counter-clockwise triangles of `u32` vertex indices (outward normal by the
//!   right-hand rule);
//! - the vertex order of the input file is kept exactly: labels and ground-truth maps index
//!   vertices, so no reader merges, drops or reorders vertices.

use thiserror::Error;

mod bvh_triangle;
pub mod io;
mod topology;
mod validate;

pub(crate) use bvh_triangle::BvhTriangle;
pub use io::{
    MeshFormat, PlyVertexProperty, read_mesh, read_mesh_from_bytes, read_mesh_with_report,
    write_atomic, write_mesh,
};
pub(crate) use topology::for_each_label_boundary;
pub use topology::{
    Components, boundary_edges, connected_components, edge_adjacency, edges, labelled_components,
};
pub use validate::{MeshReport, MeshWarning};

/// Errors raised while reading, writing or building a mesh. Every variant that concerns a file
/// names it, so a message can be shown to a user as is.
#[derive(Debug, Error)]
pub enum MeshError {
    /// The file could not be opened, read or written.
    #[error(transparent)]
    Io(#[from] crate::FileError),
    /// The file's extension does not name a supported format.
    #[error("{path}: unsupported mesh format (expected .obj, .off or .ply)")]
    UnsupportedFormat {
        /// The file concerned.
        path: String,
    },
    /// The file's content does not follow its format.
    #[error("{path}: {message}")]
    Parse {
        /// The file concerned.
        path: String,
        /// What is wrong, with a line number where known.
        message: String,
    },
    /// The mesh has no vertices or no faces.
    #[error("{path}: empty mesh ({vertices} vertices, {faces} faces)")]
    Empty {
        /// The file concerned (or `<memory>`).
        path: String,
        /// Number of vertices.
        vertices: usize,
        /// Number of faces.
        faces: usize,
    },
    /// A face refers to a vertex that does not exist.
    #[error("{path}: face {face} refers to vertex {index}, but the mesh has {vertices} vertices")]
    IndexOutOfRange {
        /// The file concerned (or `<memory>`).
        path: String,
        /// Face number (0-based, after triangulation).
        face: usize,
        /// The offending index, 0-based (an OBJ file's 1-based `k` is reported as `k - 1`).
        index: u64,
        /// Number of vertices.
        vertices: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("{path}: vertex {vertex} has a non-finite coordinate")]
    NonFinite {
        /// The file concerned (or `<memory>`).
        path: String,
        /// Vertex number (0-based).
        vertex: usize,
    },
    /// Every triangle has zero area: no surface to work on.
    #[error("{path}: every triangle is degenerate (total area {area})")]
    ZeroArea {
        /// The file concerned (or `<memory>`).
        path: String,
        /// The total area found.
        area: f64,
    },
    /// The file ends before all the records its header (or its syntax) announces.
    #[error("{path}: truncated file: {message}")]
    Truncated {
        /// The file concerned.
        path: String,
        /// What was expected and where the file ends (line number where known).
        message: String,
    },
    /// The file's header is wrong, or declares something coseg does not read (an unknown
    /// encoding, a missing or unsupported element or property type).
    #[error("{path}: {message}")]
    Header {
        /// The file concerned.
        path: String,
        /// What is wrong ("wrong header: …" or "unsupported …").
        message: String,
    },
    /// A per-vertex property given to a writer is invalid (wrong length or name).
    #[error("{path}: {message}")]
    Property {
        /// The file concerned.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// More vertices than a `u32` index can address.
    #[error("{path}: {vertices} vertices exceed the u32 index range")]
    TooLarge {
        /// The file concerned (or `<memory>`).
        path: String,
        /// Number of vertices.
        vertices: usize,
    },
}

impl MeshError {
    /// The same error, naming `path` instead of whatever it named.
    pub fn with_path(self, path: &str) -> Self {
        let p = path.to_string();
        match self {
            MeshError::Io(e) => MeshError::Io(crate::FileError {
                path: p,
                source: e.source,
            }),
            MeshError::UnsupportedFormat { .. } => MeshError::UnsupportedFormat { path: p },
            MeshError::Parse { message, .. } => MeshError::Parse { path: p, message },
            MeshError::Empty {
                vertices, faces, ..
            } => MeshError::Empty {
                path: p,
                vertices,
                faces,
            },
            MeshError::IndexOutOfRange {
                face,
                index,
                vertices,
                ..
            } => MeshError::IndexOutOfRange {
                path: p,
                face,
                index,
                vertices,
            },
            MeshError::NonFinite { vertex, .. } => MeshError::NonFinite { path: p, vertex },
            MeshError::ZeroArea { area, .. } => MeshError::ZeroArea { path: p, area },
            MeshError::TooLarge { vertices, .. } => MeshError::TooLarge { path: p, vertices },
            MeshError::Truncated { message, .. } => MeshError::Truncated { path: p, message },
            MeshError::Header { message, .. } => MeshError::Header { path: p, message },
            MeshError::Property { message, .. } => MeshError::Property { path: p, message },
        }
    }
}

/// A validated triangle mesh: `d` vertices (`f64` positions) and `m` triangles (`u32` indices).
///
/// Invariants, checked by [`TriMesh::new`]: at least one vertex and one face, every index
/// `< d`, every coordinate finite, positive total area.
/// Conditions the method survives (degenerate triangles, non-manifold edges, several
/// components…) are not errors; [`TriMesh::report`] lists them.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TriMesh {
    positions: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
}

/// Name used in errors for meshes that do not come from a file.
pub(crate) const IN_MEMORY: &str = "<memory>";

impl TriMesh {
    /// Builds a mesh, checking the invariants listed on [`TriMesh`].
    ///
    /// ```
    /// use coseg::mesh::TriMesh;
    /// let mesh = TriMesh::new(
    ///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    ///     vec![[0, 1, 2]],
    /// ).unwrap();
    /// assert_eq!(mesh.vertex_count(), 3);
    /// assert!((mesh.total_area() - 0.5).abs() < 1e-12);
    /// ```
    pub fn new(positions: Vec<[f64; 3]>, faces: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        let path = IN_MEMORY.to_string();
        if positions.is_empty() || faces.is_empty() {
            return Err(MeshError::Empty {
                path,
                vertices: positions.len(),
                faces: faces.len(),
            });
        }
        if positions.len() > u32::MAX as usize {
            return Err(MeshError::TooLarge {
                path,
                vertices: positions.len(),
            });
        }
        if let Some(v) = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(MeshError::NonFinite { path, vertex: v });
        }
        let d = positions.len();
        for (fi, f) in faces.iter().enumerate() {
            for &i in f {
                if i as usize >= d {
                    return Err(MeshError::IndexOutOfRange {
                        path,
                        face: fi,
                        index: i as u64,
                        vertices: d,
                    });
                }
            }
        }
        let mesh = TriMesh { positions, faces };
        let area = mesh.total_area();
        if area <= 0.0 || !area.is_finite() {
            return Err(MeshError::ZeroArea { path, area });
        }
        Ok(mesh)
    }

    /// Vertex positions, in file order.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }

    /// Triangles as vertex-index triples, counter-clockwise.
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// Number of vertices `d`.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles `m`.
    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// The three corner positions of face `f`.
    #[inline]
    pub fn corners(&self, f: usize) -> [[f64; 3]; 3] {
        let [a, b, c] = self.faces[f];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// Area of every triangle (length `m`, non-negative, squared file units).
    pub fn face_areas(&self) -> Vec<f64> {
        (0..self.faces.len())
            .map(|f| {
                let [a, b, c] = self.corners(f);
                0.5 * norm(cross(sub(b, a), sub(c, a)))
            })
            .collect()
    }

    /// Sum of the triangle areas.
    pub fn total_area(&self) -> f64 {
        self.face_areas().iter().sum()
    }

    /// Barycentric vertex areas ω (length `d`): each triangle gives a third of its area to each
    /// of its corners, so `Σ ω = total_area()`. Unreferenced vertices get 0.
    pub fn vertex_areas(&self) -> Vec<f64> {
        let mut w = vec![0.0; self.positions.len()];
        for (f, a) in self.faces.iter().zip(self.face_areas()) {
            for &i in f {
                w[i as usize] += a / 3.0;
            }
        }
        w
    }

    /// Unit normal of every triangle (right-hand rule on the face's vertex order). A degenerate
    /// triangle gets the zero vector.
    pub fn face_normals(&self) -> Vec<[f64; 3]> {
        (0..self.faces.len())
            .map(|f| {
                let [a, b, c] = self.corners(f);
                normalized(cross(sub(b, a), sub(c, a)))
            })
            .collect()
    }

    /// Unit normal of every vertex: the area-weighted mean of its faces' normals. A vertex with
    /// no non-degenerate face gets the zero vector.
    pub fn vertex_normals(&self) -> Vec<[f64; 3]> {
        let mut n = vec![[0.0; 3]; self.positions.len()];
        for f in 0..self.faces.len() {
            let [a, b, c] = self.corners(f);
            // The unnormalised cross product is twice the area times the unit normal.
            let w = cross(sub(b, a), sub(c, a));
            for &i in &self.faces[f] {
                let v = &mut n[i as usize];
                v[0] += w[0];
                v[1] += w[1];
                v[2] += w[2];
            }
        }
        n.into_iter().map(normalized).collect()
    }

    /// The same mesh with its vertices moved by `f` (faces unchanged). Fails if `f` produces a
    /// non-finite coordinate or a zero-area mesh.
    pub fn map_positions(&self, f: impl Fn([f64; 3]) -> [f64; 3]) -> Result<Self, MeshError> {
        TriMesh::new(
            self.positions.iter().map(|&p| f(p)).collect(),
            self.faces.clone(),
        )
    }

    /// Checks the conditions the method survives but a user should know of (see
    /// [`MeshWarning`]).
    pub fn report(&self) -> MeshReport {
        validate::report(self)
    }
}

#[inline]
pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

#[inline]
fn normalized(a: [f64; 3]) -> [f64; 3] {
    let n = norm(a);
    if n > 0.0 {
        [a[0] / n, a[1] / n, a[2] / n]
    } else {
        [0.0; 3]
    }
}
