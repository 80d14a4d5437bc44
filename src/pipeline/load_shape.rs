//! The one loader ([`load_shape`]) and the cached computations it runs
//! ([`load_or_compute`], [`load_or_compute_bands`]).

use super::shape_data::{
    PipelineError, ShapeBands, ShapeData, ShapePipelineOptions, StoredShape, compute_shape_data,
    encode_bands_entry, encode_shape_entry, shape_key,
};
use crate::cache::{
    CacheOutcome, EntryKind, Lookup, bands_path, cache_path, read_entry, write_entry,
};
use crate::mesh::{TriMesh, read_mesh_with_report};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The result of [`load_or_compute`].
#[derive(Debug, Clone)]
pub struct CacheResult {
    /// The shape's data (identical whether read or computed).
    pub data: ShapeData,
    /// Hit, miss or recomputed (with the reason).
    pub outcome: CacheOutcome,
    /// The cache entry's path.
    pub path: PathBuf,
    /// Set when freshly computed data could not be written (the data are still valid): a
    /// warning for the caller.
    pub write_error: Option<String>,
}

impl CacheResult {
    /// Its warnings for the user: why the entry was recomputed, that it could not be written.
    fn warnings(&self) -> Vec<String> {
        let recomputed = match &self.outcome {
            CacheOutcome::Recomputed { reason } => Some(reason.clone()),
            _ => None,
        };
        recomputed
            .into_iter()
            .chain(self.write_error.clone())
            .collect()
    }
}

/// The result of [`load_or_compute_bands`].
#[derive(Debug, Clone)]
pub struct BandsResult {
    /// The shape's band table and areas (identical whether read or computed).
    pub data: ShapeBands,
    /// Hit (the compact entry was valid), or where the data came from otherwise: the full
    /// entry's outcome ([`CacheOutcome::Hit`] when rebuilt from a valid full entry).
    pub outcome: CacheOutcome,
    /// Warnings for the caller: untrusted compact entries, entries that could not be written.
    pub warnings: Vec<String>,
}

/// The shape's data from `cache_dir` if a verified entry exists, otherwise computed (and
/// written atomically). A corrupt, truncated, stale or foreign entry is never trusted: it is
/// recomputed and replaced, and [`CacheOutcome::Recomputed`] carries the reason.
///
/// ```
/// use coseg::{mesh::TriMesh, cache::CacheOutcome, pipeline::{load_or_compute, ShapePipelineOptions}};
/// let dir = std::env::temp_dir().join(format!("coseg-doc-{}", std::process::id()));
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.]], vec![[0,1,2],[0,2,3]]).unwrap();
/// let mut o = ShapePipelineOptions::default();
/// o.spectrum.eigenpairs = 4;
/// o.bands.bands = 2;
/// let first = load_or_compute(&m, &o, &dir).unwrap();
/// let second = load_or_compute(&m, &o, &dir).unwrap();
/// assert_eq!(second.outcome, CacheOutcome::Hit);
/// assert_eq!(first.data, second.data);
/// # std::fs::remove_dir_all(&dir).ok();
/// ```
pub fn load_or_compute(
    mesh: &TriMesh,
    options: &ShapePipelineOptions,
    cache_dir: &Path,
) -> Result<CacheResult, PipelineError> {
    let key = shape_key(mesh, options);
    let path = cache_path(cache_dir, &key);
    let vertices = mesh.vertex_count();
    let outcome = match read_entry(&path, EntryKind::Full, &key, |d: &StoredShape| {
        d.check(&key, vertices)
    }) {
        // The entry holds the spectrum and the costly columns; the rest is recomputed from
        // them by the cold run's own code (see `StoredShape`).
        Lookup::Hit(stored) => match stored.into_shape_data(mesh, options) {
            Ok(data) => {
                return Ok(CacheResult {
                    data,
                    outcome: CacheOutcome::Hit,
                    path,
                    write_error: None,
                });
            }
            Err(e) => CacheOutcome::Recomputed {
                reason: format!(
                    "{}: the entry does not rebuild the shape's data ({e}); recomputed",
                    path.display()
                ),
            },
        },
        Lookup::Missing => CacheOutcome::Miss,
        Lookup::Untrusted(reason) => CacheOutcome::Recomputed {
            reason: format!("{}: {reason}; recomputed", path.display()),
        },
    };
    let data = compute_shape_data(mesh, options)?;
    // A cache that cannot be written (read-only, full, not a folder) costs a recomputation
    // next time, not this run: the data are returned with a warning.
    let write_error = std::fs::create_dir_all(cache_dir)
        .and_then(|()| write_entry(&path, &encode_shape_entry(&data)))
        .err()
        .map(|e| format!("{}: cache entry not written: {e}", path.display()));
    Ok(CacheResult {
        data,
        outcome,
        path,
        write_error,
    })
}

