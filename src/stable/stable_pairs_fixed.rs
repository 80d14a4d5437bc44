//! [`stable_pairs_fixed`]: Algorithm 2, several stable pairs with fixed thresholds.

use super::extraction::extract_pairs;
use super::region_types::{AreaReference, StableRegions, StableRegionsOptions};
use super::{StableError, StablePairOptions, initial_indicator};
use crate::affinity::BandAffinity;

/// Algorithm 2: `K − 1` stable pairs with the fixed rules `options.p` (on B) and `options.q`
/// (on A), each found by Algorithm 1 on what the previous pairs left and removed; the leftovers
/// form the last pair. Stops early (leftovers last) when a shape runs out of vertices.
///
/// `areas_a`, `areas_b`: per-vertex areas of A (`d_a`) and B (`d_b`).
///
/// ```
/// use coseg::affinity::BandAffinity;
/// use coseg::bands::equal_count_bands;
/// use coseg::stable::{stable_pairs_fixed, StableRegionsOptions};
/// let vals: Vec<f64> = (0..30).map(|v| v as f64).collect();
/// let a = equal_count_bands(&vals, 1, 30, 3).unwrap();
/// let w = BandAffinity::new(&a, &a).unwrap();
/// let areas = vec![1.0; 30];
/// let mut opts = StableRegionsOptions::default();
/// opts.pairs = 3;
/// let r = stable_pairs_fixed(&w, &areas, &areas, &opts).unwrap();
/// assert_eq!(r.pairs.len(), 3);
/// assert_eq!(r.pairs[0].region_a, r.pairs[0].region_b);
/// ```
pub fn stable_pairs_fixed(
    w: &BandAffinity<'_>,
    areas_a: &[f64],
    areas_b: &[f64],
    options: &StableRegionsOptions,
) -> Result<StableRegions, StableError> {
    let opts = StablePairOptions {
        p: options.p,
        q: options.q,
        max_iterations: options.max_iterations,
    };
    extract_pairs(w, areas_a, areas_b, options, |ex, i| {
        let reference = match options.area_reference {
            AreaReference::Total => (ex.total_a, ex.total_b),
            AreaReference::Remaining => (ex.remaining_area_a(), ex.remaining_area_b()),
        };
        let f0 = initial_indicator(w, &ex.rem_a, options.init, options.seed, i);
        let pair = ex.run(w, &f0, &opts, reference)?;
        if pair.region_a.is_empty() || pair.region_b.is_empty() {
            return Ok(None);
        }
        Ok(Some(ex.take(pair)))
    })
}
