//! [`cycle_consistency`]: how much of a region carried once around a cycle comes back.

use super::GraphError;
use super::stable_cycle::{CycleShape, CycleStep};
use crate::affinity::AffinityWorkspace;
use crate::stable::threshold;
use crate::vertex_sets::intersect_sorted;
use serde::{Deserialize, Serialize};

/// The region carried once around a cycle and its agreement with where it started.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CycleConsistency {
    /// Area-weighted intersection over union of the start region `R` and the returned region
    /// `R'` on shape 0: `ω(R ∩ R') / ω(R ∪ R')`, in `[0, 1]` (1 when both are empty).
    pub iou: f64,
    /// Area fraction of `R` that comes back: `ω(R ∩ R') / ω(R)` (1 when `R` is empty).
    pub overlap: f64,
    /// The regions carried to each shape, in cycle order: `carried[0]` is `R'` (the returned
    /// region on shape 0), `carried[i]` the region on shape `i`.
    pub carried: Vec<Vec<u32>>,
}

/// Carries `region` (ascending vertices of shape 0) once around the cycle with thresholded
/// transports, `f_{i+1} = P_{i+1}(W_{i+1,i} f_i)` (the rules, remaining subsets and areas of
/// `shapes`; `steps[i]` carries shape `i` to shape `i + 1` mod `m`), and measures how much of
/// it returns (a triangle of shapes is `m = 3`). A region that is a fixed point of
/// [`super::stable_cycle`] on the same cycle returns exactly (`iou = 1`).
///
/// ```
/// use coseg::affinity::{BandAffinity, Direction};
/// use coseg::bands::equal_count_bands;
/// use coseg::graph::{cycle_consistency, CycleShape, CycleStep};
/// use coseg::stable::Threshold;
/// let vals: Vec<f64> = (0..8).map(|v| v as f64).collect();
/// let a = equal_count_bands(&vals, 1, 8, 2).unwrap();
/// let w = BandAffinity::new(&a, &a).unwrap();
/// let all: Vec<u32> = (0..8).collect();
/// let areas = vec![1.0; 8];
/// let s = CycleShape { remaining: &all, areas: &areas, reference_area: 8.0, rule: Threshold::Count(4) };
/// let step = CycleStep { affinity: &w, direction: Direction::AtoB };
/// let c = cycle_consistency(&[s; 3], &[step; 3], &[4, 5, 6, 7]).unwrap();
/// assert_eq!(c.iou, 1.0);
/// let half = cycle_consistency(&[s; 3], &[step; 3], &[2, 3, 4, 5]).unwrap();
/// assert!(half.iou < 1.0);
/// ```
pub fn cycle_consistency(
    shapes: &[CycleShape<'_>],
    steps: &[CycleStep<'_, '_>],
    region: &[u32],
) -> Result<CycleConsistency, GraphError> {
    let m = shapes.len();
    if m < 2 || steps.len() != m {
        return Err(GraphError::BadOption(format!(
            "a cycle needs m ≥ 2 shapes and m steps, got {m} shapes and {} steps",
            steps.len()
        )));
    }
    if !region.windows(2).all(|p| p[0] < p[1]) {
        return Err(GraphError::BadOption(
            "region must be strictly ascending".into(),
        ));
    }
    let mut ws = AffinityWorkspace::default();
    let mut start = Vec::new();
    intersect_sorted(region, shapes[0].remaining, &mut start);
    let mut carried: Vec<Vec<u32>> = vec![Vec::new(); m];
    let mut current = start.clone();
    let mut scratch = crate::stable::ThresholdScratch::default();
    for (i, step) in steps.iter().enumerate() {
        let j = (i + 1) % m;
        let dst = &shapes[j];
        let mut scores = vec![0.0; dst.remaining.len()];
        step.affinity.transport_indicator(
            step.direction,
            &current,
            Some(dst.remaining),
            &mut scores,
            &mut ws,
        )?;
        let mut out = Vec::new();
        threshold(
            dst.rule,
            dst.remaining,
            &scores,
            dst.areas,
            dst.reference_area,
            &mut out,
            &mut scratch,
        );
        carried[j].clone_from(&out);
        current = out;
    }
    let areas = shapes[0].areas;
    let area = |v: &[u32]| v.iter().map(|&p| areas[p as usize]).sum::<f64>();
    let mut inter = Vec::new();
    intersect_sorted(&start, &carried[0], &mut inter);
    let (a_inter, a_start, a_back) = (area(&inter), area(&start), area(&carried[0]));
    let union = a_start + a_back - a_inter;
    Ok(CycleConsistency {
        iou: if union > 0.0 { a_inter / union } else { 1.0 },
        overlap: if a_start > 0.0 {
            a_inter / a_start
        } else {
            1.0
        },
        carried,
    })
}
