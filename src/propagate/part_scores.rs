//! Part scores from per-part band histograms: how much each vertex of a destination shape
//! resembles each labelled part of a source shape, under the pairs and weights of a
//! [`BandAffinity`].
//!
//! Part `r` of the source is summarised, per feature, by the histogram of its bands
//! (`h_{r,k}(b)`: the share of the part — by vertex count or by area — in band `b` of feature
//! `k`). A destination vertex `q` in band `b_k(q)` of feature `k` then scores
//! - [`PartScore::Affinity`]: `Σ_i w_i h_{r,a_i}(b_{b_i}(q))` (pairs `i = (a_i, b_i)`, weights
//!   `w_i` summing to one): with vertex counts this is the band affinity's transport of the
//!   part's indicator divided by its size ([`crate::stable::region_scores`]) over the sum of
//!   the raw pair weights, i.e. the mean affinity of `q` to the part, in `[0, 1]`;
//! - [`PartScore::Geometric`]: `Π_i (h_{r,a_i}(b_{b_i}(q)) + ε)^{w_i}`, the weighted geometric
//!   mean of the same histogram values: a vertex must fall inside the part's distribution in
//!   (nearly) every feature, not only in most, to score high (a naive-Bayes likelihood with the
//!   features' weights as exponents, per feature so the scale matches the arithmetic mean).

use crate::affinity::{BandAffinity, Direction};
use crate::bands::BandTable;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How a vertex's per-feature histogram values are combined into a part score.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[non_exhaustive]
pub enum PartScore {
    /// The weighted arithmetic mean: the band affinity's mean transport (the paper's score).
    #[default]
    Affinity,
    /// The weighted geometric mean (`ε` = `GEOMETRIC_FLOOR` added to every value).
    Geometric,
}

/// Floor added to every histogram value of the geometric mean, so that one feature where the
/// part never falls lowers a score without zeroing it.
const GEOMETRIC_FLOOR: f64 = 1e-3;

