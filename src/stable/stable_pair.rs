//! [`stable_pair`]: Algorithm 1, a stable pair of regions from an initial indicator.

use super::{StableError, Threshold, ThresholdScratch, threshold};
use crate::affinity::{AffinityWorkspace, BandAffinity, Direction, IndicatorHistogram};
use crate::vertex_sets::{intersect_sorted, selected_sum};
use serde::{Deserialize, Serialize};

/// The remaining vertex subsets of both shapes and the per-vertex areas the rules use.
#[derive(Debug, Clone, Copy)]
pub struct Remaining<'s> {
    /// Remaining vertices of A, strictly ascending.
    pub vertices_a: &'s [u32],
    /// Remaining vertices of B, strictly ascending.
    pub vertices_b: &'s [u32],
    /// Per-vertex areas of A (length `d_a`).
    pub areas_a: &'s [f64],
    /// Per-vertex areas of B (length `d_b`).
    pub areas_b: &'s [f64],
    /// Area an [`Threshold::AreaFraction`] on A is a fraction of.
    pub reference_area_a: f64,
    /// Area an [`Threshold::AreaFraction`] on B is a fraction of.
    pub reference_area_b: f64,
}

/// Options of Algorithm 1.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct StablePairOptions {
    /// `P`: the rule on B applied to `W f`.
    pub p: Threshold,
    /// `Q`: the rule on A applied to `Wᵀ g`.
    pub q: Threshold,
    /// Iteration cap (default 100; the paper sees fewer than 10).
    pub max_iterations: usize,
}

impl Default for StablePairOptions {
    /// `P_α`, `Q_α` with `α = 0.1`, 100 iterations at most.
    fn default() -> Self {
        Self {
            p: Threshold::AreaFraction(0.1),
            q: Threshold::AreaFraction(0.1),
            max_iterations: 100,
        }
    }
}

/// A pair of regions found by Algorithm 1.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StablePair {
    /// `Ω_A`: vertices of A, ascending.
    pub region_a: Vec<u32>,
    /// `Ω_B`: vertices of B, ascending.
    pub region_b: Vec<u32>,
    /// `Σ_{q ∈ Ω_B, p ∈ Ω_A} W_qp`.
    pub objective: f64,
    /// Number of `f → g → f` rounds run.
    pub iterations: usize,
    /// `true` when `f` stopped changing (a fixed point); `false` when the cap was hit or a cycle
    /// was detected, in which case the visited pair of highest objective is returned.
    pub converged: bool,
    /// `true` when `f` returned to an earlier value (a cycle of length ≥ 2).
    pub cycled: bool,
    /// Objective after each half-step: `(f⁽ʲ⁾, g⁽ʲ⁺¹⁾)` then `(f⁽ʲ⁺¹⁾, g⁽ʲ⁺¹⁾)`, alternately
    /// (`j = 0, 1, …`). With `P_p`/`Q_q` it never decreases after the first entry (which pairs
    /// the initial `f⁽⁰⁾` of arbitrary size).
    pub history: Vec<f64>,
}

/// Reusable buffers for [`stable_pair_with`].
#[derive(Debug, Default)]
pub struct StableWorkspace {
    /// The affinity operator's buffers.
    pub affinity: AffinityWorkspace,
    scores_a: Vec<f64>,
    scores_b: Vec<f64>,
    scratch: ThresholdScratch,
    /// Incremental histograms of `f` (A → B) and `g` (B → A).
    hists: Option<(IndicatorHistogram, IndicatorHistogram)>,
}

/// Algorithm 1 with a fresh workspace. See [`stable_pair_with`].
///
/// ```
/// use coseg::affinity::BandAffinity;
/// use coseg::bands::equal_count_bands;
/// use coseg::stable::{stable_pair, Remaining, StablePairOptions, Threshold};
/// let vals: Vec<f64> = (0..8).map(|v| v as f64).collect();
/// let a = equal_count_bands(&vals, 1, 8, 2).unwrap();
/// let w = BandAffinity::new(&a, &a).unwrap();
/// let all: Vec<u32> = (0..8).collect();
/// let areas = vec![1.0; 8];
/// let rem = Remaining { vertices_a: &all, vertices_b: &all, areas_a: &areas, areas_b: &areas,
///     reference_area_a: 8.0, reference_area_b: 8.0 };
/// let mut opts = StablePairOptions::default();
/// (opts.p, opts.q, opts.max_iterations) = (Threshold::Count(4), Threshold::Count(4), 10);
/// let pair = stable_pair(&w, &rem, &[7], &opts).unwrap();
/// assert_eq!(pair.region_a, vec![4, 5, 6, 7]);
/// assert_eq!(pair.region_b, vec![4, 5, 6, 7]);
/// assert!(pair.converged);
/// ```
pub fn stable_pair(
    w: &BandAffinity<'_>,
    remaining: &Remaining<'_>,
    f0: &[u32],
    options: &StablePairOptions,
) -> Result<StablePair, StableError> {
    let mut ws = StableWorkspace::default();
    stable_pair_with(w, remaining, f0, options, &mut ws)
}

