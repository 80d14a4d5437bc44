//! [`write_regions`]: region-id files, coloured PLY meshes and the JSON summary.

use super::{OutputError, region_colors};
use crate::mesh::{PlyVertexProperty, TriMesh, write_atomic, write_mesh};
use std::io::Write;
use std::path::{Path, PathBuf};

/// One shape's output: a name (file stem), its mesh and one region id per vertex.
#[derive(Debug, Clone, Copy)]
pub struct ShapeRegions<'a> {
    /// File stem for `<name>.regions.txt` / `<name>.regions.ply`.
    pub name: &'a str,
    /// The mesh, in its input vertex order.
    pub mesh: &'a TriMesh,
    /// Region id per vertex (`-1` = in no region).
    pub regions: &'a [i32],
}

impl<'a> ShapeRegions<'a> {
    /// One entry per shape of a collection, `names[i]` with `meshes[i]` and `labels[i]` (the
    /// three in the same order, e.g. a co-segmentation's names, its meshes and
    /// `segmentation.labels(i)`), as `coseg segment` writes them.
    ///
    /// ```
    /// use coseg::mesh::TriMesh;
    /// use coseg::output::ShapeRegions;
    /// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
    /// let (names, meshes, labels) = (vec!["a".to_string()], vec![m], vec![vec![0, 0, 1]]);
    /// let shapes = ShapeRegions::collection(&names, &meshes, &labels);
    /// assert_eq!((shapes[0].name, shapes[0].regions), ("a", &[0, 0, 1][..]));
    /// ```
    pub fn collection(
        names: &'a [String],
        meshes: &'a [TriMesh],
        labels: &'a [Vec<i32>],
    ) -> Vec<Self> {
        names
            .iter()
            .zip(meshes)
            .zip(labels)
            .map(|((name, mesh), regions)| ShapeRegions {
                name,
                mesh,
                regions,
            })
            .collect()
    }

    /// The shape as the pictures draw it (coloured by region, no confidence, its own view).
    pub fn picture(&self) -> crate::render::RenderShape<'a> {
        crate::render::RenderShape {
            name: self.name,
            mesh: self.mesh,
            labels: self.regions,
            confidence: None,
            view: None,
        }
    }
}

fn check_name(name: &str) -> Result<(), OutputError> {
    if name.is_empty() || name.contains(['/', '\\']) || name == "." || name == ".." {
        return Err(OutputError::BadName(name.to_string()));
    }
    Ok(())
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |source| {
        OutputError::Io(crate::FileError {
            path: path.display().to_string(),
            source,
        })
    }
}

/// Writes `dir/<name>.regions.txt` (one id per line, vertex order) atomically; returns its path.
pub fn write_region_ids(dir: &Path, name: &str, regions: &[i32]) -> Result<PathBuf, OutputError> {
    check_name(name)?;
    let path = dir.join(format!("{name}.regions.txt"));
    write_atomic(&path, |w| {
        for r in regions {
            writeln!(w, "{r}")?;
        }
        Ok(())
    })
    .map_err(io_err(&path))?;
    Ok(path)
}

/// Writes `dir/<name>.regions.ply`: the mesh coloured by region (see [`region_colors`]) with an
/// integer `region` vertex property; returns its path.
pub fn write_region_mesh(dir: &Path, shape: &ShapeRegions<'_>) -> Result<PathBuf, OutputError> {
    check_name(shape.name)?;
    if shape.regions.len() != shape.mesh.vertex_count() {
        return Err(OutputError::Length {
            name: shape.name.to_string(),
            ids: shape.regions.len(),
            vertices: shape.mesh.vertex_count(),
        });
    }
    let path = dir.join(format!("{}.regions.ply", shape.name));
    write_mesh(
        &path,
        shape.mesh,
        &[
            PlyVertexProperty::Color(region_colors(shape.regions)),
            PlyVertexProperty::Int("region".into(), shape.regions.to_vec()),
        ],
    )?;
    Ok(path)
}

/// Writes `dir/summary.json` (pretty JSON of `summary`) atomically; returns its path.
pub fn write_summary<T: serde::Serialize>(dir: &Path, summary: &T) -> Result<PathBuf, OutputError> {
    let path = dir.join("summary.json");
    let text =
        serde_json::to_string_pretty(summary).map_err(|e| OutputError::Json(e.to_string()))?;
    write_atomic(&path, |w| {
        w.write_all(text.as_bytes())?;
        w.write_all(b"\n")
    })
    .map_err(io_err(&path))?;
    Ok(path)
}

/// Writes every output of a segmentation into `dir` (created if missing): for each shape its
/// `.regions.txt` and `.regions.ply`, then `summary.json`. Returns the written paths.
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::output::{write_regions, ShapeRegions};
/// let mesh = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let dir = std::env::temp_dir().join(format!("coseg-doc-out-{}", std::process::id()));
/// let shapes = [ShapeRegions { name: "tri", mesh: &mesh, regions: &[0, 0, 1] }];
/// let paths = write_regions(&dir, &shapes, &serde_json::json!({"pairs": 2})).unwrap();
/// assert_eq!(paths.len(), 3);
/// assert_eq!(std::fs::read_to_string(dir.join("tri.regions.txt")).unwrap(), "0\n0\n1\n");
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_regions<T: serde::Serialize>(
    dir: &Path,
    shapes: &[ShapeRegions<'_>],
    summary: &T,
) -> Result<Vec<PathBuf>, OutputError> {
    std::fs::create_dir_all(dir).map_err(io_err(dir))?;
    let mut names = std::collections::HashSet::new();
    for s in shapes {
        check_name(s.name)?;
        if !names.insert(s.name) {
            return Err(OutputError::BadName(format!("{} (duplicate)", s.name)));
        }
        if s.regions.len() != s.mesh.vertex_count() {
            return Err(OutputError::Length {
                name: s.name.to_string(),
                ids: s.regions.len(),
                vertices: s.mesh.vertex_count(),
            });
        }
    }
    let mut paths = Vec::new();
    for s in shapes {
        paths.push(write_region_ids(dir, s.name, s.regions)?);
        paths.push(write_region_mesh(dir, s)?);
    }
    paths.push(write_summary(dir, summary)?);
    Ok(paths)
}
