//! The per-shape cache: stores and verifies entries on disk, nothing else. What goes into an
//! entry, and when it is computed, is the per-shape pipeline's business
//! ([`crate::pipeline`]: [`crate::pipeline::load_shape`] is the one loader everything uses).
//!
//! # Keys and files
//! A key ([`entry_key`]) is a BLAKE3 hash of the file-format version, the mesh content
//! ([`mesh_hash`]: vertex and face counts, positions as little-endian `f64`, faces as
//! little-endian `u32`) and every option that changes the result (serialised with bincode).
//! Changing a vertex, a face or any option gives another key, hence another file
//! `<cache_dir>/<key hex>.<extension>` ([`EntryKind::extension`]).
//!
//! File layout (all integers little-endian):
//! `magic (8) | format version u32 | key (32) | payload length u64 | BLAKE3 of payload (32) |
//! payload` where the payload is the bincode 2 (serde, standard config) encoding of the stored
//! value, deflated for the kinds that say so ([`EntryKind::compressed`]: then the payload is
//! `raw length u64 | deflate stream`). [`read_entry`] trusts a file only if the magic,
//! version, key, length and checksum all match, the payload inflates to exactly its stated
//! length (if compressed) and decodes with no trailing bytes, and the caller's check of the
//! decoded value passes; anything else is reported as untrusted with the reason.
//! [`write_entry`] writes atomically (temporary file in the same directory, then rename), so a
//! crash never leaves a half-written entry under a valid name.
//!
//! # What the entries hold (format version 5)
//! Per shape, at the default options (200 eigenpairs, 300 features, 20 bands), `d` vertices:
//!
//! | file | value | content | bytes (≈) |
//! |---|---|---|---|
//! | `<key>.coseg-shape` ([`EntryKind::Full`]) | [`crate::pipeline::StoredShape`] | eigenvalues (f64), eigenvectors (**f32**, `d × k`), vertex areas (f64), the sdf and user feature columns (f64) when those families are on, band table (u8 `d × N`, deflated inside the payload) | `4·d·k + 8·d + d·N/6` (10k vertices: 8.6 MB) |
//! | `<key>.coseg-bands` ([`EntryKind::Bands`]) | [`crate::pipeline::ShapeBands`] | band table (u8, `d × N`), vertex areas (f64), the whole payload deflated | about `d·N / 6 + 8·d` (10k: 0.5 MB) |
//! | `<key>.coseg-cues` ([`EntryKind::PartCues`], only with `--parts-from geometry`; key: the mesh and the SDF options, not the feature options) | [`crate::parts::PartCues`] | thickness and mean curvature (f64) | `16·d` (10k: 0.16 MB) |
//! | `<key>.coseg-tree` ([`EntryKind::PartTree`], one per collection, with parts from geometry; key: [`crate::parts::part_tree_key`]) | the part tree of [`crate::parts::segment_collection_cached`] (`coseg segment`, and the parts route of `coseg propagate`, which reads the same entry) | the leaves' vertex lists (u32), the tree, the feature choice, the extrinsic band tables when chosen (u8), the whole payload deflated | about `4·Σd` + `Σd·E/6` (E extrinsic columns) |
//! | `<key>.coseg-pair` ([`EntryKind::RigidPair`], one per (source, target) pair of `coseg propagate`'s rigid route; key: both meshes, the refinement steps, the start rotation) | the registration (every candidate pose) and, per pose read, the nearest source vertex (i32) and distance (f64) of every target vertex | `12·d` per pose read (d: the target's vertices) + ~0.5 kB |
//! | `<key>.coseg-align` ([`EntryKind::Alignment`], one per collection of `coseg propagate`; key: every mesh in order) | the collection alignment the rigid route starts from | ~0.3 kB per shape |
//! | `<key>.coseg-map` ([`EntryKind::PointMap`], one per target and labelling of `coseg propagate`'s map route; key: both shapes' per-shape keys, the source's and the target's labels, the map options) | the point map (u32 per target vertex) | `4·d` |
//!
//! The descriptors (spectral and extrinsic) are not in the full entry: a warm load recomputes
//! them from the stored spectrum with the cold run's own code
//! ([`crate::pipeline::StoredShape::into_shape_data`]), about 0.07 s for 10k vertices, and
//! gets the same bits because the pipeline rounds the eigenvectors to `f32` before anything
//! uses them. Format 3 stored everything in f64 (43 MB for 10k vertices, 227 MB for 52k);
//! format 4 had the layout of 5 but cut the normal columns into rank bands (5: fixed-range
//! bands, [`crate::bands::fixed_range_bands`]); such entries read as stale and are recomputed. Measurements and the reasoning:
//! `docs/PERFORMANCE.md`, "Compact cache".

