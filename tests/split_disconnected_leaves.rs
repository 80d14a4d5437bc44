//! Tests of `parts::split_disconnected_leaves`: a region made of pieces that border different
//! regions becomes one tuple per kind of piece.

mod common;

use common::graph::{coseg_of, uniform_cues};
use coseg::graph::{Cosegmentation, GraphError};
use coseg::mesh::TriMesh;
use coseg::parts::{
    PartCues, geometric_part_tree_linked, geometric_part_tree_with_cues, split_disconnected_leaves,
};

/// A strip of 10 unit columns of quads (vertices 2c and 2c + 1 at x = c, c = 0..=10).
fn strip() -> TriMesh {
    let mut p = Vec::new();
    for c in 0..=10 {
        p.push([c as f64, 0.0, 0.0]);
        p.push([c as f64, 1.0, 0.0]);
    }
    let mut f = Vec::new();
    for c in 0..10u32 {
        let a = 2 * c;
        f.push([a, a + 2, a + 1]);
        f.push([a + 1, a + 2, a + 3]);
    }
    TriMesh::new(p, f).unwrap()
}

/// [`strip`] with its last two columns (x = 9, 10) folded up about the line x = 8 by
/// `degrees`: their faces' normals turn by that angle, the rest stays in the plane z = 0.
fn folded_strip(degrees: f64) -> TriMesh {
    let (sin, cos) = degrees.to_radians().sin_cos();
    let m = strip();
    let p: Vec<[f64; 3]> = m
        .positions()
        .iter()
        .map(|&[x, y, _]| {
            if x > 8.0 {
                [8.0 + (x - 8.0) * cos, y, (x - 8.0) * sin]
            } else {
                [x, y, 0.0]
            }
        })
        .collect();
    TriMesh::new(p, m.faces().to_vec()).unwrap()
}

/// The vertices of columns `cols` (x values).
fn cols(cols: impl IntoIterator<Item = u32>) -> Vec<u32> {
    let mut v: Vec<u32> = cols.into_iter().flat_map(|c| [2 * c, 2 * c + 1]).collect();
    v.sort_unstable();
    v
}

/// Region 0 is both ends of the strip (x ≤ 1 and x ≥ 9), region 1 the middle-left (2..=4) and
/// region 2 the middle-right (5..=8): region 0's left piece borders region 1, its right
/// piece region 2.
fn two_kinds() -> Vec<Vec<u32>> {
    vec![cols([0, 1, 9, 10]), cols(2..=4), cols(5..=8)]
}

/// Nothing splits: the same tuples, bit for bit, each its own origin, no siblings.
fn assert_unsplit(meshes: &[TriMesh], coseg: &Cosegmentation) {
    let split = split_disconnected_leaves(meshes, coseg).unwrap();
    assert_eq!(&split.segmentation, coseg);
    assert_eq!(split.origin, (0..coseg.tuples.len()).collect::<Vec<_>>());
    assert!(split.siblings().is_empty());
}

fn union(c: &Cosegmentation, i: usize, ids: &[usize]) -> Vec<u32> {
    let mut v: Vec<u32> = ids
        .iter()
        .flat_map(|&t| c.tuples[t].regions[i].clone())
        .collect();
    v.sort_unstable();
    v
}

#[test]
fn pieces_bordering_different_regions_become_two_tuples() {
    let meshes = vec![strip(); 3];
    let coseg = coseg_of(&meshes, &vec![two_kinds(); 3]);
    let split = split_disconnected_leaves(&meshes, &coseg).unwrap();
    let s = &split.segmentation;
    assert_eq!(s.tuples.len(), 4);
    assert_eq!(split.origin, vec![0, 1, 2, 0]);
    assert_eq!(split.siblings(), vec![(0, 3)]);
    // A flat strip: both pieces face the same way.
    assert_eq!(split.alike, vec![(0, 3)]);
    let total = meshes[0].total_area();
    for (i, mesh) in meshes.iter().enumerate() {
        // Equal pieces: the kind with the lower key (region 1) keeps the id.
        assert_eq!(s.tuples[0].regions[i], cols([0, 1]));
        assert_eq!(s.tuples[3].regions[i], cols([9, 10]));
        assert_eq!(union(s, i, &[0, 3]), coseg.tuples[0].regions[i]);
        // Each piece is one column of quads (area 1) plus half a column's vertex areas.
        let areas = mesh.vertex_areas();
        for t in [0, 3] {
            let a: f64 = s.tuples[t].regions[i]
                .iter()
                .map(|&v| areas[v as usize])
                .sum();
            assert!((s.tuples[t].area_fractions[i] - a / total).abs() < 1e-15);
        }
        // The other tuples are untouched.
        assert_eq!(s.tuples[1], coseg.tuples[1]);
        assert_eq!(s.tuples[2], coseg.tuples[2]);
    }
    assert!(!s.tuples[3].leftover);
}

