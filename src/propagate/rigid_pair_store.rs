//! [`rigid_pair_key`]: the rigid route's label-independent work on disk, so that a rerun of
//! `coseg propagate` on the same shapes (other labels, one more source, the same command again)
//! reads each pair's registration and nearest points instead of registering it again.
//!
//! # What is stored, and why
//! Per (source, target) pair ([`EntryKind::RigidPair`], `<key>.coseg-pair`): the registration
//! of the target onto the source (every candidate pose, residuals, inlier share, or why it
//! failed) and, per candidate pose the route has read, the source vertex each target vertex
//! reads its label from, its distance to the source's surface and the pair's residual after
//! the refinement steps. That is all the route keeps of a pair between updates
//! ([`super::rigid_route`]'s cache), and nothing of it depends on the labels: the labels are
//! read through the stored vertex indices. About `12·d` bytes per pose read (`d` the target's
//! vertices) plus a few hundred for the registration.
//!
//! Per collection ([`EntryKind::Alignment`], `<key>.coseg-align`): the collection alignment
//! the registrations start from ([`crate::align::align_collection`], default options), so that
//! a warm run does not align the collection again to learn the starts.
//!
//! # Keys
//! A pair's key ([`rigid_pair_key`]): both meshes' content hashes ([`mesh_hash`]), the
//! refinement steps, the start rotation's bits (which carry everything the collection
//! alignment contributes: another collection that gives the pair the same start reads the
//! same entry), the registration options, the cache format, this entry's layout version, the
//! crate version and a hash of the crate's sources at build time (the result depends on every
//! algorithm of the registration and the refinements, which no option names). The
//! alignment's key ([`alignment_key`]): every mesh's content hash in order, the alignment's
//! options and the same versions. An entry that is missing, of another version or corrupt is
//! recomputed and rewritten; a result never depends on the cache.

use crate::align::{AlignOptions, Candidate, CollectionAlignment, RegisterOptions, Registration};
use crate::cache::{
    EntryKind, FORMAT_VERSION, Lookup, ShapeKey, encode_entry, entry_path, mesh_hash, read_entry,
    write_entry,
};
use crate::mesh::TriMesh;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Version of the layout of both entries ([`StoredPair`], the alignment); part of the keys.
const RIGID_PAIR_VERSION: u32 = 1;

/// The content hash of a mesh, as the per-shape cache keys it ([`mesh_hash`]).
pub(crate) fn shape_hash(mesh: &TriMesh) -> [u8; 32] {
    mesh_hash(mesh)
}

fn versions(h: &mut blake3::Hasher) {
    h.update(&FORMAT_VERSION.to_le_bytes());
    h.update(&RIGID_PAIR_VERSION.to_le_bytes());
    for s in [env!("CARGO_PKG_VERSION"), env!("COSEG_SOURCE_HASH")] {
        h.update(&(s.len() as u64).to_le_bytes());
        h.update(s.as_bytes());
    }
}

/// The cache key of the rigid route's work on one pair: BLAKE3 of the versions (see the
/// module notes), the source's and the target's content hashes, the refinement steps
/// (`[affine, nonrigid]`), the bits of the registration's start rotation (row-major), the
/// affine step's trimmed share and the registration's default options.
pub(crate) fn rigid_pair_key(
    source: &[u8; 32],
    target: &[u8; 32],
    steps: [bool; 2],
    start: &[[f64; 3]; 3],
    trim: f64,
) -> ShapeKey {
    let mut h = blake3::Hasher::new();
    h.update(b"coseg rigid pair key");
    versions(&mut h);
    h.update(source);
    h.update(target);
    h.update(&[u8::from(steps[0]), u8::from(steps[1])]);
    for row in start {
        for x in row {
            h.update(&x.to_bits().to_le_bytes());
        }
    }
    h.update(&trim.to_bits().to_le_bytes());
    // `Debug` names every field and prints floats so that they read back exactly.
    h.update(format!("{:?}", RegisterOptions::default()).as_bytes());
    ShapeKey(*h.finalize().as_bytes())
}

/// The cache key of a collection's alignment: BLAKE3 of the versions, every mesh's content
/// hash in graph order and the alignment's default options.
pub(crate) fn alignment_key(hashes: &[[u8; 32]]) -> ShapeKey {
    let mut h = blake3::Hasher::new();
    h.update(b"coseg collection alignment key");
    versions(&mut h);
    h.update(&(hashes.len() as u64).to_le_bytes());
    for x in hashes {
        h.update(x);
    }
    h.update(format!("{:?}", AlignOptions::default()).as_bytes());
    ShapeKey(*h.finalize().as_bytes())
}

/// A candidate pose as stored: rotation (row-major), scale, translation, residual, angle to
/// the best.
type StoredCandidate = ([[f64; 3]; 3], f64, [f64; 3], f64, f64);

/// A [`Registration`] as stored (the similarity's fields spelt out, every `f64` exact).
#[derive(Debug, Clone, Serialize, Deserialize)]
struct StoredRegistration {
    transform: StoredCandidate,
    inlier_share: f64,
    runner_up: Option<StoredCandidate>,
    candidates: Vec<StoredCandidate>,
}

fn stored_candidate(c: &Candidate) -> StoredCandidate {
    let t = &c.transform;
    (
        t.rotation,
        t.scale,
        t.translation,
        c.residual,
        c.angle_to_best,
    )
}

