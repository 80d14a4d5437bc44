//! [`stable_pairs_auto`]: Algorithm 3, stable pairs with automatic thresholds.

use super::stable_pairs_fixed::Extraction;
use super::stable_regions::{AutoThreshold, StableRegions, StableRegionsOptions};
use super::{StableError, StablePairOptions, Threshold, initial_indicator};
use crate::affinity::BandAffinity;

/// Algorithm 3: for each of the first `K − 1` pairs, raise `t = 0, δt, 2δt, …` while
/// Algorithm 1 with `P[τ_t]`, `Q[τ_t]` still returns a non-empty pair (up to `t_max`); with the
/// last non-empty pair `(Ω^t_A, Ω^t_B)` set `α = max(α_A, α_B)` (fractions of the remaining
/// areas) and run Algorithm 1 with `P_α`, `Q_α` from `1_{Ω^t_A}`; remove the pair. The
/// leftovers form the last pair. Stops early when even `t = 0` gives an empty pair.
///
/// ```
/// use coseg::affinity::BandAffinity;
/// use coseg::bands::equal_count_bands;
/// use coseg::stable::{stable_pairs_auto, Algorithm, StableRegionsOptions};
/// let vals: Vec<f64> = (0..60).map(|v| ((v * 13) % 60) as f64).collect();
/// let a = equal_count_bands(&vals, 1, 60, 6).unwrap();
/// let w = BandAffinity::new(&a, &a).unwrap();
/// let areas = vec![1.0; 60];
/// let opts = StableRegionsOptions { algorithm: Algorithm::Auto, pairs: 4, ..Default::default() };
/// let r = stable_pairs_auto(&w, &areas, &areas, &opts).unwrap();
/// assert!(r.pairs.len() >= 2);
/// assert!(r.pairs[0].auto.is_some());
/// ```
pub fn stable_pairs_auto(
    w: &BandAffinity<'_>,
    areas_a: &[f64],
    areas_b: &[f64],
    options: &StableRegionsOptions,
) -> Result<StableRegions, StableError> {
    options.validate()?;
    let mut ex = Extraction::new(w, areas_a, areas_b)?;
    let mut pairs = Vec::with_capacity(options.pairs);
    let steps = (options.t_max / options.delta_t).floor().max(0.0) as usize;
    for i in 0..options.pairs - 1 {
        if ex.rem_a.is_empty() || ex.rem_b.is_empty() {
            break;
        }
        let (rem_area_a, rem_area_b) = (ex.remaining_area_a(), ex.remaining_area_b());
        let f_in = initial_indicator(w, &ex.rem_a, options.init, options.seed, i);
        let mut start = f_in.clone();
        let mut last = None;
        let mut search_iterations = 0;
        for s in 0..=steps {
            let t = s as f64 * options.delta_t;
            let opts = StablePairOptions {
                p: Threshold::MeanStd(t),
                q: Threshold::MeanStd(t),
                max_iterations: options.max_iterations,
            };
            let pair = ex.run(w, &start, &opts, (rem_area_a, rem_area_b))?;
            search_iterations += pair.iterations;
            if pair.region_a.is_empty() || pair.region_b.is_empty() {
                break;
            }
            if options.warm_start {
                start.clone_from(&pair.region_a);
            }
            last = Some((t, pair));
        }
        let Some((t, pt)) = last else { break };
        let alpha =
            (ex.area_a(&pt.region_a) / rem_area_a).max(ex.area_b(&pt.region_b) / rem_area_b);
        let opts = StablePairOptions {
            p: Threshold::AreaFraction(alpha),
            q: Threshold::AreaFraction(alpha),
            max_iterations: options.max_iterations,
        };
        let pair = ex.run(w, &pt.region_a, &opts, (rem_area_a, rem_area_b))?;
        if pair.region_a.is_empty() || pair.region_b.is_empty() {
            break;
        }
        let mut rp = ex.take(pair);
        rp.auto = Some(AutoThreshold {
            t,
            alpha,
            search_iterations,
        });
        pairs.push(rp);
    }
    if !ex.rem_a.is_empty() || !ex.rem_b.is_empty() {
        pairs.push(ex.leftovers(w)?);
    }
    Ok(StableRegions {
        vertices_a: w.cols(),
        vertices_b: w.rows(),
        pairs,
    })
}
