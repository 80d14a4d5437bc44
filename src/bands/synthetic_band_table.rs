//! `synthetic_band_table()`: the band table of seeded smooth pseudo-features, for benchmarks.

use super::{BandError, BandTable, equal_count_bands};
use crate::generate::SmoothFeatures;

/// The equal-count band table of [`crate::generate::smooth_features`] (the same labels as
/// `equal_count_bands(&smooth_features(vertices, features, seed), features, vertices, bands)`):
/// a `features × vertices` table with `bands` bands, as the per-shape pipeline would make from
/// descriptors, without any spectrum. Features are made and banded one at a time, so beyond the
/// table only one feature's values are held (the scaling study measures the operator's memory,
/// not this). Used by `benches/core.rs` and `examples/scaling_study.rs`.
///
/// ```
/// use coseg::bands::{equal_count_bands, synthetic_band_table};
/// use coseg::generate::smooth_features;
/// let t = synthetic_band_table(1000, 10, 20, 1).unwrap();
/// assert_eq!((t.features, t.vertices), (10, 1000));
/// let all_at_once = equal_count_bands(&smooth_features(1000, 10, 1), 10, 1000, 20).unwrap();
/// assert_eq!(t, all_at_once);
/// ```
pub fn synthetic_band_table(
    vertices: usize,
    features: usize,
    bands: usize,
    seed: u64,
) -> Result<BandTable, BandError> {
    let mut labels = vec![0u8; vertices * features];
    let mut table = None;
    for (k, column) in SmoothFeatures::new(vertices, features, seed).enumerate() {
        let one = equal_count_bands(&column, 1, vertices, bands)?;
        for (v, &l) in one.labels.iter().enumerate() {
            labels[v * features + k] = l;
        }
        table = Some(one);
    }
    match table {
        Some(one) => Ok(BandTable {
            features,
            labels,
            ..one
        }),
        // No features: whatever `equal_count_bands` says of an empty table.
        None => equal_count_bands(&[], 0, vertices, bands),
    }
}