fn candidate(c: &StoredCandidate) -> Candidate {
    Candidate {
        transform: crate::align::Similarity {
            rotation: c.0,
            scale: c.1,
            translation: c.2,
        },
        residual: c.3,
        angle_to_best: c.4,
    }
}

/// Per target vertex the source vertex it reads and its distance to the source's surface,
/// and the pair's residual after the refinement steps (the route's `Nearest`).
pub(crate) type StoredNearest = (Vec<i32>, Vec<f64>, f64);

/// What is stored of one pair: the registration (or why it failed) and the nearest points of
/// every pose read so far, by the pose's index in the registration's candidates.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct StoredPair {
    registration: Result<StoredRegistration, String>,
    nearest: Vec<(u32, StoredNearest)>,
}

impl StoredPair {
    /// The entry of `registration` and the nearest points read under its poses.
    pub(crate) fn new<'a>(
        registration: &Result<Registration, String>,
        nearest: impl IntoIterator<Item = (usize, &'a StoredNearest)>,
    ) -> Self {
        StoredPair {
            registration: registration
                .as_ref()
                .map_err(Clone::clone)
                .map(|r| StoredRegistration {
                    transform: stored_candidate(&Candidate {
                        transform: r.transform,
                        residual: r.residual,
                        angle_to_best: 0.0,
                    }),
                    inlier_share: r.inlier_share,
                    runner_up: r.runner_up.as_ref().map(stored_candidate),
                    candidates: r.candidates.iter().map(stored_candidate).collect(),
                }),
            nearest: nearest
                .into_iter()
                .map(|(k, n)| (k as u32, n.clone()))
                .collect(),
        }
    }

    /// The registration and the nearest points by pose, as the route keeps them.
    pub(crate) fn into_parts(self) -> (Result<Registration, String>, Vec<(usize, StoredNearest)>) {
        let registration = self.registration.map(|r| {
            let best = candidate(&r.transform);
            Registration {
                transform: best.transform,
                residual: best.residual,
                inlier_share: r.inlier_share,
                runner_up: r.runner_up.as_ref().map(candidate),
                candidates: r.candidates.iter().map(candidate).collect(),
            }
        });
        let nearest = self
            .nearest
            .into_iter()
            .map(|(k, n)| (k as usize, n))
            .collect();
        (registration, nearest)
    }

    /// Sizes against the pair: every nearest-point table one entry per target vertex, every
    /// source vertex index in range, every pose an index of a stored candidate.
    fn check(&self, source_vertices: usize, target_vertices: usize) -> Result<(), String> {
        let poses = self
            .registration
            .as_ref()
            .map_or(0, |r| r.candidates.len().max(1));
        for (k, (from, distance, _)) in &self.nearest {
            if *k as usize >= poses {
                return Err(format!("pose {k} of {poses}"));
            }
            if from.len() != target_vertices || distance.len() != target_vertices {
                return Err(format!(
                    "{} nearest points for {target_vertices} target vertices",
                    from.len()
                ));
            }
            if from.iter().any(|&v| v < 0 || v as usize >= source_vertices) {
                return Err("a source vertex out of range".into());
            }
        }
        Ok(())
    }
}

/// The stored pair under `key` in `dir`, checked against the pair's vertex counts; `None`
/// when there is none or it cannot be trusted (then it is recomputed and rewritten).
pub(crate) fn read_pair(
    dir: &Path,
    key: &ShapeKey,
    source_vertices: usize,
    target_vertices: usize,
) -> Option<StoredPair> {
    let path = entry_path(dir, key, EntryKind::RigidPair);
    match read_entry(&path, EntryKind::RigidPair, key, |p: &StoredPair| {
        p.check(source_vertices, target_vertices)
    }) {
        Lookup::Hit(p) => Some(p),
        Lookup::Missing | Lookup::Untrusted(_) => None,
    }
}

/// Writes `pair` under `key` in `dir` (created if missing), atomically.
pub(crate) fn write_pair(dir: &Path, key: &ShapeKey, pair: &StoredPair) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    write_entry(
        &entry_path(dir, key, EntryKind::RigidPair),
        &encode_entry(EntryKind::RigidPair, key, pair),
    )
}

/// The stored collection alignment under `key` in `dir`, checked to hold `shapes` shapes;
/// `None` when there is none or it cannot be trusted.
pub(crate) fn read_alignment(
    dir: &Path,
    key: &ShapeKey,
    shapes: usize,
) -> Option<CollectionAlignment> {
    let path = entry_path(dir, key, EntryKind::Alignment);
    match read_entry(
        &path,
        EntryKind::Alignment,
        key,
        |a: &CollectionAlignment| {
            if a.shapes.len() == shapes {
                Ok(())
            } else {
                Err(format!("{} shapes for {shapes}", a.shapes.len()))
            }
        },
    ) {
        Lookup::Hit(a) => Some(a),
        Lookup::Missing | Lookup::Untrusted(_) => None,
    }
}

/// Writes `alignment` under `key` in `dir` (created if missing), atomically.
pub(crate) fn write_alignment(
    dir: &Path,
    key: &ShapeKey,
    alignment: &CollectionAlignment,
) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    write_entry(
        &entry_path(dir, key, EntryKind::Alignment),
        &encode_entry(EntryKind::Alignment, key, alignment),
    )
}
