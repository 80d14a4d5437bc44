//! [`stable_cycle`]: fixed points of `P_0 ∘ W_{0,m−1} ∘ … ∘ P_2 ∘ W_21 ∘ P_1 ∘ W_10` around a
//! cycle of `m ≥ 2` shapes (docs/METHOD.md §5), Algorithm 1 generalised.

use super::GraphError;
use crate::affinity::{AffinityWorkspace, BandAffinity, Direction};
use crate::stable::{Threshold, threshold};
use crate::vertex_sets::{intersect_sorted, selected_sum};
use serde::{Deserialize, Serialize};

/// One shape of a cycle: its remaining vertices, areas and the thresholding rule applied to the
/// scores it receives.
#[derive(Debug, Clone, Copy)]
pub struct CycleShape<'s> {
    /// Remaining vertices, strictly ascending.
    pub remaining: &'s [u32],
    /// Per-vertex areas of the whole shape (indexed by vertex).
    pub areas: &'s [f64],
    /// The area an [`Threshold::AreaFraction`] is a fraction of.
    pub reference_area: f64,
    /// `P_i`, applied to the scores transported into this shape.
    pub rule: Threshold,
}

/// One step of a cycle: the operator carrying an indicator from shape `i` to shape `i + 1`
/// (mod `m`). With `W = BandAffinity::new(A, B)`, `Direction::AtoB` carries A → B (`W x`) and
/// `Direction::BtoA` carries B → A (`Wᵀ y`).
#[derive(Debug, Clone, Copy)]
pub struct CycleStep<'w, 'a> {
    /// The band-table operator of the edge.
    pub affinity: &'w BandAffinity<'a>,
    /// Which way the step uses it.
    pub direction: Direction,
}

/// The fixed point found by [`stable_cycle`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StableCycle {
    /// One region per shape of the cycle (ascending vertex lists), in cycle order.
    pub regions: Vec<Vec<u32>>,
    /// Mass of the closing step: `Σ_{p ∈ Ω_0, q ∈ Ω_{m−1}} (W_{0,m−1})_{pq}` (for `m = 2`, the
    /// objective of Algorithm 1).
    pub objective: f64,
    /// Number of full rounds around the cycle.
    pub iterations: usize,
    /// `true` when the region on shape 0 stopped changing (a fixed point of the whole cycle).
    pub converged: bool,
    /// `true` when shape 0's region returned to an earlier value (a limit cycle); the visited
    /// tuple of highest objective is returned, with `converged = false`.
    pub cycled: bool,
    /// Mass of every step, in order: `m` entries per round (the last of each round is the
    /// closing mass). For `m = 2` this is exactly Algorithm 1's history.
    pub history: Vec<f64>,
}

/// Options of [`stable_cycle`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct StableCycleOptions {
    /// Round cap (default 100, as Algorithm 1's).
    pub max_iterations: usize,
}

impl Default for StableCycleOptions {
    fn default() -> Self {
        Self {
            max_iterations: 100,
        }
    }
}

fn ascending(v: &[u32]) -> bool {
    v.windows(2).all(|p| p[0] < p[1])
}