use crate::mesh::{TriMesh, write_atomic};
use serde::Serialize;
use serde::de::DeserializeOwned;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Version of the cache file format and of the computations it stores. Bump it whenever the
/// layout or any algorithm's output changes: older files then read as stale and are recomputed.
pub const FORMAT_VERSION: u32 = 6;

const HEADER_LEN: usize = 8 + 4 + 32 + 8 + 32;
/// File extension of full entries ([`EntryKind::Full`]).
pub const CACHE_EXTENSION: &str = "coseg-shape";
/// File extension of the compact bands entries ([`EntryKind::Bands`]).
pub const BANDS_EXTENSION: &str = "coseg-bands";
/// File extension of the part-cue entries ([`EntryKind::PartCues`]).
pub const CUES_EXTENSION: &str = "coseg-cues";
/// File extension of the part-tree entries ([`EntryKind::PartTree`]).
pub const PART_TREE_EXTENSION: &str = "coseg-tree";
/// File extension of the rigid route's pair entries ([`EntryKind::RigidPair`]).
pub const RIGID_PAIR_EXTENSION: &str = "coseg-pair";
/// File extension of the collection-alignment entries ([`EntryKind::Alignment`]).
pub const ALIGNMENT_EXTENSION: &str = "coseg-align";
/// File extension of the map route's point-map entries ([`EntryKind::PointMap`]).
pub const POINT_MAP_EXTENSION: &str = "coseg-map";
/// Deflate level of compressed payloads ([`EntryKind::compressed`]).
const DEFLATE_LEVEL: u32 = 3;
/// Deflate's largest expansion (a run of one byte: 258 bytes per 2-bit code, about 1032:1),
/// plus slack: a compressed payload claiming more is refused before anything is allocated.
const MAX_INFLATE_RATIO: u64 = 1040;

/// The kinds of entry a cache directory holds; each has its own magic and file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EntryKind {
    /// What a shape's full data are rebuilt from (f32 spectrum, band table, the costly
    /// feature columns; [`crate::pipeline::StoredShape`]).
    Full,
    /// The compact entry: band table and vertex areas only.
    Bands,
    /// The geometric cues of part boundaries ([`crate::parts::PartCues`]: thickness and mean
    /// curvature per vertex), for `--parts-from geometry`; keyed by the mesh alone.
    PartCues,
    /// A collection's part tree, what `coseg segment` cuts at any number of parts
    /// ([`crate::parts::segment_collection_cached`]); keyed by every shape's key and the
    /// collection stage's options but the number of parts.
    PartTree,
    /// The rigid route's registration of one (source, target) pair and the nearest source
    /// vertex of every target vertex under the poses read (`coseg propagate`); keyed by both
    /// meshes, the refinement steps and the registration's start.
    RigidPair,
    /// A collection's alignment ([`crate::align::align_collection`], default options), the
    /// rigid route's starts; keyed by every mesh of the collection in order.
    Alignment,
    /// The map route's point map of one target onto its source (`coseg propagate`); keyed by
    /// both shapes' per-shape keys, the source's annotation and the labels the map was fitted
    /// to.
    PointMap,
}

