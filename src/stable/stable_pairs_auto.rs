//! [`stable_pairs_auto`]: Algorithm 3, stable pairs with automatic thresholds.

use super::extraction::{Extraction, extract_pairs};
use super::region_types::{AutoThreshold, StableRegions, StableRegionsOptions, TSearch};
use super::{StableError, StablePair, StablePairOptions, Threshold, initial_indicator};
use crate::affinity::BandAffinity;

/// Algorithm 3: for each of the first `K − 1` pairs, find the largest `t ∈ {0, δt, 2δt, …}`
/// (up to `t_max`) for which Algorithm 1 with `P[τ_t]`, `Q[τ_t]` returns a non-empty pair —
/// stepping up one `δt` at a time as the paper does ([`TSearch::Linear`]) or by galloping and
/// bisection from the previous pair's `t`, which assumes emptiness is monotone in `t`
/// ([`TSearch::Bisect`]); with the
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
/// let mut opts = StableRegionsOptions::default();
/// (opts.algorithm, opts.pairs) = (Algorithm::Auto, 4);
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
    let steps = (options.t_max / options.delta_t).floor().max(0.0) as usize;
    let mut prev_step = 0usize;
    extract_pairs(w, areas_a, areas_b, options, |ex, i| {
        let (rem_area_a, rem_area_b) = (ex.remaining_area_a(), ex.remaining_area_b());
        let f_in = initial_indicator(w, &ex.rem_a, options.init, options.seed, i);
        let mut search_iterations = 0;
        let mut start = f_in.clone();
        // Runs Algorithm 1 with P[τ_t], Q[τ_t] at step s; `None` when the pair is empty.
        let mut probe = |s: usize, start: &[u32], ex: &mut Extraction<'_>| {
            let t = s as f64 * options.delta_t;
            let opts = StablePairOptions {
                p: Threshold::MeanStd(t),
                q: Threshold::MeanStd(t),
                max_iterations: options.max_iterations,
            };
            let pair = ex.run(w, start, &opts, (rem_area_a, rem_area_b))?;
            search_iterations += pair.iterations;
            Ok::<_, StableError>(
                (!pair.region_a.is_empty() && !pair.region_b.is_empty()).then_some((t, pair)),
            )
        };
        let last = match options.t_search {
            TSearch::Linear => {
                let mut last = None;
                for s in 0..=steps {
                    let Some(found) = probe(s, &start, ex)? else {
                        break;
                    };
                    if options.warm_start {
                        start.clone_from(&found.1.region_a);
                    }
                    last = Some(found);
                }
                last
            }
            TSearch::Bisect => bisect_search(
                &mut probe,
                ex,
                &mut start,
                prev_step.min(steps),
                steps,
                options.warm_start,
            )?,
        };
        let Some((t, pt)) = last else {
            return Ok(None);
        };
        prev_step = (t / options.delta_t).round() as usize;
        let alpha =
            (ex.area_a(&pt.region_a) / rem_area_a).max(ex.area_b(&pt.region_b) / rem_area_b);
        let opts = StablePairOptions {
            p: Threshold::AreaFraction(alpha),
            q: Threshold::AreaFraction(alpha),
            max_iterations: options.max_iterations,
        };
        let pair = ex.run(w, &pt.region_a, &opts, (rem_area_a, rem_area_b))?;
        if pair.region_a.is_empty() || pair.region_b.is_empty() {
            return Ok(None);
        }
        let mut rp = ex.take(pair);
        rp.auto = Some(AutoThreshold {
            t,
            alpha,
            search_iterations,
        });
        Ok(Some(rp))
    })
}

/// The [`TSearch::Bisect`] search: brackets the last step whose `probe` gives a non-empty pair
/// by galloping from step `s0` (up while non-empty, down while empty), then bisects. Returns the
/// last non-empty `(t, pair)` found; with `warm_start`, each found pair's `Ω_A` becomes `start`.
fn bisect_search<'w, P>(
    probe: &mut P,
    ex: &mut Extraction<'w>,
    start: &mut Vec<u32>,
    s0: usize,
    steps: usize,
    warm_start: bool,
) -> Result<Option<(f64, StablePair)>, StableError>
where
    P: FnMut(usize, &[u32], &mut Extraction<'w>) -> Result<Option<(f64, StablePair)>, StableError>,
{
    let mut last = None;
    // Bracket the last non-empty step by galloping from the previous pair's step
    // (up while non-empty, down while empty), then bisect.
    let (mut lo, mut hi) = (None::<usize>, None::<usize>);
    let mut keep = |s: usize, found: (f64, StablePair), start: &mut Vec<u32>| {
        if warm_start {
            start.clone_from(&found.1.region_a);
        }
        last = Some(found);
        s
    };
    match probe(s0, start, ex)? {
        Some(found) => {
            lo = Some(keep(s0, found, start));
            let mut d = 1;
            while lo != Some(steps) {
                let s = (s0 + d).min(steps);
                match probe(s, start, ex)? {
                    Some(found) => lo = Some(keep(s, found, start)),
                    None => {
                        hi = Some(s);
                        break;
                    }
                }
                d *= 2;
            }
        }
        None => {
            hi = Some(s0);
            let mut d = 1;
            while hi != Some(0) {
                let s = s0.saturating_sub(d);
                match probe(s, start, ex)? {
                    Some(found) => {
                        lo = Some(keep(s, found, start));
                        break;
                    }
                    None => hi = Some(s),
                }
                d *= 2;
            }
        }
    }
    if let (Some(mut lo), Some(mut hi)) = (lo, hi) {
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            match probe(mid, start, ex)? {
                Some(found) => lo = keep(mid, found, start),
                None => hi = mid,
            }
        }
    }
    Ok(last)
}
