//! [`refine_regions`]: [`refine_partition`] applied to the output of Algorithm 2 or 3.

use super::{RefineOptions, RegionPair, StableError, StableRegions, refine_partition};
use crate::affinity::{BandAffinity, Direction};
use crate::spectral::HeatSmoother;

/// Refines the region pairs of [`stable_regions`](super::stable_regions) with
/// [`refine_partition`] and rebuilds them: the same number of pairs with the same meaning
/// (pair `i` stays pair `i`, the leftover pair stays last), new vertex sets, area fractions and
/// objectives `Σ_{q ∈ Ω_B, p ∈ Ω_A} W_qp`; `iterations` and `converged` of every pair report the
/// refinement's rounds and whether it reached its fixed point. `w` must be the operator the
/// regions were computed with; `areas_a`, `areas_b` as for `stable_regions`; the smoothers (one
/// per shape, see [`HeatSmoother`]) may be `None` to skip smoothing.
///
/// ```
/// use coseg::affinity::BandAffinity;
/// use coseg::bands::equal_count_bands;
/// use coseg::stable::{refine_regions, stable_regions, RefineOptions, StableRegionsOptions};
/// let vals: Vec<f64> = (0..40).map(|v| ((v * 7) % 40) as f64).collect();
/// let t = equal_count_bands(&vals, 1, 40, 4).unwrap();
/// let areas = vec![1.0; 40];
/// let r = stable_regions(&t, &t, &areas, &areas, &StableRegionsOptions::default()).unwrap();
/// let w = BandAffinity::new(&t, &t).unwrap();
/// let refined = refine_regions(&w, &r, &areas, &areas, None, None, &RefineOptions::default()).unwrap();
/// assert_eq!(refined.pairs.len(), r.pairs.len());
/// assert!(refined.labels_a().iter().all(|&l| l >= 0));
/// ```
pub fn refine_regions(
    w: &BandAffinity<'_>,
    regions: &StableRegions,
    areas_a: &[f64],
    areas_b: &[f64],
    smoother_a: Option<&HeatSmoother>,
    smoother_b: Option<&HeatSmoother>,
    options: &RefineOptions,
) -> Result<StableRegions, StableError> {
    if areas_a.len() != regions.vertices_a || areas_b.len() != regions.vertices_b {
        return Err(StableError::AreaLength {
            expected_a: regions.vertices_a,
            expected_b: regions.vertices_b,
            got_a: areas_a.len(),
            got_b: areas_b.len(),
        });
    }
    let refined = refine_partition(
        w,
        &regions.labels_a(),
        &regions.labels_b(),
        smoother_a,
        smoother_b,
        options,
    )?;
    rebuild_regions(
        w,
        regions,
        &refined.labels_a,
        &refined.labels_b,
        areas_a,
        areas_b,
        refined.rounds,
        refined.converged,
    )
}

/// New pairs from labels (pair `i` = label `i`, same meaning and order as `regions`), with
/// their area fractions and objectives; `iterations` and `converged` are set on every pair.
#[allow(clippy::too_many_arguments)]
pub(crate) fn rebuild_regions(
    w: &BandAffinity<'_>,
    regions: &StableRegions,
    labels_a: &[i32],
    labels_b: &[i32],
    areas_a: &[f64],
    areas_b: &[f64],
    iterations: usize,
    converged: bool,
) -> Result<StableRegions, StableError> {
    let n = regions.pairs.len();
    let members = |labels: &[i32]| {
        let mut m: Vec<Vec<u32>> = vec![Vec::new(); n];
        for (v, &l) in labels.iter().enumerate() {
            if l >= 0 && (l as usize) < n {
                m[l as usize].push(v as u32);
            }
        }
        m
    };
    let (ma, mb) = (members(labels_a), members(labels_b));
    let (total_a, total_b): (f64, f64) = (areas_a.iter().sum(), areas_b.iter().sum());
    let area = |set: &[u32], areas: &[f64], total: f64| {
        set.iter().map(|&v| areas[v as usize]).sum::<f64>() / total
    };
    let mut ws = w.workspace();
    let mut scores = vec![0.0; regions.vertices_b];
    let mut pairs = Vec::with_capacity(n);
    for (i, old) in regions.pairs.iter().enumerate() {
        let (ra, rb) = (ma[i].clone(), mb[i].clone());
        let objective = if ra.is_empty() || rb.is_empty() {
            0.0
        } else {
            w.transport_indicator(Direction::AtoB, &ra, None, &mut scores, &mut ws)?;
            w.unit() * rb.iter().map(|&q| scores[q as usize]).sum::<f64>()
        };
        pairs.push(RegionPair {
            area_fraction_a: area(&ra, areas_a, total_a),
            area_fraction_b: area(&rb, areas_b, total_b),
            region_a: ra,
            region_b: rb,
            objective,
            iterations,
            converged,
            leftover: old.leftover,
            auto: old.auto,
        });
    }
    Ok(StableRegions {
        vertices_a: regions.vertices_a,
        vertices_b: regions.vertices_b,
        pairs,
    })
}
