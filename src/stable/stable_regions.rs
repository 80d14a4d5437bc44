//! [`stable_regions`]: the one-call entry point (Algorithm 2 or 3 on two band tables); its
//! options and result are in `region_types`. [`pair_affinity`]: the operator it (and
//! [`segment_pair`](super::segment_pair)) runs on, with optional per-feature weights.

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
    let w = pair_affinity(a, b, None)?;
    stable_regions_with(&w, areas_a, areas_b, options)
}

/// Algorithm 2 or 3, as `options` says, on an affinity already built (for example a weighted
/// one from [`pair_affinity`]); [`stable_regions`] is this on the equal-weight operator.
pub fn stable_regions_with(
    w: &BandAffinity<'_>,
    areas_a: &[f64],
    areas_b: &[f64],
    options: &StableRegionsOptions,
) -> Result<StableRegions, StableError> {
    match options.algorithm {
        Algorithm::Fixed => stable_pairs_fixed(w, areas_a, areas_b, options),
        Algorithm::Auto => stable_pairs_auto(w, areas_a, areas_b, options),
    }
}

/// The affinity between two shapes' band tables as the pair stage uses it: feature `k` of A
/// with feature `k` of B, weighted by `weights[k]` (one per feature, e.g. the families' shares
/// from [`ShapePipelineOptions::feature_weights`](crate::pipeline::ShapePipelineOptions::feature_weights),
/// the same weights `coseg segment` and `coseg propagate` use); `None` = equal weights, the
/// operator's exact integer path. The two tables must have the same feature count.
///
/// ```
/// use coseg::bands::equal_count_bands;
/// use coseg::stable::pair_affinity;
/// let vals: Vec<f64> = (0..8).map(|v| v as f64).collect();
/// let a = equal_count_bands(&vals, 2, 4, 2).unwrap(); // 2 features, 4 vertices, K = 2
/// let w = pair_affinity(&a, &a, Some(&[3.0, 1.0])).unwrap();
/// assert_eq!(w.weights(), vec![0.75, 0.25]);
/// assert_eq!(pair_affinity(&a, &a, None).unwrap().weights(), vec![0.5, 0.5]);
/// ```
pub fn pair_affinity<'a>(
    a: &'a BandTable,
    b: &'a BandTable,
    weights: Option<&[f64]>,
) -> Result<BandAffinity<'a>, StableError> {
    if a.features != b.features {
        return Err(StableError::BadOption(format!(
            "feature counts differ ({} vs {}): pass an explicit FeaturePairing",
            a.features, b.features
        )));
    }
    let pairing = match weights {
        None => FeaturePairing::identity(a.features),
        Some(w) => FeaturePairing::new(
            FeaturePairing::identity(a.features).pairs().to_vec(),
            Some(w.to_vec()),
        ),
    };
    Ok(BandAffinity::with_pairing(a, b, &pairing)?)
}
