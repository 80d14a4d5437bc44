//! Tests of the band-table affinity operator against the dense oracle.

mod common;

use common::stable::{random_equal_table, random_table, random_vec};
use coseg::affinity::{AffinityError, BandAffinity, Direction, FeaturePairing, dense_affinity};

fn dense_mul(w: &[f64], rows: usize, cols: usize, x: &[f64]) -> Vec<f64> {
    (0..rows)
        .map(|q| (0..cols).map(|p| w[q * cols + p] * x[p]).sum())
        .collect()
}

fn dense_mul_t(w: &[f64], rows: usize, cols: usize, y: &[f64]) -> Vec<f64> {
    (0..cols)
        .map(|p| (0..rows).map(|q| w[q * cols + p] * y[q]).sum())
        .collect()
}

fn assert_close(a: &[f64], b: &[f64], rel: f64) {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            (x - y).abs() <= rel * scale,
            "entry {i}: {x} vs {y} (scale {scale})"
        );
    }
}

#[test]
fn products_match_dense_oracle() {
    for (seed, (da, db, n, k)) in [
        (37, 41, 7, 5),
        (120, 90, 13, 20),
        (64, 64, 30, 4),
        (3, 200, 2, 3),
    ]
    .into_iter()
    .enumerate()
    {
        let a = random_table(da, n, k, seed as u64);
        let b = random_table(db, n, k, 100 + seed as u64);
        let w = BandAffinity::new(&a, &b).unwrap();
        let d = dense_affinity(&w).unwrap();
        let mut ws = w.workspace();
        let mut x = random_vec(da, 7 + seed as u64);
        for v in x.iter_mut().step_by(3) {
            *v = 0.0; // sparse entries are skipped
        }
        x[0] = -2.5; // signed input too
        let y = random_vec(db, 9 + seed as u64);
        let mut wx = vec![0.0; db];
        w.apply(&x, &mut wx, &mut ws).unwrap();
        assert_close(&wx, &dense_mul(&d, db, da, &x), 1e-12);
        let mut wty = vec![0.0; da];
        w.apply_transpose(&y, &mut wty, &mut ws).unwrap();
        assert_close(&wty, &dense_mul_t(&d, db, da, &y), 1e-12);
    }
}

#[test]
fn large_support_uses_all_chunks_and_matches() {
    // Enough vertices that the scatter splits into several chunks.
    let (da, db, n, k) = (9000, 300, 6, 7);
    let a = random_table(da, n, k, 1);
    let b = random_table(db, n, k, 2);
    let w = BandAffinity::new(&a, &b).unwrap();
    let d = dense_affinity(&w).unwrap();
    let mut ws = w.workspace();
    let x = random_vec(da, 3);
    let mut wx = vec![0.0; db];
    w.apply(&x, &mut wx, &mut ws).unwrap();
    assert_close(&wx, &dense_mul(&d, db, da, &x), 1e-12);
}

#[test]
fn indicator_scores_are_exact_integers_times_unit() {
    let a = random_table(50, 9, 6, 11);
    let b = random_table(70, 9, 6, 12);
    let w = BandAffinity::new(&a, &b).unwrap();
    let d = dense_affinity(&w).unwrap();
    let mut ws = w.workspace();
    let support: Vec<u32> = vec![1, 4, 9, 20, 49];
    let rows: Vec<u32> = vec![0, 3, 69];
    let mut out = vec![0.0; rows.len()];
    w.transport_indicator(Direction::AtoB, &support, Some(&rows), &mut out, &mut ws)
        .unwrap();
    for (i, &q) in rows.iter().enumerate() {
        // Raw score = number of (feature, p ∈ support) matches: an integer.
        let count: usize = support
            .iter()
            .map(|&p| {
                (0..9)
                    .filter(|&f| a.label(p as usize, f) == b.label(q as usize, f))
                    .count()
            })
            .sum();
        assert_eq!(out[i], count as f64);
        let dense: f64 = support
            .iter()
            .map(|&p| d[q as usize * 50 + p as usize])
            .sum();
        assert!((out[i] * w.unit() - dense).abs() <= 1e-14);
    }
    // Transpose direction on a subset of A.
    let rows_a: Vec<u32> = vec![2, 5];
    let mut out_a = vec![0.0; 2];
    w.transport_indicator(
        Direction::BtoA,
        &[0, 1, 2],
        Some(&rows_a),
        &mut out_a,
        &mut ws,
    )
    .unwrap();
    for (i, &p) in rows_a.iter().enumerate() {
        let dense: f64 = [0usize, 1, 2].iter().map(|&q| d[q * 50 + p as usize]).sum();
        assert!((out_a[i] * w.unit() - dense).abs() <= 1e-14);
    }
}

