//! Per-face ↔ per-vertex label conversion.

use super::LabelError;
use crate::mesh::TriMesh;
use std::collections::BTreeMap;

/// Per-vertex labels from per-face labels (`face_labels.len()` = face count): every vertex
/// takes the label of largest total area among its incident faces (faces labelled `< 0` are
/// ignored; on equal areas the label of more faces, then the lower label). A vertex with no
/// labelled incident face gets `-1`. Output length = vertex count.
///
/// ```
/// use coseg::labels::faces_to_vertices;
/// use coseg::mesh::TriMesh;
/// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [5., 5., 5.]],
///     vec![[0, 1, 2]]).unwrap();
/// assert_eq!(faces_to_vertices(&m, &[4]).unwrap(), vec![4, 4, 4, -1]); // vertex 3: in no face
/// ```
pub fn faces_to_vertices(mesh: &TriMesh, face_labels: &[i32]) -> Result<Vec<i32>, LabelError> {
    one_each("faces", mesh.face_count(), face_labels.len())?;
    let areas = mesh.face_areas();
    // (label, area, faces) per vertex; a vertex touches few faces, so a short list beats a map.
    let mut acc: Vec<Vec<(i32, f64, u32)>> = vec![Vec::new(); mesh.vertex_count()];
    for (f, tri) in mesh.faces().iter().enumerate() {
        let l = face_labels[f];
        if l < 0 {
            continue;
        }
        let a = if areas[f].is_finite() { areas[f] } else { 0.0 };
        for &v in tri {
            let list = &mut acc[v as usize];
            match list.iter_mut().find(|e| e.0 == l) {
                Some(e) => {
                    e.1 += a;
                    e.2 += 1;
                }
                None => list.push((l, a, 1)),
            }
        }
    }
    Ok(acc
        .iter()
        .map(|list| {
            let mut best: Option<(i32, f64, u32)> = None;
            for &e in list {
                best = match best {
                    None => Some(e),
                    Some(b) => {
                        let better =
                            e.1 > b.1 || (e.1 == b.1 && (e.2 > b.2 || (e.2 == b.2 && e.0 < b.0)));
                        Some(if better { e } else { b })
                    }
                };
            }
            best.map_or(-1, |b| b.0)
        })
        .collect())
}

/// Per-face labels from per-vertex labels (`vertex_labels.len()` = vertex count): every face
/// takes the label most of its three corners carry (corners labelled `< 0` are ignored; three
/// different labels: the lowest). A face with no labelled corner gets `-1`.
///
/// ```
/// use coseg::labels::vertices_to_faces;
/// use coseg::mesh::TriMesh;
/// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]],
///     vec![[0, 1, 2], [1, 3, 2]]).unwrap();
/// assert_eq!(vertices_to_faces(&m, &[0, 1, 1, -1]).unwrap(), vec![1, 1]);
/// ```
pub fn vertices_to_faces(mesh: &TriMesh, vertex_labels: &[i32]) -> Result<Vec<i32>, LabelError> {
    one_each("vertices", mesh.vertex_count(), vertex_labels.len())?;
    Ok(mesh
        .faces()
        .iter()
        .map(|tri| {
            let l = tri.map(|v| vertex_labels[v as usize]);
            let count = |x: i32| l.iter().filter(|&&y| y == x).count();
            let mut best = -1;
            let mut best_count = 0;
            for &x in &l {
                if x < 0 {
                    continue;
                }
                let c = count(x);
                if c > best_count || (c == best_count && x < best) {
                    best = x;
                    best_count = c;
                }
            }
            best
        })
        .collect())
}

/// The distinct non-negative labels of several label vectors, ascending, with their total
/// count of entries (a map `label → entries`).
///
/// ```
/// let s = coseg::labels::label_set([&[1, 3, -1, 1][..], &[3]]);
/// assert_eq!(s.into_iter().collect::<Vec<_>>(), vec![(1, 2), (3, 2)]);
/// ```
pub fn label_set<'a>(labels: impl IntoIterator<Item = &'a [i32]>) -> BTreeMap<i32, usize> {
    let mut out = BTreeMap::new();
    for l in labels {
        for &x in l.iter().filter(|&&x| x >= 0) {
            *out.entry(x).or_insert(0) += 1;
        }
    }
    out
}

/// Checks that there is one label per face or vertex (`what`): `got` labels for `expected`.
fn one_each(what: &'static str, expected: usize, got: usize) -> Result<(), LabelError> {
    if got == expected {
        Ok(())
    } else {
        Err(LabelError::Length {
            what,
            expected,
            got,
        })
    }
}
