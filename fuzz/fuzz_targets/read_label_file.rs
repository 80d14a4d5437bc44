//! Any bytes as a `.seg` (per-face) or per-vertex label file of `src/labels/`, through
//! `labels::parse_shape_labels` against a mesh sized to fit: labels of the mesh's length or an
//! error naming the file, never a panic, a hang or a huge allocation.
//!
//! The first byte picks the kind (even: `fuzz.seg`, odd: `fuzz.labels.txt`); the rest is the
//! file. The mesh is a triangle fan with as many faces (or vertices) as the file has labels,
//! when it parses (at most 4,096), so the count check passes and the per-face → per-vertex
//! conversion runs; one face (vertex) more checks that a wrong count is refused.
#![no_main]

use coseg::labels::{
    LabelKind, label_set, parse_label_file, parse_shape_labels, vertices_to_faces,
};
use coseg::mesh::TriMesh;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

/// A fan around vertex 0 with `faces` triangles and `faces + 2` vertices, some duplicated
/// positions (zero-area faces) included.
fn fan(faces: usize) -> TriMesh {
    let n = faces + 2;
    let positions = (0..n)
        .map(|i| {
            if i == 0 {
                [0.0, 0.0, 0.0]
            } else {
                let a = (i / 2) as f64 * 0.01; // pairs of equal points: zero-area faces
                [a.cos(), a.sin(), 0.0]
            }
        })
        .collect();
    let faces = (0..faces as u32).map(|f| [0, f + 1, f + 2]).collect();
    TriMesh::new(positions, faces).unwrap()
}

fuzz_target!(|data: &[u8]| {
    let Some((&first, file)) = data.split_first() else {
        return;
    };
    let path = Path::new(if first % 2 == 0 {
        "fuzz.seg"
    } else {
        "fuzz.labels.txt"
    });
    let Ok((kind, labels)) = parse_label_file(file, path) else {
        let e = parse_shape_labels(file, path, &fan(1), "fan").unwrap_err();
        assert!(e.to_string().starts_with(path.to_str().unwrap()), "{e}");
        return;
    };
    assert!(labels.len() <= file.len() / 2 + 1);
    let n = labels.len().min(4096);
    if n == 0 || labels.len() > n {
        return;
    }
    // A mesh of exactly the right count: a fan of n faces for a .seg; for per-vertex labels,
    // n vertices needs n - 2 faces, so n < 3 is checked to be refused instead.
    let mesh = match kind {
        LabelKind::Face => fan(n),
        LabelKind::Vertex if n >= 3 => fan(n - 2),
        LabelKind::Vertex => {
            assert!(parse_shape_labels(file, path, &fan(1), "fan").is_err());
            return;
        }
    };
    let s = parse_shape_labels(file, path, &mesh, "fan").unwrap();
    assert_eq!(s.file_labels, labels);
    assert_eq!(s.vertex_labels.len(), mesh.vertex_count());
    let known = label_set([&labels[..]]);
    assert!(
        s.vertex_labels
            .iter()
            .all(|&l| l == -1 || known.contains_key(&l))
    );
    let faces = vertices_to_faces(&mesh, &s.vertex_labels).unwrap();
    assert_eq!(faces.len(), mesh.face_count());
    assert!(faces.iter().all(|&l| l == -1 || known.contains_key(&l)));
    // One element too many in the mesh: refused, naming the file.
    let bigger = match kind {
        LabelKind::Face => fan(n + 1),
        LabelKind::Vertex => fan(n - 1),
    };
    let e = parse_shape_labels(file, path, &bigger, "fan").unwrap_err();
    assert!(e.to_string().starts_with(path.to_str().unwrap()), "{e}");
});
