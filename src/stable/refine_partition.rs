//! [`refine_partition`]: sharpen the boundaries of corresponding partitions of two shapes by
//! alternating smoothed best-response assignments, and its building blocks
//! [`region_scores`] and [`assign_regions`] (shared with the collection solver).

use super::StableError;
use crate::affinity::{AffinityWorkspace, BandAffinity, Direction};
use crate::option_range::non_negative;
use crate::spectral::HeatSmoother;
use serde::{Deserialize, Serialize};

/// Options of [`refine_partition`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct RefineOptions {
    /// Largest number of rounds (one round = B from A, then A from B); default 10. The
    /// refinement stops earlier when a round changes no label.
    pub max_rounds: usize,
    /// Heat-smoothing time of the region scores (unit-area surface, see [`HeatSmoother`]);
    /// default `3e-3` (best of `3e-4…3e-2` on TOSCA), roughly 5 % of a shape's size. `0` disables smoothing.
    pub smoothing_time: f64,
}

impl Default for RefineOptions {
    fn default() -> Self {
        RefineOptions {
            max_rounds: 10,
            smoothing_time: 3e-3,
        }
    }
}

impl RefineOptions {
    /// `max_rounds` rounds at `smoothing_time`, or `None` (no refinement) for 0 rounds: a
    /// stage's refinement as `--refine-rounds` and `--smoothing-time` (and Python's
    /// `refine_rounds`, `smoothing_time`) set it.
    ///
    /// ```
    /// use coseg::stable::RefineOptions;
    /// assert_eq!(RefineOptions::rounds(0, 3e-3), None);
    /// assert_eq!(RefineOptions::rounds(4, 0.0).unwrap().max_rounds, 4);
    /// ```
    pub fn rounds(max_rounds: usize, smoothing_time: f64) -> Option<Self> {
        (max_rounds > 0).then_some(Self {
            max_rounds,
            smoothing_time,
        })
    }

    /// The rounds and smoothing time of `refine` (0 rounds for `None`), the inverse of
    /// [`Self::rounds`]: what a command's flags show as their defaults.
    pub fn rounds_of(refine: Option<&Self>) -> (usize, f64) {
        match refine {
            Some(r) => (r.max_rounds, r.smoothing_time),
            None => (0, Self::default().smoothing_time),
        }
    }

    pub(crate) fn validate(&self) -> Result<(), StableError> {
        non_negative("smoothing_time", self.smoothing_time).map_err(StableError::BadOption)?;
        Ok(())
    }
}

/// Result of [`refine_partition`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RefinedPartition {
    /// Region id of every vertex of A (`0..regions`).
    pub labels_a: Vec<i32>,
    /// Region id of every vertex of B.
    pub labels_b: Vec<i32>,
    /// Per vertex of A: best score minus second-best score over the best score (`0..=1`; `0`
    /// on a tie, `1` when only one region receives the vertex at all).
    pub margin_a: Vec<f64>,
    /// The same on B.
    pub margin_b: Vec<f64>,
    /// Rounds run.
    pub rounds: usize,
    /// Whether the last round changed no label (a fixed point of both assignments).
    pub converged: bool,
}

