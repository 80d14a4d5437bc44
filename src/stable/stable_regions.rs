//! [`stable_regions`]: the one-call entry point (Algorithm 2 or 3 on two band tables); its
//! options and result are in `region_types`.

use super::region_types::{Algorithm, StableRegions, StableRegionsOptions};
use super::{StableError, stable_pairs_auto, stable_pairs_fixed};
use crate::affinity::{BandAffinity, FeaturePairing};
use crate::bands::BandTable;

/// One call for the common case: builds the affinity between two band tables (identity
/// pairing, equal weights) and runs Algorithm 2 or 3 as `options` says.
///
/// `areas_a`, `areas_b`: per-vertex areas (length `d_a`, `d_b`; any positive unit).
///
/// ```
/// use coseg::bands::equal_count_bands;
/// use coseg::stable::{stable_regions, StableRegionsOptions};
/// let vals: Vec<f64> = (0..40).map(|v| ((v * 7) % 40) as f64).collect();
/// let a = equal_count_bands(&vals, 1, 40, 4).unwrap();
/// let areas = vec![1.0; 40];
/// let r = stable_regions(&a, &a, &areas, &areas, &StableRegionsOptions::default()).unwrap();
/// assert_eq!(r.pairs.len(), 10);
/// assert!(r.labels_a().iter().all(|&l| l >= 0));
/// ```
pub fn stable_regions(
    a: &BandTable,
    b: &BandTable,
    areas_a: &[f64],
    areas_b: &[f64],
    options: &StableRegionsOptions,
) -> Result<StableRegions, StableError> {
    if a.features != b.features {
        return Err(StableError::BadOption(format!(
            "feature counts differ ({} vs {}): pass an explicit FeaturePairing",
            a.features, b.features
        )));
    }
    let w = BandAffinity::with_pairing(a, b, &FeaturePairing::identity(a.features))?;
    match options.algorithm {
        Algorithm::Fixed => stable_pairs_fixed(&w, areas_a, areas_b, options),
        Algorithm::Auto => stable_pairs_auto(&w, areas_a, areas_b, options),
    }
}
