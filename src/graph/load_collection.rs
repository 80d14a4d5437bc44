//! [`load_collection`]: a folder of meshes to shape-graph nodes through the per-shape cache.
//!
//! Two rules keep a folder's shapes what the user means them to be:
//! - **coseg's own outputs are never inputs**: files named `*.regions.ply` (what `coseg segment`
//!   and `coseg pair` write, see [`is_coseg_output`]) are left out and reported in
//!   [`LoadedCollection::ignored`] and a warning, so `coseg segment same -o same` run twice
//!   co-segments the same shapes both times;
//! - **names are distinct**: a shape is named by its file stem, except that files sharing a
//!   stem (ignoring case: `g.obj`, `g.off`) are named `<stem>_<extension>` (`g_obj`, `g_off`,
//!   with `_2`, `_3`… appended should that still collide), with a warning ([`shape_names`]).

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
    /// coseg's own output files found in the folder and not read ([`is_coseg_output`]).
    pub ignored: Vec<PathBuf>,
    /// Warnings for the user (mesh warnings, stale cache entries, cache write failures).
    pub warnings: Vec<String>,
    /// Time spent reading meshes, summed over shapes (across threads: it can exceed the wall
    /// time).
    pub read_time: Duration,
    /// Time spent in the per-shape pipeline (cache reads, or spectrum + features + bands),
    /// summed over shapes like `read_time`.
    pub shape_time: Duration,
}

/// The mesh files (`.obj`, `.off`, `.ply`, any case) directly in `folder`, sorted by file name,
/// without coseg's own output files ([`is_coseg_output`]).
pub fn mesh_files(folder: &Path) -> Result<Vec<PathBuf>, GraphError> {
    Ok(list_mesh_files(folder)?.0)
}

/// Whether `path` is named like a file coseg writes beside its results (`<name>.regions.ply`,
/// any case), which must not be read back as a shape.
///
/// ```
/// use coseg::graph::is_coseg_output;
/// use std::path::Path;
/// assert!(is_coseg_output(Path::new("out/cat.regions.ply")));
/// assert!(!is_coseg_output(Path::new("shapes/cat.ply")));
/// ```
pub fn is_coseg_output(path: &Path) -> bool {
    path.file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.to_ascii_lowercase().ends_with(".regions.ply"))
}

/// The mesh files of `folder` (sorted) and, apart, the coseg outputs among them (sorted).
fn list_mesh_files(folder: &Path) -> Result<(Vec<PathBuf>, Vec<PathBuf>), GraphError> {
    let io = |source| {
        GraphError::Io(crate::FileError {
            path: folder.display().to_string(),
            source,
        })
    };
    let (mut keep, mut ignored) = (Vec::new(), Vec::new());
    for entry in std::fs::read_dir(folder).map_err(io)? {
        let path = entry.map_err(io)?.path();
        if path.is_file() && MeshFormat::from_path(&path).is_some() {
            if is_coseg_output(&path) {
                ignored.push(path);
            } else {
                keep.push(path);
            }
        }
    }
    keep.sort();
    ignored.sort();
    Ok((keep, ignored))
}

/// Distinct shape names for `paths`, in order, and a warning per group of files that share a
/// stem (see the module docs). Names are file stems where those are unique (ignoring case,
/// so that outputs never collide on a case-insensitive file system).
///
/// ```
/// use coseg::graph::shape_names;
/// use std::path::PathBuf;
/// let paths: Vec<PathBuf> = ["s/g.obj", "s/g.off", "s/h.ply"].iter().map(PathBuf::from).collect();
/// let (names, warnings) = shape_names(&paths);
/// assert_eq!(names, ["g_obj", "g_off", "h"]);
/// assert_eq!(warnings.len(), 1);
/// ```
pub fn shape_names(paths: &[PathBuf]) -> (Vec<String>, Vec<String>) {
    let stem = |p: &Path| {
        p.file_stem()
            .map_or_else(|| "shape".to_string(), |s| s.to_string_lossy().into_owned())
    };
    let stems: Vec<String> = paths.iter().map(|p| stem(p)).collect();
    let lower: Vec<String> = stems.iter().map(|s| s.to_lowercase()).collect();
    let mut names = stems.clone();
    let mut warnings = Vec::new();
    let mut reported = std::collections::HashSet::new();
    for i in 0..paths.len() {
        let group: Vec<usize> = (0..paths.len()).filter(|&j| lower[j] == lower[i]).collect();
        if group.len() < 2 {
            continue;
        }
        let ext = paths[i]
            .extension()
            .map_or_else(String::new, |e| e.to_string_lossy().to_lowercase());
        names[i] = format!("{}_{ext}", stems[i]);
        if reported.insert(lower[i].clone()) {
            let files: Vec<String> = group
                .iter()
                .map(|&j| paths[j].display().to_string())
                .collect();
            warnings.push(format!(
                "{} share the stem \"{}\": their outputs are named <stem>_<extension>",
                files.join(", "),
                stems[i]
            ));
        }
    }
    let mut used = std::collections::HashSet::new();
    for name in names.iter_mut() {
        let base = name.clone();
        let mut n = 2;
        while !used.insert(name.to_lowercase()) {
            *name = format!("{base}_{n}");
            n += 1;
        }
    }
    (names, warnings)
}

/// Reads every mesh file of `folder` ([`mesh_files`]) and gets its band table through the
/// per-shape cache in `cache_dir` ([`crate::pipeline::load_shape`] of
/// [`crate::pipeline::ShapeBands`]: only the band
/// tables and vertex areas are read when the cache is warm). Shapes are processed in
/// parallel on rayon's pool (one shape per thread: the per-shape work is independent, so the
/// result is the same whatever the thread count); the result keeps file order. Files that fail
/// to read or compute are reported in [`LoadedCollection::skipped`], not fatal.
/// `progress(started, total, path)` is called when a file starts (from the worker threads, one
/// call at a time). Nodes are named by [`shape_names`]; coseg's own outputs are not read (see
/// the module docs).
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
    let (files, ignored) = list_mesh_files(folder)?;
    let (names, name_warnings) = shape_names(&files);
    let mut out = LoadedCollection {
        paths: Vec::new(),
        meshes: Vec::new(),
        nodes: Vec::new(),
        outcomes: Vec::new(),
        skipped: Vec::new(),
        warnings: name_warnings,
        ignored,
        read_time: Duration::ZERO,
        shape_time: Duration::ZERO,
    };
    if !out.ignored.is_empty() {
        let list: Vec<String> = out
            .ignored
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        out.warnings.push(format!(
            "{}: not reading {} file(s) coseg wrote as results (*.regions.ply): {}",
            folder.display(),
            list.len(),
            list.join(", ")
        ));
    }
    let total = files.len();
    let started = Mutex::new((0usize, progress));
    let results: Vec<ShapeResult> = files
        .into_par_iter()
        .zip(names)
        .map(|(path, name)| {
            if let Ok(mut guard) = started.lock() {
                let (count, report) = &mut *guard;
                report(*count, total, &path);
                *count += 1;
            }
            load_one(name, path, options, cache_dir)
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
    name: String,
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
    r.outcome = match ShapeNode::new(name, res.data.bands, &res.data.vertex_areas) {
        Ok(node) => Ok((mesh, node, outcome)),
        Err(e) => skip(format!("{}: {e}", path.display())),
    };
    r
}
