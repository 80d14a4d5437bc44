//! Tests of the band tables: equal-count and area-weighted bands, tie-breaking, permutations,
//! and the parallel engine against a sequential oracle.

mod common;

use common::features::{blob, permutation};
use coseg::bands::{
    BandOptions, BandTable, BandWeighting, area_weighted_bands, band_table, equal_count_bands,
};
use coseg::features::{DescriptorOptions, descriptors};
use coseg::spectral::dense_spectrum;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// Sequential oracle: the straightforward sort-and-cut of docs/METHOD.md §2.
fn oracle(values: &[f64], n: usize, d: usize, k: usize) -> Vec<u8> {
    let mut labels = vec![0u8; n * d];
    for f in 0..n {
        let x = &values[f * d..(f + 1) * d];
        let mut order: Vec<usize> = (0..d).collect();
        order.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
        for (pos, &v) in order.iter().enumerate() {
            // Larger blocks first: with base = d / k, extra = d % k, the first `extra` blocks
            // have base + 1 entries.
            let (base, extra) = (d / k, d % k);
            let big = extra * (base + 1);
            let band = if pos < big {
                pos / (base + 1)
            } else {
                extra + (pos - big) / base.max(1)
            };
            labels[v * n + f] = band as u8;
        }
    }
    labels
}

fn runner() -> TestRunner {
    TestRunner::new_with_rng(
        Config {
            cases: 200,
            ..Config::default()
        },
        TestRng::from_seed(RngAlgorithm::ChaCha, &[7u8; 32]),
    )
}

/// Values with many ties (small integer range) or none (wide floats).
fn table_strategy() -> impl Strategy<Value = (usize, usize, usize, Vec<f64>)> {
    (1usize..5, 1usize..120, 1usize..30, any::<bool>()).prop_flat_map(|(n, d, k, ties)| {
        let vals = if ties {
            proptest::collection::vec((0i32..4).prop_map(f64::from).boxed(), n * d).boxed()
        } else {
            proptest::collection::vec(-1e3f64..1e3, n * d).boxed()
        };
        (Just(n), Just(d), Just(k), vals)
    })
}

#[test]
fn equal_count_bands_match_the_oracle_and_have_exact_sizes() {
    runner()
        .run(&table_strategy(), |(n, d, k, values)| {
            let t = equal_count_bands(&values, n, d, k).unwrap();
            prop_assert_eq!(&t.labels, &oracle(&values, n, d, k));
            for f in 0..n {
                let mut sizes = vec![0usize; k];
                for v in 0..d {
                    sizes[t.label(v, f) as usize] += 1;
                }
                let (lo, hi) = (sizes.iter().min().unwrap(), sizes.iter().max().unwrap());
                prop_assert!(hi - lo <= 1, "sizes {:?}", sizes);
                // Monotone: a smaller value never gets a higher band.
                for u in 0..d {
                    for v in 0..d {
                        let (xu, xv) = (values[f * d + u], values[f * d + v]);
                        if xu < xv || (xu == xv && u < v) {
                            prop_assert!(t.label(u, f) <= t.label(v, f));
                        }
                    }
                }
            }
            Ok(())
        })
        .unwrap();
}

#[test]
fn ties_are_broken_by_vertex_index() {
    let t = equal_count_bands(&[5.0; 6], 1, 6, 3).unwrap();
    assert_eq!(t.labels, vec![0, 0, 1, 1, 2, 2]);
    let w = area_weighted_bands(&[5.0; 6], &[1.0; 6], 1, 6, 3).unwrap();
    assert_eq!(w.labels, vec![0, 0, 1, 1, 2, 2]);
}

#[test]
fn area_weighted_bands_have_equal_area_up_to_one_vertex() {
    runner()
        .run(
            &(1usize..4, 2usize..150, 1usize..25).prop_flat_map(|(n, d, k)| {
                (
                    Just(n),
                    Just(d),
                    Just(k),
                    proptest::collection::vec(-1e3f64..1e3, n * d),
                    proptest::collection::vec(0.0f64..5.0, d),
                )
            }),
            |(n, d, k, values, mut weights)| {
                weights[0] += 0.1; // positive total
                let t = area_weighted_bands(&values, &weights, n, d, k).unwrap();
                let total: f64 = weights.iter().sum();
                let wmax = weights.iter().cloned().fold(0.0, f64::max);
                for f in 0..n {
                    let mut area = vec![0.0; k];
                    for v in 0..d {
                        area[t.label(v, f) as usize] += weights[v];
                    }
                    for (b, a) in area.iter().enumerate() {
                        prop_assert!(
                            (a - total / k as f64).abs() <= wmax + 1e-9 * total,
                            "band {} area {} target {} max weight {}",
                            b,
                            a,
                            total / k as f64,
                            wmax
                        );
                    }
                    for u in 0..d {
                        for v in 0..d {
                            if values[f * d + u] < values[f * d + v] {
                                prop_assert!(t.label(u, f) <= t.label(v, f));
                            }
                        }
                    }
                }
                Ok(())
            },
        )
        .unwrap();
}

