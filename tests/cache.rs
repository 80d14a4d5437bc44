//! Tests of the per-shape cache: hits, misses, corrupt/truncated/stale entries, keys,
//! determinism.

mod common;

use common::features::{blob, permutation, permute_mesh};
use coseg::cache::{CacheOutcome, cache_path, mesh_hash};
use coseg::mesh::TriMesh;
use coseg::pipeline::{
    CacheResult, ShapeData, ShapePipelineOptions, compute_shape_data,
    encode_shape_entry as encode_entry, load_or_compute, shape_key,
};
use tempfile::TempDir;

fn opts() -> ShapePipelineOptions {
    common::features::small_pipeline(20, 6)
}

fn mesh() -> TriMesh {
    blob(2)
}

/// A fresh cache folder, the test mesh and options, and their first `load_or_compute` there
/// (a miss that writes the entry).
fn first_entry() -> (TempDir, TriMesh, ShapePipelineOptions, CacheResult) {
    let dir = tempfile::tempdir().unwrap();
    let (m, o) = (mesh(), opts());
    let first = load_or_compute(&m, &o, dir.path()).unwrap();
    (dir, m, o, first)
}

fn is_recomputed(o: &CacheOutcome, needle: &str) -> bool {
    matches!(o, CacheOutcome::Recomputed { reason } if reason.contains(needle))
}

