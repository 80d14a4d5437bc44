//! Cache entries whose payload is arbitrary: the header is framed correctly (magic, version,
//! key, length, BLAKE3 checksum, the layout documented in `coseg::cache`) around the fuzzed
//! bytes, so the fuzzer reaches the payload decoder and the consistency checks instead of
//! stopping at the checksum. The first payload bytes decode as the entry's key, so they are
//! also taken as the expected key. Byte 0 picks the entry kind (full or compact) and the
//! expected vertex count. Whatever decodes must be fully consistent and finite
//! (`coseg::pipeline::decode_shape_entry`, `decode_bands_entry`).
#![no_main]

use coseg::cache::{FORMAT_VERSION, ShapeKey};
use coseg::pipeline::{decode_bands_entry, decode_shape_entry};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let [pick, payload @ ..] = data else {
        return;
    };
    let mut key = [0u8; 32];
    let n = payload.len().min(32);
    key[..n].copy_from_slice(&payload[..n]);
    let key = ShapeKey(key);
    let magic: &[u8; 8] = if pick & 1 == 0 {
        b"COSEGSHP"
    } else {
        b"COSEGBND"
    };
    let mut bytes = Vec::with_capacity(84 + payload.len());
    bytes.extend_from_slice(magic);
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&key.0);
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(blake3::hash(payload).as_bytes());
    bytes.extend_from_slice(payload);
    let vertices = (pick >> 1) as usize;
    if pick & 1 == 0 {
        if let Ok(d) = decode_shape_entry(&bytes, &key, vertices) {
            assert_eq!(d.vertices, vertices);
            assert_eq!(d.eigenvectors.len(), vertices * d.eigenvalues.len());
            assert!(d.eigenvectors.iter().all(|x| x.is_finite()));
            assert!(d.kept_columns.values.iter().all(|x| x.is_finite()));
        }
    } else if let Ok(b) = decode_bands_entry(&bytes, &key, vertices) {
        assert_eq!(b.vertex_areas.len(), vertices);
        assert!(b.vertex_areas.iter().all(|x| x.is_finite()));
    }
});
