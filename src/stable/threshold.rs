//! [`threshold`]: the thresholding functions `P_p`, `P_α`, `P[τ_t]` on a remaining subset.

use serde::{Deserialize, Serialize};

/// A thresholding function: maps scores on the remaining vertices to a 0/1 indicator. A
/// higher score is never dropped while a lower one is kept; equal scores are ordered by vertex
/// index (lower index first), so every rule is deterministic.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Threshold {
    /// `P_p`: exactly the `p` best vertices (all of them when fewer remain).
    Count(usize),
    /// `P_α`: the best vertices, in order, until their area first reaches `α` times the
    /// reference area (all remaining vertices when their area is smaller). `α ≤ 0` selects none.
    AreaFraction(f64),
    /// `P[τ_t]`: every vertex with score `≥ μ + t σ` (mean and population standard deviation
    /// over the remaining vertices). When all scores are equal (`σ = 0`), all are selected for
    /// `t ≤ 0` and none for `t > 0`.
    MeanStd(f64),
}

/// Applies `rule` to `scores` on the remaining `vertices` and writes the selected vertex
/// indices, ascending, into `out`.
///
/// - `vertices`: remaining vertex indices, strictly ascending.
/// - `scores[i]`: score of `vertices[i]` (same length).
/// - `areas`: per-vertex areas of the whole shape (indexed by vertex), used by `AreaFraction`.
/// - `reference_area`: the area `α` is a fraction of (the remaining area, or the shape's total).
/// - `scratch`: reused buffer.
///
/// Cost: `O(n)` for `Count` and `MeanStd`, `O(n + m log m)` for `AreaFraction` selecting `m`.
///
/// ```
/// use coseg::stable::{threshold, Threshold, ThresholdScratch};
/// let (mut out, mut scratch) = (Vec::new(), ThresholdScratch::default());
/// let v = [0, 2, 5, 7];
/// let s = [1.0, 3.0, 3.0, 2.0];
/// threshold(Threshold::Count(2), &v, &s, &[1.0; 8], 4.0, &mut out, &mut scratch);
/// assert_eq!(out, vec![2, 5]);
/// threshold(Threshold::AreaFraction(0.6), &v, &s, &[1.0; 8], 4.0, &mut out, &mut scratch);
/// assert_eq!(out, vec![2, 5, 7]);
/// ```
pub fn threshold(
    rule: Threshold,
    vertices: &[u32],
    scores: &[f64],
    areas: &[f64],
    reference_area: f64,
    out: &mut Vec<u32>,
    scratch: &mut ThresholdScratch,
) {
    debug_assert_eq!(vertices.len(), scores.len());
    out.clear();
    let n = vertices.len();
    if n == 0 {
        return;
    }
    let keys = &mut scratch.keys;
    match rule {
        Threshold::Count(p) => {
            if p >= n {
                out.extend_from_slice(vertices);
                return;
            }
            if p == 0 {
                return;
            }
            fill_keys(keys, scores);
            keys.select_nth_unstable(p - 1);
            out.extend(keys[..p].iter().map(|&k| vertices[(k as u32) as usize]));
            out.sort_unstable();
        }
        Threshold::AreaFraction(alpha) => {
            let target = alpha * reference_area;
            if target.is_nan() || target <= 0.0 {
                return;
            }
            fill_keys(keys, scores);
            // Most calls need a small prefix: select a generous candidate set first, sort only
            // it, and fall back to a full sort when its area does not reach the target.
            let total: f64 = vertices.iter().map(|&v| areas[v as usize]).sum();
            let guess = ((target / total.max(f64::MIN_POSITIVE)) * n as f64 * 1.5) as usize + 64;
            let mut prefix = n;
            if guess < n {
                keys.select_nth_unstable(guess - 1);
                keys[..guess].sort_unstable();
                let mut acc = 0.0;
                if let Some(pos) = keys[..guess].iter().position(|&k| {
                    acc += areas[vertices[(k as u32) as usize] as usize];
                    acc >= target
                }) {
                    prefix = pos + 1;
                } else {
                    keys.sort_unstable();
                }
            } else {
                keys.sort_unstable();
            }
            if prefix == n {
                let mut acc = 0.0;
                prefix = keys
                    .iter()
                    .position(|&k| {
                        acc += areas[vertices[(k as u32) as usize] as usize];
                        acc >= target
                    })
                    .map_or(n, |p| p + 1);
            }
            out.extend(
                keys[..prefix]
                    .iter()
                    .map(|&k| vertices[(k as u32) as usize]),
            );
            out.sort_unstable();
        }
        Threshold::MeanStd(t) => {
            let mean = scores.iter().sum::<f64>() / n as f64;
            let var = scores.iter().map(|s| (s - mean) * (s - mean)).sum::<f64>() / n as f64;
            let (lo, hi) = scores
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &s| {
                    (l.min(s), h.max(s))
                });
            if lo == hi {
                if t <= 0.0 {
                    out.extend_from_slice(vertices);
                }
                return;
            }
            let tau = mean + t * var.sqrt();
            out.extend(
                vertices
                    .iter()
                    .zip(scores)
                    .filter(|(_, s)| **s >= tau)
                    .map(|(v, _)| *v),
            );
        }
    }
}

/// Reusable buffer of [`threshold`].
#[derive(Debug, Clone, Default)]
pub struct ThresholdScratch {
    keys: Vec<u128>,
}

/// Sort keys: ascending key order = descending score, then ascending position (the position is
/// the low 32 bits).
fn fill_keys(keys: &mut Vec<u128>, scores: &[f64]) {
    keys.clear();
    keys.extend(scores.iter().enumerate().map(|(i, &s)| {
        let b = s.to_bits();
        // Monotone map of the f64 total order onto u64.
        let ord = if b >> 63 == 1 { !b } else { b | (1 << 63) };
        ((!ord as u128) << 64) | i as u128
    }));
}
