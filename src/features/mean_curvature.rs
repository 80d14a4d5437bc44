use crate::mesh::TriMesh;
use crate::spectral::SurfaceOperators;
#[cfg(test)]
use crate::spectral::cotan_laplacian;

/// Pointwise mean curvature `H` (length `d`, units 1/file length) from the cotangent Laplacian
/// of the vertex positions.
///
/// With the positive semi-definite weak Laplacian `L` and a diagonal mass `A`,
/// `A⁻¹ L X ≈ −Δ X = 2 H n`; `H(v) = ⟨(A⁻¹ L X)_v, n_v⟩ / 2` where `n_v` is the
/// area-weighted vertex normal (outward for counter-clockwise faces). `A` is the *mixed Voronoi*
/// area of Meyer et al. (2003) rather than the barycentric lumped mass: with barycentric areas
/// the pointwise estimate does not converge at irregular vertices (e.g. 15 % too large at the
/// valence-5 vertices of an icosphere, at any resolution); with mixed areas it does. Sign: `H = +1/r` on a
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
    let lx = cotan_laplacian_times_positions(mesh);
    let mass = mixed_voronoi_areas(mesh);
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

/// The resolution of [`mean_curvature`] on `mesh` (length `d`, units 1/file length): per
/// vertex, how far its `H` can move when every coordinate moves by up to
/// `COORDINATE_RESOLUTION` × the mesh's RMS radius (about its vertex centroid), to first order
/// in `L X` (normals and areas move `H` in proportion to itself, not from zero): `ε Σ_j |w_vj|
/// / A_v` with the weights and mixed areas of [`mean_curvature`]. A vertex with `|H|` within
/// it is flat as far as the coordinates can tell: its sign comes from how the coordinates were
/// rounded (an exactly planar patch gives `H = 0` when axis-aligned and `±10⁻⁹` once moved by
/// a rotation or a change in the last digits), so a decision on the sign of `H` must treat it
/// as 0. Vertices with zero area (`H = 0`) get 0. Does not depend on the mesh's placement
/// (rotation, translation); scales as `H` does.
///
/// ```
/// use coseg::{mesh::TriMesh, features::{mean_curvature, mean_curvature_resolution}};
/// // A flat square turned by an arbitrary rotation: H is rounding, within the resolution.
/// let (c, s) = (0.6f64, 0.8f64);
/// let p: Vec<[f64; 3]> = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.], [0.3, 0.7, 0.]]
///     .iter().map(|q| [c * q[0] + 5.0, q[1], s * q[0] - 3.0]).collect();
/// let m = TriMesh::new(p, vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]).unwrap();
/// let (h, r) = (mean_curvature(&m), mean_curvature_resolution(&m));
/// assert!(h.iter().zip(&r).all(|(h, r)| h.abs() <= *r && *r < 1e-6));
/// ```
pub fn mean_curvature_resolution(mesh: &TriMesh) -> Vec<f64> {
    let d = mesh.vertex_count();
    let pos = mesh.positions();
    if d == 0 {
        return Vec::new();
    }
    let mut c = [0.0f64; 3];
    for p in pos {
        (0..3).for_each(|k| c[k] += p[k] / d as f64);
    }
    let radius = (pos
        .iter()
        .map(|p| (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>())
        .sum::<f64>()
        / d as f64)
        .sqrt();
    let eps = COORDINATE_RESOLUTION * radius;
    let sums = SurfaceOperators::new(mesh).absolute_weight_sums(mesh);
    let mass = mixed_voronoi_areas(mesh);
    sums.iter()
        .zip(&mass)
        .map(|(&s, &a)| if a > 0.0 { eps * s / a } else { 0.0 })
        .collect()
}

/// The relative resolution of a mesh's coordinates [`mean_curvature_resolution`] assumes, ×
/// the mesh's RMS radius (a numerical constant, not fitted to data): far above how a motion
/// rounds coordinates (10⁻¹⁶ of their magnitude; 10⁻¹² of the radius for a shape moved ten
/// thousand of its sizes away) and above a change in the last twelve digits, far below any
/// modelled detail (a bump of 10⁻⁹ of a shape's size).
const COORDINATE_RESOLUTION: f64 = 1e-9;

/// `L X` for the cotangent Laplacian `L` of the mesh's [`SurfaceOperators`] (the same
/// weights, clamp and degenerate-triangle rule as the spectrum's), assembled face by face
/// without building the sparse matrix: `(L X)_i = Σ_j w_ij (x_i − x_j)`.
pub(crate) fn cotan_laplacian_times_positions(mesh: &TriMesh) -> Vec<[f64; 3]> {
    SurfaceOperators::new(mesh).laplacian_times(mesh, mesh.positions())
}

/// Mixed Voronoi vertex areas (Meyer, Desbrun, Schröder, Barr 2003): the Voronoi area inside
/// non-obtuse triangles, half/quarter of the triangle area at/beside an obtuse angle. Sums to the
/// total area.
fn mixed_voronoi_areas(mesh: &TriMesh) -> Vec<f64> {
    let mut a = vec![0.0; mesh.vertex_count()];
    for (f, idx) in mesh.faces().iter().enumerate() {
        let p = mesh.corners(f);
        let e = |i: usize, j: usize| [p[j][0] - p[i][0], p[j][1] - p[i][1], p[j][2] - p[i][2]];
        let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let (ab, ac, bc) = (e(0, 1), e(0, 2), e(1, 2));
        let cr = [
            ab[1] * ac[2] - ab[2] * ac[1],
            ab[2] * ac[0] - ab[0] * ac[2],
            ab[0] * ac[1] - ab[1] * ac[0],
        ];
        let twice = dot(cr, cr).sqrt();
        if twice <= 0.0 {
            continue;
        }
        let area = 0.5 * twice;
        // Dot products at each corner (cosine sign = obtuse test).
        let d = [
            dot(ab, ac),
            dot([-ab[0], -ab[1], -ab[2]], bc),
            dot([-ac[0], -ac[1], -ac[2]], [-bc[0], -bc[1], -bc[2]]),
        ];
        if let Some(obtuse) = d.iter().position(|&x| x < 0.0) {
            for (k, &v) in idx.iter().enumerate() {
                a[v as usize] += if k == obtuse { area / 2.0 } else { area / 4.0 };
            }
        } else {
            // cot of the angle at corner k = d[k] / twice.
            let len2 = [dot(bc, bc), dot(ac, ac), dot(ab, ab)]; // edge opposite corner k
            for k in 0..3 {
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                // Vertex k's Voronoi share: edges (k,i) and (k,j), opposite corners j and i.
                a[idx[k] as usize] += (len2[j] * d[j] / twice + len2[i] * d[i] / twice) / 8.0;
            }
        }
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `L X` by the face loop against the sparse `L` times `X`, to rounding.
    fn assert_face_loop_matches_sparse(mesh: &TriMesh) {
        let lx = cotan_laplacian_times_positions(mesh);
        let l = cotan_laplacian(mesh);
        // Rounding of the two summation orders grows with the weights (cancellation of
        // w·x_i − w·x_j): bound it by the largest entry of L times the largest coordinate.
        let big_w = l.val().iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let big_x = mesh
            .positions()
            .iter()
            .flatten()
            .fold(0.0f64, |a, v| a.max(v.abs()));
        let scale = (big_w * big_x).max(1.0);
        for (j, got) in lx.iter().enumerate() {
            let rows = l.as_ref().row_idx_of_col_raw(j);
            let vals = l.as_ref().val_of_col(j);
            let mut want = [0.0; 3];
            for (&i, &w) in rows.iter().zip(vals) {
                for (c, out) in want.iter_mut().enumerate() {
                    *out += w * mesh.positions()[i][c];
                }
            }
            for c in 0..3 {
                assert!(
                    (got[c] - want[c]).abs() <= 1e-12 * scale,
                    "{j} {c}: {got:?} {want:?}"
                );
            }
        }
    }

    /// Regression (one house, #15): the curvature clamped each cotangent apart and skipped
    /// single corners, while the Laplacian of the spectrum scales a needle triangle's three
    /// cotangents together and drops a degenerate triangle whole. On a needle (angles ~2e-7,
    /// cotangents ~5e6) and a zero-area triangle the two gave different `L X`.
    #[test]
    fn regression_needle_and_zero_area_triangles_follow_the_laplacians_rule() {
        let mesh = TriMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.2],
                [0.5, 1e-7, 0.1],
                [0.5, 0.8, 0.6],
                [2.0, 0.0, 0.4],
                [0.4, -0.7, -0.3],
            ],
            // 0-1-2 is the needle (vertex 2 lies 1e-7 off the segment 0-1); the other faces
            // are regular.
            vec![
                [0, 1, 2],
                [0, 2, 3],
                [2, 1, 3],
                [1, 4, 3],
                [0, 5, 1],
                [0, 1, 4],
            ],
        )
        .unwrap();
        assert_face_loop_matches_sparse(&mesh);
        // Exactly collinear corners: a zero-area triangle beside regular ones.
        let flat = TriMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [1.0, 1.0, 0.5],
                [1.0, -1.0, 0.3],
            ],
            vec![[0, 1, 2], [0, 1, 3], [1, 2, 3], [1, 0, 4], [2, 1, 4]],
        )
        .unwrap();
        assert_face_loop_matches_sparse(&flat);
    }

    #[test]
    fn face_assembly_equals_the_sparse_laplacian() {
        let mesh = TriMesh::new(
            vec![
                [0.0, 0.0, 0.1],
                [1.0, 0.0, 0.0],
                [1.2, 1.0, 0.3],
                [0.0, 1.0, -0.2],
                [0.5, 0.4, 0.9],
            ],
            vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]],
        )
        .unwrap();
        assert_face_loop_matches_sparse(&mesh);
        let total: f64 = mixed_voronoi_areas(&mesh).iter().sum();
        assert!((total - mesh.total_area()).abs() < 1e-12);
    }
}
