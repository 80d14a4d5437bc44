//! Tests of the per-shape cache: hits, misses, corrupt/truncated/stale entries, keys,
//! determinism.

mod common;

use common::features::{blob, permutation, permute_mesh};
use coseg::cache::{CacheOutcome, cache_path, mesh_hash};
use coseg::mesh::TriMesh;
use coseg::pipeline::{
    ShapePipelineOptions, compute_shape_data, encode_shape_entry as encode_entry, load_or_compute,
    shape_key,
};

fn opts() -> ShapePipelineOptions {
    common::features::small_pipeline(20, 6)
}

fn mesh() -> TriMesh {
    blob(2)
}

fn is_recomputed(o: &CacheOutcome, needle: &str) -> bool {
    matches!(o, CacheOutcome::Recomputed { reason } if reason.contains(needle))
}

#[test]
fn miss_then_hit_with_identical_data() {
    let dir = tempfile::tempdir().unwrap();
    let (m, o) = (mesh(), opts());
    let first = load_or_compute(&m, &o, dir.path()).unwrap();
    assert_eq!(first.outcome, CacheOutcome::Miss);
    assert!(first.write_error.is_none());
    assert!(first.path.exists());
    let second = load_or_compute(&m, &o, dir.path()).unwrap();
    assert_eq!(second.outcome, CacheOutcome::Hit);
    assert_eq!(first.data, second.data);
    assert_eq!(first.data.key, shape_key(&m, &o));
    // Nothing but the entry is left in the directory (no temporary files).
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn computation_is_bitwise_reproducible() {
    let (m, o) = (mesh(), opts());
    let a = compute_shape_data(&m, &o).unwrap();
    let b = compute_shape_data(&m, &o).unwrap();
    assert_eq!(encode_entry(&a), encode_entry(&b));
}

#[test]
fn every_flipped_payload_byte_region_and_truncation_is_detected() {
    let dir = tempfile::tempdir().unwrap();
    let (m, o) = (mesh(), opts());
    let first = load_or_compute(&m, &o, dir.path()).unwrap();
    let good = std::fs::read(&first.path).unwrap();
    // Positions across header and payload.
    let len = good.len();
    let cases: Vec<(usize, &str)> = vec![
        (0, "magic"),
        (9, "version"),
        (20, "key"),
        (45, "payload is"),
        (60, "checksum"),
        (100, "checksum"),
        (len / 2, "checksum"),
        (len - 1, "checksum"),
    ];
    for (pos, needle) in cases {
        let mut bad = good.clone();
        bad[pos] ^= 0x40;
        std::fs::write(&first.path, &bad).unwrap();
        let r = load_or_compute(&m, &o, dir.path()).unwrap();
        assert!(
            is_recomputed(&r.outcome, needle),
            "byte {pos}: {:?}",
            r.outcome
        );
        assert_eq!(r.data, first.data);
        // The entry was rewritten and is trusted again.
        assert_eq!(std::fs::read(&first.path).unwrap(), good);
    }
    for cut in [0, 10, 83, 84, len / 3, len - 1] {
        std::fs::write(&first.path, &good[..cut]).unwrap();
        let r = load_or_compute(&m, &o, dir.path()).unwrap();
        assert!(
            matches!(r.outcome, CacheOutcome::Recomputed { .. }),
            "cut {cut}: {:?}",
            r.outcome
        );
        assert_eq!(r.data, first.data);
        assert_eq!(
            load_or_compute(&m, &o, dir.path()).unwrap().outcome,
            CacheOutcome::Hit
        );
    }
    // Extra trailing bytes.
    let mut long = good.clone();
    long.push(0);
    std::fs::write(&first.path, &long).unwrap();
    assert!(is_recomputed(
        &load_or_compute(&m, &o, dir.path()).unwrap().outcome,
        "payload is"
    ));
}

#[test]
fn a_changed_option_or_mesh_gets_another_entry() {
    let dir = tempfile::tempdir().unwrap();
    let (m, o) = (mesh(), opts());
    let first = load_or_compute(&m, &o, dir.path()).unwrap();
    let mut o2 = o.clone();
    o2.bands.bands = 5;
    let second = load_or_compute(&m, &o2, dir.path()).unwrap();
    assert_eq!(second.outcome, CacheOutcome::Miss);
    assert_ne!(second.path, first.path);
    assert_eq!(second.data.bands.bands, 5);
    assert_eq!(second.data.spectrum, first.data.spectrum);
    // Every option field takes part in the key.
    let base = shape_key(&m, &o);
    let mut v = Vec::new();
    let mut x = o.clone();
    x.spectrum.eigenpairs += 1;
    v.push(x);
    let mut x = o.clone();
    x.descriptors.wks_sigma_multiple = 6.0;
    v.push(x);
    let mut x = o.clone();
    x.descriptors.zero_eigenvalue = 1e-6;
    v.push(x);
    let mut x = o.clone();
    x.descriptors.band = coseg::features::SpectralBand::Fixed {
        lambda_min: 10.0,
        lambda_max: 1000.0,
    };
    v.push(x);
    let mut x = o.clone();
    x.bands.weighting = coseg::bands::BandWeighting::Area;
    v.push(x);
    for x in &v {
        assert_ne!(shape_key(&m, x), base);
    }
    // The mesh content, including vertex order, takes part too.
    let moved = m.map_positions(|p| [p[0], p[1], p[2] + 1e-12]).unwrap();
    assert_ne!(mesh_hash(&moved), mesh_hash(&m));
    let permuted = permute_mesh(&m, &permutation(m.vertex_count(), 1));
    assert_ne!(mesh_hash(&permuted), mesh_hash(&m));
}

#[test]
fn an_entry_stored_under_the_wrong_key_is_stale() {
    let dir = tempfile::tempdir().unwrap();
    let (m, o) = (mesh(), opts());
    let first = load_or_compute(&m, &o, dir.path()).unwrap();
    let mut o2 = o.clone();
    o2.descriptors.hks_count = 3;
    // Someone copies the old entry to the new key's name: the header's key gives it away.
    let target = cache_path(dir.path(), &shape_key(&m, &o2));
    std::fs::copy(&first.path, &target).unwrap();
    let r = load_or_compute(&m, &o2, dir.path()).unwrap();
    assert!(is_recomputed(&r.outcome, "stale"), "{:?}", r.outcome);
    assert_eq!(r.data.descriptors.hks_times.len(), 3);
    assert_eq!(
        load_or_compute(&m, &o2, dir.path()).unwrap().outcome,
        CacheOutcome::Hit
    );
}

/// A cache that cannot be written costs a recomputation next time, not the shape (#21): the
/// data come back with a warning.
#[test]
fn a_file_in_place_of_the_directory_is_a_warning_not_a_failure() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("not-a-dir");
    std::fs::write(&file, b"x").unwrap();
    let r = load_or_compute(&mesh(), &opts(), &file).unwrap();
    assert!(is_recomputed(&r.outcome, "unreadable"), "{:?}", r.outcome);
    assert!(r.write_error.is_some_and(|e| e.contains("not written")));
}

