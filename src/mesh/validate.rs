//! Conditions a mesh can have that the method survives, reported as warnings.

use super::{TriMesh, topology};
use std::fmt;

/// Something about a mesh that the method survives but a user should know of.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum MeshWarning {
    /// Triangles with (numerically) zero area; their cotangent weights are clamped.
    DegenerateFaces {
        /// How many.
        count: usize,
        /// The first one (0-based face index).
        first: usize,
    },
    /// Faces listing the same three vertices as an earlier face (in any order).
    DuplicateFaces {
        /// How many.
        count: usize,
        /// The first one.
        first: usize,
    },
    /// Vertices used by no face; they get zero area and are isolated in the spectrum.
    UnreferencedVertices {
        /// How many.
        count: usize,
        /// The first one.
        first: usize,
    },
    /// Edges shared by more than two faces.
    NonManifoldEdges {
        /// How many.
        count: usize,
        /// The first one, as a vertex pair.
        first: [u32; 2],
    },
    /// The surface has several connected components (one zero eigenvalue each).
    SeveralComponents {
        /// How many.
        count: usize,
    },
    /// The surface has boundary edges (it is not closed).
    Boundary {
        /// Number of boundary edges.
        edges: usize,
    },
    /// The file holds data the reader skipped (an OFF file's lines after the elements its
    /// header declares): the mesh is what the header declares.
    IgnoredData {
        /// What was skipped and where (line number).
        message: String,
    },
}

impl fmt::Display for MeshWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshWarning::DegenerateFaces { count, first } => {
                write!(
                    f,
                    "{count} degenerate (zero-area) triangles, first is face {first}"
                )
            }
            MeshWarning::DuplicateFaces { count, first } => {
                write!(f, "{count} duplicate faces, first is face {first}")
            }
            MeshWarning::UnreferencedVertices { count, first } => {
                write!(f, "{count} unreferenced vertices, first is vertex {first}")
            }
            MeshWarning::NonManifoldEdges { count, first } => write!(
                f,
                "{count} non-manifold edges, first is ({}, {})",
                first[0], first[1]
            ),
            MeshWarning::SeveralComponents { count } => {
                write!(f, "{count} connected components")
            }
            MeshWarning::Boundary { edges } => write!(f, "open surface: {edges} boundary edges"),
            MeshWarning::IgnoredData { message } => write!(f, "ignored: {message}"),
        }
    }
}

/// The warnings found on a mesh (empty when the mesh is a clean closed manifold).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MeshReport {
    /// Warnings, in a fixed order.
    pub warnings: Vec<MeshWarning>,
}

impl MeshReport {
    /// True when nothing was found.
    pub fn is_clean(&self) -> bool {
        self.warnings.is_empty()
    }
}

/// Relative area below which a triangle counts as degenerate (times the mean triangle area).
const DEGENERATE_RELATIVE_AREA: f64 = 1e-12;

pub(super) fn report(mesh: &TriMesh) -> MeshReport {
    let mut warnings = Vec::new();
    let areas = mesh.face_areas();
    let mean = areas.iter().sum::<f64>() / areas.len() as f64;
    let degenerate: Vec<usize> = (0..areas.len())
        .filter(|&f| areas[f] <= DEGENERATE_RELATIVE_AREA * mean)
        .collect();
    if let Some(&first) = degenerate.first() {
        warnings.push(MeshWarning::DegenerateFaces {
            count: degenerate.len(),
            first,
        });
    }
    let mut keyed: Vec<([u32; 3], usize)> = mesh
        .faces()
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let mut k = *f;
            k.sort_unstable();
            (k, i)
        })
        .collect();
    keyed.sort_unstable();
    let mut dups: Vec<usize> = keyed
        .windows(2)
        .filter(|w| w[0].0 == w[1].0)
        .map(|w| w[1].1)
        .collect();
    dups.sort_unstable();
    if let Some(&first) = dups.first() {
        warnings.push(MeshWarning::DuplicateFaces {
            count: dups.len(),
            first,
        });
    }
    let mut used = vec![false; mesh.vertex_count()];
    for f in mesh.faces() {
        for &i in f {
            used[i as usize] = true;
        }
    }
    let unused: Vec<usize> = (0..used.len()).filter(|&v| !used[v]).collect();
    if let Some(&first) = unused.first() {
        warnings.push(MeshWarning::UnreferencedVertices {
            count: unused.len(),
            first,
        });
    }
    let (edges, counts) = topology::edges(mesh);
    let nonmanifold: Vec<[u32; 2]> = edges
        .iter()
        .zip(&counts)
        .filter(|&(_, &c)| c > 2)
        .map(|(e, _)| *e)
        .collect();
    if let Some(&first) = nonmanifold.first() {
        warnings.push(MeshWarning::NonManifoldEdges {
            count: nonmanifold.len(),
            first,
        });
    }
    let boundary = counts.iter().filter(|&&c| c == 1).count();
    if boundary > 0 {
        warnings.push(MeshWarning::Boundary { edges: boundary });
    }
    let comps = topology::connected_components(mesh);
    let referenced_components = {
        let mut seen = vec![false; comps.count];
        for (v, &u) in used.iter().enumerate() {
            if u {
                seen[comps.labels[v] as usize] = true;
            }
        }
        seen.iter().filter(|&&s| s).count()
    };
    if referenced_components > 1 {
        warnings.push(MeshWarning::SeveralComponents {
            count: referenced_components,
        });
    }
    MeshReport { warnings }
}