/// Scores of every destination vertex of `dir` for every part of the source labels:
/// column-major `d_dst × parts` (`scores[r · d_dst + q]`). `source_labels[p] ∈ 0..parts` or
/// `< 0` (no part); `source_areas` weighs the histograms by area (`None`: vertex counts).
/// Empty parts score 0 everywhere. Deterministic (each vertex is summed in pair order).
pub(crate) fn part_scores(
    w: &BandAffinity<'_>,
    dir: Direction,
    source_labels: &[i32],
    source_areas: Option<&[f64]>,
    parts: usize,
    rule: PartScore,
) -> Vec<f64> {
    let (src, dst): (&BandTable, &BandTable) = match dir {
        Direction::AtoB => (w.table_a(), w.table_b()),
        Direction::BtoA => (w.table_b(), w.table_a()),
    };
    let k = w.bands();
    let weights = w.weights();
    // Pair i: (source feature, destination feature, weight).
    let pairs: Vec<(usize, usize, f64)> = w
        .pairs()
        .iter()
        .zip(&weights)
        .map(|(&(a, b), &wt)| match dir {
            Direction::AtoB => (a as usize, b as usize, wt),
            Direction::BtoA => (b as usize, a as usize, wt),
        })
        .collect();
    let nf = src.features;
    // hist[(r · nf + f) · k + band]
    let mut hist = vec![0.0; parts * nf * k];
    let mut mass = vec![0.0; parts];
    for (p, &l) in source_labels.iter().enumerate() {
        if l < 0 || l as usize >= parts {
            continue;
        }
        let r = l as usize;
        let m = source_areas.map_or(1.0, |a| a[p]);
        mass[r] += m;
        let base = r * nf * k;
        for (f, &b) in src.row(p).iter().enumerate() {
            hist[base + f * k + b as usize] += m;
        }
    }
    for (h, &m) in hist.chunks_mut(nf * k).zip(&mass) {
        if m > 0.0 {
            h.iter_mut().for_each(|x| *x /= m);
        }
    }
    if rule == PartScore::Geometric {
        hist.iter_mut()
            .for_each(|h| *h = (*h + GEOMETRIC_FLOOR).ln());
    }
    let d = dst.vertices;
    let mut scores = vec![0.0; d * parts];
    let rows: Vec<Vec<f64>> = (0..d)
        .into_par_iter()
        .map(|q| {
            let row = dst.row(q);
            (0..parts)
                .map(|r| {
                    if mass[r] <= 0.0 {
                        return 0.0;
                    }
                    let h = &hist[r * nf * k..(r + 1) * nf * k];
                    let s: f64 = pairs
                        .iter()
                        .map(|&(fs, fd, wt)| wt * h[fs * k + row[fd] as usize])
                        .sum();
                    match rule {
                        PartScore::Affinity => s,
                        PartScore::Geometric => s.exp(),
                    }
                })
                .collect()
        })
        .collect();
    for (q, row) in rows.iter().enumerate() {
        for (r, &s) in row.iter().enumerate() {
            scores[r * d + q] = s;
        }
    }
    scores
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::affinity::FeaturePairing;
    use crate::bands::equal_count_bands;
    use crate::stable::region_scores;

    fn tables() -> (BandTable, BandTable) {
        // Two features, 12 and 9 vertices, 3 bands.
        let a: Vec<f64> = (0..24)
            .map(|i| ((i * 7) % 12) as f64 + 0.1 * i as f64)
            .collect();
        let b: Vec<f64> = (0..18)
            .map(|i| ((i * 5) % 9) as f64 - 0.2 * i as f64)
            .collect();
        (
            equal_count_bands(&a, 2, 12, 3).unwrap(),
            equal_count_bands(&b, 2, 9, 3).unwrap(),
        )
    }

    #[test]
    fn affinity_rule_with_counts_is_the_band_affinity_transport() {
        let (a, b) = tables();
        let labels: Vec<i32> = (0..12).map(|p| [0, 1, 2, -1][p % 4]).collect();
        for weights in [None, Some(vec![3.0, 1.0])] {
            let pairing = FeaturePairing::new(vec![(0, 0), (1, 1)], weights);
            let w = BandAffinity::with_pairing(&a, &b, &pairing).unwrap();
            let raw_sum: f64 = (0..2).map(|i| w.raw_weight(i)).sum();
            let expect =
                region_scores(&w, Direction::AtoB, &labels, 3, &mut w.workspace()).unwrap();
            let got = part_scores(&w, Direction::AtoB, &labels, None, 3, PartScore::Affinity);
            for (e, g) in expect.iter().zip(&got) {
                assert!((e / raw_sum - g).abs() < 1e-12, "{e} / {raw_sum} vs {g}");
            }
            // The other direction: labels on B.
            let lb: Vec<i32> = (0..9).map(|p| p % 3).collect();
            let expect = region_scores(&w, Direction::BtoA, &lb, 3, &mut w.workspace()).unwrap();
            let got = part_scores(&w, Direction::BtoA, &lb, None, 3, PartScore::Affinity);
            for (e, g) in expect.iter().zip(&got) {
                assert!((e / raw_sum - g).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn area_weights_and_geometric_mean_by_hand() {
        // One feature pair duplicated with weights 1/4, 3/4 and a hand-computed histogram.
        let src = equal_count_bands(&[0.0, 1.0, 2.0, 3.0, 0.5, 2.5, 1.5, 3.5], 2, 4, 2).unwrap();
        // Feature 0 bands: [0, 0, 1, 1]; feature 1 (0.5, 2.5, 1.5, 3.5): [0, 1, 0, 1].
        assert_eq!(src.row(0), &[0, 0]);
        assert_eq!(src.row(1), &[0, 1]);
        assert_eq!(src.row(2), &[1, 0]);
        assert_eq!(src.row(3), &[1, 1]);
        let pairing = FeaturePairing::new(vec![(0, 0), (1, 1)], Some(vec![1.0, 3.0]));
        let w = BandAffinity::with_pairing(&src, &src, &pairing).unwrap();
        // Part 0 = vertices 0 (area 3) and 1 (area 1); part 1 = vertex 3.
        let labels = [0, 0, -1, 1];
        let areas = [3.0, 1.0, 5.0, 2.0];
        let s = part_scores(
            &w,
            Direction::AtoB,
            &labels,
            Some(&areas),
            2,
            PartScore::Affinity,
        );
        // Part 0: feature 0 all in band 0; feature 1: band 0 share 3/4, band 1 share 1/4.
        // Vertex 2 (bands 1, 0): 0.25 · 0 + 0.75 · 0.75.
        assert!((s[2] - 0.5625).abs() < 1e-12);
        // Vertex 1 (bands 0, 1): 0.25 · 1 + 0.75 · 0.25.
        assert!((s[1] - 0.4375).abs() < 1e-12);
        // Part 1 on vertex 3 (bands 1, 1): 1.
        assert!((s[4 + 3] - 1.0).abs() < 1e-12);
        let g = part_scores(
            &w,
            Direction::AtoB,
            &labels,
            Some(&areas),
            2,
            PartScore::Geometric,
        );
        let e = GEOMETRIC_FLOOR;
        let v2 = (0.25 * e.ln() + 0.75 * (0.75 + e).ln()).exp();
        assert!((g[2] - v2).abs() < 1e-12);
        // The geometric mean never exceeds the arithmetic mean (plus the floor).
        for (a, b) in s.iter().zip(&g) {
            assert!(*b <= a + e + 1e-12);
        }
        // An empty part scores 0.
        let z = part_scores(
            &w,
            Direction::AtoB,
            &[0, 0, 0, 0],
            None,
            2,
            PartScore::Geometric,
        );
        assert!(z[4..].iter().all(|&x| x == 0.0));
    }
}
