//! `propagate::refine_nonrigid` and the rigid route's non-rigid step on synthetic shapes.

mod common;

use coseg::align::SurfaceIndex;
use coseg::mesh::TriMesh;
use coseg::propagate::{AffineMap, RigidSteps, refine_nonrigid, rigid_route};

/// Smooth step from 0 (at `a − w`) to 1 (at `a + w`).
fn step(x: f64, a: f64, w: f64) -> f64 {
    let t = ((x - a + w) / (2.0 * w)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The side of a tube of `along` rings of `around` vertices each (ring `i`'s vertex `j` at
/// index `i · around + j`): two triangles per quad, wound the same way round.
fn ring_faces(along: usize, around: usize) -> Vec<[u32; 3]> {
    let id = |i: usize, j: usize| (i * around + j % around) as u32;
    let mut faces = Vec::new();
    for i in 0..along - 1 {
        for j in 0..around {
            faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            faces.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    faces
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
    let mut faces = ring_faces(along, around);
    let id = |i: usize, j: usize| (i * around + j % around) as u32;
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

/// Share of the vertices labelled right: the tube's vertices are evenly spaced along its
/// axis, so this weighs each part by its length (by area the thin neck would hardly count).
fn accuracy(labels: &[i32], truth: &[i32]) -> f64 {
    let right = labels.iter().zip(truth).filter(|(a, b)| a == b).count();
    right as f64 / truth.len() as f64
}

/// An open tube of length 4 along a centreline straight up to its middle and then turned by
/// `bend` radians in the xy-plane, tapering from radius 0.35 to 0.25 (so it has one
/// orientation). Per vertex its half (0 before the middle, 1 after), by arc length.
fn bent_tube(bend: f64, along: usize, around: usize) -> (TriMesh, Vec<i32>) {
    let length = 4.0;
    let mut positions = Vec::new();
    let mut labels = Vec::new();
    for i in 0..along {
        let s = length * i as f64 / (along - 1) as f64;
        // Direction turned gradually over a short knee, so the rings do not cross.
        let turn = bend * step(s, 2.0, 0.25);
        let d = [turn.cos(), turn.sin(), 0.0];
        // Centre: integral of the direction, by the midpoint rule on a fine grid.
        let mut c = [0.0, 0.0, 0.0];
        let n = 400;
        for k in 0..n {
            let u = s * (k as f64 + 0.5) / n as f64;
            let t = bend * step(u, 2.0, 0.25);
            c[0] += t.cos() * s / n as f64;
            c[1] += t.sin() * s / n as f64;
        }
        let r = 0.35 - 0.1 * s / length;
        let n1 = [-d[1], d[0], 0.0];
        for j in 0..around {
            let a = std::f64::consts::TAU * j as f64 / around as f64;
            positions.push([
                c[0] + r * (a.cos() * n1[0]),
                c[1] + r * (a.cos() * n1[1]),
                r * a.sin(),
            ]);
            labels.push(i32::from(s >= 2.0));
        }
    }
    let faces = ring_faces(along, around);
    (TriMesh::new(positions, faces).unwrap(), labels)
}

/// Per target vertex, the label of the nearest corner of the closest point of the source
/// surface with vertices `positions` (the source's faces).
fn read_labels(
    source: &TriMesh,
    positions: &[[f64; 3]],
    labels: &[i32],
    target: &TriMesh,
) -> Vec<i32> {
    let moved = TriMesh::new(positions.to_vec(), source.faces().to_vec()).unwrap();
    let index = SurfaceIndex::new(&moved);
    target
        .positions()
        .iter()
        .map(|&x| {
            let c = index.closest(x);
            let k = (0..3)
                .max_by(|&a, &b| c.barycentric[a].total_cmp(&c.barycentric[b]))
                .unwrap();
            labels[source.faces()[c.face][k] as usize]
        })
        .collect()
}

/// A straight tube's halves carried onto a copy bent by a right angle, from the map that
/// overlays their first halves: nearest points on the straight source give the bent half's
/// labels by where it leaves the line, the deformed source gives them by arc length.
#[test]
fn a_bent_copy_takes_its_labels_better_deformed_than_undeformed() {
    let (source, source_labels) = bent_tube(0.0, 81, 16);
    let (target, truth) = bent_tube(std::f64::consts::FRAC_PI_2, 73, 14);
    let identity = AffineMap {
        matrix: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        translation: [0.0, 0.0, 0.0],
    };
    let fit = refine_nonrigid(&source, &target, &identity, 0.9);
    assert!(
        fit.levels > 0 && fit.residual < fit.start_residual,
        "{fit:?}"
    );
    let before = read_labels(&source, source.positions(), &source_labels, &target);
    let after = read_labels(&source, &fit.deformed, &source_labels, &target);
    let (acc_b, acc_a) = (accuracy(&before, &truth), accuracy(&after, &truth));
    assert!(
        acc_a > acc_b + 0.03 && acc_a > 0.9,
        "undeformed {acc_b:.3}, deformed {acc_a:.3}"
    );
}

/// A copy whose neck is longer: nearest points already tell a thin neck from a thick head,
/// so the affine step is right almost everywhere, and the deformation must not lose that.
#[test]
fn a_longer_neck_keeps_its_labels_deformed() {
    let (source, source_labels) = dumbbell(3.0, 81, 24);
    let (target, truth) = dumbbell(5.0, 97, 20);
    let meshes = [source, target];
    let annotations = [Some(source_labels), None];
    let steps = RigidSteps {
        affine: true,
        nonrigid: true,
    };
    let (n, _) = rigid_route(&meshes, &annotations, steps);
    let acc = accuracy(&n.labels[1], &truth);
    assert!(acc > 0.97, "non-rigid {acc:.3}");
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
    let tetra = common::mesh::tetrahedron();
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