/// The shape's band table and vertex areas: from the compact bands entry in `cache_dir` if it
/// is valid, otherwise from [`load_or_compute`] (the full entry, or computed), after which the
/// compact entry is written. For 10k vertices × 300 features this reads 0.5 MB instead of the
/// full entry's 8.6 MB and rebuilds no descriptors, which is what makes a warm `coseg segment`
/// fast.
///
/// ```
/// use coseg::cache::CacheOutcome;
/// use coseg::pipeline::{load_or_compute, load_or_compute_bands, ShapePipelineOptions};
/// use coseg::mesh::TriMesh;
/// let dir = std::env::temp_dir().join(format!("coseg-doc-bands-{}", std::process::id()));
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.]], vec![[0,1,2],[0,2,3]]).unwrap();
/// let mut o = ShapePipelineOptions::default();
/// o.spectrum.eigenpairs = 4;
/// o.bands.bands = 2;
/// let first = load_or_compute_bands(&m, &o, &dir).unwrap();
/// assert_eq!(first.outcome, CacheOutcome::Miss);
/// let second = load_or_compute_bands(&m, &o, &dir).unwrap();
/// assert_eq!(second.outcome, CacheOutcome::Hit);
/// assert_eq!(second.data.bands, load_or_compute(&m, &o, &dir).unwrap().data.bands);
/// # std::fs::remove_dir_all(&dir).ok();
/// ```
pub fn load_or_compute_bands(
    mesh: &TriMesh,
    options: &ShapePipelineOptions,
    cache_dir: &Path,
) -> Result<BandsResult, PipelineError> {
    let key = shape_key(mesh, options);
    let path = bands_path(cache_dir, &key);
    let vertices = mesh.vertex_count();
    let mut warnings = Vec::new();
    match read_entry(&path, EntryKind::Bands, &key, |d: &ShapeBands| {
        d.check(&key, vertices)
    }) {
        Lookup::Hit(data) => {
            return Ok(BandsResult {
                data,
                outcome: CacheOutcome::Hit,
                warnings,
            });
        }
        Lookup::Missing => {}
        Lookup::Untrusted(reason) => {
            warnings.push(format!("{}: {reason}; rebuilt", path.display()))
        }
    }
    let full = load_or_compute(mesh, options, cache_dir)?;
    warnings.extend(full.warnings());
    let data = ShapeBands::of(&full.data);
    if let Err(e) = write_entry(&path, &encode_bands_entry(&data)) {
        warnings.push(format!("{}: cache entry not written: {e}", path.display()));
    }
    Ok(BandsResult {
        data,
        outcome: full.outcome,
        warnings,
    })
}

/// What [`load_shape`] can load per shape: the full [`ShapeData`] or the compact
/// [`ShapeBands`].
pub trait ShapeContent: Sized {
    /// The data of `mesh`, through the cache in `cache_dir` when given (then with its outcome
    /// and warnings), computed otherwise.
    fn obtain(
        mesh: &TriMesh,
        options: &ShapePipelineOptions,
        cache_dir: Option<&Path>,
    ) -> Result<(Self, Option<CacheOutcome>, Vec<String>), PipelineError>;
}

impl ShapeContent for ShapeData {
    fn obtain(
        mesh: &TriMesh,
        options: &ShapePipelineOptions,
        cache_dir: Option<&Path>,
    ) -> Result<(Self, Option<CacheOutcome>, Vec<String>), PipelineError> {
        let Some(dir) = cache_dir else {
            return Ok((compute_shape_data(mesh, options)?, None, Vec::new()));
        };
        let r = load_or_compute(mesh, options, dir)?;
        let warnings = r.warnings();
        Ok((r.data, Some(r.outcome), warnings))
    }
}

