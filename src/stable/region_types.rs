//! The options and results of Algorithms 2 and 3 ([`super::stable_regions`],
//! [`super::stable_pairs_fixed`], [`super::stable_pairs_auto`]), apart from the algorithms so
//! that the dispatcher and the algorithms do not import each other.

use super::{Init, StableError, Threshold};
use serde::{Deserialize, Serialize};

/// Which multi-pair algorithm to run; parsed from `fixed` or `auto` (`coseg pair --algorithm`).
///
/// ```
/// use coseg::stable::Algorithm;
/// assert_eq!("auto".parse::<Algorithm>().unwrap(), Algorithm::Auto);
/// assert!("fast".parse::<Algorithm>().unwrap_err().to_string().contains("`fixed` `auto`"));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Algorithm {
    /// Algorithm 2: fixed thresholds `P`, `Q` for every pair.
    Fixed,
    /// Algorithm 3: automatic `τ_t` search, then the area-matched pair.
    Auto,
}

/// What an [`Threshold::AreaFraction`] of Algorithm 2 is a fraction of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum AreaReference {
    /// The whole shape's area: every pair gets the same size (the paper's "10 % cutoff").
    Total,
    /// The area still remaining when the pair is extracted.
    Remaining,
}

/// How Algorithm 3 searches for the largest `t` with a non-empty pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum TSearch {
    /// `t = 0, δt, 2δt, …` until the pair is empty (the paper).
    Linear,
    /// `t = 0, δt, 2δt, 4δt, …` to the first empty step, then bisection: `O(log(t/δt))`
    /// Algorithm 1 runs, the same `t` as `Linear` when emptiness is monotone in `t`.
    Bisect,
}

/// Options of [`stable_regions`](super::stable_regions),
/// [`stable_pairs_fixed`](super::stable_pairs_fixed) and
/// [`stable_pairs_auto`](super::stable_pairs_auto).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct StableRegionsOptions {
    /// Algorithm 2 or 3 (default [`Algorithm::Fixed`]).
    pub algorithm: Algorithm,
    /// Number of pairs `K`, the last being the leftovers (default 10).
    pub pairs: usize,
    /// Algorithm 2's rule `P` on B (default `AreaFraction(0.1)`).
    pub p: Threshold,
    /// Algorithm 2's rule `Q` on A (default `AreaFraction(0.1)`).
    pub q: Threshold,
    /// Algorithm 2's area reference (default [`AreaReference::Total`]).
    pub area_reference: AreaReference,
    /// Algorithm 3's step `δt` (default 0.1).
    pub delta_t: f64,
    /// Algorithm 3's largest `t` tried (default 20).
    pub t_max: f64,
    /// Algorithm 3's search for `t` (default [`TSearch::Bisect`]).
    pub t_search: TSearch,
    /// Algorithm 3: start each `t` from the previous `t`'s region instead of the pair's initial
    /// indicator (default `true`; same fixed points in practice, fewer iterations).
    pub warm_start: bool,
    /// Initial indicators (default [`Init::Random`]: on TOSCA within-class pairs it matched or
    /// beat [`Init::Extreme`] — Algorithm 2 86.2 % vs 86.0 %; with Algorithm 3 the extreme
    /// start yields tiny regions covering ~3 % of the surface — see `examples/eval_tosca.rs`).
    pub init: Init,
    /// Seed of [`Init::Random`] (default 0).
    pub seed: u64,
    /// Algorithm 1's iteration cap (default 100).
    pub max_iterations: usize,
}

impl Default for StableRegionsOptions {
    fn default() -> Self {
        Self {
            algorithm: Algorithm::Fixed,
            pairs: 10,
            p: Threshold::AreaFraction(0.1),
            q: Threshold::AreaFraction(0.1),
            area_reference: AreaReference::Total,
            delta_t: 0.1,
            t_max: 20.0,
            t_search: TSearch::Bisect,
            warm_start: true,
            init: Init::Random,
            seed: 0,
            max_iterations: 100,
        }
    }
}

impl StableRegionsOptions {
    pub(crate) fn validate(&self) -> Result<(), StableError> {
        if self.pairs == 0 {
            return Err(StableError::BadOption("pairs must be at least 1".into()));
        }
        if self.max_iterations == 0 {
            return Err(StableError::BadOption(
                "max_iterations must be at least 1".into(),
            ));
        }
        if self.algorithm == Algorithm::Auto
            && !(self.delta_t.is_finite() && self.delta_t > 0.0 && self.t_max.is_finite())
        {
            return Err(StableError::BadOption(format!(
                "delta_t = {} must be positive and t_max = {} finite",
                self.delta_t, self.t_max
            )));
        }
        Ok(())
    }
}

/// One pair of corresponding regions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RegionPair {
    /// Vertices of A, ascending.
    pub region_a: Vec<u32>,
    /// Vertices of B, ascending.
    pub region_b: Vec<u32>,
    /// Area of the region on A over A's total area.
    pub area_fraction_a: f64,
    /// Area of the region on B over B's total area.
    pub area_fraction_b: f64,
    /// `Σ_{q ∈ Ω_B, p ∈ Ω_A} W_qp`.
    pub objective: f64,
    /// Algorithm 1 rounds of the final run (0 for the leftovers).
    pub iterations: usize,
    /// Whether the final Algorithm 1 run reached a fixed point (`true` for the leftovers).
    pub converged: bool,
    /// `true` for the last pair made of the leftovers.
    pub leftover: bool,
    /// Algorithm 3: the last `t` with a non-empty pair, and the `α` used.
    pub auto: Option<AutoThreshold>,
}

/// Algorithm 3's chosen thresholds for one pair.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AutoThreshold {
    /// The largest `t = i δt` whose `P[τ_t]`, `Q[τ_t]` pair was non-empty.
    pub t: f64,
    /// `α = max(α_A, α_B)`, fractions of the remaining areas.
    pub alpha: f64,
    /// Total Algorithm 1 rounds spent in the `t` search.
    pub search_iterations: usize,
}

/// The pairs of corresponding regions between A and B, in extraction order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StableRegions {
    /// `d_a`.
    pub vertices_a: usize,
    /// `d_b`.
    pub vertices_b: usize,
    /// The pairs; region `i` of A corresponds to region `i` of B.
    pub pairs: Vec<RegionPair>,
}

impl StableRegions {
    /// Region id of every vertex of A (`-1` when in no region, which only happens when the
    /// algorithm stopped early on the other shape).
    pub fn labels_a(&self) -> Vec<i32> {
        labels(self.vertices_a, self.pairs.iter().map(|p| &p.region_a))
    }

    /// Region id of every vertex of B (`-1` when in no region).
    pub fn labels_b(&self) -> Vec<i32> {
        labels(self.vertices_b, self.pairs.iter().map(|p| &p.region_b))
    }
}

fn labels<'r>(n: usize, regions: impl Iterator<Item = &'r Vec<u32>>) -> Vec<i32> {
    let mut out = vec![-1; n];
    for (i, r) in regions.enumerate() {
        for &v in r {
            out[v as usize] = i as i32;
        }
    }
    out
}