// The compact bands entry

/// The bands entry is written on the first call (with the full entry), read on the next, and
/// holds exactly the full entry's band table and vertex areas.
#[test]
fn bands_entry_miss_then_hit_matches_the_full_entry() {
    use coseg::cache::bands_path;
    use coseg::pipeline::{ShapeBands, load_or_compute_bands};
    let dir = tempfile::tempdir().unwrap();
    let (m, o) = (mesh(), opts());
    let first = load_or_compute_bands(&m, &o, dir.path()).unwrap();
    assert_eq!(first.outcome, CacheOutcome::Miss);
    assert!(first.warnings.is_empty(), "{:?}", first.warnings);
    let key = shape_key(&m, &o);
    assert!(bands_path(dir.path(), &key).exists());
    assert!(cache_path(dir.path(), &key).exists());
    let second = load_or_compute_bands(&m, &o, dir.path()).unwrap();
    assert_eq!(second.outcome, CacheOutcome::Hit);
    let full = load_or_compute(&m, &o, dir.path()).unwrap();
    assert_eq!(second.data, ShapeBands::of(&full.data));
    assert_eq!(first.data, second.data);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

/// A corrupt, truncated or foreign bands entry is never trusted: it is rebuilt from the full
/// entry (no recomputation), with a warning naming the file and the reason; a missing one is
/// rebuilt silently.
#[test]
fn bad_bands_entries_are_rebuilt_from_the_full_entry() {
    use coseg::cache::bands_path;
    use coseg::pipeline::load_or_compute_bands;
    let dir = tempfile::tempdir().unwrap();
    let (m, o) = (mesh(), opts());
    let good = load_or_compute_bands(&m, &o, dir.path()).unwrap().data;
    let path = bands_path(dir.path(), &shape_key(&m, &o));
    let bytes = std::fs::read(&path).unwrap();
    let mut flipped = bytes.clone();
    let mid = flipped.len() / 2;
    flipped[mid] ^= 0x40;
    let full = std::fs::read(cache_path(dir.path(), &shape_key(&m, &o))).unwrap();
    for (bad, needle) in [
        (flipped, "checksum"),
        (bytes[..bytes.len() - 3].to_vec(), "payload is"),
        (bytes[..10].to_vec(), "truncated header"),
        (full, "bad magic"),
    ] {
        std::fs::write(&path, &bad).unwrap();
        let r = load_or_compute_bands(&m, &o, dir.path()).unwrap();
        assert_eq!(
            r.outcome,
            CacheOutcome::Hit,
            "{needle}: the full entry was valid"
        );
        assert_eq!(r.data, good);
        assert!(
            r.warnings
                .iter()
                .any(|w| w.contains(needle) && w.contains("coseg-bands")),
            "{needle}: {:?}",
            r.warnings
        );
        assert_eq!(
            std::fs::read(&path).unwrap(),
            bytes,
            "{needle}: entry rewritten"
        );
    }
    std::fs::remove_file(&path).unwrap();
    let r = load_or_compute_bands(&m, &o, dir.path()).unwrap();
    assert_eq!((r.outcome, r.warnings.len()), (CacheOutcome::Hit, 0));
    assert_eq!(std::fs::read(&path).unwrap(), bytes);
}

/// Frames `payload` as a cache entry of the full kind under `key` (the layout of
/// `coseg::cache`: magic, version, key, payload length, BLAKE3 of the payload), so that the
/// checksum holds and the payload decoder is reached.
fn framed(key: &coseg::cache::ShapeKey, payload: &[u8]) -> Vec<u8> {
    let mut bytes = b"COSEGSHP".to_vec();
    bytes.extend_from_slice(&coseg::cache::FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&key.0);
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(blake3::hash(payload).as_bytes());
    bytes.extend_from_slice(payload);
    bytes
}

/// Regression (fuzzing, `cache_entry` target): a payload behind a valid checksum whose
/// descriptor-name string declares a length of 2⁵⁶ − 2 bytes made bincode allocate that much
/// before reading, and the process abort (`memory allocation … failed`; under ASan,
/// `allocation-size-too-big`). The input is the fuzzer's, byte for byte
/// (`tests/data/fuzz/cache_entry_huge_string_length.bin`: byte 0 the target's selector, the
/// rest the payload). Now the decoder's memory limit refuses it: the entry is untrusted with
/// the reason and, through the cache, recomputed.
#[test]
fn a_cache_entry_declaring_a_huge_string_is_refused_not_an_abort() {
    let input = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/fuzz/cache_entry_huge_string_length.bin"),
    )
    .unwrap();
    let (pick, payload) = (input[0], &input[1..]);
    // As the fuzz target runs it: the payload's first 32 bytes are the key.
    let key = coseg::cache::ShapeKey(payload[..32].try_into().unwrap());
    let e = coseg::pipeline::decode_shape_entry(&framed(&key, payload), &key, (pick >> 1) as usize)
        .unwrap_err();
    assert!(
        e.contains("does not decode") && e.to_lowercase().contains("limit"),
        "{e}"
    );
    // Through the cache: the same payload stored under a mesh's key is recomputed.
    let dir = tempfile::tempdir().unwrap();
    let (m, o) = (mesh(), opts());
    let key = shape_key(&m, &o);
    std::fs::write(cache_path(dir.path(), &key), framed(&key, payload)).unwrap();
    let r = load_or_compute(&m, &o, dir.path()).unwrap();
    assert!(
        is_recomputed(&r.outcome, "does not decode"),
        "{:?}",
        r.outcome
    );
    assert_eq!(r.data, compute_shape_data(&m, &o).unwrap());
    let again = load_or_compute(&m, &o, dir.path()).unwrap();
    assert_eq!(again.outcome, CacheOutcome::Hit);
}
