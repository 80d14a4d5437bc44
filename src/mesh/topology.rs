//! Edges, boundaries and connected components of a [`TriMesh`].

use super::TriMesh;

/// Every undirected edge once, as `(i, j)` with `i < j`, sorted. Together with the number of
/// faces each edge belongs to (1 on a boundary, 2 inside a manifold, more when non-manifold).
pub fn edges(mesh: &TriMesh) -> (Vec<[u32; 2]>, Vec<u32>) {
    let mut all: Vec<[u32; 2]> = Vec::with_capacity(mesh.face_count() * 3);
    for f in mesh.faces() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            if a != b {
                all.push([a.min(b), a.max(b)]);
            }
        }
    }
    all.sort_unstable();
    let mut unique: Vec<[u32; 2]> = Vec::with_capacity(all.len() / 2 + 1);
    let mut counts: Vec<u32> = Vec::with_capacity(all.len() / 2 + 1);
    for e in all {
        if unique.last() == Some(&e) {
            *counts.last_mut().unwrap() += 1;
        } else {
            unique.push(e);
            counts.push(1);
        }
    }
    (unique, counts)
}

/// Edges that belong to exactly one face, as `(i, j)` with `i < j`, sorted.
pub fn boundary_edges(mesh: &TriMesh) -> Vec<[u32; 2]> {
    let (e, c) = edges(mesh);
    e.into_iter()
        .zip(c)
        .filter(|&(_, n)| n == 1)
        .map(|(e, _)| e)
        .collect()
}

/// Connected components of the vertex graph (vertices joined by triangle edges).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Components {
    /// Component id of every vertex, `0..count`, numbered in order of each component's
    /// lowest vertex index. Unreferenced vertices form their own singleton components.
    pub labels: Vec<u32>,
    /// Number of components.
    pub count: usize,
}

/// Connected components of the mesh (union–find over face edges).
pub fn connected_components(mesh: &TriMesh) -> Components {
    let d = mesh.vertex_count();
    let mut parent: Vec<u32> = (0..d as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for f in mesh.faces() {
        for k in 1..3 {
            let (ra, rb) = (find(&mut parent, f[0]), find(&mut parent, f[k]));
            if ra != rb {
                // Keep the smaller index as root so numbering is deterministic.
                let (lo, hi) = (ra.min(rb), ra.max(rb));
                parent[hi as usize] = lo;
            }
        }
    }
    let mut labels = vec![u32::MAX; d];
    let mut count = 0usize;
    let mut root_label = vec![u32::MAX; d];
    for (v, label) in labels.iter_mut().enumerate() {
        let r = find(&mut parent, v as u32) as usize;
        if root_label[r] == u32::MAX {
            root_label[r] = count as u32;
            count += 1;
        }
        *label = root_label[r];
    }
    Components { labels, count }
}
