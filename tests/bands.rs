//! Tests of the band tables: equal-count and area-weighted bands, tie-breaking, permutations,
//! and the parallel engine against a sequential oracle.

mod common;

use common::features::{blob, permutation};
use coseg::bands::{
    BandOptions, BandTable, BandWeighting, area_weighted_bands, band_table, equal_count_bands,
    fixed_range_bands,
};
use coseg::features::{
    DescriptorOptions, Descriptors, ExtrinsicOptions, descriptors, extrinsic_features,
};
use coseg::mesh::TriMesh;
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

/// Exact oracle: each value is drawn inside a known band, away from its edges, or exactly on
/// an edge (which belongs to the band above it), or beyond the range (the end bands).
#[test]
fn fixed_range_bands_put_every_value_in_its_interval() {
    let strategy = (1usize..40, -5.0f64..5.0, 0.01f64..10.0).prop_flat_map(|(k, lo, width)| {
        let value = (0..k, 0.001f64..0.999, 0u8..4).prop_map(move |(b, frac, kind)| {
            let step = width / k as f64;
            match kind {
                0 => (lo - 1.0 - frac, 0),
                1 => (lo + width + frac, k - 1),
                _ => (lo + (b as f64 + frac) * step, b),
            }
        });
        (
            Just(k),
            Just([lo, lo + width]),
            proptest::collection::vec(value, 1..60),
        )
    });
    runner()
        .run(&strategy, |(k, range, pairs)| {
            let (values, want): (Vec<f64>, Vec<usize>) = pairs.into_iter().unzip();
            let got = fixed_range_bands(&values, range, k).unwrap();
            let got: Vec<usize> = got.into_iter().map(usize::from).collect();
            prop_assert_eq!(got, want);
            Ok(())
        })
        .unwrap();
    // Edges belong to the band above; the ends and infinities clamp.
    let edges = [
        0.0,
        0.25,
        0.5,
        0.75,
        1.0,
        -1.0,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    assert_eq!(
        fixed_range_bands(&edges, [0.0, 1.0], 4).unwrap(),
        vec![0, 1, 2, 3, 3, 0, 3, 0]
    );
    assert_eq!(
        fixed_range_bands(&[0.3, 0.7], [0.0, 1.0], 256).unwrap(),
        vec![76, 179]
    );
}

#[test]
fn fixed_range_bands_refuse_bad_input() {
    assert!(fixed_range_bands(&[0.5], [0.0, 1.0], 0).is_err());
    assert!(fixed_range_bands(&[0.5], [0.0, 1.0], 257).is_err());
    assert!(fixed_range_bands(&[0.5], [1.0, 1.0], 4).is_err());
    assert!(fixed_range_bands(&[0.5], [1.0, 0.0], 4).is_err());
    assert!(fixed_range_bands(&[0.5], [0.0, f64::INFINITY], 4).is_err());
    assert!(fixed_range_bands(&[0.5], [f64::NAN, 1.0], 4).is_err());
    let e = fixed_range_bands(&[0.5, f64::NAN], [0.0, 1.0], 4).unwrap_err();
    assert!(
        matches!(e, coseg::bands::BandError::NaN { vertex: 1, .. }),
        "{e}"
    );
    assert_eq!(
        fixed_range_bands(&[], [0.0, 1.0], 4).unwrap(),
        Vec::<u8>::new()
    );
}

/// Spectral descriptors (3 per kind) of `mesh` followed by the extrinsic family with `up = z`,
/// 3 height directions and `normals` normal columns.
fn with_extrinsic(mesh: &TriMesh, normals: usize) -> Descriptors {
    let s = dense_spectrum(mesh, 12).unwrap();
    let mut opts = DescriptorOptions::default();
    (opts.hks_count, opts.wks_count, opts.curvature_count) = (3, 3, 3);
    let mut d = descriptors(mesh, &s, &opts).unwrap();
    let mut e = ExtrinsicOptions::default();
    e.alignment = coseg::features::Alignment::Up("z".parse().unwrap());
    (e.directions, e.normal_directions) = (3, normals);
    let c = extrinsic_features(mesh, &e).unwrap();
    let n = c.len();
    d.append(c, [n, 0, 0]).unwrap();
    d
}

#[test]
fn band_table_cuts_the_normal_columns_by_value_and_the_rest_by_rank() {
    let mesh = blob(2);
    let f = with_extrinsic(&mesh, 5);
    let ranges = f.value_ranges();
    let n = f.feature_count();
    assert_eq!(ranges.iter().filter(|r| r.is_some()).count(), 5);
    assert!(ranges[..n - 5].iter().all(Option::is_none));
    for weighting in [BandWeighting::Count, BandWeighting::Area] {
        let mut o = BandOptions::default();
        o.weighting = weighting;
        let t = band_table(&f, &o).unwrap();
        let ranked = match weighting {
            BandWeighting::Count => equal_count_bands(&f.values, n, f.vertices, 20),
            BandWeighting::Area => {
                area_weighted_bands(&f.values, &f.vertex_areas, n, f.vertices, 20)
            }
        }
        .unwrap();
        for (k, range) in ranges.iter().enumerate() {
            let want: Vec<u8> = match range {
                Some(r) => fixed_range_bands(f.feature(k), *r, 20).unwrap(),
                None => (0..f.vertices).map(|v| ranked.label(v, k)).collect(),
            };
            let got: Vec<u8> = (0..f.vertices).map(|v| t.label(v, k)).collect();
            assert_eq!(got, want, "feature {k}");
        }
    }
}

/// The reason for fixed-range bands: a patch's normal bands do not depend on what else the
/// shape holds. A horizontal plate alone and the same plate beside a vertical wall give its
/// vertices the same normal bands (rank bands would move them: checked, so the test can fail).
#[test]
fn a_patch_keeps_its_normal_bands_whatever_else_the_shape_holds() {
    let plate = common::mesh::grid(8);
    let wall_positions: Vec<[f64; 3]> = plate
        .positions()
        .iter()
        .map(|p| [p[0] + 2.0, p[2], p[1]])
        .collect();
    let offset = plate.vertex_count() as u32;
    let mut positions = plate.positions().to_vec();
    positions.extend(wall_positions);
    let mut faces = plate.faces().to_vec();
    faces.extend(plate.faces().iter().map(|t| t.map(|i| i + offset)));
    let both = TriMesh::new(positions, faces).unwrap();
    let (a, b) = (with_extrinsic(&plate, 6), with_extrinsic(&both, 6));
    let (ta, tb) = (
        band_table(&a, &BandOptions::default()).unwrap(),
        band_table(&b, &BandOptions::default()).unwrap(),
    );
    let ranges = a.value_ranges();
    let normal_columns: Vec<usize> = (0..a.feature_count())
        .filter(|&k| ranges[k].is_some())
        .collect();
    assert_eq!(normal_columns.len(), 6);
    let mut rank_moved = false;
    for &k in &normal_columns {
        let ra = equal_count_bands(a.feature(k), 1, a.vertices, 20).unwrap();
        let rb = equal_count_bands(&b.feature(k)[..a.vertices], 1, a.vertices, 20).unwrap();
        let rb_in_both = equal_count_bands(b.feature(k), 1, b.vertices, 20).unwrap();
        rank_moved |= (0..a.vertices).any(|v| ra.labels[v] != rb_in_both.labels[v]);
        assert_eq!(
            ra, rb,
            "the plate's normal values are the same in both meshes"
        );
        for v in 0..a.vertices {
            assert_eq!(ta.label(v, k), tb.label(v, k), "feature {k}, vertex {v}");
        }
    }
    assert!(
        rank_moved,
        "rank bands would have moved the plate's normal bands"
    );
}
