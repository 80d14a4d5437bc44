use crate::mesh::{TriMesh, cross, dot, norm, sub};
use faer::sparse::{SparseColMat, Triplet};

/// Largest magnitude allowed for a cotangent weight. Nearly degenerate triangles have
/// unbounded cotangents; when one of a triangle's cotangents exceeds this, all three are scaled
/// down by the same factor (which keeps `L` positive semi-definite), bounding `L`'s entries at
/// the price of a local error on those triangles only. Degenerate (zero-area) triangles
/// contribute nothing.
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
        // Cotangent of the angle at each corner k, opposite edge (k+1, k+2).
        let mut cot = [0.0f64; 3];
        let mut degenerate = false;
        for (k, ck) in cot.iter_mut().enumerate() {
            let u = sub(p[(k + 1) % 3], p[k]);
            let v = sub(p[(k + 2) % 3], p[k]);
            let c = norm(cross(u, v));
            if c.is_nan() || c <= 0.0 || !c.is_finite() {
                degenerate = true;
                break;
            }
            *ck = dot(u, v) / c;
        }
        if degenerate {
            continue;
        }
        // Clamp by scaling all three cotangents of the triangle by the same factor: this keeps
        // the triangle's stiffness matrix positive semi-definite (its cotangents satisfy
        // c₀c₁ + c₁c₂ + c₂c₀ = 1 > 0, which a common positive factor preserves), whereas
        // clamping each one separately can make a needle triangle indefinite.
        let big = cot.iter().fold(0.0f64, |a, c| a.max(c.abs()));
        if big > MAX_COTANGENT {
            let s = MAX_COTANGENT / big;
            for c in cot.iter_mut() {
                *c *= s;
            }
        }
        for (k, &ck) in cot.iter().enumerate() {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let w = 0.5 * ck;
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