#[test]
fn transport_plan_marginals() {
    // K divides both vertex counts and each band holds exactly d/K vertices.
    let (da, db, n, k) = (60, 80, 11, 20);
    let a = random_equal_table(da, n, k, 5);
    let b = random_equal_table(db, n, k, 6);
    let w = BandAffinity::new(&a, &b).unwrap();
    let mut ws = w.workspace();
    let mut rows = vec![0.0; db];
    w.apply(&vec![1.0; da], &mut rows, &mut ws).unwrap();
    for r in rows {
        assert!((r - 1.0 / db as f64).abs() < 1e-15, "row sum {r}");
    }
    let mut cols = vec![0.0; da];
    w.apply_transpose(&vec![1.0; db], &mut cols, &mut ws)
        .unwrap();
    for c in cols {
        assert!((c - 1.0 / da as f64).abs() < 1e-15, "column sum {c}");
    }
    // Same check against the dense oracle directly.
    let d = dense_affinity(&w).unwrap();
    let total: f64 = d.iter().sum();
    assert!((total - 1.0).abs() < 1e-12);
}

#[test]
fn weighted_and_permuted_pairing_matches_dense() {
    let a = random_table(40, 5, 4, 21);
    let b = random_table(33, 7, 4, 22);
    let pairing = FeaturePairing::new(
        vec![(0, 6), (1, 1), (4, 2), (4, 3), (2, 0)],
        Some(vec![1.0, 2.0, 0.5, 0.0, 3.0]),
    );
    let w = BandAffinity::with_pairing(&a, &b, &pairing).unwrap();
    let d = dense_affinity(&w).unwrap();
    let mut ws = w.workspace();
    let x = random_vec(40, 1);
    let y = random_vec(33, 2);
    let mut wx = vec![0.0; 33];
    w.apply(&x, &mut wx, &mut ws).unwrap();
    assert_close(&wx, &dense_mul(&d, 33, 40, &x), 1e-12);
    let mut wty = vec![0.0; 40];
    w.apply_transpose(&y, &mut wty, &mut ws).unwrap();
    assert_close(&wty, &dense_mul_t(&d, 33, 40, &y), 1e-12);
    // Indicator path with weights.
    let mut s = vec![0.0; 33];
    w.transport_indicator(Direction::AtoB, &[3, 7, 8], None, &mut s, &mut ws)
        .unwrap();
    let mut ind = vec![0.0; 40];
    for i in [3, 7, 8] {
        ind[i] = 1.0;
    }
    let expect = dense_mul(&d, 33, 40, &ind);
    let scaled: Vec<f64> = s.iter().map(|v| v * w.unit()).collect();
    assert_close(&scaled, &expect, 1e-12);
    // Equal weights given explicitly behave like none, with a non-identity pairing.
    let p2 = FeaturePairing::new(vec![(0, 6), (1, 1), (4, 2)], Some(vec![2.0; 3]));
    let w2 = BandAffinity::with_pairing(&a, &b, &p2).unwrap();
    let d2 = dense_affinity(&w2).unwrap();
    let mut s2 = vec![0.0; 33];
    w2.transport_indicator(Direction::AtoB, &[3, 7, 8], None, &mut s2, &mut ws)
        .unwrap();
    let expect2 = dense_mul(&d2, 33, 40, &ind);
    for (v, e) in s2.iter().zip(&expect2) {
        assert_eq!(*v, v.round());
        assert!((v * w2.unit() - e).abs() < 1e-15);
    }
}

