//! Tests of the feature stage: HKS, WKS, multiscale mean curvature, the scale rule, invariances,
//! determinism and export.

mod common;

use common::features::{blob, icosphere, permutation, permute_mesh, similarity, spearman};
use coseg::bands::{BandOptions, band_table};
use coseg::features::{
    DescriptorOptions, SpectralBand, descriptors, heat_kernel_signature, mean_curvature,
    multiscale_mean_curvature, scale_grid, wave_kernel_signature,
};
use coseg::output::{ExportFormat, ExportOptions, export_features};
use coseg::spectral::{Spectrum, dense_spectrum};

fn small_opts() -> DescriptorOptions {
    let mut opts = DescriptorOptions::default();
    opts.hks_count = 16;
    opts.wks_count = 16;
    opts.curvature_count = 16;
    opts
}

/// A synthetic spectrum (not from a mesh) with deterministic pseudo-random entries.
fn synthetic_spectrum(d: usize, k: usize) -> Spectrum {
    let mut s = 12345u64;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    let eigenvalues: Vec<f64> = (0..k)
        .map(|i| {
            if i == 0 {
                0.0
            } else {
                12.0 * i as f64 + 5.0 * next()
            }
        })
        .collect();
    let eigenvectors: Vec<f64> = (0..d * k).map(|_| next()).collect();
    Spectrum {
        eigenvalues,
        eigenvectors,
        vertex_areas: vec![1.0 / d as f64; d],
        original_area: 1.0,
    }
}

#[test]
fn mean_curvature_is_one_over_radius_on_spheres() {
    let sphere = icosphere(4);
    let h = mean_curvature(&sphere);
    let worst = h.iter().map(|x| (x - 1.0).abs()).fold(0.0, f64::max);
    assert!(worst < 2e-5, "max |H - 1| = {worst}");
    // Radius 2: H = 1/2.
    let big = sphere
        .map_positions(|p| [2.0 * p[0], 2.0 * p[1], 2.0 * p[2]])
        .unwrap();
    assert!(mean_curvature(&big).iter().all(|x| (x - 0.5).abs() < 1e-5));
    // Inward orientation flips the sign.
    let flipped = coseg::mesh::TriMesh::new(
        sphere.positions().to_vec(),
        sphere.faces().iter().map(|f| [f[0], f[2], f[1]]).collect(),
    )
    .unwrap();
    assert!(
        mean_curvature(&flipped)
            .iter()
            .all(|x| (x + 1.0).abs() < 2e-5)
    );
}

#[test]
fn mean_curvature_is_one_on_a_fine_icosphere() {
    let h = mean_curvature(&icosphere(5));
    let worst = h.iter().map(|x| (x - 1.0).abs()).fold(0.0, f64::max);
    assert!(worst < 5e-6, "max |H - 1| = {worst}");
}

