//! [`point_map_key`]: the map route's point maps on disk, so that a rerun whose labels did
//! not change on a shape (the same command again, a label changed elsewhere) reads that
//! shape's map instead of fitting a functional map and running ZoomOut again.
//!
//! # What is stored, and why
//! Per (source, target) pair and labelling ([`EntryKind::PointMap`], `<key>.coseg-map`): the
//! point map of [`crate::maps::region_point_map`], one source vertex (u32) per target vertex,
//! `4·d` bytes. The map is a function of the two shapes' spectra and positions, the source's
//! annotation and the target's labels it is fitted to, and the map options; the map step's
//! labels and agreement are read off it exactly as when it is fitted
//! ([`super::map_step`]).
//!
//! # Key
//! BLAKE3 of the cache format, this entry's layout version, the crate version, a hash of the
//! crate's sources at build time (the map depends on every algorithm of the spectrum and of
//! ZoomOut), both shapes' per-shape keys ([`crate::pipeline::shape_key`]: the mesh and every
//! option of the per-shape stage, hence the spectrum), both label vectors and the `Debug` form
//! of the map options. Labels that changed give another key; an entry that is missing, stale
//! or corrupt is fitted again and rewritten.

use super::MapStepOptions;
use crate::cache::{
    EntryKind, FORMAT_VERSION, Lookup, ShapeKey, encode_entry, entry_path, read_entry, write_entry,
};
use std::path::Path;

/// Version of the point-map entry's layout; part of [`point_map_key`].
const POINT_MAP_VERSION: u32 = 1;

/// The cache key of the point map from a target to a source (see the module notes):
/// `source`, `target` the shapes' per-shape keys, `source_labels` the source's annotation,
/// `target_labels` the labels the map is fitted to, `options` the map step's.
pub(crate) fn point_map_key(
    source: &ShapeKey,
    target: &ShapeKey,
    source_labels: &[i32],
    target_labels: &[i32],
    options: &MapStepOptions,
) -> ShapeKey {
    let mut h = blake3::Hasher::new();
    h.update(b"coseg point map key");
    h.update(&FORMAT_VERSION.to_le_bytes());
    h.update(&POINT_MAP_VERSION.to_le_bytes());
    for s in [env!("CARGO_PKG_VERSION"), env!("COSEG_SOURCE_HASH")] {
        h.update(&(s.len() as u64).to_le_bytes());
        h.update(s.as_bytes());
    }
    h.update(&source.0);
    h.update(&target.0);
    for labels in [source_labels, target_labels] {
        h.update(&(labels.len() as u64).to_le_bytes());
        for l in labels {
            h.update(&l.to_le_bytes());
        }
    }
    // `Debug` names every field and prints floats so that they read back exactly.
    h.update(format!("{options:?}").as_bytes());
    ShapeKey(*h.finalize().as_bytes())
}

/// The point map stored under `key` in `folder`, checked to give every one of
/// `target_vertices` vertices a vertex of the source's `source_vertices`; `None` when there
/// is none or it cannot be trusted.
pub(crate) fn read_point_map(
    folder: &Path,
    key: &ShapeKey,
    source_vertices: usize,
    target_vertices: usize,
) -> Option<Vec<u32>> {
    let path = entry_path(folder, key, EntryKind::PointMap);
    let check = |m: &Vec<u32>| {
        if m.len() != target_vertices {
            return Err(format!(
                "{} entries for {target_vertices} vertices",
                m.len()
            ));
        }
        if m.iter().any(|&v| v as usize >= source_vertices) {
            return Err("a source vertex out of range".into());
        }
        Ok(())
    };
    match read_entry(&path, EntryKind::PointMap, key, check) {
        Lookup::Hit(m) => Some(m),
        Lookup::Missing | Lookup::Untrusted(_) => None,
    }
}

/// Writes `map` under `key` in `folder` (created if missing), atomically.
pub(crate) fn write_point_map(folder: &Path, key: &ShapeKey, map: &[u32]) -> std::io::Result<()> {
    std::fs::create_dir_all(folder)?;
    write_entry(
        &entry_path(folder, key, EntryKind::PointMap),
        &encode_entry(EntryKind::PointMap, key, &map.to_vec()),
    )
}
