//! The per-shape cache: everything computed once per shape (spectrum, descriptors, band table),
//! stored on disk and reused by every pair and graph stage.
//!
//! The common call is [`load_or_compute`]: it returns the shape's [`ShapeData`] and says whether
//! it came from the cache ([`CacheOutcome::Hit`]), was computed because there was no entry
//! ([`CacheOutcome::Miss`]), or was recomputed because the entry could not be trusted
//! ([`CacheOutcome::Recomputed`], with the reason — a warning for the caller to show; the library
//! prints nothing).
//!
//! # Keys and files
//! The key ([`shape_key`]) is a BLAKE3 hash of the file-format version, the mesh content
//! ([`mesh_hash`]: vertex and face counts, positions as little-endian `f64`, faces as
//! little-endian `u32`) and every option that changes the result ([`ShapePipelineOptions`],
//! serialised with bincode). Changing a vertex, a face or any option gives another key, hence
//! another file `<cache_dir>/<key hex>.coseg-shape`.
//!
//! File layout (all integers little-endian):
//! `magic "COSEGSHP" (8) | format version u32 | key (32) | payload length u64 |
//! BLAKE3 of payload (32) | payload` where the payload is the bincode 2 (serde, standard
//! config) encoding of [`ShapeData`]. A file is trusted only if the magic, version, key, length
//! and checksum all match and the payload decodes to data of the mesh's size; anything else is
//! recomputed and rewritten. Files are written atomically (temporary file in the same directory,
//! then rename), so a crash never leaves a half-written entry under a valid name.
//!
//! # The compact bands entry
//! The collection stage needs only each shape's band table and vertex areas (a few MB for 10k
//! vertices), while the full entry also holds the spectrum and the descriptors (about 40 MB).
//! [`load_or_compute_bands`] therefore keeps a second file per shape,
//! `<cache_dir>/<key hex>.coseg-bands`, with the same header (magic `"COSEGBND"`) around the
//! bincode of [`ShapeBands`]; it is written next to the full entry and rebuilt from it (or from
//! scratch) whenever it is missing or cannot be trusted.

use crate::bands::{BandError, BandOptions, BandTable, band_table};
use crate::features::{DescriptorOptions, Descriptors, FeatureError, descriptors};
use crate::mesh::{TriMesh, write_atomic};
use crate::spectral::{SpectralError, Spectrum, SpectrumOptions, laplace_beltrami_spectrum};
use std::io::Write;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Version of the cache file format and of the computations it stores. Bump it whenever the
/// layout or any algorithm's output changes: older files then read as stale and are recomputed.
pub const FORMAT_VERSION: u32 = 2;

const MAGIC: &[u8; 8] = b"COSEGSHP";
const BANDS_MAGIC: &[u8; 8] = b"COSEGBND";
const HEADER_LEN: usize = 8 + 4 + 32 + 8 + 32;
/// File extension of cache entries.
pub const CACHE_EXTENSION: &str = "coseg-shape";
/// File extension of the compact bands entries (see [`load_or_compute_bands`]).
pub const BANDS_EXTENSION: &str = "coseg-bands";

