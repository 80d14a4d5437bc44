//! The per-shape stage as a pure task: mesh file bytes and options in, cache entry bytes out.
//!
//! [`compute_shape_entry`] is what a distributed engine (Dask, Ray, a batch queue) runs on a
//! worker: it touches no file system and returns the bytes of the two cache entries
//! ([`crate::pipeline`]'s full entry and compact bands entry) under the same content key
//! ([`crate::pipeline::shape_key`]) that [`crate::pipeline::load_or_compute`] uses. Whoever collects
//! the bytes calls [`store_shape_entry`], which verifies them against the mesh's key and writes
//! them atomically into a cache directory; the collection stage (`coseg segment`,
//! [`crate::graph::load_collection`]) then finds them warm. [`entry_is_valid`] lets a rerun skip
//! the shapes that are already done.

use crate::cache::{ShapeKey, bands_path, cache_path};
use crate::mesh::{MeshError, MeshFormat, TriMesh, read_mesh_from_bytes, write_atomic};
use crate::pipeline::{
    PipelineError, ShapeBands, ShapePipelineOptions, compute_shape_data, decode_bands_entry,
    decode_shape_entry, encode_bands_entry, encode_shape_entry, shape_key,
};
use std::io::Write;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Errors of the per-shape task.
#[derive(Debug, Error)]
pub enum ShapeTaskError {
    /// The mesh bytes do not parse or do not form a valid mesh.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The spectrum, descriptors or bands could not be computed.
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
    /// Entry bytes handed to [`store_shape_entry`] cannot be trusted for this key.
    #[error("{path}: refusing to store the entry: {reason}")]
    Untrusted {
        /// The entry file it was meant for.
        path: String,
        /// Why it failed verification.
        reason: String,
    },
    /// A cache file or directory could not be written.
    #[error(transparent)]
    Io(#[from] crate::FileError),
}

/// What [`compute_shape_entry`] returns: the key and the bytes of both cache entries.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeEntry {
    /// The content key ([`shape_key`]) of the mesh under the options.
    pub key: ShapeKey,
    /// Number of vertices `d` of the mesh.
    pub vertices: usize,
    /// Bytes of the full entry (`<key>.coseg-shape`: f32 spectrum, band table, costly
    /// feature columns).
    pub entry: Vec<u8>,
    /// Bytes of the compact entry (`<key>.coseg-bands`: band table and vertex areas).
    pub bands_entry: Vec<u8>,
}

/// The key and vertex count of the mesh held in `mesh_bytes` (a whole `.obj`, `.off` or `.ply`
/// file) under `options`, without computing anything else. Errors name `<memory>`.
///
/// ```
/// use coseg::pipeline::ShapePipelineOptions;
/// use coseg::mesh::MeshFormat;
/// use coseg::shape_task::shape_key_of_bytes;
/// let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
/// let (key, d) = shape_key_of_bytes(obj, MeshFormat::Obj, &ShapePipelineOptions::default()).unwrap();
/// assert_eq!((key.to_hex().len(), d), (64, 3));
/// ```
pub fn shape_key_of_bytes(
    mesh_bytes: &[u8],
    format: MeshFormat,
    options: &ShapePipelineOptions,
) -> Result<(ShapeKey, usize), ShapeTaskError> {
    let mesh = read_mesh_from_bytes(mesh_bytes, format)?;
    Ok((shape_key(&mesh, options), mesh.vertex_count()))
}

/// The per-shape stage as a pure function: parses `mesh_bytes` (a whole mesh file in
/// `format`), computes spectrum, descriptors and band table under `options`, and returns the
/// bytes of the two cache entries, exactly as [`crate::pipeline::load_or_compute_bands`] would
/// write them. Deterministic: the same bytes and options give the same entry bytes.
///
/// ```
/// use coseg::pipeline::ShapePipelineOptions;
/// use coseg::mesh::MeshFormat;
/// use coseg::shape_task::{compute_shape_entry, shape_key_of_bytes};
/// let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
/// let mut o = ShapePipelineOptions::default();
/// o.spectrum.eigenpairs = 4;
/// o.bands.bands = 2;
/// let e = compute_shape_entry(obj, MeshFormat::Obj, &o).unwrap();
/// assert_eq!(e.key, shape_key_of_bytes(obj, MeshFormat::Obj, &o).unwrap().0);
/// assert_eq!(e, compute_shape_entry(obj, MeshFormat::Obj, &o).unwrap());
/// ```
pub fn compute_shape_entry(
    mesh_bytes: &[u8],
    format: MeshFormat,
    options: &ShapePipelineOptions,
) -> Result<ShapeEntry, ShapeTaskError> {
    let mesh = read_mesh_from_bytes(mesh_bytes, format)?;
    entry_of_mesh(&mesh, options)
}

