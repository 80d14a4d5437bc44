use crate::mesh::{TriMesh, cross, dot, norm, sub};
use faer::sparse::{SparseColMat, Triplet};

/// Largest magnitude allowed for a cotangent weight. Nearly degenerate triangles have
/// unbounded cotangents; clamping keeps `L` well conditioned at the price of a local error on
/// those triangles only. Degenerate (zero-area) triangles contribute nothing.
pub const MAX_COTANGENT: f64 = 1e5;

/// Cotangent Laplacian `L` (`d × d`, symmetric positive semi-definite, weak form):
/// `L_ij = -(cot α_ij + cot β_ij) / 2` for an edge `ij` with opposite angles `α_ij`, `β_ij`,
/// `L_ii = -Σ_j L_ij`, so `L 1 = 0`. Dimensionless (invariant to uniform scaling of the mesh).
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::cotan_laplacian};
/// let mesh = TriMesh::new(vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]).unwrap();
/// let l = cotan_laplacian(&mesh);
/// assert_eq!(l.nrows(), 3);
/// ```
pub fn cotan_laplacian(mesh: &TriMesh) -> SparseColMat<usize, f64> {
    let d = mesh.vertex_count();
    let mut triplets = Vec::with_capacity(mesh.face_count() * 12);
    for f in 0..mesh.face_count() {
        let idx = mesh.faces()[f];
        let p = mesh.corners(f);
        for k in 0..3 {
            // Angle at corner k, opposite edge (k+1, k+2).
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let u = sub(p[i], p[k]);
            let v = sub(p[j], p[k]);
            let c = norm(cross(u, v));
            if !(c > 0.0) {
                continue;
            }
            let cot = (dot(u, v) / c).clamp(-MAX_COTANGENT, MAX_COTANGENT);
            let w = 0.5 * cot;
            let (a, b) = (idx[i] as usize, idx[j] as usize);
            triplets.push(Triplet::new(a, b, -w));
            triplets.push(Triplet::new(b, a, -w));
            triplets.push(Triplet::new(a, a, w));
            triplets.push(Triplet::new(b, b, w));
        }
    }
    // Duplicate entries are summed by the constructor.
    SparseColMat::try_new_from_triplets(d, d, &triplets)
        .expect("indices are in range by TriMesh's invariants")
}