#[test]
fn multiscale_curvature_of_a_sphere_is_the_unit_area_constant() {
    let sphere = icosphere(3);
    let s = dense_spectrum(&sphere, 40).unwrap();
    let times = [1e-3, 1e-2, 0.1];
    let h = multiscale_mean_curvature(&sphere, &s, &times).unwrap();
    // H = 1 at the vertices; unit-area scaling multiplies it by sqrt(area) (slightly below
    // sqrt(4π) for the inscribed polyhedron).
    let expect = sphere.total_area().sqrt();
    assert!((expect / (4.0 * std::f64::consts::PI).sqrt() - 1.0).abs() < 1e-2);
    let worst = h
        .iter()
        .map(|x| (x / expect - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-4, "max relative error {worst}");
}

#[test]
fn hks_and_wks_match_the_direct_formulas() {
    // d > one row block (1024) so the blocked product is exercised across blocks.
    let (d, k) = (2500, 25);
    let s = synthetic_spectrum(d, k);
    let times = [1e-3, 0.01, 0.05];
    let hks = heat_kernel_signature(&s, &times);
    for (j, &t) in times.iter().enumerate() {
        for v in (0..d).step_by(7) {
            let direct: f64 = (0..k)
                .map(|i| (-s.eigenvalues[i] * t).exp() * s.eigenvector(i)[v].powi(2))
                .sum();
            assert!((hks[j * d + v] - direct).abs() <= 1e-12 * direct.abs().max(1.0));
        }
    }
    let energies = [3.0, 4.5, 5.5];
    let sigma = 0.3;
    let wks = wave_kernel_signature(&s, &energies, sigma, 1e-5);
    for (j, &e) in energies.iter().enumerate() {
        let w: Vec<f64> = (1..k)
            .map(|i| (-(e - s.eigenvalues[i].ln()).powi(2) / (2.0 * sigma * sigma)).exp())
            .collect();
        let total: f64 = w.iter().sum();
        for v in (0..d).step_by(7) {
            let direct: f64 = (1..k)
                .map(|i| w[i - 1] * s.eigenvector(i)[v].powi(2))
                .sum::<f64>()
                / total;
            assert!(
                (wks[j * d + v] - direct).abs() <= 1e-12 * direct.abs().max(1.0),
                "wks {j} {v}: {} vs {direct}",
                wks[j * d + v]
            );
        }
    }
}

#[test]
fn wks_is_finite_far_outside_the_spectrum() {
    let s = synthetic_spectrum(50, 10);
    let w = wave_kernel_signature(&s, &[40.0, -40.0], 0.1, 1e-5);
    assert!(w.iter().all(|x| x.is_finite()));
}

#[test]
fn scale_grid_follows_the_documented_rule() {
    let k = 200;
    let g = scale_grid(&SpectralBand::Weyl, k, 100, 100, 50, 7.0).unwrap();
    let four_pi = 4.0 * std::f64::consts::PI;
    let c = 4.0 * std::f64::consts::LN_10;
    assert!((g.hks_times[0] - c / (four_pi * k as f64)).abs() < 1e-15);
    assert!((g.hks_times[99] - c / four_pi).abs() < 1e-12);
    assert_eq!(g.curvature_times.len(), 50);
    // Log-spaced: constant ratio.
    let r0 = g.hks_times[1] / g.hks_times[0];
    assert!(
        g.hks_times
            .windows(2)
            .all(|w| ((w[1] / w[0]) / r0 - 1.0).abs() < 1e-9)
    );
    // WKS: sigma = 7 (ln hi - ln lo) / n, energies evenly spaced within [lo + 2σ, hi - 2σ].
    let (lo, hi) = (four_pi.ln(), (four_pi * k as f64).ln());
    assert!((g.wks_sigma - 7.0 * (hi - lo) / 100.0).abs() < 1e-12);
    assert!((g.wks_energies[0] - (lo + 2.0 * g.wks_sigma)).abs() < 1e-12);
    assert!((g.wks_energies[99] - (hi - 2.0 * g.wks_sigma)).abs() < 1e-12);
    // Invalid bands are errors, not panics.
    assert!(
        scale_grid(
            &SpectralBand::Fixed {
                lambda_min: 0.0,
                lambda_max: 1.0
            },
            k,
            1,
            1,
            1,
            7.0
        )
        .is_err()
    );
    assert!(
        scale_grid(
            &SpectralBand::Fixed {
                lambda_min: 5.0,
                lambda_max: 2.0
            },
            k,
            1,
            1,
            1,
            7.0
        )
        .is_err()
    );
}

#[test]
fn scale_grid_is_the_same_on_shapes_with_different_spectra() {
    let k = 30;
    let a = icosphere(2);
    let b = blob(2);
    let (sa, sb) = (
        dense_spectrum(&a, k).unwrap(),
        dense_spectrum(&b, k).unwrap(),
    );
    // The shapes' own ranges really differ…
    assert!((sa.eigenvalues[1] / sb.eigenvalues[1] - 1.0).abs() > 0.05);
    assert!((sa.eigenvalues[k - 1] / sb.eigenvalues[k - 1] - 1.0).abs() > 0.01);
    let (fa, fb) = (
        descriptors(&a, &sa, &small_opts()).unwrap(),
        descriptors(&b, &sb, &small_opts()).unwrap(),
    );
    // …but the grids are bit-identical and equal to the rule's.
    assert_eq!(fa.hks_times, fb.hks_times);
    assert_eq!(fa.wks_energies, fb.wks_energies);
    assert_eq!(fa.wks_sigma.to_bits(), fb.wks_sigma.to_bits());
    assert_eq!(fa.curvature_times, fb.curvature_times);
    let g = scale_grid(&SpectralBand::Weyl, k, 16, 16, 16, 7.0).unwrap();
    assert_eq!(fa.hks_times, g.hks_times);
    assert_eq!(fa.wks_energies, g.wks_energies);
}

fn max_rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
        / scale
}

#[test]
fn features_are_invariant_to_rigid_motion_and_scaling() {
    let k = 50;
    let mesh = blob(3);
    let opts = small_opts();
    let s = dense_spectrum(&mesh, k).unwrap();
    let f = descriptors(&mesh, &s, &opts).unwrap();
    let bands = band_table(&f, &BandOptions::default()).unwrap();
    for scale in [1.0, 3.7, 0.05] {
        let moved = similarity(&mesh, scale);
        let sm = dense_spectrum(&moved, k).unwrap();
        let fm = descriptors(&moved, &sm, &opts).unwrap();
        for feat in 0..f.feature_count() {
            let diff = max_rel_diff(f.feature(feat), fm.feature(feat));
            assert!(
                diff < 1e-7,
                "scale {scale}, feature {feat}: relative difference {diff}"
            );
            assert!(spearman(f.feature(feat), fm.feature(feat)) > 0.99999);
        }
        let bm = band_table(&fm, &BandOptions::default()).unwrap();
        let differ = bands
            .labels
            .iter()
            .zip(&bm.labels)
            .filter(|(a, b)| a != b)
            .count();
        let off_by_more = bands
            .labels
            .iter()
            .zip(&bm.labels)
            .filter(|(a, b)| a.abs_diff(**b) > 1)
            .count();
        assert_eq!(off_by_more, 0);
        assert!(
            differ * 1000 <= bands.labels.len(),
            "{differ} labels changed"
        );
    }
}