#[test]
fn equal_weights_reduce_area_bands_to_count_bands_when_k_divides_d() {
    let (n, d, k) = (3, 60, 20);
    let values: Vec<f64> = (0..n * d)
        .map(|i| ((i * 7919) % 613) as f64 * 0.37)
        .collect();
    let a = area_weighted_bands(&values, &vec![0.25; d], n, d, k).unwrap();
    let c = equal_count_bands(&values, n, d, k).unwrap();
    assert_eq!(a, c);
}

#[test]
fn bands_permute_exactly_with_the_vertices() {
    let (n, d, k) = (4, 500, 20);
    let values: Vec<f64> = (0..n * d)
        .map(|i| ((i as f64) * 0.618).sin() * 1e3)
        .collect();
    let weights: Vec<f64> = (0..d).map(|i| 1.0 + (i % 7) as f64).collect();
    let perm = permutation(d, 3);
    let pv: Vec<f64> = (0..n)
        .flat_map(|f| perm.iter().map(move |&old| (f, old)))
        .map(|(f, old)| values[f * d + old])
        .collect();
    let pw: Vec<f64> = perm.iter().map(|&old| weights[old]).collect();
    let check = |a: &BandTable, b: &BandTable| {
        for (new, &old) in perm.iter().enumerate() {
            assert_eq!(b.row(new), a.row(old));
        }
    };
    check(
        &equal_count_bands(&values, n, d, k).unwrap(),
        &equal_count_bands(&pv, n, d, k).unwrap(),
    );
    check(
        &area_weighted_bands(&values, &weights, n, d, k).unwrap(),
        &area_weighted_bands(&pv, &pw, n, d, k).unwrap(),
    );
}

#[test]
fn bad_inputs_are_errors() {
    assert!(equal_count_bands(&[1.0, 2.0], 1, 2, 0).is_err());
    assert!(equal_count_bands(&[1.0, 2.0], 1, 2, 257).is_err());
    assert!(equal_count_bands(&[1.0, 2.0, 3.0], 1, 2, 2).is_err());
    assert!(equal_count_bands(&[1.0, f64::NAN], 1, 2, 2).is_err());
    assert!(area_weighted_bands(&[1.0, 2.0], &[1.0], 1, 2, 2).is_err());
    assert!(area_weighted_bands(&[1.0, 2.0], &[1.0, -1.0], 1, 2, 2).is_err());
    assert!(area_weighted_bands(&[1.0, 2.0], &[0.0, 0.0], 1, 2, 2).is_err());
    assert!(area_weighted_bands(&[1.0, 2.0], &[f64::NAN, 1.0], 1, 2, 2).is_err());
}

#[test]
fn band_table_uses_the_descriptors_vertex_areas() {
    let mesh = blob(2);
    let s = dense_spectrum(&mesh, 20).unwrap();
    let opts = {
        let mut opts = DescriptorOptions::default();
        opts.hks_count = 4;
        opts.wks_count = 4;
        opts.curvature_count = 4;
        opts
    };
    let f = descriptors(&mesh, &s, &opts).unwrap();
    let count = band_table(&f, &BandOptions::default()).unwrap();
    assert_eq!(
        count,
        equal_count_bands(&f.values, 12, f.vertices, 20).unwrap()
    );
    let area = band_table(&f, &{
        let mut opts = BandOptions::default();
        opts.bands = 20;
        opts.weighting = BandWeighting::Area;
        opts
    })
    .unwrap();
    assert_eq!(
        area,
        area_weighted_bands(&f.values, &s.vertex_areas, 12, f.vertices, 20).unwrap()
    );
    assert_eq!(
        (area.features, area.vertices, area.bands),
        (12, f.vertices, 20)
    );
}

#[test]
fn large_skewed_and_tied_features_match_the_oracle() {
    let d = 7001;
    let mut values = Vec::new();
    // Heavy tail, clusters of exact ties, both zeros, negatives, a wide dynamic range.
    values.extend((0..d).map(|i| ((i * 37 % 101) as f64).powi(6)));
    values.extend((0..d).map(|i| {
        if i % 3 == 0 {
            1.5
        } else {
            (i % 11) as f64 * 1e-300
        }
    }));
    values.extend((0..d).map(|i| if i % 2 == 0 { 0.0 } else { -0.0 }));
    values.extend((0..d).map(|i| ((i as f64) * 0.37).sin() * 1e12 + (i % 5) as f64 * 1e-3));
    values.extend((0..d).map(|i| 1.0 + (i % 2) as f64 * f64::EPSILON));
    let n = values.len() / d;
    for k in [2, 7, 20, 64, 256] {
        let t = equal_count_bands(&values, n, d, k).unwrap();
        assert_eq!(t.labels, oracle(&values, n, d, k), "K = {k}");
    }
}
