//! Tests of the feature families beyond the spectrum (src/features/{extrinsic,sdf,user}.rs):
//! oracles, invariances, the alignment rule and determinism.

mod common;

use common::features::{blob, icosphere, similarity};
use coseg::bands::equal_count_bands;
use coseg::features::{
    Alignment, Axis, ExtrinsicOptions, FeatureColumns, extrinsic_features, height_directions,
    shape_frame,
};
use coseg::mesh::TriMesh;

fn ext(directions: usize, alignment: Alignment) -> ExtrinsicOptions {
    let mut o = ExtrinsicOptions::default();
    o.directions = directions;
    o.alignment = alignment;
    o
}

fn up(s: &str) -> Alignment {
    Alignment::Up(s.parse().unwrap())
}

fn bands_of(c: &FeatureColumns) -> Vec<u8> {
    equal_count_bands(&c.values, c.len(), c.vertices, 20)
        .unwrap()
        .labels
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn axis_parses_signs_and_rejects_junk() {
    assert_eq!(
        "-Z".parse::<Axis>().unwrap(),
        Axis {
            index: 2,
            positive: false
        }
    );
    assert_eq!("+x".parse::<Axis>().unwrap(), "x".parse::<Axis>().unwrap());
    assert!("w".parse::<Axis>().is_err());
    assert!("".parse::<Axis>().is_err());
}

#[test]
fn height_directions_are_unit_and_cover_the_hemisphere() {
    let d = height_directions(200, true);
    assert!(d.iter().all(|u| u[2] > 0.0));
    // The mean of a uniform cover of the upper hemisphere is (0, 0, 1/2).
    let mean: Vec<f64> = (0..3)
        .map(|k| d.iter().map(|u| u[k]).sum::<f64>() / 200.0)
        .collect();
    assert!(mean[0].abs() < 0.02 && mean[1].abs() < 0.02, "{mean:?}");
    assert!((mean[2] - 0.5).abs() < 0.01, "{mean:?}");
    let full = height_directions(200, false);
    assert!(full.iter().any(|u| u[2] < -0.9) && full.iter().any(|u| u[2] > 0.9));
    for u in d.iter().chain(&full) {
        assert!((u[0] * u[0] + u[1] * u[1] + u[2] * u[2] - 1.0).abs() < 1e-12);
    }
}

#[test]
fn distances_on_a_sphere_are_the_unit_area_radius_and_the_axis_distance() {
    let m = icosphere(3);
    let c = extrinsic_features(&m, &ext(0, up("+y"))).unwrap();
    assert_eq!(c.names, ["ext_centroid", "ext_axis"]);
    let s = 1.0 / m.total_area().sqrt();
    for (v, p) in m.positions().iter().enumerate() {
        assert!(
            (c.column(0)[v] - s).abs() < 1e-9,
            "centroid distance at {v}"
        );
        let axis = (p[0] * p[0] + p[2] * p[2]).sqrt() * s;
        assert!((c.column(1)[v] - axis).abs() < 1e-9, "axis distance at {v}");
    }
}

#[test]
fn the_up_rule_is_a_cyclic_frame_so_relabelled_axes_give_identical_columns() {
    // Up = +Y on M is the frame (z, x, y); M' = (z, x, y) with up = +Z is the same frame.
    let m = blob(2);
    let cyc = m.map_positions(|p| [p[2], p[0], p[1]]).unwrap();
    let a = extrinsic_features(&m, &ext(30, up("+y"))).unwrap();
    let b = extrinsic_features(&cyc, &ext(30, up("+z"))).unwrap();
    assert_eq!(a, b);
    // The negative axis turns the shape upside down: heights along the up direction reverse.
    let neg = extrinsic_features(&m, &ext(30, up("-y"))).unwrap();
    let f = shape_frame(&m, up("-y"));
    assert_eq!(f.axes[2], [0.0, -1.0, 0.0]);
    assert_ne!(a.column(0), neg.column(0));
}

#[test]
fn extrinsic_columns_ignore_translation_and_uniform_scaling() {
    let m = blob(2);
    let moved = m
        .map_positions(|p| [2.5 * p[0] + 7.0, 2.5 * p[1] - 3.0, 2.5 * p[2] + 0.5])
        .unwrap();
    let a = extrinsic_features(&m, &ext(40, up("z"))).unwrap();
    let b = extrinsic_features(&moved, &ext(40, up("z"))).unwrap();
    assert!(max_abs_diff(&a.values, &b.values) < 1e-9);
}

#[test]
fn a_rotated_copy_gets_the_same_bands_after_pca_alignment() {
    let m = blob(3);
    let rotated = similarity(&m, 1.7);
    let a = extrinsic_features(&m, &ext(60, Alignment::Pca)).unwrap();
    let b = extrinsic_features(&rotated, &ext(60, Alignment::Pca)).unwrap();
    assert!(max_abs_diff(&a.values, &b.values) < 1e-9);
    assert_eq!(bands_of(&a), bands_of(&b));
    // Without alignment the rotation does change the bands (so the test can fail).
    let c = extrinsic_features(&rotated, &ext(60, up("z"))).unwrap();
    let d = extrinsic_features(&m, &ext(60, up("z"))).unwrap();
    assert_ne!(bands_of(&c), bands_of(&d));
}

#[test]
fn pca_sign_rule_makes_a_mirror_image_give_the_same_columns() {
    let m = blob(2);
    let mirrored = m.map_positions(|p| [-p[0], p[1], p[2]]).unwrap();
    let a = extrinsic_features(&m, &ext(30, Alignment::Pca)).unwrap();
    let b = extrinsic_features(&mirrored, &ext(30, Alignment::Pca)).unwrap();
    assert!(max_abs_diff(&a.values, &b.values) < 1e-9);
}

#[test]
fn pca_up_is_the_axis_of_largest_variance() {
    // A long thin box along x: up must be ±x.
    let m = icosphere(2)
        .map_positions(|p| [5.0 * p[0], p[1], 0.5 * p[2]])
        .unwrap();
    let f = shape_frame(&m, Alignment::Pca);
    assert!(f.axes[2][0].abs() > 0.999, "{:?}", f.axes);
    assert!(f.axes[0][2].abs() > 0.999, "{:?}", f.axes);
}

#[test]
fn an_extrinsic_family_without_columns_is_an_error() {
    let mut o = ext(0, up("y"));
    o.centroid_distance = false;
    o.axis_distance = false;
    let m = TriMesh::new(
        vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]],
        vec![[0, 1, 2]],
    )
    .unwrap();
    assert!(extrinsic_features(&m, &o).is_err());
}