/// [`compute_shape_entry`] for a mesh already in memory.
pub fn entry_of_mesh(
    mesh: &TriMesh,
    options: &ShapePipelineOptions,
) -> Result<ShapeEntry, ShapeTaskError> {
    let data = compute_shape_data(mesh, options)?;
    Ok(ShapeEntry {
        key: data.key,
        vertices: data.vertices,
        entry: encode_shape_entry(&data),
        bands_entry: encode_bands_entry(&ShapeBands::of(&data)),
    })
}

/// Verifies `entry` and `bands_entry` as cache entries of `key` for a mesh of `vertices`
/// vertices (magic, format version, key, length, checksum, sizes), then writes them atomically
/// into `cache_dir` (created if missing) under their cache names. Returns the two paths (full
/// entry first). Nothing is written unless both entries verify.
///
/// ```
/// use coseg::cache::CacheOutcome;
/// use coseg::pipeline::{ShapePipelineOptions, load_or_compute_bands};
/// use coseg::mesh::{MeshFormat, read_mesh_from_bytes};
/// use coseg::shape_task::{compute_shape_entry, store_shape_entry};
/// let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
/// let mut o = ShapePipelineOptions::default();
/// o.spectrum.eigenpairs = 4;
/// o.bands.bands = 2;
/// let e = compute_shape_entry(obj, MeshFormat::Obj, &o).unwrap();
/// let dir = std::env::temp_dir().join(format!("coseg-doc-task-{}", std::process::id()));
/// store_shape_entry(&dir, &e.key, e.vertices, &e.entry, &e.bands_entry).unwrap();
/// let mesh = read_mesh_from_bytes(obj, MeshFormat::Obj).unwrap();
/// assert_eq!(load_or_compute_bands(&mesh, &o, &dir).unwrap().outcome, CacheOutcome::Hit);
/// let mut bad = e.entry.clone();
/// *bad.last_mut().unwrap() ^= 1;
/// assert!(store_shape_entry(&dir, &e.key, e.vertices, &bad, &e.bands_entry).is_err());
/// # std::fs::remove_dir_all(&dir).ok();
/// ```
pub fn store_shape_entry(
    cache_dir: &Path,
    key: &ShapeKey,
    vertices: usize,
    entry: &[u8],
    bands_entry: &[u8],
) -> Result<[PathBuf; 2], ShapeTaskError> {
    let full = cache_path(cache_dir, key);
    let compact = bands_path(cache_dir, key);
    let untrusted = |path: &Path, reason: String| ShapeTaskError::Untrusted {
        path: path.display().to_string(),
        reason,
    };
    decode_shape_entry(entry, key, vertices).map_err(|r| untrusted(&full, r))?;
    decode_bands_entry(bands_entry, key, vertices).map_err(|r| untrusted(&compact, r))?;
    std::fs::create_dir_all(cache_dir).map_err(|source| {
        ShapeTaskError::Io(crate::FileError {
            path: cache_dir.display().to_string(),
            source,
        })
    })?;
    // Full entry first: a crash between the two leaves a valid full entry, from which the
    // compact one is rebuilt on the next read.
    for (path, bytes) in [(&full, entry), (&compact, bands_entry)] {
        write_atomic(path, |w| w.write_all(bytes)).map_err(|source| {
            ShapeTaskError::Io(crate::FileError {
                path: path.display().to_string(),
                source,
            })
        })?;
    }
    Ok([full, compact])
}

/// True when `cache_dir` holds both entries of `key` and both verify for a mesh of `vertices`
/// vertices (a rerun of a distributed precompute skips such shapes).
///
/// ```
/// use coseg::cache::ShapeKey;
/// use coseg::shape_task::entry_is_valid;
/// assert!(!entry_is_valid(std::path::Path::new("/nonexistent"), &ShapeKey([0; 32]), 3));
/// ```
pub fn entry_is_valid(cache_dir: &Path, key: &ShapeKey, vertices: usize) -> bool {
    let full = std::fs::read(cache_path(cache_dir, key))
        .is_ok_and(|b| decode_shape_entry(&b, key, vertices).is_ok());
    full && std::fs::read(bands_path(cache_dir, key))
        .is_ok_and(|b| decode_bands_entry(&b, key, vertices).is_ok())
}

/// Parses a 64-character lower- or upper-case hexadecimal key ([`ShapeKey::to_hex`]'s form).
///
/// ```
/// use coseg::cache::ShapeKey;
/// use coseg::shape_task::parse_key;
/// let k = ShapeKey([7; 32]);
/// assert_eq!(parse_key(&k.to_hex()), Some(k));
/// assert_eq!(parse_key("xyz"), None);
/// ```
pub fn parse_key(hex: &str) -> Option<ShapeKey> {
    let b = hex.as_bytes();
    if b.len() != 64 || !b.iter().all(u8::is_ascii_hexdigit) {
        return None;
    }
    let mut out = [0u8; 32];
    for (i, o) in out.iter_mut().enumerate() {
        let s = std::str::from_utf8(&b[2 * i..2 * i + 2]).ok()?;
        *o = u8::from_str_radix(s, 16).ok()?;
    }
    Some(ShapeKey(out))
}
