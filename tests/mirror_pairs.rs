//! Tests of the mirror-pair test (`parts::mirror_plane`, `parts::mirror_pairs`) and of the part
//! tree that merges mirror pairs first (`AdaptiveCosegmentation::regroup`).

mod common;

use common::graph::coseg_of;
use coseg::bands::BandTable;
use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
use coseg::mesh::TriMesh;
use coseg::parts::{Likeness, mirror_pairs, mirror_plane};

/// Boxes (centre, half sizes) as one mesh; per box, its 14 vertex ids.
fn figure(boxes: &[([f64; 3], [f64; 3])]) -> (TriMesh, Vec<Vec<u32>>) {
    let mut p = Vec::new();
    let mut f = Vec::new();
    let mut parts = Vec::new();
    for (c, h) in boxes {
        let o = p.len() as u32;
        for k in 0..8 {
            let s = |b: u32| if k >> b & 1 == 1 { 1.0 } else { -1.0 };
            p.push([c[0] + s(0) * h[0], c[1] + s(1) * h[1], c[2] + s(2) * h[2]]);
        }
        // Corner k has bit 0 = x, bit 1 = y, bit 2 = z. Each face is cut into four triangles
        // around its centre, so the vertex areas are as symmetric as the box.
        for q in [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ] {
            let m = p.len() as u32;
            let centre = |k: usize| q.iter().map(|&v| p[(o + v) as usize][k]).sum::<f64>() / 4.0;
            p.push([centre(0), centre(1), centre(2)]);
            for e in 0..4 {
                f.push([o + q[e], o + q[(e + 1) % 4], m]);
            }
        }
        parts.push((o..p.len() as u32).collect());
    }
    (TriMesh::new(p, f).unwrap(), parts)
}

/// A figure standing along +y, symmetric across x = 0 except where `pose` moves the right arm
/// (0 = mirror image of the left one): torso, left arm, right arm, head, left leg, right leg,
/// nose (in front, +z, so that z = 0 is no plane of symmetry).
fn person(scale: f64, pose: f64) -> (TriMesh, Vec<Vec<u32>>) {
    let s = |v: [f64; 3]| v.map(|x| x * scale);
    figure(&[
        (s([0.0, 0.0, 0.0]), s([0.6, 1.0, 0.3])),
        (s([1.4, 0.6, 0.0]), s([0.8, 0.15, 0.15])),
        (
            s([-1.4 + 0.3 * pose, 0.6 + 0.9 * pose, 0.4 * pose]),
            s([0.8, 0.15, 0.15]),
        ),
        (s([0.0, 1.5, 0.0]), s([0.3, 0.3, 0.3])),
        (s([0.35, -2.0, 0.0]), s([0.2, 1.0, 0.2])),
        (s([-0.35, -2.0, 0.0]), s([0.2, 1.0, 0.2])),
        (s([0.0, 1.5, 0.45]), s([0.05, 0.05, 0.15])),
    ])
}

/// The meshes and the per-shape part vertex sets of `shapes`.
fn split(shapes: Vec<(TriMesh, Vec<Vec<u32>>)>) -> (Vec<TriMesh>, Vec<Vec<Vec<u32>>>) {
    shapes.into_iter().unzip()
}

/// Three shapes (scaled 1, 1.1, 0.9 along x): a body and two end blocks opposite each other
/// along x at one height, the second block `half` thick in y and z (0.3: the first's size).
fn blocks(half: f64) -> (Vec<TriMesh>, Vec<Vec<Vec<u32>>>) {
    split(
        [1.0, 1.1, 0.9]
            .iter()
            .map(|&s| {
                figure(&[
                    ([0.0, 0.0, 0.0], [1.0 * s, 0.5, 0.5]),
                    ([1.5 * s, 0.0, 0.0], [0.3, 0.3, 0.3]),
                    ([-1.5 * s, 0.0, 0.0], [0.3, half, half]),
                ])
            })
            .collect(),
    )
}

fn pairs(p: &[coseg::parts::MirrorPair]) -> Vec<(usize, usize)> {
    let mut v: Vec<(usize, usize)> = p.iter().map(|m| (m.a, m.b)).collect();
    v.sort_unstable();
    v
}

#[test]
fn mirror_plane_of_a_symmetric_figure_is_its_plane() {
    let (mesh, _) = person(1.0, 0.0);
    let plane = mirror_plane(&mesh).unwrap();
    assert!(plane.error < 1e-12, "error {}", plane.error);
    assert!(
        plane.normal[0].abs() > 1.0 - 1e-9,
        "normal {:?}",
        plane.normal
    );
    assert!(plane.point[0].abs() < 1e-12);
    // Rotated and moved, the plane follows (a fixed rotation about a tilted axis).
    let (c, s) = (0.6f64.cos(), 0.6f64.sin());
    let moved = mesh
        .map_positions(|p| {
            [
                c * p[0] - s * p[1] + 3.0,
                s * p[0] + c * p[1] - 1.0,
                p[2] + 0.5,
            ]
        })
        .unwrap();
    let plane = mirror_plane(&moved).unwrap();
    assert!(plane.error < 1e-9, "error {}", plane.error);
    let along = (plane.normal[0] * c + plane.normal[1] * s).abs();
    assert!(along > 1.0 - 1e-9, "normal {:?}", plane.normal);
}

#[test]
fn mirror_plane_of_a_posed_figure_reports_its_asymmetry() {
    // The same figure standing straight is exactly symmetric; posed, its best plane's error
    // is of the order of its limbs' displacement, not of rounding.
    let (straight, _) = person(1.0, 0.0);
    let (mesh, _) = person(1.0, 1.0);
    let plane = mirror_plane(&mesh).unwrap();
    let exact = mirror_plane(&straight).unwrap();
    assert!(exact.error < 1e-9, "error {}", exact.error);
    assert!(plane.error > 0.01, "error {}", plane.error);
}

