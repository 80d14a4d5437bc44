//! Exact closest points on a triangle mesh's surface: [`SurfaceIndex`] (a bounding volume
//! hierarchy over the triangles, built once) and [`closest_surface_points`] (many queries).

use crate::mesh::{BvhTriangle, TriMesh};
use bvh::bvh::Bvh;
use bvh::point_query::PointDistance;
use nalgebra::Point3;
use rayon::prelude::*;

/// The closest point of a mesh's surface to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// The face it lies on (index into [`TriMesh::faces`]).
    pub face: usize,
    /// Its barycentric coordinates on that face (weights of the face's three corners, in the
    /// face's vertex order; non-negative, summing to 1).
    pub barycentric: [f64; 3],
    /// Euclidean distance from the query point, in the mesh's units.
    pub distance: f64,
}

/// A triangle of the hierarchy, with the index of its face.
type Tri = BvhTriangle<usize>;

impl PointDistance<f64, 3> for Tri {
    fn distance_squared(&self, q: Point3<f64>) -> f64 {
        let (p, _) = closest_on_triangle(&q, &self.corners);
        (p - q).norm_squared()
    }
}

/// A mesh's triangles in a bounding volume hierarchy (the `bvh` crate), for exact
/// closest-point queries.
///
/// Cost: building is `O(F log F)` for `F` faces; a query visits `O(log F)` boxes on compact
/// surfaces. Ties between equally distant faces go to the first one the (deterministic)
/// hierarchy visits, so results are the same on every run.
///
/// See also: [`closest_surface_points`], [`nearest_point_labels`](super::nearest_point_labels).
pub struct SurfaceIndex {
    tris: Vec<Tri>,
    bvh: Bvh<f64, 3>,
}

impl SurfaceIndex {
    /// The hierarchy of `mesh`'s triangles.
    pub fn new(mesh: &TriMesh) -> Self {
        let mut tris: Vec<Tri> = (0..mesh.face_count())
            .map(|f| Tri::new(mesh, f, f))
            .collect();
        let bvh = Bvh::build(&mut tris);
        Self { tris, bvh }
    }

    /// The closest surface point to `p`.
    pub fn closest(&self, p: [f64; 3]) -> SurfacePoint {
        let q = Point3::new(p[0], p[1], p[2]);
        let (tri, _) = self
            .bvh
            .nearest_to(q, &self.tris)
            .expect("a validated mesh has at least one face");
        let (c, barycentric) = closest_on_triangle(&q, &tri.corners);
        SurfacePoint {
            face: tri.data,
            barycentric,
            distance: (c - q).norm(),
        }
    }
}

/// The exact closest surface point of `mesh` to each of `points`.
///
/// - `mesh`: any validated mesh (`F` faces);
/// - `points`: `n` query points in the mesh's units;
/// - returns `n` [`SurfacePoint`]s (face, barycentric coordinates, distance), in query order.
///
/// Builds one [`SurfaceIndex`] and queries it in parallel; use the index directly to query the
/// same mesh several times.
///
/// Known issues: on a face shared by equally near triangles (a query on an edge) the face is
/// the first the hierarchy finds; the point and distance are the same either way.
pub fn closest_surface_points(mesh: &TriMesh, points: &[[f64; 3]]) -> Vec<SurfacePoint> {
    let index = SurfaceIndex::new(mesh);
    points.par_iter().map(|&p| index.closest(p)).collect()
}

/// Closest point of triangle `t` to `p` and its barycentric coordinates (Ericson, *Real-Time
/// Collision Detection*, 5.1.5: the Voronoi regions of the vertices, edges and face).
fn closest_on_triangle(p: &Point3<f64>, t: &[Point3<f64>; 3]) -> (Point3<f64>, [f64; 3]) {
    let (a, b, c) = (t[0], t[1], t[2]);
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, [0.0, 1.0 - w, w]);
    }
    let denom = va + vb + vc;
    if denom.abs() < f64::MIN_POSITIVE || !denom.is_finite() {
        // A degenerate (zero-area) triangle: its vertex nearest to p.
        let d = [(a - p).norm(), (b - p).norm(), (c - p).norm()];
        let k = (0..3).min_by(|&i, &j| d[i].total_cmp(&d[j])).unwrap_or(0);
        let mut w = [0.0; 3];
        w[k] = 1.0;
        return (t[k], w);
    }
    let v = vb / denom;
    let w = vc / denom;
    (a + ab * v + ac * w, [1.0 - v - w, v, w])
}
