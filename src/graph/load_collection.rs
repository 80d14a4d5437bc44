//! [`load_collection`]: a folder of meshes to shape-graph nodes through the per-shape cache.

use super::{GraphError, ShapeNode};
use crate::cache::CacheOutcome;
use crate::mesh::{MeshFormat, TriMesh};
use crate::pipeline::{PipelineError, ShapeBands, ShapePipelineOptions, load_shape};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Duration;

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
    /// Time spent reading meshes, summed over shapes (across threads: it can exceed the wall
    /// time).
    pub read_time: Duration,
    /// Time spent in the per-shape pipeline (cache reads, or spectrum + features + bands),
    /// summed over shapes like `read_time`.
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
/// per-shape cache in `cache_dir` ([`crate::pipeline::load_shape`] of
/// [`crate::pipeline::ShapeBands`]: only the band
/// tables and vertex areas are read when the cache is warm). Shapes are processed in
/// parallel on rayon's pool (one shape per thread: the per-shape work is independent, so the
/// result is the same whatever the thread count); the result keeps file order. Files that fail
/// to read or compute are reported in [`LoadedCollection::skipped`], not fatal.
/// `progress(started, total, path)` is called when a file starts (from the worker threads, one
/// call at a time). Nodes are named by file stem.
///
/// ```no_run
/// use coseg::pipeline::ShapePipelineOptions;
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
    progress: impl FnMut(usize, usize, &Path) + Send,
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
    let started = Mutex::new((0usize, progress));
    let results: Vec<ShapeResult> = files
        .into_par_iter()
        .enumerate()
        .map(|(i, path)| {
            if let Ok(mut guard) = started.lock() {
                let (count, report) = &mut *guard;
                report(*count, total, &path);
                *count += 1;
            }
            load_one(i, path, options, cache_dir)
        })
        .collect();
    for r in results {
        out.read_time += r.read_time;
        out.shape_time += r.shape_time;
        out.warnings.extend(r.warnings);
        match r.outcome {
            Err(skipped) => out.skipped.push(skipped),
            Ok((mesh, node, outcome)) => {
                out.paths.push(r.path);
                out.meshes.push(mesh);
                out.nodes.push(node);
                out.outcomes.push(outcome);
            }
        }
    }
    Ok(out)
}

/// One file's contribution to a [`LoadedCollection`].
struct ShapeResult {
    path: PathBuf,
    read_time: Duration,
    shape_time: Duration,
    warnings: Vec<String>,
    outcome: Result<(TriMesh, ShapeNode, CacheOutcome), SkippedFile>,
}

fn load_one(
    i: usize,
    path: PathBuf,
    options: &ShapePipelineOptions,
    cache_dir: &Path,
) -> ShapeResult {
    let mut r = ShapeResult {
        path: path.clone(),
        read_time: Duration::ZERO,
        shape_time: Duration::ZERO,
        warnings: Vec::new(),
        outcome: Err(SkippedFile {
            path: path.clone(),
            error: String::new(),
        }),
    };
    let skip = |error: String| {
        Err(SkippedFile {
            path: path.clone(),
            error,
        })
    };
    let res = match load_shape::<ShapeBands>(&path, options, Some(cache_dir)) {
        Ok(x) => x,
        Err(PipelineError::Mesh(e)) => {
            r.outcome = skip(e.to_string());
            return r;
        }
        Err(e) => {
            r.outcome = skip(format!("{}: {e}", path.display()));
            return r;
        }
    };
    r.read_time = res.read_time;
    r.shape_time = res.shape_time;
    r.warnings = res.warnings;
    let outcome = res.outcome.unwrap_or(CacheOutcome::Miss);
    let mesh = res.mesh;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| format!("shape{i}"));
    r.outcome = match ShapeNode::new(name, res.data.bands, &res.data.vertex_areas) {
        Ok(node) => Ok((mesh, node, outcome)),
        Err(e) => skip(format!("{}: {e}", path.display())),
    };
    r
}
