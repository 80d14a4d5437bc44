//! [`load_collection`]: a folder of meshes to shape-graph nodes through the per-shape cache.

use super::{GraphError, ShapeNode};
use crate::cache::{CacheOutcome, ShapePipelineOptions, load_or_compute};
use crate::mesh::{MeshFormat, TriMesh, read_mesh_with_report};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A file that could not be used, and why (the message names the file).
#[derive(Debug, Clone, PartialEq)]
pub struct SkippedFile {
    /// The file.
    pub path: PathBuf,
    /// Why it was skipped.
    pub error: String,
}

/// The shapes of a folder, ready for [`super::ShapeGraph::build`].
#[derive(Debug, Clone)]
pub struct LoadedCollection {
    /// Paths of the loaded shapes (same order as `nodes`).
    pub paths: Vec<PathBuf>,
    /// The meshes (same order).
    pub meshes: Vec<TriMesh>,
    /// Graph nodes: name (file stem), band table, unit-area vertex areas.
    pub nodes: Vec<ShapeNode>,
    /// Where each shape's data came from (same order).
    pub outcomes: Vec<CacheOutcome>,
    /// Files that failed to read or compute, in file order.
    pub skipped: Vec<SkippedFile>,
    /// Warnings for the user (mesh warnings, stale cache entries, cache write failures).
    pub warnings: Vec<String>,
    /// Time spent reading meshes.
    pub read_time: Duration,
    /// Time spent in the per-shape pipeline (cache reads, or spectrum + features + bands).
    pub shape_time: Duration,
}

/// The mesh files (`.obj`, `.off`, `.ply`, any case) directly in `folder`, sorted by file name.
pub fn mesh_files(folder: &Path) -> Result<Vec<PathBuf>, GraphError> {
    let io = |source| GraphError::Io {
        path: folder.display().to_string(),
        source,
    };
    let mut out = Vec::new();
    for entry in std::fs::read_dir(folder).map_err(io)? {
        let path = entry.map_err(io)?.path();
        if path.is_file() && MeshFormat::from_path(&path).is_some() {
            out.push(path);
        }
    }
    out.sort();
    Ok(out)
}

/// Reads every mesh file of `folder` ([`mesh_files`]) and gets its band table through the
/// per-shape cache in `cache_dir` ([`crate::cache::load_or_compute`]). Files that fail to read
/// or compute are reported in [`LoadedCollection::skipped`], not fatal. `progress(i, total,
/// path)` is called before each file. Nodes are named by file stem.
///
/// ```no_run
/// use coseg::cache::ShapePipelineOptions;
/// use coseg::graph::load_collection;
/// use std::path::Path;
/// let c = load_collection(Path::new("shapes"), &ShapePipelineOptions::default(),
///     Path::new("shapes/.cache"), |_, _, _| {}).unwrap();
/// println!("{} shapes, {} skipped", c.nodes.len(), c.skipped.len());
/// ```
pub fn load_collection(
    folder: &Path,
    options: &ShapePipelineOptions,
    cache_dir: &Path,
    mut progress: impl FnMut(usize, usize, &Path),
) -> Result<LoadedCollection, GraphError> {
    let files = mesh_files(folder)?;
    let mut out = LoadedCollection {
        paths: Vec::new(),
        meshes: Vec::new(),
        nodes: Vec::new(),
        outcomes: Vec::new(),
        skipped: Vec::new(),
        warnings: Vec::new(),
        read_time: Duration::ZERO,
        shape_time: Duration::ZERO,
    };
    let total = files.len();
    for (i, path) in files.into_iter().enumerate() {
        progress(i, total, &path);
        let t = Instant::now();
        let read = read_mesh_with_report(&path);
        out.read_time += t.elapsed();
        let (mesh, report) = match read {
            Ok(x) => x,
            Err(e) => {
                out.skipped.push(SkippedFile {
                    path,
                    error: e.to_string(),
                });
                continue;
            }
        };
        for w in &report.warnings {
            out.warnings.push(format!("{}: {w}", path.display()));
        }
        let t = Instant::now();
        let data = load_or_compute(&mesh, options, cache_dir);
        out.shape_time += t.elapsed();
        let res = match data {
            Ok(r) => r,
            Err(e) => {
                out.skipped.push(SkippedFile {
                    error: format!("{}: {e}", path.display()),
                    path,
                });
                continue;
            }
        };
        if let CacheOutcome::Recomputed { reason } = &res.outcome {
            out.warnings.push(reason.clone());
        }
        if let Some(w) = &res.write_error {
            out.warnings.push(w.clone());
        }
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| format!("shape{i}"));
        let node = match ShapeNode::new(name, res.data.bands, &res.data.descriptors.vertex_areas) {
            Ok(n) => n,
            Err(e) => {
                out.skipped.push(SkippedFile {
                    error: format!("{}: {e}", path.display()),
                    path,
                });
                continue;
            }
        };
        out.paths.push(path);
        out.meshes.push(mesh);
        out.nodes.push(node);
        out.outcomes.push(res.outcome);
    }
    Ok(out)
}