#[test]
fn pieces_bordering_one_region_stay_one_tuple() {
    // Both ends border the one middle region: mirror copies, not different parts.
    let meshes = vec![strip(); 2];
    let parts = vec![cols([0, 1, 9, 10]), cols(2..=8)];
    let coseg = coseg_of(&meshes, &vec![parts; 2]);
    assert_unsplit(&meshes, &coseg);
}

#[test]
fn a_fragment_under_the_share_is_not_a_kind() {
    // The right piece is the last column's vertices only: half a column of area out of 6.5.
    let meshes = vec![strip(); 2];
    let parts = vec![cols([0, 1, 2, 3, 4, 5, 10]), cols(6..=7), cols(8..=9)];
    let coseg = coseg_of(&meshes, &vec![parts; 2]);
    let areas = meshes[0].vertex_areas();
    let share = cols([10]).iter().map(|&v| areas[v as usize]).sum::<f64>()
        / coseg.tuples[0].regions[0]
            .iter()
            .map(|&v| areas[v as usize])
            .sum::<f64>();
    // A tenth of the region: a fragment the refinement leaves, not a part.
    assert!(share < 0.1, "{share}");
    assert_unsplit(&meshes, &coseg);
}

#[test]
fn kinds_on_too_few_shapes_do_not_split() {
    // Two pieces of different kinds on one shape of three: not the collection's pattern.
    let meshes = vec![strip(); 3];
    let one = vec![cols(0..=1), cols(2..=4), cols(5..=10)];
    let coseg = coseg_of(&meshes, &[two_kinds(), one.clone(), one]);
    assert_unsplit(&meshes, &coseg);
}

#[test]
fn the_largest_kind_keeps_the_id_and_a_missing_kind_is_empty() {
    // Two shapes of three have both kinds; the third only the right piece, so the right kind
    // is the larger over the collection and keeps id 0; the left kind, appended, is empty
    // on the third shape.
    let meshes = vec![strip(); 3];
    let right_only = vec![cols([9, 10]), cols(0..=4), cols(5..=8)];
    let coseg = coseg_of(&meshes, &[two_kinds(), two_kinds(), right_only]);
    let s = split_disconnected_leaves(&meshes, &coseg)
        .unwrap()
        .segmentation;
    assert_eq!(s.tuples.len(), 4);
    assert_eq!(s.tuples[0].regions[0], cols([9, 10]));
    assert_eq!(s.tuples[3].regions[0], cols([0, 1]));
    assert_eq!(s.tuples[0].regions[2], cols([9, 10]));
    assert!(s.tuples[3].regions[2].is_empty());
    assert_eq!(s.tuples[3].area_fractions[2], 0.0);
}

#[test]
fn same_result_in_one_thread() {
    let meshes = vec![strip(); 4];
    let coseg = coseg_of(&meshes, &vec![two_kinds(); 4]);
    let many = split_disconnected_leaves(&meshes, &coseg).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let one = pool.install(|| split_disconnected_leaves(&meshes, &coseg).unwrap());
    assert_eq!(many, one);
}

#[test]
fn meshes_that_do_not_match_are_refused() {
    let meshes = vec![strip(); 2];
    let coseg = coseg_of(&meshes, &vec![two_kinds(); 2]);
    let err = split_disconnected_leaves(&meshes[..1], &coseg).unwrap_err();
    assert!(matches!(err, GraphError::BadOption(_)), "{err}");
}