impl ShapeContent for ShapeBands {
    fn obtain(
        mesh: &TriMesh,
        options: &ShapePipelineOptions,
        cache_dir: Option<&Path>,
    ) -> Result<(Self, Option<CacheOutcome>, Vec<String>), PipelineError> {
        let Some(dir) = cache_dir else {
            let data = compute_shape_data(mesh, options)?;
            return Ok((ShapeBands::of(&data), None, Vec::new()));
        };
        let r = load_or_compute_bands(mesh, options, dir)?;
        Ok((r.data, Some(r.outcome), r.warnings))
    }
}

/// A shape loaded by [`load_shape`].
#[derive(Debug, Clone)]
pub struct LoadedShape<T> {
    /// The mesh, in the file's vertex order.
    pub mesh: TriMesh,
    /// Its per-shape data.
    pub data: T,
    /// Where the data came from; `None` when no cache directory was given (computed).
    pub outcome: Option<CacheOutcome>,
    /// Warnings for the user, each naming the file: the mesh's (prefixed by its path), then
    /// untrusted cache entries and entries that could not be written.
    pub warnings: Vec<String>,
    /// Time spent reading the mesh.
    pub read_time: Duration,
    /// Time spent in the per-shape pipeline (cache reads, or spectrum + features + bands).
    pub shape_time: Duration,
}

/// The one loader: reads the mesh at `path` and gets its per-shape data `T` ([`ShapeData`]
/// or [`ShapeBands`]) through the cache in `cache_dir` (read if valid, written otherwise), or
/// computes it when `cache_dir` is `None`. A mesh that cannot be read is
/// [`PipelineError::Mesh`] (the message names the file); the pipeline's errors are returned as
/// they are, for the caller to prefix with the path.
///
/// ```no_run
/// use coseg::pipeline::{load_shape, ShapeData, ShapePipelineOptions};
/// use std::path::Path;
/// let s = load_shape::<ShapeData>(Path::new("a.obj"), &ShapePipelineOptions::default(),
///     Some(Path::new("cache"))).unwrap();
/// for w in &s.warnings { eprintln!("warning: {w}"); }
/// println!("{} eigenpairs", s.data.spectrum.len());
/// ```
pub fn load_shape<T: ShapeContent>(
    path: &Path,
    options: &ShapePipelineOptions,
    cache_dir: Option<&Path>,
) -> Result<LoadedShape<T>, PipelineError> {
    let t = Instant::now();
    let (mesh, report) = read_mesh_with_report(path)?;
    let read_time = t.elapsed();
    let reader_warnings = report
        .warnings
        .iter()
        .map(|w| format!("{}: {w}", path.display()))
        .collect();
    let mut loaded = load_shape_from_mesh(mesh, path, options, cache_dir)?;
    loaded.read_time = read_time;
    loaded.warnings = [reader_warnings, loaded.warnings].concat();
    Ok(loaded)
}

/// [`load_shape`] for a mesh already in memory (arrays from Python, a mesh built by the
/// caller): the same warnings, cache and per-shape options, without reading a file.
///
/// - `mesh`: the validated mesh;
/// - `path`: the file it came from, or any path whose stem names the shape (`name.` for a
///   name with dots): warnings are prefixed by it and user features (`user:DIR`) are resolved
///   to `DIR/<stem>.npy` or `.csv` by it;
/// - returns the [`LoadedShape`] with `read_time` zero.
///
/// See also: [`load_shape`], which reads the mesh first.
pub fn load_shape_from_mesh<T: ShapeContent>(
    mesh: TriMesh,
    path: &Path,
    options: &ShapePipelineOptions,
    cache_dir: Option<&Path>,
) -> Result<LoadedShape<T>, PipelineError> {
    let mut warnings = Vec::new();
    let spectrum_warnings = [
        super::small_mesh_warning(&mesh, options),
        super::unresolved_triangles_warning(&mesh),
    ];
    for w in spectrum_warnings.into_iter().flatten() {
        warnings.push(format!("{}: {w}", path.display()));
    }
    let t = Instant::now();
    // User features are per shape: resolve the folder to this shape's file (and its hash).
    let options = &ShapePipelineOptions {
        families: options.families.for_shape(path)?,
        ..options.clone()
    };
    let (data, outcome, more) = T::obtain(&mesh, options, cache_dir)?;
    warnings.extend(more);
    Ok(LoadedShape {
        mesh,
        data,
        outcome,
        warnings,
        read_time: Duration::ZERO,
        shape_time: t.elapsed(),
    })
}