/// Algorithm 1 (stable pair): from `f⁽⁰⁾ = 1_{f0 ∩ remaining A}`, repeat
/// `g = P(W f)` on the remaining B, `f = Q(Wᵀ g)` on the remaining A, until `f` stops changing.
/// Guards: `max_iterations`, and cycle detection (an earlier `f` seen again). On either, the
/// visited pair of highest objective is returned with `converged = false`.
///
/// `f0` must be ascending. Products use `W` restricted to the remaining subsets.
pub fn stable_pair_with(
    w: &BandAffinity<'_>,
    remaining: &Remaining<'_>,
    f0: &[u32],
    options: &StablePairOptions,
    ws: &mut StableWorkspace,
) -> Result<StablePair, StableError> {
    ws.hists = None;
    stable_pair_inner(w, remaining, f0, options, ws)
}

/// [`stable_pair_with`] keeping the workspace's histograms from an earlier call, which must
/// have used the same operator `w` (Algorithms 2 and 3 hold one operator per extraction).
pub(crate) fn stable_pair_inner(
    w: &BandAffinity<'_>,
    remaining: &Remaining<'_>,
    f0: &[u32],
    options: &StablePairOptions,
    ws: &mut StableWorkspace,
) -> Result<StablePair, StableError> {
    let (ra, rb) = (remaining.vertices_a, remaining.vertices_b);
    if remaining.areas_a.len() != w.cols() || remaining.areas_b.len() != w.rows() {
        return Err(StableError::AreaLength {
            expected_a: w.cols(),
            expected_b: w.rows(),
            got_a: remaining.areas_a.len(),
            got_b: remaining.areas_b.len(),
        });
    }
    if !ra.windows(2).all(|p| p[0] < p[1]) || !rb.windows(2).all(|p| p[0] < p[1]) {
        return Err(StableError::NotAscending("remaining vertices"));
    }
    if !f0.windows(2).all(|p| p[0] < p[1]) {
        return Err(StableError::NotAscending("initial indicator"));
    }
    let unit = w.unit();
    ws.scores_a.resize(ra.len(), 0.0);
    ws.scores_b.resize(rb.len(), 0.0);
    let mut f = Vec::new();
    intersect_sorted(f0, ra, &mut f);
    let mut g = Vec::new();
    let mut f_next = Vec::new();
    let mut history = Vec::new();
    let mut seen: Vec<Vec<u32>> = vec![f.clone()];
    let mut best: Option<(f64, Vec<u32>, Vec<u32>)> = None;
    let mut iterations = 0;
    let mut converged = false;
    let mut cycled = false;
    while iterations < options.max_iterations {
        iterations += 1;
        let (hf, _) = ws
            .hists
            .get_or_insert_with(|| (w.histogram(Direction::AtoB), w.histogram(Direction::BtoA)));
        w.update_histogram(hf, &f, &mut ws.affinity)?;
        w.transport_histogram(hf, Some(rb), &mut ws.scores_b, &mut ws.affinity)?;
        threshold(
            options.p,
            rb,
            &ws.scores_b,
            remaining.areas_b,
            remaining.reference_area_b,
            &mut g,
            &mut ws.scratch,
        );
        history.push(unit * selected_sum(rb, &ws.scores_b, &g));
        let (_, hg) = ws.hists.as_mut().expect("set above");
        w.update_histogram(hg, &g, &mut ws.affinity)?;
        w.transport_histogram(hg, Some(ra), &mut ws.scores_a, &mut ws.affinity)?;
        threshold(
            options.q,
            ra,
            &ws.scores_a,
            remaining.areas_a,
            remaining.reference_area_a,
            &mut f_next,
            &mut ws.scratch,
        );
        let obj = unit * selected_sum(ra, &ws.scores_a, &f_next);
        history.push(obj);
        if best.as_ref().is_none_or(|b| obj > b.0) {
            best = Some((obj, f_next.clone(), g.clone()));
        }
        if f_next == f {
            converged = true;
            f.clone_from(&f_next);
            break;
        }
        if seen.contains(&f_next) {
            cycled = true;
            break;
        }
        seen.push(f_next.clone());
        std::mem::swap(&mut f, &mut f_next);
    }
    let (objective, region_a, region_b) = if converged {
        (*history.last().unwrap_or(&0.0), f, g)
    } else {
        best.unwrap_or((0.0, f, g))
    };
    Ok(StablePair {
        region_a,
        region_b,
        objective,
        iterations,
        converged,
        cycled,
        history,
    })
}
