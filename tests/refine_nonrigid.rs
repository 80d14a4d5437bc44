//! `propagate::refine_nonrigid` and the rigid route's non-rigid step on synthetic shapes.

use coseg::mesh::TriMesh;
use coseg::propagate::{AffineMap, RigidSteps, refine_nonrigid, rigid_route};

/// Smooth step from 0 (at `a − w`) to 1 (at `a + w`).
fn step(x: f64, a: f64, w: f64) -> f64 {
    let t = ((x - a + w) / (2.0 * w)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A closed-ended tube along x: a head of radius 1 on `[0, 1]`, a neck of radius 0.3 up to
/// `neck_end`, a second head of radius 0.7 up to `neck_end + 1` (the heads differ, so the
/// shape has one orientation). Per vertex the part it belongs to (0 head, 1 neck, 2 other
/// head), read off its position along the axis.
fn dumbbell(neck_end: f64, along: usize, around: usize) -> (TriMesh, Vec<i32>) {
    let length = neck_end + 1.0;
    let radius = |x: f64| {
        let r = 1.0 - 0.7 * step(x, 1.0, 0.1) + 0.4 * step(x, neck_end, 0.1);
        // Rounded ends, so the caps are not flat discs of the same size as the heads.
        let end = (x.min(length - x) / 0.3).clamp(0.0, 1.0);
        r * (0.35 + 0.65 * end.sqrt())
    };
    let mut positions = Vec::new();
    let mut labels = Vec::new();
    for i in 0..along {
        let x = length * i as f64 / (along - 1) as f64;
        let r = radius(x);
        for j in 0..around {
            let a = std::f64::consts::TAU * j as f64 / around as f64;
            positions.push([x, r * a.cos(), r * a.sin()]);
            labels.push(if x < 1.0 {
                0
            } else if x < neck_end {
                1
            } else {
                2
            });
        }
    }
    let mut faces = Vec::new();
    let id = |i: usize, j: usize| (i * around + j % around) as u32;
    for i in 0..along - 1 {
        for j in 0..around {
            faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            faces.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    // Caps: a centre vertex at each end.
    for (i, x, l) in [(0usize, 0.0, 0), (along - 1, length, 2)] {
        let c = positions.len() as u32;
        positions.push([x, 0.0, 0.0]);
        labels.push(l);
        for j in 0..around {
            if i == 0 {
                faces.push([c, id(i, j + 1), id(i, j)]);
            } else {
                faces.push([c, id(i, j), id(i, j + 1)]);
            }
        }
    }
    (TriMesh::new(positions, faces).unwrap(), labels)
}

fn accuracy(mesh: &TriMesh, labels: &[i32], truth: &[i32]) -> f64 {
    let areas = mesh.vertex_areas();
    let total: f64 = areas.iter().sum();
    labels
        .iter()
        .zip(truth)
        .zip(&areas)
        .filter(|((a, b), _)| a == b)
        .map(|(_, w)| w)
        .sum::<f64>()
        / total
}

/// A copy whose neck is twice as long: no affine map puts both heads on the source's heads
/// (stretching the whole shape lands the source's necks on the target's heads), a deformation
/// does.
#[test]
fn a_longer_neck_takes_its_labels_better_deformed_than_affine() {
    let (source, source_labels) = dumbbell(3.0, 81, 24);
    let (target, truth) = dumbbell(5.0, 97, 20);
    let meshes = [source, target];
    let annotations = [Some(source_labels), None];
    let affine = RigidSteps {
        affine: true,
        nonrigid: false,
    };
    let nonrigid = RigidSteps {
        affine: true,
        nonrigid: true,
    };
    let (a, wa) = rigid_route(&meshes, &annotations, affine);
    let (n, wn) = rigid_route(&meshes, &annotations, nonrigid);
    assert!(wa.is_empty() && wn.is_empty(), "{wa:?} {wn:?}");
    let acc_a = accuracy(&meshes[1], &a.labels[1], &truth);
    let acc_n = accuracy(&meshes[1], &n.labels[1], &truth);
    assert!(
        acc_n > acc_a + 0.03 && acc_n > 0.9,
        "affine {acc_a:.3}, non-rigid {acc_n:.3}"
    );
    // The deformation's residual is below the affine one's.
    assert!(
        n.residual[1] < a.residual[1],
        "{:?} {:?}",
        n.residual,
        a.residual
    );
}

/// Same inputs, same bytes.
#[test]
fn the_deformation_is_deterministic() {
    let (source, _) = dumbbell(3.0, 41, 16);
    let (target, _) = dumbbell(4.0, 45, 14);
    let start = AffineMap {
        matrix: [[0.8, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        translation: [0.0, 0.0, 0.0],
    };
    let bits = |f: &coseg::propagate::NonrigidFit| -> Vec<u64> {
        f.deformed
            .iter()
            .flatten()
            .map(|x| x.to_bits())
            .chain([f.residual.to_bits(), f.levels as u64])
            .collect()
    };
    let a = refine_nonrigid(&source, &target, &start, 0.9);
    let b = refine_nonrigid(&source, &target, &start, 0.9);
    assert!(a.levels > 0, "the stretched copy should be deformed");
    assert!(a.residual < a.start_residual);
    assert_eq!(bits(&a), bits(&b));
}

/// Tiny meshes and a target far coarser than its source: no panic, and a source too small
/// for a node neighbourhood keeps the start.
#[test]
fn degenerate_inputs_keep_the_start_or_deform_without_panic() {
    let triangle = TriMesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2]],
    )
    .unwrap();
    let tetra = TriMesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
    .unwrap();
    let identity = AffineMap {
        matrix: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        translation: [0.0, 0.0, 0.0],
    };
    for (s, t) in [(&triangle, &tetra), (&tetra, &triangle), (&tetra, &tetra)] {
        let fit = refine_nonrigid(s, t, &identity, 0.9);
        assert_eq!(fit.levels, 0);
        assert_eq!(fit.deformed, s.positions());
    }
    let (fine, fine_labels) = dumbbell(3.0, 81, 24);
    let (coarse, _) = dumbbell(4.0, 7, 4);
    let fit = refine_nonrigid(&fine, &coarse, &identity, 0.9);
    assert_eq!(fit.deformed.len(), fine.vertex_count());
    assert!(fit.deformed.iter().flatten().all(|x| x.is_finite()));
    let fit = refine_nonrigid(&coarse, &fine, &identity, 0.9);
    assert!(fit.deformed.iter().flatten().all(|x| x.is_finite()));
    // A zero trim share is no fit at all.
    assert_eq!(refine_nonrigid(&fine, &coarse, &identity, 0.0).levels, 0);
    // Through the route: every target labelled.
    let steps = RigidSteps {
        affine: true,
        nonrigid: true,
    };
    let meshes = [fine, coarse, tetra];
    let (r, _) = rigid_route(&meshes, &[Some(fine_labels), None, None], steps);
    assert_eq!(r.labels[1].len(), meshes[1].vertex_count());
    assert_eq!(r.labels[2].len(), meshes[2].vertex_count());
}