#[test]
fn siblings_merge_after_touching_leaves_of_the_same_cost() {
    // The split strip: leaves 0 (x ≤ 1), 1, 2 and 3 (x ≥ 9); 0 and 3 are siblings and do not
    // touch. Uniform cues: every cost is the thickness term, 0, so the touching merges come
    // first and the siblings' merge costs more.
    let meshes = vec![strip(); 2];
    let coseg = coseg_of(&meshes, &vec![two_kinds(); 2]);
    let split = split_disconnected_leaves(&meshes, &coseg).unwrap();
    let cues = uniform_cues(&meshes);
    let plain = geometric_part_tree_with_cues(&meshes, &cues, &split.segmentation, &[]).unwrap();
    let none = geometric_part_tree_linked(&meshes, &cues, &split.segmentation, &[], &[]).unwrap();
    assert_eq!(plain, none);
    let tree =
        geometric_part_tree_linked(&meshes, &cues, &split.segmentation, &[], &split.siblings())
            .unwrap();
    let merges: Vec<(usize, usize)> = tree.merges.iter().map(|m| (m.a, m.b)).collect();
    // 0–1 (touch), 2–3 (touch), then the two groups touch (1–2): all at cost 0.
    assert_eq!(merges, vec![(0, 1), (2, 3), (4, 5)]);
    assert!(tree.merges.iter().all(|m| m.similarity == 1.0));
    // Without the touching pair 1–2 (its cue set apart), the siblings still link the groups.
    let far: Vec<PartCues> = cues
        .iter()
        .map(|c| {
            let mut c = c.clone();
            for v in cols(5..=8) {
                c.thickness[v as usize] = std::f64::consts::E;
            }
            c
        })
        .collect();
    let tree =
        geometric_part_tree_linked(&meshes, &far, &split.segmentation, &[], &split.siblings())
            .unwrap();
    // Leaf 2 is thicker by ln e = 1: 0–1 (0), then 1-group with 3 as siblings
    // (at the siblings' extra cost, below 1) before anything that involves leaf 2 (cost 1 or
    // more).
    assert_eq!((tree.merges[0].a, tree.merges[0].b), (0, 1));
    assert_eq!((tree.merges[1].a, tree.merges[1].b), (3, 4));
    let sibling = tree.merges[1].similarity;
    assert!(sibling < 1.0 && sibling > (-1.0f64).exp(), "{sibling}");
    assert!(
        tree.merges[2..]
            .iter()
            .all(|m| m.similarity <= (-1.0f64).exp() + 1e-12)
    );
}

#[test]
fn siblings_are_alike_when_their_pieces_face_the_same_way() {
    // The right piece (columns 9, 10) is folded up: its mean normal turns by exactly the fold
    // angle against the left piece's (columns 0, 1; column 9's faces are both folded).
    // Copies side by side turn by up to about 25° (a chair's front and back feet), different
    // parts in like places by 45° and more (a leg's tip and the tail's tip): alike below that
    // gap, not above it, and never alike again once the fold has turned them apart.
    let mut apart = false;
    for step in 0..=18 {
        let degrees = 5.0 * step as f64;
        let meshes = vec![folded_strip(degrees); 3];
        let coseg = coseg_of(&meshes, &vec![two_kinds(); 3]);
        let split = split_disconnected_leaves(&meshes, &coseg).unwrap();
        // The split itself does not depend on the fold.
        assert_eq!(split.origin, vec![0, 1, 2, 0], "{degrees}°");
        let alike = split.alike == vec![(0, 3)];
        assert!(
            alike || split.alike.is_empty(),
            "{degrees}°: {:?}",
            split.alike
        );
        if degrees <= 25.0 {
            assert!(alike, "{degrees}°");
        }
        if degrees >= 45.0 {
            assert!(!alike, "{degrees}°");
        }
        assert!(
            !(apart && alike),
            "{degrees}°: alike again after a smaller fold was not"
        );
        apart |= !alike;
    }
    // Both normals turn over with the winding: the same answer on inside-out meshes.
    for (degrees, expected) in [(0.0, vec![(0, 3)]), (90.0, vec![])] {
        let m = folded_strip(degrees);
        let flipped = TriMesh::new(
            m.positions().to_vec(),
            m.faces().iter().map(|&[a, b, c]| [a, c, b]).collect(),
        )
        .unwrap();
        let meshes = vec![flipped; 3];
        let coseg = coseg_of(&meshes, &vec![two_kinds(); 3]);
        let split = split_disconnected_leaves(&meshes, &coseg).unwrap();
        assert_eq!(split.alike, expected, "{degrees}° inside out");
    }
    // The median over shapes decides: folded on two of three shapes, not alike.
    let meshes = vec![folded_strip(90.0), folded_strip(0.0), folded_strip(90.0)];
    let coseg = coseg_of(&meshes, &vec![two_kinds(); 3]);
    assert!(
        split_disconnected_leaves(&meshes, &coseg)
            .unwrap()
            .alike
            .is_empty()
    );
    let meshes = vec![folded_strip(0.0), folded_strip(90.0), folded_strip(0.0)];
    let coseg = coseg_of(&meshes, &vec![two_kinds(); 3]);
    assert_eq!(
        split_disconnected_leaves(&meshes, &coseg).unwrap().alike,
        vec![(0, 3)]
    );
}
