//! Label files, vertex ↔ face conversion and label metrics (`coseg::labels`,
//! `coseg::evaluate::label_agreement`).

use coseg::evaluate::{face_label_agreement, label_agreement, vertex_label_agreement};
use coseg::labels::{
    LabelKind, faces_to_vertices, match_label_files, read_part_names, read_shape_labels,
    vertices_to_faces, write_face_labels, write_vertex_labels,
};
use coseg::mesh::TriMesh;
use proptest::prelude::*;
use std::path::PathBuf;

/// An `n × n` grid of unit squares, two triangles each, in the plane.
fn grid(n: usize) -> TriMesh {
    let mut p = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            p.push([x as f64, y as f64, 0.0]);
        }
    }
    let id = |x: usize, y: usize| (y * (n + 1) + x) as u32;
    let mut f = Vec::new();
    for y in 0..n {
        for x in 0..n {
            f.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
            f.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    TriMesh::new(p, f).unwrap()
}

#[test]
fn faces_to_vertices_takes_the_area_majority() {
    // Vertex 0 of a fan: one big face labelled 7, two small ones labelled 3.
    let m = TriMesh::new(
        vec![
            [0., 0., 0.],
            [10., 0., 0.],
            [0., 10., 0.],
            [-1., 0., 0.],
            [0., -1., 0.],
        ],
        vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]],
    )
    .unwrap();
    let v = faces_to_vertices(&m, &[7, 3, 3]).unwrap();
    assert_eq!(v[0], 7);
    assert_eq!(v[3], 3);
    assert_eq!(v[1], 7);
}

#[test]
fn unlabelled_faces_are_ignored_and_isolated_vertices_stay_unlabelled() {
    let m = grid(2);
    let mut faces = vec![-1; m.face_count()];
    faces[0] = 4;
    let v = faces_to_vertices(&m, &faces).unwrap();
    let labelled: Vec<usize> = (0..v.len()).filter(|&i| v[i] >= 0).collect();
    assert_eq!(labelled, vec![0, 1, 4]); // the corners of face 0
    assert!(v.iter().all(|&l| l == -1 || l == 4));
}

#[test]
fn conversion_lengths_are_checked() {
    let m = grid(2);
    assert!(faces_to_vertices(&m, &[0; 3]).is_err());
    assert!(vertices_to_faces(&m, &[0; 3]).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(17), ..ProptestConfig::default() })]
    /// Labels constant on blocks of faces survive face → vertex → face everywhere but on
    /// faces touching a block boundary, and a constant labelling survives exactly.
    #[test]
    fn face_vertex_face_round_trip_keeps_block_interiors(split in 1usize..5, a in 0i32..5, b in 5i32..9) {
        let n = 6;
        let m = grid(n);
        // Faces of columns < split are `a`, the rest `b`.
        let faces: Vec<i32> = (0..m.face_count()).map(|f| if (f / 2) % n < split { a } else { b }).collect();
        let back = vertices_to_faces(&m, &faces_to_vertices(&m, &faces).unwrap()).unwrap();
        for f in 0..m.face_count() {
            let col = (f / 2) % n;
            if col + 1 < split || col > split {
                prop_assert_eq!(back[f], faces[f]);
            }
        }
        let constant = vec![a; m.face_count()];
        prop_assert_eq!(vertices_to_faces(&m, &faces_to_vertices(&m, &constant).unwrap()).unwrap(), constant);
    }

    /// Confusion rows sum to the truth shares, columns to the predicted shares, the
    /// diagonal to the accuracy, and accuracy is 1 exactly when the labels agree.
    #[test]
    fn metrics_are_consistent(truth in proptest::collection::vec(-1i32..4, 1..60), noise in proptest::collection::vec(-1i32..4, 60), w in proptest::collection::vec(0.1f64..3.0, 60)) {
        let n = truth.len();
        let w = &w[..n];
        prop_assume!(truth.iter().any(|&t| t >= 0));
        let pred: Vec<i32> = (0..n).map(|i| if i % 3 == 0 { noise[i] } else { truth[i] }).collect();
        let a = label_agreement(w, &truth, &pred).unwrap();
        let total: f64 = a.confusion.iter().flatten().sum();
        prop_assert!((total - 1.0).abs() < 1e-9);
        let diag: f64 = (0..a.labels.len()).map(|i| a.confusion[i][i]).sum();
        prop_assert!((diag - a.accuracy).abs() < 1e-12);
        for (i, p) in a.parts.iter().enumerate() {
            let row: f64 = a.confusion[i].iter().sum();
            prop_assert!((row - p.truth_area).abs() < 1e-12);
            prop_assert!(p.iou >= 0.0 && p.iou <= 1.0 + 1e-12);
        }
        let scored: f64 = (0..n).filter(|&i| truth[i] >= 0).map(|i| w[i]).sum();
        let right: f64 = (0..n).filter(|&i| truth[i] >= 0 && pred[i] == truth[i]).map(|i| w[i]).sum();
        prop_assert!((a.accuracy - right / scored).abs() < 1e-12);
        let same = label_agreement(w, &truth, &truth).unwrap();
        prop_assert!((same.accuracy - 1.0).abs() < 1e-12);
        prop_assert!(same.parts.iter().filter(|p| p.truth_area > 0.0).all(|p| (p.iou - 1.0).abs() < 1e-12));
    }
}