/// Errors of the per-shape pipeline and its cache.
#[derive(Debug, Error)]
pub enum PipelineError {
    /// The spectrum could not be computed.
    #[error(transparent)]
    Spectral(#[from] SpectralError),
    /// The descriptors could not be computed.
    #[error(transparent)]
    Features(#[from] FeatureError),
    /// The band table could not be computed.
    #[error(transparent)]
    Bands(#[from] BandError),
    /// The cache directory could not be created.
    #[error("{path}: {source}")]
    Io {
        /// The directory or file concerned.
        path: String,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// Every option of the per-shape stages; all of it goes into the cache key.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShapePipelineOptions {
    /// Eigenpairs (default: 200).
    pub spectrum: SpectrumOptions,
    /// Features (default: 100 HKS + 100 WKS + 100 mean curvature).
    pub descriptors: DescriptorOptions,
    /// Bands (default: `K = 20`, equal counts).
    pub bands: BandOptions,
}

/// A 32-byte BLAKE3 digest identifying a cache entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct ShapeKey(pub [u8; 32]);

impl ShapeKey {
    /// Lower-case hexadecimal form (64 characters), used as the file name.
    pub fn to_hex(&self) -> String {
        self.0.iter().map(|b| format!("{b:02x}")).collect()
    }
}

/// Everything coseg computes once per shape.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShapeData {
    /// The key these data were computed for (see [`shape_key`]).
    pub key: ShapeKey,
    /// Number of vertices `d` of the mesh.
    pub vertices: usize,
    /// Unit-area Laplace–Beltrami spectrum.
    pub spectrum: Spectrum,
    /// `N × d` feature table.
    pub descriptors: Descriptors,
    /// `d × N` band labels.
    pub bands: BandTable,
}

/// What the collection stage needs of a shape: its band table and vertex areas (the compact
/// cache entry of [`load_or_compute_bands`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShapeBands {
    /// The key these data were computed for (see [`shape_key`]).
    pub key: ShapeKey,
    /// `d × N` band labels.
    pub bands: BandTable,
    /// Per-vertex areas (length `d`), as [`Descriptors::vertex_areas`].
    pub vertex_areas: Vec<f64>,
}

impl ShapeBands {
    /// The compact part of `data`.
    pub fn of(data: &ShapeData) -> Self {
        Self {
            key: data.key,
            bands: data.bands.clone(),
            vertex_areas: data.descriptors.vertex_areas.clone(),
        }
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

/// Where [`load_or_compute`]'s data came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CacheOutcome {
    /// Read from a verified cache entry.
    Hit,
    /// No entry existed: computed and written.
    Miss,
    /// An entry existed but was corrupt, stale or unreadable: computed again and rewritten.
    /// `reason` is a warning meant for the user.
    Recomputed {
        /// Why the entry was not trusted.
        reason: String,
    },
}

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

/// BLAKE3 hash of a mesh's content: vertex and face counts (`u64`), then positions (`f64`) and
/// faces (`u32`), all little-endian, in file order. Any change to a coordinate bit, a face index,
/// or the vertex order changes it.
///
/// ```
/// use coseg::{mesh::TriMesh, cache::mesh_hash};
/// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let moved = m.map_positions(|p| [p[0] + 1e-9, p[1], p[2]]).unwrap();
/// assert_ne!(mesh_hash(&m), mesh_hash(&moved));
/// ```
pub fn mesh_hash(mesh: &TriMesh) -> [u8; 32] {
    let mut h = blake3::Hasher::new();
    h.update(&(mesh.vertex_count() as u64).to_le_bytes());
    h.update(&(mesh.face_count() as u64).to_le_bytes());
    let mut buf = Vec::with_capacity(mesh.vertex_count() * 24);
    for p in mesh.positions() {
        for c in p {
            buf.extend_from_slice(&c.to_le_bytes());
        }
    }
    h.update(&buf);
    buf.clear();
    for f in mesh.faces() {
        for i in f {
            buf.extend_from_slice(&i.to_le_bytes());
        }
    }
    h.update(&buf);
    *h.finalize().as_bytes()
}

/// The cache key of a mesh under some options: BLAKE3 of [`FORMAT_VERSION`], [`mesh_hash`]
/// and the bincode encoding of `options`.
///
/// ```
/// use coseg::{mesh::TriMesh, cache::{shape_key, ShapePipelineOptions}};
/// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let mut o = ShapePipelineOptions::default();
/// let k1 = shape_key(&m, &o);
/// o.bands.bands = 10;
/// assert_ne!(k1, shape_key(&m, &o));
/// ```
pub fn shape_key(mesh: &TriMesh, options: &ShapePipelineOptions) -> ShapeKey {
    let mut h = blake3::Hasher::new();
    h.update(b"coseg shape key");
    h.update(&FORMAT_VERSION.to_le_bytes());
    h.update(&mesh_hash(mesh));
    let opts = bincode::serde::encode_to_vec(options, bincode::config::standard())
        .expect("options are plain data and always encode");
    h.update(&opts);
    ShapeKey(*h.finalize().as_bytes())
}

/// Spectrum, descriptors and band table of a mesh, without touching any cache.
///
/// ```
/// use coseg::{mesh::TriMesh, cache::{compute_shape_data, ShapePipelineOptions}};
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.]], vec![[0,1,2],[0,2,3]]).unwrap();
/// let mut o = ShapePipelineOptions::default();
/// o.spectrum.eigenpairs = 4;
/// o.bands.bands = 2;
/// let data = compute_shape_data(&m, &o).unwrap();
/// assert_eq!(data.bands.features, 300);
/// ```
pub fn compute_shape_data(
    mesh: &TriMesh,
    options: &ShapePipelineOptions,
) -> Result<ShapeData, PipelineError> {
    let spectrum = laplace_beltrami_spectrum(mesh, &options.spectrum)?;
    shape_data_from_spectrum(mesh, spectrum, options)
}

