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

/// The vertex graph of `edges` (as [`edges`] lists them) over `d` vertices, compressed: the
/// neighbours of vertex `v` are `adjacent[offsets[v]..offsets[v + 1]]`, each with the index of
/// the edge joining them, in edge order. `offsets` has `d + 1` entries.
///
/// ```
/// use coseg::mesh::{edge_adjacency, edges, TriMesh};
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[0.,1.,0.]], vec![[0, 1, 2]]).unwrap();
/// let (e, _) = edges(&m);
/// let (offsets, adjacent) = edge_adjacency(3, &e);
/// assert_eq!(offsets, [0, 2, 4, 6]);
/// assert_eq!(&adjacent[offsets[1]..offsets[2]], &[(0, 0), (2, 2)]);
/// ```
pub fn edge_adjacency(d: usize, edges: &[[u32; 2]]) -> (Vec<usize>, Vec<(u32, u32)>) {
    let mut offsets = vec![0usize; d + 1];
    for e in edges {
        offsets[e[0] as usize + 1] += 1;
        offsets[e[1] as usize + 1] += 1;
    }
    for v in 0..d {
        offsets[v + 1] += offsets[v];
    }
    let mut fill = offsets.clone();
    let mut adjacent = vec![(0u32, 0u32); edges.len() * 2];
    for (k, e) in edges.iter().enumerate() {
        for (a, b) in [(e[0], e[1]), (e[1], e[0])] {
            adjacent[fill[a as usize]] = (b, k as u32);
            fill[a as usize] += 1;
        }
    }
    (offsets, adjacent)
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
    labelled_components(mesh, &vec![0; mesh.vertex_count()])
}

/// Connected components of each label's vertices: vertices joined by a triangle edge whose
/// two ends carry the same label (#V labels, any values; negative ones are a label too).
/// Numbered as [`connected_components`] numbers them.
///
/// ```
/// use coseg::mesh::{labelled_components, TriMesh};
/// // A strip of two triangles, labels 0, 1, 0, 0: vertex 1 is cut off from the others.
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[0.,1.,0.],[1.,1.,0.]],
///     vec![[0, 1, 2], [1, 3, 2]]).unwrap();
/// let c = labelled_components(&m, &[0, 1, 0, 0]);
/// assert_eq!((c.labels, c.count), (vec![0, 1, 0, 0], 2));
/// ```
pub fn labelled_components(mesh: &TriMesh, labels: &[i32]) -> Components {
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
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            if labels[a as usize] != labels[b as usize] {
                continue;
            }
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            if ra != rb {
                // Keep the smaller index as root so numbering is deterministic.
                let (lo, hi) = (ra.min(rb), ra.max(rb));
                parent[hi as usize] = lo;
            }
        }
    }
    let mut out = vec![u32::MAX; d];
    let mut count = 0usize;
    let mut root_label = vec![u32::MAX; d];
    for (v, label) in out.iter_mut().enumerate() {
        let r = find(&mut parent, v as u32) as usize;
        if root_label[r] == u32::MAX {
            root_label[r] = count as u32;
            count += 1;
        }
        *label = root_label[r];
    }
    Components { labels: out, count }
}

/// Calls `visit(u, v, length)` for every face side `(u, v)` whose ends carry two different
/// labels, both non-negative (#V labels): each interior boundary edge twice, once from each
/// of its faces, in face order.
pub(crate) fn for_each_label_boundary(
    mesh: &TriMesh,
    labels: &[i32],
    mut visit: impl FnMut(usize, usize, f64),
) {
    let p = mesh.positions();
    for f in mesh.faces() {
        for k in 0..3 {
            let (u, v) = (f[k] as usize, f[(k + 1) % 3] as usize);
            let (x, y) = (labels[u], labels[v]);
            if x < 0 || y < 0 || x == y {
                continue;
            }
            visit(u, v, super::norm(super::sub(p[u], p[v])));
        }
    }
}
