use super::surface_operators;
use crate::mesh::TriMesh;
use faer::sparse::SparseColMat;

/// Cotangent Laplacian `L` (`d × d`, symmetric positive semi-definite, weak form):
/// `L_ij = -(cot α_ij + cot β_ij) / 2` for an edge `ij` with opposite angles `α_ij`, `β_ij`,
/// `L_ii = -Σ_j L_ij`, so `L 1 = 0`. Dimensionless (invariant to uniform scaling of the mesh).
/// The weights follow the clamp and degenerate-triangle rule of
/// [`SurfaceOperators`](super::SurfaceOperators); build that instead when the mass or the
/// weights are needed too.
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::cotan_laplacian};
/// let mesh = TriMesh::new(vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]).unwrap();
/// let l = cotan_laplacian(&mesh);
/// assert_eq!(l.nrows(), 3);
/// ```
pub fn cotan_laplacian(mesh: &TriMesh) -> SparseColMat<usize, f64> {
    surface_operators::laplacian(mesh)
}