impl EntryKind {
    /// The 8-byte magic at the start of such a file.
    pub fn magic(self) -> &'static [u8; 8] {
        match self {
            EntryKind::Full => b"COSEGSHP",
            EntryKind::Bands => b"COSEGBND",
            EntryKind::PartCues => b"COSEGCUE",
            EntryKind::PartTree => b"COSEGTRE",
            EntryKind::RigidPair => b"COSEGPAR",
            EntryKind::Alignment => b"COSEGALN",
            EntryKind::PointMap => b"COSEGMAP",
        }
    }

    /// The file extension of such a file.
    pub fn extension(self) -> &'static str {
        match self {
            EntryKind::Full => CACHE_EXTENSION,
            EntryKind::Bands => BANDS_EXTENSION,
            EntryKind::PartCues => CUES_EXTENSION,
            EntryKind::PartTree => PART_TREE_EXTENSION,
            EntryKind::RigidPair => RIGID_PAIR_EXTENSION,
            EntryKind::Alignment => ALIGNMENT_EXTENSION,
            EntryKind::PointMap => POINT_MAP_EXTENSION,
        }
    }

    /// True when the whole payload of such a file is deflate-compressed (see the module
    /// docs): the compact entry is mostly its band table, which shrinks about 6× for a few ms
    /// per read; the part tree is mostly vertex lists and the extrinsic band tables. The full entry deflates only its band table: its `f32` eigenvectors would
    /// shrink by 7 % (16 % with a byte shuffle) for a quarter of a second per write.
    pub fn compressed(self) -> bool {
        matches!(self, EntryKind::Bands | EntryKind::PartTree)
    }
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

/// Where [`crate::pipeline`]'s data came from.
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