#[test]
fn label_agreement_exact_values() {
    // Areas 1, 1, 1, 1; truth 0 0 1 1; prediction 0 1 1 -1.
    let a = label_agreement(&[1.0; 4], &[0, 0, 1, 1], &[0, 1, 1, -1]).unwrap();
    assert_eq!(a.labels, vec![0, 1]);
    assert!((a.accuracy - 0.5).abs() < 1e-15);
    // Part 0: inter 1, union 2; part 1: inter 1, union 3.
    assert!((a.parts[0].iou - 0.5).abs() < 1e-15);
    assert!((a.parts[1].iou - 1.0 / 3.0).abs() < 1e-15);
    assert!((a.mean_iou - (0.5 + 1.0 / 3.0) / 2.0).abs() < 1e-15);
    assert_eq!(a.confusion[1], vec![0.0, 0.25, 0.25]); // last column: predicted -1
    // A predicted label absent from the truth appears as a column and a part of IoU 0.
    let b = label_agreement(&[1.0; 2], &[0, 0], &[0, 9]).unwrap();
    assert_eq!(b.labels, vec![0, 9]);
    assert_eq!(b.parts[1].iou, 0.0);
    assert_eq!(b.mean_iou, 0.5); // over truth parts only
}

#[test]
fn label_agreement_rejects_bad_input() {
    assert!(label_agreement(&[1.0], &[0, 1], &[0, 1]).is_err());
    assert!(label_agreement(&[f64::NAN, 1.0], &[0, 1], &[0, 1]).is_err());
    assert!(label_agreement(&[1.0, 1.0], &[-1, -1], &[0, 1]).is_err());
}