/// Mean affinity of every destination vertex to every region of the source shape:
/// `scores[r · d_dst + q] = (R 1_{S_r})_q / |S_r|`, column-major `d_dst × regions`, where
/// `S_r = {p : source_labels[p] = r}` and `R = W / unit` is the raw (integer-count) operator
/// of [`BandAffinity::transport_indicator`] in direction `dir`. Empty regions score 0;
/// vertices labelled `-1` (or `≥ regions`) belong to no region.
///
/// ```
/// use coseg::affinity::{BandAffinity, Direction};
/// use coseg::bands::equal_count_bands;
/// use coseg::stable::region_scores;
/// let t = equal_count_bands(&[0.0, 1.0, 2.0, 3.0], 1, 4, 2).unwrap();
/// let w = BandAffinity::new(&t, &t).unwrap();
/// let s = region_scores(&w, Direction::AtoB, &[0, 0, 1, 1], 2, &mut w.workspace()).unwrap();
/// assert_eq!(s, vec![1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0]);
/// ```
pub fn region_scores(
    w: &BandAffinity<'_>,
    dir: Direction,
    source_labels: &[i32],
    regions: usize,
    ws: &mut AffinityWorkspace,
) -> Result<Vec<f64>, StableError> {
    let (d_src, d_dst) = match dir {
        Direction::AtoB => (w.cols(), w.rows()),
        Direction::BtoA => (w.rows(), w.cols()),
    };
    if source_labels.len() != d_src {
        return Err(StableError::BadOption(format!(
            "{} labels given for a shape of {d_src} vertices",
            source_labels.len()
        )));
    }
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); regions];
    for (p, &l) in source_labels.iter().enumerate() {
        if l >= 0 && (l as usize) < regions {
            members[l as usize].push(p as u32);
        }
    }
    let mut scores = vec![0.0; d_dst * regions];
    for (r, support) in members.iter().enumerate() {
        if support.is_empty() {
            continue;
        }
        let col = &mut scores[r * d_dst..(r + 1) * d_dst];
        w.transport_indicator(dir, support, None, col, ws)?;
        // Raw scores are exact integers: dividing (not multiplying by a reciprocal) makes equal
        // ratios equal floats, so ties are exact and broken by region id.
        let n = support.len() as f64;
        col.iter_mut().for_each(|v| *v /= n);
    }
    Ok(scores)
}

/// Each vertex takes the region of highest score (ties: the lowest region id) after the
/// scores are heat-smoothed over the mesh when a smoother is given. `scores` is column-major
/// `d × regions` as [`region_scores`] returns (it is smoothed in place). Returns the labels and
/// the relative margin of each vertex's choice (see [`RefinedPartition::margin_a`]).
pub fn assign_regions(
    scores: &mut [f64],
    regions: usize,
    smoother: Option<&HeatSmoother>,
) -> Result<(Vec<i32>, Vec<f64>), StableError> {
    if regions == 0 || !scores.len().is_multiple_of(regions) {
        return Err(StableError::BadOption(format!(
            "{} scores do not make {regions} region columns",
            scores.len()
        )));
    }
    let d = scores.len() / regions;
    if let Some(s) = smoother {
        if s.vertex_count() != d {
            return Err(StableError::BadOption(format!(
                "smoother has {} vertices, scores have {d}",
                s.vertex_count()
            )));
        }
        s.smooth(scores, regions)
            .map_err(|e| StableError::BadOption(e.to_string()))?;
    }
    let mut labels = vec![0i32; d];
    let mut margins = vec![0.0; d];
    for q in 0..d {
        let (best, second, arg) = best_two((0..regions).map(|r| scores[r * d + q]));
        labels[q] = arg as i32;
        margins[q] = if best > 0.0 {
            ((best - second.max(0.0)) / best).clamp(0.0, 1.0)
        } else {
            0.0
        };
    }
    Ok((labels, margins))
}

