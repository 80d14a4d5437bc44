//! [`canonical_frame`]: the view every picture and the viewer page start from.

use crate::mesh::{TriMesh, cross, dot, sub};
use nalgebra::{Matrix3, SymmetricEigen};

/// An orthonormal, right-handed view frame: screen right, screen up and toward the viewer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewFrame {
    /// Area-weighted centroid of the mesh (file units).
    pub center: [f64; 3],
    /// `axes[0]` = screen right, `axes[1]` = screen up, `axes[2]` = toward the viewer
    /// (`axes[2] = axes[0] × axes[1]`).
    pub axes: [[f64; 3]; 3],
}

impl ViewFrame {
    /// Coordinates of `p` in the frame: `(right, up, toward viewer)`, file units.
    pub fn project(&self, p: [f64; 3]) -> [f64; 3] {
        let d = sub(p, self.center);
        self.axes.map(|a| dot(d, a))
    }
}

/// The canonical view of a mesh, from its principal axes; the same rule for every shape.
///
/// - Centre: the area-weighted centroid (barycentric vertex areas; uniform weights if the mesh
///   has no area).
/// - Axes: eigenvectors of the area-weighted covariance of the vertex positions, by decreasing
///   variance: the longest axis runs left to right, the second bottom to top, the shortest
///   points at the viewer, so the picture shows the shape's largest silhouette.
/// - Signs (the rule that makes the view deterministic): the first two axes point toward the
///   shape's heavier tail, i.e. their weighted third moment `Σ ωᵢ ((pᵢ − c)·a)³` is positive;
///   when that moment is negligible (below `1e-6 Σωᵢ σ³`, a symmetric shape) the axis' largest
///   component (first such coordinate on ties) is made positive. The third axis is
///   `a₀ × a₁`, so the picture is never mirrored.
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::render::canonical_frame;
/// // A long thin triangle along z: z becomes screen right.
/// let mesh = TriMesh::new(vec![[0., 0., 0.], [0., 1., 0.], [0., 0., 10.]], vec![[0, 1, 2]]).unwrap();
/// let f = canonical_frame(&mesh);
/// assert!(f.axes[0][2].abs() > 0.9);
/// ```
pub fn canonical_frame(mesh: &TriMesh) -> ViewFrame {
    let pos = mesh.positions();
    let (w, c) = weighted_centroid(mesh);
    let total: f64 = w.iter().sum();
    let mut cov = Matrix3::<f64>::zeros();
    for (p, &wi) in pos.iter().zip(&w) {
        let d = sub(*p, c);
        for r in 0..3 {
            for s in 0..3 {
                cov[(r, s)] += wi * d[r] * d[s];
            }
        }
    }
    cov /= total;
    let eig = SymmetricEigen::new(cov);
    let mut order = [0usize, 1, 2];
    // Stable sort: equal variances keep nalgebra's (deterministic) order.
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let mut axes = order.map(|i| {
        let v = eig.eigenvectors.column(i);
        let n = v.norm();
        [v[0] / n, v[1] / n, v[2] / n]
    });
    for a in axes.iter_mut().take(2) {
        let mut m3 = 0.0;
        let mut m2 = 0.0;
        for (p, &wi) in pos.iter().zip(&w) {
            let t = dot(sub(*p, c), *a);
            m2 += wi * t * t;
            m3 += wi * t * t * t;
        }
        let sigma = (m2 / total).sqrt();
        let flip = if m3.abs() > 1e-6 * total * sigma.powi(3) {
            m3 < 0.0
        } else {
            let mut best = 0;
            for k in 1..3 {
                if a[k].abs() > a[best].abs() + 1e-12 {
                    best = k;
                }
            }
            a[best] < 0.0
        };
        if flip {
            *a = a.map(|x| -x);
        }
    }
    axes[2] = cross(axes[0], axes[1]);
    ViewFrame { center: c, axes }
}

/// The vertex weights of the views (barycentric vertex areas; uniform if the mesh has no
/// area) and the weighted centroid of the vertices.
pub(super) fn weighted_centroid(mesh: &TriMesh) -> (Vec<f64>, [f64; 3]) {
    let pos = mesh.positions();
    let mut w = mesh.vertex_areas();
    let total: f64 = w.iter().sum();
    if total <= 0.0 || !total.is_finite() {
        w = vec![1.0; pos.len()];
    }
    let total: f64 = w.iter().sum();
    let mut c = [0.0; 3];
    for (p, &wi) in pos.iter().zip(&w) {
        for k in 0..3 {
            c[k] += wi * p[k];
        }
    }
    (w, c.map(|x| x / total))
}
