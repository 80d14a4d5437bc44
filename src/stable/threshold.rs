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
/// ```
/// use coseg::stable::{threshold, Threshold};
/// let (mut out, mut scratch) = (Vec::new(), Vec::new());
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
    scratch: &mut Vec<u32>,
) {
    debug_assert_eq!(vertices.len(), scores.len());
    out.clear();
    let n = vertices.len();
    if n == 0 {
        return;
    }
    // Order: higher score first, then lower position (= lower vertex index).
    let cmp = |a: &u32, b: &u32| {
        scores[*b as usize]
            .total_cmp(&scores[*a as usize])
            .then(a.cmp(b))
    };
    match rule {
        Threshold::Count(p) => {
            if p >= n {
                out.extend_from_slice(vertices);
                return;
            }
            if p == 0 {
                return;
            }
            scratch.clear();
            scratch.extend(0..n as u32);
            scratch.select_nth_unstable_by(p - 1, cmp);
            out.extend(scratch[..p].iter().map(|&i| vertices[i as usize]));
            out.sort_unstable();
        }
        Threshold::AreaFraction(alpha) => {
            let target = alpha * reference_area;
            if target.is_nan() || target <= 0.0 {
                return;
            }
            scratch.clear();
            scratch.extend(0..n as u32);
            scratch.sort_unstable_by(cmp);
            let mut acc = 0.0;
            for &i in scratch.iter() {
                let v = vertices[i as usize];
                out.push(v);
                acc += areas[v as usize];
                if acc >= target {
                    break;
                }
            }
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
