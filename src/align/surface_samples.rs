//! Per-shape data the registrations share: exact area moments (centroid, RMS radius, inertia
//! frame), seeded area-weighted surface samples in the shape's normalised frame, and a
//! nearest-neighbour index over them.

use super::AlignError;
use crate::mesh::TriMesh;
use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::BHShape;
use bvh::bvh::Bvh;
use bvh::point_query::PointDistance;
use nalgebra::{Matrix3, Point3, SymmetricEigen, Vector3};
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{Rng, SeedableRng};

/// Area moments of a surface: exact integrals over its triangles.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Moments {
    /// Area-weighted centroid.
    pub centroid: Vector3<f64>,
    /// Root mean square distance of the surface from its centroid (area-weighted), > 0.
    pub radius: f64,
    /// Total area.
    pub area: f64,
    /// Principal axes of the area covariance, as columns, by decreasing variance; a proper
    /// rotation (determinant +1).
    pub frame: Matrix3<f64>,
    /// Variances along the principal axes, decreasing, in units of `radius²` (sum 1).
    pub spectrum: [f64; 3],
}

/// The exact area moments of `mesh`. Errors when the surface has no area.
pub(crate) fn moments(mesh: &TriMesh) -> Result<Moments, AlignError> {
    let mut area = 0.0;
    let mut first = Vector3::zeros();
    let mut second = Matrix3::zeros();
    for f in 0..mesh.face_count() {
        let c = mesh.corners(f).map(|p| Vector3::new(p[0], p[1], p[2]));
        let a = 0.5 * (c[1] - c[0]).cross(&(c[2] - c[0])).norm();
        if !a.is_finite() || a == 0.0 {
            continue;
        }
        let s = c[0] + c[1] + c[2];
        area += a;
        first += s * (a / 3.0);
        // ∫ x xᵀ over a triangle = A/12 (Σ vᵢ vᵢᵀ + s sᵀ), s = Σ vᵢ.
        second += (c[0] * c[0].transpose()
            + c[1] * c[1].transpose()
            + c[2] * c[2].transpose()
            + s * s.transpose())
            * (a / 12.0);
    }
    if area.is_nan() || area <= 0.0 {
        return Err(AlignError::Degenerate(
            "the surface has no area (every face is degenerate)".into(),
        ));
    }
    let centroid = first / area;
    let cov = second / area - centroid * centroid.transpose();
    let trace = cov.trace();
    if !trace.is_finite() || trace <= 0.0 {
        return Err(AlignError::Degenerate(
            "the surface has no extent (all points coincide)".into(),
        ));
    }
    let radius = trace.sqrt();
    let eig = SymmetricEigen::new(cov);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
    let mut frame = Matrix3::zeros();
    let mut spectrum = [0.0; 3];
    for (k, &i) in order.iter().enumerate() {
        frame.set_column(k, &eig.eigenvectors.column(i));
        spectrum[k] = eig.eigenvalues[i].max(0.0) / trace;
    }
    if frame.determinant() < 0.0 {
        let c = -frame.column(2);
        frame.set_column(2, &c);
    }
    Ok(Moments {
        centroid,
        radius,
        area,
        frame,
        spectrum,
    })
}

/// A shape ready for registration: its moments, `n` seeded area-weighted samples of its
/// surface in its normalised frame (`(x − centroid) / radius`), and an index over them.
pub(crate) struct Prepared {
    pub moments: Moments,
    /// Samples in the normalised frame.
    pub samples: Vec<Vector3<f64>>,
    /// Area in the normalised frame (`area / radius²`).
    pub normalised_area: f64,
    pub index: PointIndex,
    /// Index over the first [`COARSE_SAMPLES`] samples.
    pub coarse: PointIndex,
}

/// Samples of the coarse pass of a registration: enough to tell a right pose from a flipped
/// one (the residuals differ by a tenth of the radius, the samples are a fifth of it apart).
pub(crate) const COARSE_SAMPLES: usize = 200;

impl Prepared {
    /// Moments, `n` samples drawn with ChaCha8 seeded by `seed`, and their index.
    pub fn new(mesh: &TriMesh, n: usize, seed: u64) -> Result<Self, AlignError> {
        let moments = moments(mesh)?;
        let samples: Vec<Vector3<f64>> = surface_samples(mesh, n, seed)
            .into_iter()
            .map(|p| (p - moments.centroid) / moments.radius)
            .collect();
        let index = PointIndex::new(&samples);
        let coarse = PointIndex::new(&samples[..COARSE_SAMPLES.min(samples.len())]);
        Ok(Self {
            coarse,
            normalised_area: moments.area / (moments.radius * moments.radius),
            moments,
            samples,
            index,
        })
    }
}

impl Prepared {
    /// Nearest sample to `q` among the first `n` (`n` is either the coarse count or all).
    pub fn index_prefix_nearest(&self, n: usize, q: &Vector3<f64>) -> (usize, f64) {
        if n <= self.coarse.len() {
            self.coarse.nearest(q)
        } else {
            self.index.nearest(q)
        }
    }
}

/// `n` points uniformly distributed over the surface by area (a face drawn with probability
/// proportional to its area, then a uniform point on it). Deterministic for one seed; a prefix
/// of the list is itself a uniform sample.
fn surface_samples(mesh: &TriMesh, n: usize, seed: u64) -> Vec<Vector3<f64>> {
    let areas = mesh.face_areas();
    let mut cumulative = Vec::with_capacity(areas.len());
    let mut total = 0.0;
    for a in &areas {
        total += if a.is_finite() { *a } else { 0.0 };
        cumulative.push(total);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut unit = || (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
    (0..n)
        .map(|_| {
            let x = unit() * total;
            let f = cumulative.partition_point(|&c| c <= x).min(areas.len() - 1);
            let (r1, r2) = (unit().sqrt(), unit());
            let c = mesh.corners(f).map(|p| Vector3::new(p[0], p[1], p[2]));
            c[0] * (1.0 - r1) + c[1] * (r1 * (1.0 - r2)) + c[2] * (r1 * r2)
        })
        .collect()
}

struct Pt {
    p: Point3<f64>,
    id: usize,
    node: usize,
}

impl Bounded<f64, 3> for Pt {
    fn aabb(&self) -> Aabb<f64, 3> {
        Aabb::with_bounds(self.p, self.p)
    }
}

impl BHShape<f64, 3> for Pt {
    fn set_bh_node_index(&mut self, i: usize) {
        self.node = i;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

impl PointDistance<f64, 3> for Pt {
    fn distance_squared(&self, q: Point3<f64>) -> f64 {
        (self.p - q).norm_squared()
    }
}

/// Nearest neighbours among a fixed point set (the `bvh` crate's hierarchy over points).
pub(crate) struct PointIndex {
    pts: Vec<Pt>,
    bvh: Bvh<f64, 3>,
}

impl PointIndex {
    pub fn new(points: &[Vector3<f64>]) -> Self {
        let mut pts: Vec<Pt> = points
            .iter()
            .enumerate()
            .map(|(id, v)| Pt {
                p: Point3::from(*v),
                id,
                node: 0,
            })
            .collect();
        let bvh = Bvh::build(&mut pts);
        Self { pts, bvh }
    }

    pub fn len(&self) -> usize {
        self.pts.len()
    }

    /// Index of the nearest point to `q` and the distance.
    pub fn nearest(&self, q: &Vector3<f64>) -> (usize, f64) {
        let (pt, d) = self
            .bvh
            .nearest_to(Point3::from(*q), &self.pts)
            .expect("samples are never empty");
        (pt.id, d)
    }
}