#[test]
fn face_and_vertex_agreement_on_a_grid() {
    let m = grid(4);
    let truth_faces: Vec<i32> = (0..m.face_count())
        .map(|f| i32::from((f / 2) % 4 >= 2))
        .collect();
    let v = faces_to_vertices(&m, &truth_faces).unwrap();
    // Per-vertex labels read from the face truth reproduce it exactly on faces off the cut;
    // on a grid with the diagonal pattern they reproduce it everywhere.
    let a = face_label_agreement(&m, &truth_faces, &v).unwrap();
    assert!(a.accuracy > 0.85, "{}", a.accuracy);
    let b = vertex_label_agreement(&m, &v, &v).unwrap();
    assert!((b.accuracy - 1.0).abs() < 1e-12);
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("coseg-labels-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn reading_seg_and_vertex_files_against_a_mesh() {
    let d = tmp("read");
    let m = grid(1); // 4 vertices, 2 faces
    std::fs::write(d.join("a.seg"), "1\n2\n").unwrap();
    std::fs::write(d.join("b.labels.txt"), "0\n-5\n0\n1\n").unwrap();
    std::fs::write(d.join("c.seg"), "1\n2\n3\n").unwrap();
    std::fs::write(d.join("e.seg"), "1\nback\n").unwrap();
    let a = read_shape_labels(&d.join("a.seg"), &m, "a").unwrap();
    assert_eq!(a.kind, LabelKind::Face);
    assert_eq!(a.vertex_labels.len(), 4);
    let b = read_shape_labels(&d.join("b.labels.txt"), &m, "b").unwrap();
    assert_eq!(b.vertex_labels, vec![0, -1, 0, 1]); // negatives become -1
    let e = read_shape_labels(&d.join("c.seg"), &m, "c")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("c.seg") && e.contains("3 labels") && e.contains("2 faces"),
        "{e}"
    );
    let e = read_shape_labels(&d.join("e.seg"), &m, "e")
        .unwrap_err()
        .to_string();
    assert!(e.contains("e.seg:2") && e.contains("back"), "{e}");
    let e = read_shape_labels(&d.join("missing.seg"), &m, "x")
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.seg"), "{e}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn matching_label_files_by_stem() {
    let d = tmp("match");
    std::fs::write(d.join("1.seg"), "1\n").unwrap();
    std::fs::write(d.join("2.labels.txt"), "1\n").unwrap();
    std::fs::write(d.join("2.regions.txt"), "1\n").unwrap(); // an output, never a label
    std::fs::write(d.join("zz.seg"), "1\n").unwrap(); // no mesh: ignored in a folder
    let stems: Vec<String> = ["1", "2", "3"].iter().map(|s| s.to_string()).collect();
    let (m, w) = match_label_files(std::slice::from_ref(&d), &stems).unwrap();
    assert_eq!(m, vec![(0, d.join("1.seg")), (1, d.join("2.labels.txt"))]);
    assert!(w.is_empty());
    // Explicit files must match.
    let e = match_label_files(&[d.join("zz.seg")], &stems)
        .unwrap_err()
        .to_string();
    assert!(e.contains("zz.seg") && e.contains("no mesh"), "{e}");
    // Two files for one mesh.
    std::fs::write(d.join("1.labels.txt"), "1\n").unwrap();
    let e = match_label_files(std::slice::from_ref(&d), &stems)
        .unwrap_err()
        .to_string();
    assert!(e.contains("second label file"), "{e}");
    // An explicit list.
    let (m, _) = match_label_files(&[d.join("2.labels.txt")], &stems).unwrap();
    assert_eq!(m, vec![(1, d.join("2.labels.txt"))]);
    // A folder without matches warns.
    let empty = tmp("match-empty");
    let (m, w) = match_label_files(std::slice::from_ref(&empty), &stems).unwrap();
    assert!(m.is_empty() && w.len() == 1);
    std::fs::remove_dir_all(&d).unwrap();
    std::fs::remove_dir_all(&empty).unwrap();
}

#[test]
fn part_names_and_writers() {
    let d = tmp("names");
    std::fs::write(d.join("n.json"), r#"{"1": "back", "2": "seat"}"#).unwrap();
    let n = read_part_names(&d.join("n.json")).unwrap();
    assert_eq!(n.len(), 2);
    assert_eq!(n[&2], "seat");
    std::fs::write(d.join("bad.json"), r#"{"leg": "x"}"#).unwrap();
    let e = read_part_names(&d.join("bad.json"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad.json") && e.contains("leg"), "{e}");
    std::fs::write(d.join("bad2.json"), "[1, 2]").unwrap();
    assert!(read_part_names(&d.join("bad2.json")).is_err());
    let p = write_face_labels(&d, "s", &[3, -1, 2]).unwrap();
    assert_eq!(std::fs::read_to_string(p).unwrap(), "3\n-1\n2\n");
    let p = write_vertex_labels(&d, "s", &[0]).unwrap();
    assert!(p.ends_with("s.labels.txt"));
    std::fs::remove_dir_all(&d).unwrap();
}