#[test]
fn parallel_equals_serial_bitwise() {
    let a = random_table(20000, 16, 20, 31);
    let b = random_table(15000, 16, 20, 32);
    let w = BandAffinity::new(&a, &b).unwrap();
    let x = random_vec(20000, 33);
    let run = || {
        let mut ws = w.workspace();
        let mut out = vec![0.0; 15000];
        w.apply(&x, &mut out, &mut ws).unwrap();
        out
    };
    let serial = crate::common::on_threads(1, run);
    let parallel = crate::common::on_threads(3, run);
    assert!(
        serial
            .iter()
            .zip(&parallel)
            .all(|(s, p)| s.to_bits() == p.to_bits())
    );
}

#[test]
fn rejects_bad_input() {
    let a = random_table(10, 3, 4, 1);
    let mut b = random_table(12, 3, 4, 2);
    b.labels[5] = 4;
    b.labels[30] = 255;
    // The first offending entry is named (vertex 5 / 3 features = 1), from either side.
    assert!(matches!(
        BandAffinity::new(&a, &b),
        Err(AffinityError::LabelOutOfRange {
            vertex: 1,
            label: 4,
            ..
        })
    ));
    assert!(matches!(
        BandAffinity::new(&b, &a),
        Err(AffinityError::LabelOutOfRange {
            vertex: 1,
            label: 4,
            ..
        })
    ));
    let c = random_table(12, 3, 5, 2);
    assert!(matches!(
        BandAffinity::new(&a, &c),
        Err(AffinityError::BandCountMismatch { .. })
    ));
    let b = random_table(12, 3, 4, 2);
    let w = BandAffinity::new(&a, &b).unwrap();
    let mut ws = w.workspace();
    let mut out = vec![0.0; 11];
    assert!(matches!(
        w.apply(&[0.0; 10], &mut out, &mut ws),
        Err(AffinityError::LengthMismatch { .. })
    ));
    let mut out = vec![0.0; 12];
    assert!(matches!(
        w.transport_indicator(Direction::AtoB, &[10], None, &mut out, &mut ws),
        Err(AffinityError::IndexOutOfRange { .. })
    ));
    let bad = FeaturePairing::new(vec![(0, 3)], None);
    assert!(matches!(
        BandAffinity::with_pairing(&a, &b, &bad),
        Err(AffinityError::PairOutOfRange { .. })
    ));
    let bad_w = FeaturePairing::new(vec![(0, 1)], Some(vec![-1.0]));
    assert!(matches!(
        BandAffinity::with_pairing(&a, &b, &bad_w),
        Err(AffinityError::BadWeights(_))
    ));
}

#[test]
fn incremental_histograms_equal_fresh_products() {
    let a = random_table(3000, 17, 9, 41);
    let b = random_table(2500, 17, 9, 42);
    let w = BandAffinity::new(&a, &b).unwrap();
    let mut ws = w.workspace();
    let mut h = w.histogram(Direction::BtoA);
    let rows: Vec<u32> = (0..3000).filter(|v| v % 3 != 0).collect();
    let (mut got, mut want) = (vec![0.0; rows.len()], vec![0.0; rows.len()]);
    for step in 0..8u64 {
        // Supports of varying overlap: small deltas, then complete changes.
        let x = random_vec(2500, step / 2);
        let cut = if step % 2 == 0 { 0.3 } else { 0.31 };
        let support: Vec<u32> = (0..2500).filter(|&q| x[q as usize] < cut).collect();
        w.update_histogram(&mut h, &support, &mut ws).unwrap();
        assert_eq!(h.support(), &support[..]);
        w.transport_histogram(&h, Some(&rows), &mut got, &mut ws)
            .unwrap();
        w.transport_indicator(Direction::BtoA, &support, Some(&rows), &mut want, &mut ws)
            .unwrap();
        assert_eq!(got, want, "step {step}");
    }
    assert!(w.update_histogram(&mut h, &[3, 2], &mut ws).is_err());
    assert!(w.update_histogram(&mut h, &[2500], &mut ws).is_err());
}