/// Descriptors and band table from an already computed spectrum (e.g. read elsewhere), keyed
/// as [`compute_shape_data`] would key them. The spectrum must be the one
/// `options.spectrum` gives for `mesh`, or the cache key would lie.
pub fn shape_data_from_spectrum(
    mesh: &TriMesh,
    spectrum: Spectrum,
    options: &ShapePipelineOptions,
) -> Result<ShapeData, PipelineError> {
    let descriptors = descriptors(mesh, &spectrum, &options.descriptors)?;
    let bands = band_table(&descriptors, &options.bands)?;
    Ok(ShapeData {
        key: shape_key(mesh, options),
        vertices: mesh.vertex_count(),
        spectrum,
        descriptors,
        bands,
    })
}

/// Path of the cache entry for `key` in `cache_dir`.
pub fn cache_path(cache_dir: &Path, key: &ShapeKey) -> PathBuf {
    cache_dir.join(format!("{}.{CACHE_EXTENSION}", key.to_hex()))
}

/// The shape's data from `cache_dir` if a verified entry exists, otherwise computed (and
/// written atomically). A corrupt, truncated, stale or foreign entry is never trusted: it is
/// recomputed and replaced, and [`CacheOutcome::Recomputed`] carries the reason.
///
/// ```
/// use coseg::{mesh::TriMesh, cache::{load_or_compute, CacheOutcome, ShapePipelineOptions}};
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
    let outcome = match read_entry(&path, |b| decode_entry(b, &key, mesh.vertex_count())) {
        Ok(data) => {
            return Ok(CacheResult {
                data,
                outcome: CacheOutcome::Hit,
                path,
                write_error: None,
            });
        }
        Err(None) => CacheOutcome::Miss,
        Err(Some(reason)) => CacheOutcome::Recomputed {
            reason: format!("{}: {reason}; recomputed", path.display()),
        },
    };
    let data = compute_shape_data(mesh, options)?;
    std::fs::create_dir_all(cache_dir).map_err(|source| PipelineError::Io {
        path: cache_dir.display().to_string(),
        source,
    })?;
    let entry = encode_entry(&data);
    let write_error = write_atomic(&path, |w| w.write_all(&entry))
        .err()
        .map(|e| format!("{}: cache entry not written: {e}", path.display()));
    Ok(CacheResult {
        data,
        outcome,
        path,
        write_error,
    })
}

/// The bands entry path of `key` in `cache_dir` (see [`load_or_compute_bands`]).
pub fn bands_path(cache_dir: &Path, key: &ShapeKey) -> PathBuf {
    cache_dir.join(format!("{}.{BANDS_EXTENSION}", key.to_hex()))
}

/// The shape's band table and vertex areas: from the compact bands entry in `cache_dir` if it
/// is valid, otherwise from [`load_or_compute`] (the full entry, or computed), after which the
/// compact entry is written. Reading 10k vertices × 300 features this way costs about a tenth
/// of reading the full entry, which is what makes a warm `coseg segment` fast.
///
/// ```
/// use coseg::cache::{load_or_compute, load_or_compute_bands, CacheOutcome, ShapePipelineOptions};
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
    let mut warnings = Vec::new();
    match read_entry(&path, |b| decode_bands_entry(b, &key, mesh.vertex_count())) {
        Ok(data) => {
            return Ok(BandsResult {
                data,
                outcome: CacheOutcome::Hit,
                warnings,
            });
        }
        Err(None) => {}
        Err(Some(reason)) => warnings.push(format!("{}: {reason}; rebuilt", path.display())),
    }
    let full = load_or_compute(mesh, options, cache_dir)?;
    if let CacheOutcome::Recomputed { reason } = &full.outcome {
        warnings.push(reason.clone());
    }
    warnings.extend(full.write_error);
    let data = ShapeBands::of(&full.data);
    let entry = encode_bands_entry(&data);
    if let Err(e) = write_atomic(&path, |w| w.write_all(&entry)) {
        warnings.push(format!("{}: cache entry not written: {e}", path.display()));
    }
    Ok(BandsResult {
        data,
        outcome: full.outcome,
        warnings,
    })
}

/// Reads and decodes the entry at `path`: the data, `Err(None)` when there is no file, or
/// `Err(Some(reason))` when the file cannot be read or trusted.
fn read_entry<T>(
    path: &Path,
    decode: impl FnOnce(&[u8]) -> Result<T, String>,
) -> Result<T, Option<String>> {
    match std::fs::read(path) {
        Ok(bytes) => decode(&bytes).map_err(Some),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(None),
        Err(e) => Err(Some(format!("unreadable ({e})"))),
    }
}