/// The stable-region fixed point around a cycle of `m = shapes.len() ≥ 2` shapes.
///
/// From `f_0 = 1_{f0 ∩ remaining_0}` on shape 0, one round computes
/// `f_{i+1} = P_{i+1}(W_{i+1,i} f_i)` for `i = 0 … m−1` (indices mod `m`, so the last step
/// returns to shape 0), every product restricted to the remaining subsets and every rule
/// applied on the remaining vertices of its shape. Rounds repeat until `f_0` stops changing.
/// Guards, as in Algorithm 1: `max_iterations`, and cycle detection (an earlier `f_0` seen again);
/// on either, the visited tuple whose closing mass is highest is returned with
/// `converged = false`.
///
/// For `m = 2` with steps `(W, AtoB)`, `(W, BtoA)` and rules `P` on B, `Q` on A, this is
/// Algorithm 1 operation for operation ([`crate::stable::stable_pair`]): the same products, the
/// same thresholds, the same guards, hence identical output.
///
/// `steps[i]` carries shape `i` to shape `(i + 1) % m`; its operator's source and destination
/// vertex counts must match the areas of those shapes.
///
/// ```
/// use coseg::affinity::{BandAffinity, Direction};
/// use coseg::bands::equal_count_bands;
/// use coseg::graph::{stable_cycle, CycleShape, CycleStep, StableCycleOptions};
/// use coseg::stable::Threshold;
/// let vals: Vec<f64> = (0..8).map(|v| v as f64).collect();
/// let a = equal_count_bands(&vals, 1, 8, 2).unwrap();
/// let w = BandAffinity::new(&a, &a).unwrap();
/// let all: Vec<u32> = (0..8).collect();
/// let areas = vec![1.0; 8];
/// let shape = CycleShape { remaining: &all, areas: &areas, reference_area: 8.0, rule: Threshold::Count(4) };
/// let step = CycleStep { affinity: &w, direction: Direction::AtoB };
/// // A 3-cycle of the same shape.
/// let c = stable_cycle(&[shape; 3], &[step; 3], &[7], &StableCycleOptions::default()).unwrap();
/// assert!(c.converged);
/// for r in &c.regions {
///     assert_eq!(r, &vec![4, 5, 6, 7]);
/// }
/// ```
pub fn stable_cycle(
    shapes: &[CycleShape<'_>],
    steps: &[CycleStep<'_, '_>],
    f0: &[u32],
    options: &StableCycleOptions,
) -> Result<StableCycle, GraphError> {
    let mut ws = AffinityWorkspace::default();
    stable_cycle_with(shapes, steps, f0, options, &mut ws)
}

/// [`stable_cycle`] with a reusable affinity workspace.
pub fn stable_cycle_with(
    shapes: &[CycleShape<'_>],
    steps: &[CycleStep<'_, '_>],
    f0: &[u32],
    options: &StableCycleOptions,
    ws: &mut AffinityWorkspace,
) -> Result<StableCycle, GraphError> {
    check_cycle(shapes, steps, f0)?;
    let m = shapes.len();
    let mut scores: Vec<Vec<f64>> = shapes
        .iter()
        .map(|s| vec![0.0; s.remaining.len()])
        .collect();
    let mut scratch = crate::stable::ThresholdScratch::default();
    // regions[i]: current f_i; regions[0] is the f_0 the round starts from.
    let mut regions: Vec<Vec<u32>> = vec![Vec::new(); m];
    intersect_sorted(f0, shapes[0].remaining, &mut regions[0]);
    let mut f_next: Vec<u32> = Vec::new();
    let mut history = Vec::new();
    let mut seen: Vec<Vec<u32>> = vec![regions[0].clone()];
    let mut best: Option<(f64, Vec<Vec<u32>>)> = None;
    let mut iterations = 0;
    let mut converged = false;
    let mut cycled = false;
    while iterations < options.max_iterations {
        iterations += 1;
        let mut closing = 0.0;
        for (i, step) in steps.iter().enumerate() {
            let j = (i + 1) % m;
            let dst = &shapes[j];
            step.affinity.transport_indicator(
                step.direction,
                &regions[i],
                Some(dst.remaining),
                &mut scores[j],
                ws,
            )?;
            let out = if j == 0 { &mut f_next } else { &mut regions[j] };
            threshold(
                dst.rule,
                dst.remaining,
                &scores[j],
                dst.areas,
                dst.reference_area,
                out,
                &mut scratch,
            );
            let mass = step.affinity.unit() * selected_sum(dst.remaining, &scores[j], out);
            history.push(mass);
            closing = mass;
        }
        if best.as_ref().is_none_or(|b| closing > b.0) {
            let mut tuple = regions.clone();
            tuple[0].clone_from(&f_next);
            best = Some((closing, tuple));
        }
        if f_next == regions[0] {
            converged = true;
            break;
        }
        if seen.contains(&f_next) {
            cycled = true;
            break;
        }
        seen.push(f_next.clone());
        std::mem::swap(&mut regions[0], &mut f_next);
    }
    let (objective, regions) = if converged {
        (*history.last().unwrap_or(&0.0), regions)
    } else {
        match best {
            Some(b) => b,
            None => (0.0, regions),
        }
    };
    Ok(StableCycle {
        regions,
        objective,
        iterations,
        converged,
        cycled,
        history,
    })
}

/// Rejects a cycle of fewer than 2 shapes, a step count other than the shape count, a step
/// whose operator does not match its two shapes' vertex counts, and unsorted or out-of-range
/// remaining sets or initial indicator.
fn check_cycle(
    shapes: &[CycleShape<'_>],
    steps: &[CycleStep<'_, '_>],
    f0: &[u32],
) -> Result<(), GraphError> {
    let m = shapes.len();
    if m < 2 {
        return Err(GraphError::BadOption(format!(
            "a cycle needs at least 2 shapes, got {m}"
        )));
    }
    if steps.len() != m {
        return Err(GraphError::BadOption(format!(
            "{m} shapes need {m} steps, got {}",
            steps.len()
        )));
    }
    for (i, step) in steps.iter().enumerate() {
        let (src, dst) = match step.direction {
            Direction::AtoB => (step.affinity.cols(), step.affinity.rows()),
            Direction::BtoA => (step.affinity.rows(), step.affinity.cols()),
        };
        let (s, d) = (&shapes[i], &shapes[(i + 1) % m]);
        if s.areas.len() != src || d.areas.len() != dst {
            return Err(GraphError::BadOption(format!(
                "step {i} maps {src} to {dst} vertices, but its shapes have {} and {}",
                s.areas.len(),
                d.areas.len()
            )));
        }
    }
    for (i, s) in shapes.iter().enumerate() {
        if !ascending(s.remaining) {
            return Err(GraphError::BadOption(format!(
                "remaining vertices of cycle shape {i} must be strictly ascending"
            )));
        }
        if s.remaining
            .last()
            .is_some_and(|&v| v as usize >= s.areas.len())
        {
            return Err(GraphError::BadOption(format!(
                "remaining vertices of cycle shape {i} exceed its vertex count"
            )));
        }
    }
    if !ascending(f0) {
        return Err(GraphError::BadOption(
            "initial indicator must be strictly ascending".into(),
        ));
    }
    Ok(())
}