/// Refines two corresponding partitions (region `r` of A ↔ region `r` of B, e.g. the
/// labels of [`stable_regions`](super::stable_regions)) by alternating best responses: every
/// vertex of B takes the region of A it has the highest mean affinity to ([`region_scores`],
/// heat-smoothed over B), then every vertex of A the region of B likewise, until a round
/// changes nothing or `max_rounds` is reached.
///
/// Why: Algorithms 2 and 3 cut regions one after another with hard area quotas, so a
/// boundary between two neighbouring regions sits wherever the quota ran out, and the
/// leftover pair collects what nobody claimed. The best-response step lets every vertex
/// choose among *all* regions at once, and the smoothing makes that choice by a vertex's
/// neighbourhood rather than by its own noisy band row. On TOSCA within-class pairs it
/// raises Algorithm 2's correspondence ratio (see the README).
///
/// Labels `-1` (no region) are allowed in the input; every vertex has a region in the output.
/// Region ids keep their meaning; a region can become empty. Deterministic.
///
/// ```
/// use coseg::affinity::BandAffinity;
/// use coseg::bands::equal_count_bands;
/// use coseg::stable::{refine_partition, RefineOptions};
/// let vals: Vec<f64> = (0..8).map(|v| v as f64).collect();
/// let t = equal_count_bands(&vals, 1, 8, 2).unwrap();
/// let w = BandAffinity::new(&t, &t).unwrap();
/// // A wrong start on B is corrected from A's partition.
/// let r = refine_partition(&w, &[0, 0, 0, 0, 1, 1, 1, 1], &[0, 0, 0, 1, 1, 1, 1, 1],
///     None, None, &RefineOptions::default()).unwrap();
/// assert_eq!(r.labels_b, vec![0, 0, 0, 0, 1, 1, 1, 1]);
/// assert!(r.converged);
/// ```
pub fn refine_partition(
    w: &BandAffinity<'_>,
    labels_a: &[i32],
    labels_b: &[i32],
    smoother_a: Option<&HeatSmoother>,
    smoother_b: Option<&HeatSmoother>,
    options: &RefineOptions,
) -> Result<RefinedPartition, StableError> {
    options.validate()?;
    if labels_a.len() != w.cols() || labels_b.len() != w.rows() {
        return Err(StableError::BadOption(format!(
            "labels have lengths {} and {}, expected {} and {}",
            labels_a.len(),
            labels_b.len(),
            w.cols(),
            w.rows()
        )));
    }
    let regions = labels_a
        .iter()
        .chain(labels_b)
        .copied()
        .max()
        .map_or(0, |m| (m + 1).max(0) as usize);
    if regions == 0 {
        return Err(StableError::BadOption(
            "the partitions have no region to refine".into(),
        ));
    }
    let use_smoothing = options.smoothing_time > 0.0;
    let mut ws = w.workspace();
    let mut la = labels_a.to_vec();
    let mut lb = labels_b.to_vec();
    let mut margin_a = vec![0.0; la.len()];
    let mut margin_b = vec![0.0; lb.len()];
    let mut rounds = 0;
    let mut converged = false;
    while rounds < options.max_rounds {
        rounds += 1;
        let mut scores = region_scores(w, Direction::AtoB, &la, regions, &mut ws)?;
        let (new_b, mb) =
            assign_regions(&mut scores, regions, smoother_b.filter(|_| use_smoothing))?;
        let mut scores = region_scores(w, Direction::BtoA, &new_b, regions, &mut ws)?;
        let (new_a, ma) =
            assign_regions(&mut scores, regions, smoother_a.filter(|_| use_smoothing))?;
        let unchanged = new_a == la && new_b == lb;
        la = new_a;
        lb = new_b;
        margin_a = ma;
        margin_b = mb;
        if unchanged {
            converged = true;
            break;
        }
    }
    Ok(RefinedPartition {
        labels_a: la,
        labels_b: lb,
        margin_a,
        margin_b,
        rounds,
        converged,
    })
}

/// The largest and the second-largest of `scores` and the index of the largest (the first of
/// equals; a NaN never wins), `(-∞, -∞, 0)` when empty: a vertex's winning region and the two
/// values its margin is made of, for every best-response assignment.
pub(crate) fn best_two(scores: impl IntoIterator<Item = f64>) -> (f64, f64, usize) {
    let (mut best, mut second, mut arg) = (f64::NEG_INFINITY, f64::NEG_INFINITY, 0usize);
    for (r, s) in scores.into_iter().enumerate() {
        if s > best {
            second = best;
            best = s;
            arg = r;
        } else if s > second {
            second = s;
        }
    }
    (best, second, arg)
}