/// The bytes of a compact bands entry for `data` (see the module docs).
pub fn encode_bands_entry(data: &ShapeBands) -> Vec<u8> {
    let payload = bincode::serde::encode_to_vec(data, bincode::config::standard())
        .expect("band data are plain data and always encode");
    frame(BANDS_MAGIC, &data.key, payload)
}

/// Verifies and decodes a compact bands entry; `Err` says why it cannot be trusted.
pub(crate) fn decode_bands_entry(
    bytes: &[u8],
    key: &ShapeKey,
    vertices: usize,
) -> Result<ShapeBands, String> {
    let payload = unframe(bytes, BANDS_MAGIC, key)?;
    let (data, used): (ShapeBands, usize) =
        bincode::serde::decode_from_slice(payload, bincode::config::standard())
            .map_err(|e| format!("payload does not decode ({e})"))?;
    if used != payload.len() {
        return Err("payload has trailing bytes".into());
    }
    if data.key != *key {
        return Err("payload key does not match".into());
    }
    let t = &data.bands;
    let consistent = t.vertices == vertices
        && t.labels.len() == t.features * vertices
        && t.labels.iter().all(|&l| (l as usize) < t.bands)
        && data.vertex_areas.len() == vertices;
    if !consistent {
        return Err("payload sizes do not match the mesh".into());
    }
    Ok(data)
}

/// `magic | format version | key | payload length | BLAKE3 of payload | payload`.
fn frame(magic: &[u8; 8], key: &ShapeKey, payload: Vec<u8>) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_LEN + payload.len());
    out.extend_from_slice(magic);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&key.0);
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(blake3::hash(&payload).as_bytes());
    out.extend_from_slice(&payload);
    out
}

/// The verified payload of a framed entry; `Err` says why it cannot be trusted.
fn unframe<'b>(bytes: &'b [u8], magic: &[u8; 8], key: &ShapeKey) -> Result<&'b [u8], String> {
    if bytes.len() < HEADER_LEN {
        return Err(format!("truncated header ({} bytes)", bytes.len()));
    }
    if &bytes[..8] != magic {
        return Err("not a coseg cache file of this kind (bad magic)".into());
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if version != FORMAT_VERSION {
        return Err(format!(
            "stale format version {version} (current {FORMAT_VERSION})"
        ));
    }
    if bytes[12..44] != key.0 {
        return Err("stale entry (key does not match the mesh and options)".into());
    }
    let len = u64::from_le_bytes(bytes[44..52].try_into().expect("8 bytes"));
    let payload = &bytes[HEADER_LEN..];
    if payload.len() as u64 != len {
        return Err(format!(
            "payload is {} bytes, header says {len} (truncated or padded)",
            payload.len()
        ));
    }
    if blake3::hash(payload).as_bytes() != &bytes[52..84] {
        return Err("payload checksum mismatch (corrupt)".into());
    }
    Ok(payload)
}

/// The bytes of a cache entry for `data` (header + payload, see the module docs).
pub fn encode_entry(data: &ShapeData) -> Vec<u8> {
    let payload = bincode::serde::encode_to_vec(data, bincode::config::standard())
        .expect("shape data are plain data and always encode");
    frame(MAGIC, &data.key, payload)
}

/// Verifies and decodes a cache entry; `Err` says why it cannot be trusted.
pub(crate) fn decode_entry(
    bytes: &[u8],
    key: &ShapeKey,
    vertices: usize,
) -> Result<ShapeData, String> {
    let payload = unframe(bytes, MAGIC, key)?;
    let (data, used): (ShapeData, usize) =
        bincode::serde::decode_from_slice(payload, bincode::config::standard())
            .map_err(|e| format!("payload does not decode ({e})"))?;
    if used != payload.len() {
        return Err("payload has trailing bytes".into());
    }
    if data.key != *key {
        return Err("payload key does not match".into());
    }
    let n = data.descriptors.feature_count();
    let consistent = data.vertices == vertices
        && data.spectrum.vertex_count() == vertices
        && data.spectrum.eigenvectors.len() == vertices * data.spectrum.len()
        && data.descriptors.vertices == vertices
        && data.descriptors.values.len() == n * vertices
        && data.bands.vertices == vertices
        && data.bands.features == n
        && data.bands.labels.len() == n * vertices;
    if !consistent {
        return Err("payload sizes do not match the mesh".into());
    }
    Ok(data)
}