#[test]
fn mirror_pairs_are_the_left_and_right_parts() {
    let shapes: Vec<(TriMesh, Vec<Vec<u32>>)> =
        [1.0, 1.2, 0.9].iter().map(|&s| person(s, 0.0)).collect();
    let (meshes, parts) = split(shapes);
    let coseg = coseg_of(&meshes, &parts);
    // Each shape's own plane, and vertical planes (up = +y): the arms and the legs.
    let by_plane = mirror_pairs(&meshes, &coseg, None, None);
    assert_eq!(pairs(&by_plane), vec![(1, 2), (4, 5)]);
    assert!(by_plane.iter().all(|m| m.ratio < 1e-9));
    assert_eq!(
        pairs(&mirror_pairs(&meshes, &coseg, Some([0.0, 2.0, 0.0]), None)),
        vec![(1, 2), (4, 5)]
    );
    // Meshes that do not match the co-segmentation: nothing.
    assert!(mirror_pairs(&meshes[..2], &coseg, None, None).is_empty());
}

#[test]
fn mirror_pairs_of_posed_figures_need_the_up_direction() {
    // The right arm raised and forward differently on each shape: no plane of symmetry, but
    // with up known the arms are still a pair; the head is never paired with the legs.
    let shapes: Vec<(TriMesh, Vec<Vec<u32>>)> = [(1.0, 0.2), (1.1, 0.35), (0.9, 0.25)]
        .iter()
        .map(|&(s, p)| person(s, p))
        .collect();
    let (meshes, parts) = split(shapes);
    let coseg = coseg_of(&meshes, &parts);
    let up = mirror_pairs(&meshes, &coseg, Some([0.0, 1.0, 0.0]), None);
    assert_eq!(pairs(&up), vec![(1, 2), (4, 5)]);
    // Upside down (up = −y) is the same family of vertical planes.
    assert_eq!(
        pairs(&mirror_pairs(&meshes, &coseg, Some([0.0, -1.0, 0.0]), None)),
        vec![(1, 2), (4, 5)]
    );
    // A wrong up (x, sideways): left and right are then at different heights.
    assert!(
        pairs(&mirror_pairs(&meshes, &coseg, Some([1.0, 0.0, 0.0]), None))
            .iter()
            .all(|&p| p != (1, 2))
    );
}

#[test]
fn mirror_pairs_need_copies_of_one_size() {
    // A body with two blocks opposite each other at one height: paired when they have one
    // size, not when one has a third of the other's area (a head and a tail).
    let pair_of = |half: f64| {
        let (meshes, parts) = blocks(half);
        pairs(&mirror_pairs(
            &meshes,
            &coseg_of(&meshes, &parts),
            Some([0.0, 1.0, 0.0]),
            None,
        ))
    };
    assert_eq!(pair_of(0.3), vec![(1, 2)]);
    assert_eq!(pair_of(0.12), vec![]);
}

/// A graph over the meshes with one feature column: vertex `v`'s band is `band(part of v)`.
fn graph_of(meshes: &[TriMesh], parts: &[Vec<Vec<u32>>], band: &[u8]) -> ShapeGraph {
    let nodes = meshes
        .iter()
        .zip(parts)
        .enumerate()
        .map(|(i, (m, p))| {
            let mut labels = vec![0u8; m.vertex_count()];
            for (t, r) in p.iter().enumerate() {
                r.iter().for_each(|&v| labels[v as usize] = band[t]);
            }
            let table = BandTable {
                features: 1,
                vertices: m.vertex_count(),
                bands: 4,
                labels,
            };
            let w = m.vertex_areas();
            let total: f64 = w.iter().sum();
            let areas: Vec<f64> = w.iter().map(|a| a / total).collect();
            ShapeNode::new(format!("s{i}"), table, &areas).unwrap()
        })
        .collect();
    ShapeGraph::build(nodes, &GraphOptions::default()).unwrap()
}

#[test]
fn mirror_pairs_must_look_alike_when_the_features_say_so() {
    // Torso and two end blocks of one size opposite each other (a head and a tail, or two
    // arms): a pair by position alone; with an intrinsic column that gives the blocks the
    // same band, still a pair (likeness 1); with different bands, none (likeness 0).
    let (meshes, parts) = blocks(0.3);
    let coseg = coseg_of(&meshes, &parts);
    let up = Some([0.0, 0.0, 1.0]);
    let alike = graph_of(&meshes, &parts, &[0, 1, 1]);
    let unlike = graph_of(&meshes, &parts, &[0, 1, 2]);
    let with = |g: &ShapeGraph, columns: &[usize]| {
        mirror_pairs(&meshes, &coseg, up, Some(Likeness { graph: g, columns }))
    };
    assert_eq!(
        pairs(&mirror_pairs(&meshes, &coseg, up, None)),
        vec![(1, 2)]
    );
    let p = with(&alike, &[0]);
    assert_eq!((pairs(&p), p[0].likeness), (vec![(1, 2)], Some(1.0)));
    assert!(with(&unlike, &[0]).is_empty());
    // No column to compare on: position alone.
    assert_eq!(pairs(&with(&unlike, &[])), vec![(1, 2)]);
    let l = Likeness {
        graph: &unlike,
        columns: &[0],
    };
    assert_eq!(l.of(0, &parts[0][1], &parts[0][2]), Some(0.0));
    assert_eq!(l.of(0, &parts[0][1], &[]), None);
}