/// What [`read_entry`] found.
#[derive(Debug, Clone, PartialEq)]
pub enum Lookup<T> {
    /// A verified entry.
    Hit(T),
    /// No file.
    Missing,
    /// A file that cannot be read or trusted, and why.
    Untrusted(String),
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
/// use coseg::{mesh::TriMesh, cache::entry_key, pipeline::ShapePipelineOptions};
/// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let mut o = ShapePipelineOptions::default();
/// let k1 = entry_key(&m, &o);
/// o.bands.bands = 10;
/// assert_ne!(k1, entry_key(&m, &o));
/// ```
pub fn entry_key(mesh: &TriMesh, options: &impl Serialize) -> ShapeKey {
    let mut h = blake3::Hasher::new();
    h.update(b"coseg shape key");
    h.update(&FORMAT_VERSION.to_le_bytes());
    h.update(&mesh_hash(mesh));
    let opts = bincode::serde::encode_to_vec(options, bincode::config::standard())
        .expect("options are plain data and always encode");
    h.update(&opts);
    ShapeKey(*h.finalize().as_bytes())
}

/// Path of the entry of `kind` for `key` in `cache_dir`.
pub fn entry_path(cache_dir: &Path, key: &ShapeKey, kind: EntryKind) -> PathBuf {
    cache_dir.join(format!("{}.{}", key.to_hex(), kind.extension()))
}

/// Path of the full entry for `key` in `cache_dir`.
pub fn cache_path(cache_dir: &Path, key: &ShapeKey) -> PathBuf {
    entry_path(cache_dir, key, EntryKind::Full)
}

/// Path of the compact bands entry for `key` in `cache_dir`.
pub fn bands_path(cache_dir: &Path, key: &ShapeKey) -> PathBuf {
    entry_path(cache_dir, key, EntryKind::Bands)
}

/// Reads and verifies the entry at `path`: its frame (magic of `kind`, version, `key`, length,
/// checksum), its payload's decoding, then `check` on the decoded value (e.g. sizes against the
/// mesh); `check`'s `Err` is the reason the entry is not trusted.
pub fn read_entry<T: DeserializeOwned>(
    path: &Path,
    kind: EntryKind,
    key: &ShapeKey,
    check: impl FnOnce(&T) -> Result<(), String>,
) -> Lookup<T> {
    let bytes = match std::fs::read(path) {
        Ok(bytes) => bytes,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Lookup::Missing,
        Err(e) => return Lookup::Untrusted(format!("unreadable ({e})")),
    };
    match decode_entry(&bytes, kind, key, check) {
        Ok(v) => Lookup::Hit(v),
        Err(reason) => Lookup::Untrusted(reason),
    }
}

/// Verifies and decodes the bytes of an entry (see [`read_entry`]).
pub fn decode_entry<T: DeserializeOwned>(
    bytes: &[u8],
    kind: EntryKind,
    key: &ShapeKey,
    check: impl FnOnce(&T) -> Result<(), String>,
) -> Result<T, String> {
    let payload = unframe(bytes, kind.magic(), key)?;
    let inflated;
    let payload = if kind.compressed() {
        inflated = inflate(payload)?;
        &inflated[..]
    } else {
        payload
    };
    let (data, used): (T, usize) =
        decode_payload(payload).map_err(|e| format!("payload does not decode ({e})"))?;
    if used != payload.len() {
        return Err("payload has trailing bytes".into());
    }
    check(&data)?;
    Ok(data)
}

/// Decodes a bincode payload with a memory limit proportional to its size.
///
/// bincode allocates a string or byte vector of the length its prefix declares before reading
/// it, so a payload declaring a 2⁵⁶-byte string made the process abort on the allocation
/// (found by the `cache_entry` fuzz target; regression test
/// `tests/cache.rs::a_cache_entry_declaring_a_huge_string_is_refused_not_an_abort`). The limit
/// counts the in-memory bytes of every decoded value (at most 16 per encoded byte: a `u128`
/// in one varint byte), so 16 × the payload length never refuses a payload coseg wrote; it is
/// rounded up to a power of 4 (the limit is a const parameter of bincode's configuration), so
/// decoding allocates at most 64 × the payload's size.
fn decode_payload<T: DeserializeOwned>(
    payload: &[u8],
) -> Result<(T, usize), bincode::error::DecodeError> {
    let need = payload.len().saturating_mul(16);
    macro_rules! tiers {
        ($($bits:literal)*) => {$(
            if need <= 1usize << $bits {
                let config = bincode::config::standard().with_limit::<{ 1usize << $bits }>();
                return bincode::serde::decode_from_slice(payload, config);
            }
        )*};
    }
    tiers!(12 14 16 18 20 22 24 26 28 30 32 34 36 38 40 42 44 46);
    // Payloads over 4 TiB: no limit left to set below the address space.
    bincode::serde::decode_from_slice(payload, bincode::config::standard())
}

/// The bytes of an entry of `kind` holding `value` under `key` (header + payload, see the
/// module docs).
pub fn encode_entry<T: Serialize>(kind: EntryKind, key: &ShapeKey, value: &T) -> Vec<u8> {
    let payload = bincode::serde::encode_to_vec(value, bincode::config::standard())
        .expect("cached values are plain data and always encode");
    let payload = if kind.compressed() {
        deflate(&payload)
    } else {
        payload
    };
    frame(kind.magic(), key, payload)
}

/// `length of raw (u64 LE) | raw deflated`.
pub(crate) fn deflate(raw: &[u8]) -> Vec<u8> {
    use flate2::{Compression, write::DeflateEncoder};
    let header = (raw.len() as u64).to_le_bytes().to_vec();
    let mut encoder = DeflateEncoder::new(header, Compression::new(DEFLATE_LEVEL));
    encoder
        .write_all(raw)
        .expect("writing to memory cannot fail");
    encoder.finish().expect("writing to memory cannot fail")
}

/// The raw bytes of a [`deflate`]d payload. A length that deflate cannot reach from this many
/// bytes, a stream that does not inflate to exactly that length or leaves bytes unread, is
/// refused, so no input makes it allocate more than [`MAX_INFLATE_RATIO`] × its size.
pub(crate) fn inflate(stored: &[u8]) -> Result<Vec<u8>, String> {
    use flate2::read::DeflateDecoder;
    use std::io::Read;
    let Some((len, body)) = stored.split_first_chunk::<8>() else {
        return Err("compressed payload has no length".into());
    };
    let len = u64::from_le_bytes(*len);
    if len > (body.len() as u64).saturating_mul(MAX_INFLATE_RATIO) {
        return Err(format!(
            "compressed payload of {} bytes claims {len} bytes",
            body.len()
        ));
    }
    let mut decoder = DeflateDecoder::new(body);
    // Sized for what coseg writes (the band table deflates about 6:1); a stream that really
    // expands more grows the vector as it goes.
    let mut raw = Vec::with_capacity(len.min(body.len() as u64 * 16) as usize);
    (&mut decoder)
        .take(len + 1)
        .read_to_end(&mut raw)
        .map_err(|e| format!("compressed payload does not inflate ({e})"))?;
    if raw.len() as u64 != len || decoder.total_in() != body.len() as u64 {
        return Err(format!(
            "compressed payload inflates to {} bytes from {} of its {} (header says {len})",
            raw.len(),
            decoder.total_in(),
            body.len()
        ));
    }
    Ok(raw)
}

/// Writes `bytes` (from [`encode_entry`]) to `path` atomically. The directory must exist.
pub fn write_entry(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic(path, |w| w.write_all(bytes))
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