#[test]
fn miss_then_hit_with_identical_data() {
    let (dir, m, o, first) = first_entry();
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
    let (dir, m, o, first) = first_entry();
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
    let (dir, m, o, first) = first_entry();
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
    let (dir, m, o, first) = first_entry();
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
/// descriptor-name string declared a length of 2⁵⁶ − 2 bytes made bincode allocate that much
/// before reading, and the process abort (`memory allocation … failed`; under ASan,
/// `allocation-size-too-big`). The fuzzer's input (`tests/data/fuzz/
/// cache_entry_huge_string_length.bin`: byte 0 the target's selector, the rest the payload)
/// was made for the format-3 layout and is now simply refused; the same attack on the
/// current layout (the name of a kept column declaring 2⁵⁶ − 2 bytes) is refused by the
/// decoder's memory limit: the entry is untrusted with the reason and, through the cache,
/// recomputed.
#[test]
fn a_cache_entry_declaring_a_huge_string_is_refused_not_an_abort() {
    use coseg::features::FeatureColumns;
    use coseg::pipeline::{StoredShape, decode_shape_entry};
    let input = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/fuzz/cache_entry_huge_string_length.bin"),
    )
    .unwrap();
    let (pick, payload) = (input[0], &input[1..]);
    // As the fuzz target runs it: the payload's first 32 bytes are the key.
    let key = coseg::cache::ShapeKey(payload[..32].try_into().unwrap());
    let e = decode_shape_entry(&framed(&key, payload), &key, (pick >> 1) as usize).unwrap_err();
    assert!(e.contains("does not decode"), "{e}");

    let (m, o) = (mesh(), opts());
    let key = shape_key(&m, &o);
    let stored = StoredShape {
        key,
        vertices: 1,
        eigenvalues: vec![0.0],
        eigenvectors: vec![1.0],
        vertex_areas: vec![1.0],
        original_area: 1.0,
        kept_columns: FeatureColumns {
            vertices: 1,
            names: vec!["QQQQ".into()],
            values: vec![0.5],
        },
        kept_counts: [1, 0],
        bands: coseg::bands::BandTable {
            features: 1,
            vertices: 1,
            bands: 2,
            labels: vec![0],
        },
    };
    let good = bincode::serde::encode_to_vec(&stored, bincode::config::standard()).unwrap();
    let at = good.windows(5).position(|w| w == b"\x04QQQQ").unwrap();
    let mut payload = good[..at].to_vec();
    payload.push(0xfd); // bincode varint: a u64 follows
    payload.extend_from_slice(&((1u64 << 56) - 2).to_le_bytes());
    payload.extend_from_slice(&good[at + 1..]);
    let e = decode_shape_entry(&framed(&key, &payload), &key, 1).unwrap_err();
    assert!(
        e.contains("does not decode") && e.to_lowercase().contains("limit"),
        "{e}"
    );
    // Through the cache: the same payload stored under a mesh's key is recomputed.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(cache_path(dir.path(), &key), framed(&key, &payload)).unwrap();
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

// The compact layout (format version 4 and later)

/// Every bit of the shape's data: spectrum, descriptors (values and metadata), band table.
/// `PartialEq` on `f64` would take `0.0` for `-0.0`; this does not.
fn bits(d: &ShapeData) -> Vec<u64> {
    let s = &d.spectrum;
    let t = &d.descriptors;
    let f = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    let mut out = vec![
        d.vertices as u64,
        s.original_area.to_bits(),
        t.wks_sigma.to_bits(),
    ];
    for part in [
        &s.eigenvalues,
        &s.eigenvectors,
        &s.vertex_areas,
        &t.hks_times,
        &t.wks_energies,
        &t.curvature_times,
        &t.vertex_areas,
        &t.values,
    ] {
        out.push(part.len() as u64);
        out.extend(f(part));
    }
    out.extend(t.family_counts.iter().map(|&c| c as u64));
    out.extend([d.bands.features, d.bands.vertices, d.bands.bands].map(|c| c as u64));
    out.extend(d.bands.labels.iter().map(|&l| u64::from(l)));
    out
}

/// Options with every family the cache treats differently: spectral and extrinsic
/// (recomputed on a warm load), sdf (kept in the entry).
fn all_families() -> ShapePipelineOptions {
    let mut o = opts();
    o.set_families("spectral,extrinsic,sdf", "pca", 8, 3, "extrinsic=2,sdf=0.5")
        .unwrap();
    o
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

/// A warm load recomputes descriptors and bands from the stored `f32` spectrum: the result
/// must be the cold run's bit for bit, whatever the thread counts of the two runs, for every
/// family, and the compact bands entry must hold the same band table.
#[test]
fn a_warm_load_rebuilds_the_cold_data_bit_for_bit_whatever_the_threads() {
    use coseg::pipeline::{ShapeBands, load_or_compute_bands};
    let m = mesh();
    for o in [opts(), all_families()] {
        for (cold_threads, warm_threads) in [(1, 3), (3, 1), (2, 2)] {
            let dir = tempfile::tempdir().unwrap();
            let cold = pool(cold_threads).install(|| load_or_compute(&m, &o, dir.path()).unwrap());
            assert_eq!(cold.outcome, CacheOutcome::Miss);
            let warm = pool(warm_threads).install(|| load_or_compute(&m, &o, dir.path()).unwrap());
            assert_eq!(warm.outcome, CacheOutcome::Hit);
            assert!(
                bits(&cold.data) == bits(&warm.data),
                "{cold_threads} then {warm_threads} threads: warm data differ from cold"
            );
            assert_eq!(cold.data, warm.data);
            let uncached = compute_shape_data(&m, &o).unwrap();
            assert!(bits(&uncached) == bits(&cold.data), "no cache vs cache");
            let b =
                pool(warm_threads).install(|| load_or_compute_bands(&m, &o, dir.path()).unwrap());
            assert_eq!(b.data, ShapeBands::of(&cold.data));
        }
    }
}

/// The pipeline's eigenvectors are `f32` values (so the entry stores them without loss), and
/// are the solver's rounded to nearest.
#[test]
fn the_pipeline_rounds_the_eigenvectors_to_f32() {
    use coseg::spectral::laplace_beltrami_spectrum;
    let (m, o) = (mesh(), opts());
    let data = compute_shape_data(&m, &o).unwrap();
    let raw = laplace_beltrami_spectrum(&m, &o.spectrum).unwrap();
    assert_eq!(raw.eigenvalues, data.spectrum.eigenvalues);
    let mut changed = 0;
    for (&x, &r) in data.spectrum.eigenvectors.iter().zip(&raw.eigenvectors) {
        assert_eq!(x, f64::from(r as f32));
        changed += usize::from(x != r);
    }
    assert!(changed > raw.eigenvectors.len() / 2, "{changed}");
}

/// Bytes of the frame (magic, version, key, length, checksum).
const HEADER: usize = 84;

/// The full entry holds the `f32` eigenvectors, the `f64` eigenvalues and vertex areas, the
/// kept (sdf) columns, the deflated band table and a few bytes of lengths: no descriptors.
#[test]
fn the_full_entry_holds_the_f32_spectrum_the_kept_columns_and_the_deflated_bands() {
    let m = blob(4);
    let dir = tempfile::tempdir().unwrap();
    for o in [opts(), all_families()] {
        let r = load_or_compute(&m, &o, dir.path()).unwrap();
        let (d, k) = (m.vertex_count(), r.data.spectrum.len());
        let [_, sdf, user] = r.data.descriptors.family_counts;
        let names: usize = r.data.descriptors.extra_names
            [r.data.descriptors.extra_names.len() - sdf - user..]
            .iter()
            .map(|n| n.len() + 1)
            .sum();
        let floats = d * k * 4 + (d + k + 1) * 8 + (sdf + user) * d * 8;
        let size = std::fs::metadata(&r.path).unwrap().len() as usize;
        let rest = size - (HEADER + 32 + floats + names);
        // The band table: its deflated labels (less than a third of their d·N bytes on a
        // smooth shape) and their length, plus at most 9 bytes for each of 14 lengths and
        // counts.
        let labels = r.data.bands.labels.len();
        assert!(
            rest >= 8 && rest <= labels / 3 + 8 + 14 * 9,
            "{size} bytes: {floats} bytes of numbers, {rest} for {labels} band labels and lengths"
        );
    }
}

/// The bar of issue #19: a 10k-vertex shape with 200 eigenpairs and 300 features (the
/// defaults) takes at most 10 MB in the cache. The spectrum's size does not depend on the
/// values, so a synthetic one is measured; the band table, in both entries, deflates to less
/// than a quarter of its raw size (`the_bands_entry_is_compressed`, on a generated shape;
/// about a sixth on TOSCA shapes, docs/PERFORMANCE.md).
#[test]
fn a_10k_vertex_shape_takes_under_10_mb() {
    use coseg::features::FeatureColumns;
    use coseg::pipeline::StoredShape;
    let (d, k) = (10_008, 200);
    let stored = StoredShape {
        key: coseg::cache::ShapeKey([3; 32]),
        vertices: d,
        eigenvalues: (0..k).map(|i| i as f64 * 0.37).collect(),
        eigenvectors: (0..d * k).map(|i| (i as f32 * 0.618).sin()).collect(),
        vertex_areas: vec![1.0 / d as f64; d],
        original_area: 1.0,
        kept_columns: FeatureColumns {
            vertices: d,
            names: vec![],
            values: vec![],
        },
        kept_counts: [0, 0],
        bands: coseg::bands::BandTable {
            features: 0,
            vertices: d,
            bands: 20,
            labels: vec![],
        },
    };
    let bytes = coseg::cache::encode_entry(coseg::cache::EntryKind::Full, &stored.key, &stored);
    assert!(
        bytes.len() <= d * k * 4 + (d + k) * 8 + 200,
        "{}",
        bytes.len()
    );
    let labels = d * 300; // one byte per vertex and feature before compression
    let compact_entry = labels / 4 + d * 8 + 200;
    assert!(
        bytes.len() + labels / 4 + compact_entry <= 10_000_000,
        "{}",
        bytes.len()
    );
}

/// The compact entry's payload is deflated: on a smooth shape its band table compresses
/// more than 4:1, and it reads back exactly.
#[test]
fn the_bands_entry_is_compressed() {
    use coseg::cache::bands_path;
    use coseg::pipeline::{decode_bands_entry, load_or_compute_bands};
    let dir = tempfile::tempdir().unwrap();
    let m = blob(4);
    let o = opts();
    let r = load_or_compute_bands(&m, &o, dir.path()).unwrap();
    let key = shape_key(&m, &o);
    let bytes = std::fs::read(bands_path(dir.path(), &key)).unwrap();
    let labels = r.data.bands.labels.len();
    assert!(
        bytes.len() < HEADER + labels / 4 + 8 * m.vertex_count(),
        "{} bytes for {labels} labels",
        bytes.len()
    );
    assert_eq!(
        decode_bands_entry(&bytes, &key, m.vertex_count()).unwrap(),
        r.data
    );
}

/// Entries of another format version (such as the format-3 entries that stored `f64`
/// eigenvectors, descriptors and bands) read as stale and are recomputed and replaced, the
/// full and the compact kind alike.
#[test]
fn entries_of_another_format_version_are_stale_and_recomputed() {
    use coseg::cache::{FORMAT_VERSION, bands_path};
    use coseg::pipeline::load_or_compute_bands;
    assert_eq!(FORMAT_VERSION, 6);
    let dir = tempfile::tempdir().unwrap();
    let (m, o) = (mesh(), opts());
    let first = load_or_compute_bands(&m, &o, dir.path()).unwrap().data;
    let key = shape_key(&m, &o);
    let (full, compact) = (cache_path(dir.path(), &key), bands_path(dir.path(), &key));
    let good = [
        std::fs::read(&full).unwrap(),
        std::fs::read(&compact).unwrap(),
    ];
    for version in [3u32, 4, 5] {
        for (path, bytes) in [(&full, &good[0]), (&compact, &good[1])] {
            let mut old = bytes.clone();
            old[8..12].copy_from_slice(&version.to_le_bytes());
            std::fs::write(path, &old).unwrap();
        }
        let r = load_or_compute_bands(&m, &o, dir.path()).unwrap();
        let needle = format!("stale format version {version} (current {FORMAT_VERSION})");
        assert_eq!(
            r.outcome,
            CacheOutcome::Recomputed {
                reason: format!("{}: {needle}; recomputed", full.display())
            }
        );
        assert!(
            r.warnings
                .iter()
                .any(|w| w.contains(&needle) && w.contains("coseg-bands"))
        );
        assert_eq!(r.data, first);
        assert_eq!(std::fs::read(&full).unwrap(), good[0]);
        assert_eq!(std::fs::read(&compact).unwrap(), good[1]);
    }
}

/// A compressed payload whose stored length lies (beyond what deflate can reach, or not what
/// the stream inflates to), or whose stream is cut or has trailing bytes, is untrusted with
/// the reason, never a huge allocation or a panic.
#[test]
fn lying_or_broken_compressed_payloads_are_refused() {
    use coseg::cache::{EntryKind, decode_entry, encode_entry};
    use coseg::pipeline::ShapeBands;
    let key = coseg::cache::ShapeKey([9; 32]);
    let bands = coseg::bands::equal_count_bands(&[0.0, 1.0, 2.0, 3.0], 1, 4, 2).unwrap();
    let value = ShapeBands {
        key,
        bands,
        vertex_areas: vec![0.25; 4],
    };
    let good = encode_entry(EntryKind::Bands, &key, &value);
    let payload = &good[HEADER..];
    let decode = |p: &[u8]| {
        decode_entry::<ShapeBands>(
            &framed_as(b"COSEGBND", &key, p),
            EntryKind::Bands,
            &key,
            |_| Ok(()),
        )
    };
    assert_eq!(decode(payload).unwrap(), value);
    let with_len = |len: u64| {
        let mut p = len.to_le_bytes().to_vec();
        p.extend_from_slice(&payload[8..]);
        p
    };
    for (p, needle) in [
        (with_len(u64::MAX), "claims"),
        (with_len(1 << 40), "claims"),
        (with_len(3), "inflates to"),
        (
            with_len(u64::from_le_bytes(payload[..8].try_into().unwrap()) + 1),
            "inflates to",
        ),
        (payload[..payload.len() - 2].to_vec(), "inflate"),
        ([payload, &[0, 0]].concat(), "inflates to"),
        (payload[..5].to_vec(), "no length"),
    ] {
        let e = decode(&p).unwrap_err();
        assert!(e.contains(needle), "{needle}: {e}");
    }
}

fn framed_as(magic: &[u8; 8], key: &coseg::cache::ShapeKey, payload: &[u8]) -> Vec<u8> {
    let mut bytes = framed(key, payload);
    bytes[..8].copy_from_slice(magic);
    bytes
}