#[test]
fn a_vertex_permutation_permutes_features_and_bands() {
    let k = 50;
    let mesh = blob(3);
    let perm = permutation(mesh.vertex_count(), 7);
    let pm = permute_mesh(&mesh, &perm);
    let opts = small_opts();
    let (s, sp) = (
        dense_spectrum(&mesh, k).unwrap(),
        dense_spectrum(&pm, k).unwrap(),
    );
    let (f, fp) = (
        descriptors(&mesh, &s, &opts).unwrap(),
        descriptors(&pm, &sp, &opts).unwrap(),
    );
    let d = mesh.vertex_count();
    for feat in 0..f.feature_count() {
        let permuted: Vec<f64> = perm.iter().map(|&old| f.feature(feat)[old]).collect();
        let diff = max_rel_diff(&permuted, fp.feature(feat));
        assert!(diff < 1e-8, "feature {feat}: {diff}");
    }
    let (b, bp) = (
        band_table(&f, &BandOptions::default()).unwrap(),
        band_table(&fp, &BandOptions::default()).unwrap(),
    );
    let n = f.feature_count();
    for (new, &old) in perm.iter().enumerate() {
        assert_eq!(bp.row(new), b.row(old), "vertex {new} (was {old})");
    }
    let area = {
        let mut opts = BandOptions::default();
        opts.bands = 20;
        opts.weighting = coseg::bands::BandWeighting::Area;
        opts
    };
    let (a, ap) = (
        band_table(&f, &area).unwrap(),
        band_table(&fp, &area).unwrap(),
    );
    for (new, &old) in perm.iter().enumerate() {
        assert_eq!(
            ap.row(new),
            a.row(old),
            "area bands, vertex {new} (was {old})"
        );
    }
    assert_eq!(bp.labels.len(), d * n);
}

#[test]
fn output_is_bitwise_identical_across_runs_and_thread_counts() {
    let mesh = blob(3);
    let s = dense_spectrum(&mesh, 40).unwrap();
    let run = |threads: usize| {
        crate::common::on_threads(threads, || descriptors(&mesh, &s, &small_opts()).unwrap())
    };
    let (a, b, c) = (run(1), run(2), run(3));
    let bits =
        |f: &coseg::features::Descriptors| f.values.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(bits(&a), bits(&c));
    assert_eq!(bits(&a), bits(&run(2)));
}

#[test]
fn mismatched_spectrum_is_an_error() {
    let s = dense_spectrum(&blob(1), 10).unwrap();
    assert!(descriptors(&blob(2), &s, &small_opts()).is_err());
}

#[test]
fn export_writes_readable_npy_and_csv() {
    let mesh = blob(2);
    let s = dense_spectrum(&mesh, 20).unwrap();
    let f = descriptors(&mesh, &s, &small_opts()).unwrap();
    let b = band_table(&f, &BandOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (d, n) = (f.vertices, f.feature_count());
    export_features(dir.path(), &f, &b, Some(&s), &ExportOptions::default()).unwrap();
    let bytes = std::fs::read(dir.path().join("descriptors.npy")).unwrap();
    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
    assert_eq!(npy.shape(), &[d as u64, n as u64]);
    let data: Vec<f64> = npy.into_vec().unwrap();
    for v in 0..d {
        for k in 0..n {
            assert_eq!(data[v * n + k].to_bits(), f.feature(k)[v].to_bits());
        }
    }
    let bytes = std::fs::read(dir.path().join("bands.npy")).unwrap();
    let labels: Vec<u8> = npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap();
    assert_eq!(labels, b.labels);
    let bytes = std::fs::read(dir.path().join("eigenvectors.npy")).unwrap();
    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
    assert_eq!(npy.shape(), &[d as u64, 20]);
    let ev: Vec<f64> = npy.into_vec().unwrap();
    assert_eq!(ev[3 * 20 + 5], s.eigenvector(5)[3]);

    export_features(dir.path(), &f, &b, None, &{
        let mut opts = ExportOptions::default();
        opts.format = ExportFormat::Csv;
        opts
    })
    .unwrap();
    let text = std::fs::read_to_string(dir.path().join("descriptors.csv")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), d + 1);
    assert!(lines[0].starts_with("hks_000,"));
    let first: Vec<f64> = lines[1].split(',').map(|x| x.parse().unwrap()).collect();
    assert_eq!(first.len(), n);
    assert_eq!(first[n - 1].to_bits(), f.feature(n - 1)[0].to_bits());
}
