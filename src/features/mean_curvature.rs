use crate::mesh::TriMesh;
use crate::spectral::cotan_laplacian;

/// Pointwise mean curvature `H` (length `d`, units 1/file length) from the cotangent Laplacian
/// of the vertex positions.
///
/// With the positive semi-definite weak Laplacian `L` and lumped mass `M`,
/// `M⁻¹ L X ≈ −Δ X = 2 H n`; `H(v) = ⟨(M⁻¹ L X)_v, n_v⟩ / 2` where `n_v` is the
/// area-weighted vertex normal (outward for counter-clockwise faces). Sign: `H = +1/r` on a
/// sphere of radius `r` with outward normals, positive on convex bumps, negative in saddles'
/// concave directions. Vertices with zero area or no normal get 0.
///
/// Scaling the mesh by `s` divides `H` by `s`: multiply by `sqrt(total_area)` for the
/// unit-area value (as [`descriptors`](super::descriptors) does).
///
/// ```
/// use coseg::{mesh::TriMesh, features::mean_curvature};
/// // A flat square split in two: H = 0 everywhere.
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.]], vec![[0,1,2],[0,2,3]]).unwrap();
/// assert!(mean_curvature(&m).iter().all(|h| h.abs() < 1e-12));
/// ```
pub fn mean_curvature(mesh: &TriMesh) -> Vec<f64> {
    let d = mesh.vertex_count();
    let l = cotan_laplacian(mesh);
    let x = mesh.positions();
    let mut lx = vec![[0.0f64; 3]; d];
    // L is symmetric: column j holds row j.
    for (j, lxj) in lx.iter_mut().enumerate() {
        let rows = l.as_ref().row_idx_of_col_raw(j);
        let vals = l.as_ref().val_of_col(j);
        for (&i, &w) in rows.iter().zip(vals) {
            for c in 0..3 {
                lxj[c] += w * x[i][c];
            }
        }
    }
    let mass = mesh.vertex_areas();
    let normals = mesh.vertex_normals();
    (0..d)
        .map(|v| {
            if mass[v] > 0.0 {
                let n = normals[v];
                let p = lx[v][0] * n[0] + lx[v][1] * n[1] + lx[v][2] * n[2];
                p / (2.0 * mass[v])
            } else {
                0.0
            }
        })
        .collect()
}
