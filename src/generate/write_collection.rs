//! `write_collection()`: a generated family as OBJ files, label files and a JSON manifest.
//!
//! The writer is self-contained (it does not use the mesh module's writers) so the shipped
//! bytes depend only on this file.

use super::{Collection, GenerateError, GenerateOptions};
use crate::mesh::TriMesh;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// Version of the manifest layout.
pub const MANIFEST_FORMAT: u32 = 1;

/// Contents of `manifest.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Layout version ([`MANIFEST_FORMAT`]).
    pub format: u32,
    /// Family name.
    pub family: String,
    /// Seed the shapes were generated from.
    pub seed: u64,
    /// Relaxation sweeps used (generator option).
    pub relax_iterations: usize,
    /// Command that regenerates the directory.
    pub command: String,
    /// Part names; label `i` in a labels file means `parts[i]`.
    pub parts: Vec<String>,
    /// Groups of parts of the same kind (group name → part names).
    pub part_groups: BTreeMap<String, Vec<String>>,
    /// The shapes, in index order.
    pub shapes: Vec<ManifestShape>,
}

/// One shape's entry in the manifest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestShape {
    /// Shape name (file stem).
    pub name: String,
    /// Mesh file, relative to the manifest.
    pub mesh: String,
    /// Labels file, relative to the manifest.
    pub labels: String,
    /// Vertex count.
    pub vertices: usize,
    /// Triangle count.
    pub faces: usize,
    /// Names of the parts this shape has.
    pub parts_present: Vec<String>,
    /// Number of vertices with each label, indexed like `parts`.
    pub label_counts: Vec<usize>,
    /// Grid spacing used (model units).
    pub cell: f64,
    /// Generator parameters by name (lengths in model units, angles in radians, yes/no 1/0).
    pub parameters: BTreeMap<String, f64>,
}

impl Manifest {
    /// The manifest describing `collection` generated with `options`.
    pub fn of(collection: &Collection, options: &GenerateOptions) -> Manifest {
        let family = collection.family;
        let names = family.part_names();
        Manifest {
            format: MANIFEST_FORMAT,
            family: family.name().to_string(),
            seed: collection.seed,
            relax_iterations: options.relax_iterations,
            command: format!(
                "coseg generate {} -o <dir> --seed {} --count {}",
                family.name(),
                collection.seed,
                collection.shapes.len()
            ),
            parts: names.iter().map(|s| s.to_string()).collect(),
            part_groups: family
                .part_groups()
                .iter()
                .map(|(g, ps)| (g.to_string(), ps.iter().map(|s| s.to_string()).collect()))
                .collect(),
            shapes: collection
                .shapes
                .iter()
                .map(|s| {
                    let mut counts = vec![0usize; names.len()];
                    for &l in &s.labels {
                        counts[l as usize] += 1;
                    }
                    ManifestShape {
                        name: s.name.clone(),
                        mesh: format!("{}.obj", s.name),
                        labels: format!("{}.labels.txt", s.name),
                        vertices: s.mesh.vertex_count(),
                        faces: s.mesh.face_count(),
                        parts_present: names
                            .iter()
                            .zip(&s.parts_present)
                            .filter(|(_, p)| **p)
                            .map(|(n, _)| n.to_string())
                            .collect(),
                        label_counts: counts,
                        cell: s.cell,
                        parameters: s.parameters.iter().cloned().collect(),
                    }
                })
                .collect(),
        }
    }
}

/// The OBJ text of a generated mesh: a comment line, `v x y z` with 5 decimals, then
/// `f a b c` (1-based, counter-clockwise seen from outside).
///
/// ```
/// use coseg::generate::obj_text;
/// use coseg::mesh::TriMesh;
/// let m = TriMesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]).unwrap();
/// assert_eq!(obj_text(&m, "t"), "# t\nv 0.00000 0.00000 0.00000\nv 1.00000 0.00000 0.00000\nv 0.00000 1.00000 0.00000\nf 1 2 3\n");
/// ```
pub fn obj_text(mesh: &TriMesh, comment: &str) -> String {
    let mut s = String::with_capacity(40 * mesh.vertex_count() + 24 * mesh.face_count());
    let _ = writeln!(s, "# {comment}");
    for p in mesh.positions() {
        let _ = writeln!(s, "v {:.5} {:.5} {:.5}", p[0], p[1], p[2]);
    }
    for f in mesh.faces() {
        let _ = writeln!(s, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    s
}

/// Writes `collection` into `dir` (created if missing): `<name>.obj`, `<name>.labels.txt` (one
/// integer label per line, vertex order) per shape, and `manifest.json`.
///
/// ```
/// use coseg::generate::{generate_family, write_collection, Family, GenerateOptions};
/// let mut options = GenerateOptions::default();
/// options.count = 1;
/// let c = generate_family(Family::Goblets, &options).unwrap();
/// let dir = std::env::temp_dir().join("coseg_doc_write_collection");
/// write_collection(&c, &options, &dir).unwrap();
/// assert!(dir.join("goblets_00.obj").exists());
/// assert!(dir.join("manifest.json").exists());
/// ```
pub fn write_collection(
    collection: &Collection,
    options: &GenerateOptions,
    dir: &Path,
) -> Result<(), GenerateError> {
    let io = |path: &Path| {
        let path = path.display().to_string();
        move |source| GenerateError::Io(crate::FileError { path, source })
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    for shape in &collection.shapes {
        let obj = dir.join(format!("{}.obj", shape.name));
        let comment = format!(
            "coseg generate {} --seed {}: {}",
            collection.family.name(),
            collection.seed,
            shape.name
        );
        std::fs::write(&obj, obj_text(&shape.mesh, &comment)).map_err(io(&obj))?;
        let lab = dir.join(format!("{}.labels.txt", shape.name));
        let mut text = String::with_capacity(3 * shape.labels.len());
        for l in &shape.labels {
            let _ = writeln!(text, "{l}");
        }
        std::fs::write(&lab, text).map_err(io(&lab))?;
    }
    let manifest = dir.join("manifest.json");
    let mut json = serde_json::to_string_pretty(&Manifest::of(collection, options))
        .expect("manifest serialises");
    json.push('\n');
    std::fs::write(&manifest, json).map_err(io(&manifest))?;
    Ok(())
}
