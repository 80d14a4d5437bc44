//! Seeded synthetic inputs for benchmarks and scaling studies (`benches/core.rs`,
//! `examples/scaling_study.rs`): smooth pseudo-features without any spectrum (banded by
//! [`crate::bands::synthetic_band_table`]), a bent grid, and a finer copy of a mesh.
//! Deterministic: the same arguments give the same values on every platform (integer
//! arithmetic for the random stream).

use crate::mesh::{MeshError, TriMesh};
use std::collections::HashMap;

/// A deterministic stream of numbers in `[0, 1)` (SplitMix64 seeded with the given state).
///
/// ```
/// use coseg::generate::SplitMix64;
/// let mut r = SplitMix64(7);
/// let x = r.next_f64();
/// assert!((0.0..1.0).contains(&x));
/// assert_eq!(SplitMix64(7).next_f64(), x);
/// ```
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next number, uniform in `[0, 1)` with 53 random bits.
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The smooth pseudo-features of [`smooth_features`], one feature (a `Vec` of one value per
/// point) at a time, so that a caller can use them without holding them all (the band table of
/// [`crate::bands::synthetic_band_table`] does).
///
/// ```
/// use coseg::generate::{SmoothFeatures, smooth_features};
/// let one_by_one: Vec<f64> = SmoothFeatures::new(50, 4, 3).flatten().collect();
/// assert_eq!(one_by_one, smooth_features(50, 4, 3));
/// ```
#[derive(Debug, Clone)]
pub struct SmoothFeatures {
    random: SplitMix64,
    points: Vec<(f64, f64)>,
    remaining: usize,
}

impl SmoothFeatures {
    /// `features` features of `vertices` random points of the unit square, from `seed`.
    pub fn new(vertices: usize, features: usize, seed: u64) -> Self {
        let mut random = SplitMix64(seed);
        let points = (0..vertices)
            .map(|_| (random.next_f64(), random.next_f64()))
            .collect();
        SmoothFeatures {
            random,
            points,
            remaining: features,
        }
    }
}

impl Iterator for SmoothFeatures {
    type Item = Vec<f64>;

    fn next(&mut self) -> Option<Vec<f64>> {
        if self.remaining == 0 {
            return None;
        }
        self.remaining -= 1;
        let r = &mut self.random;
        let (a, b) = (r.next_f64() - 0.5, r.next_f64() - 0.5);
        let f = 1.0 + 6.0 * r.next_f64();
        Some(
            self.points
                .iter()
                .map(|&(x, y)| (f * (a * x + b * y)).sin())
                .collect(),
        )
    }
}

/// `features` smooth pseudo-features of `vertices` random points of the unit square, feature-
/// major (`values[k * vertices + v]`, the layout of [`crate::bands::equal_count_bands`]):
/// feature `k` is `sin(f_k (a_k x + b_k y))` with a random direction `(a_k, b_k)` and frequency
/// `f_k ∈ [1, 7)`. Like spectral descriptors, nearby points have nearby values and features are
/// correlated.
///
/// ```
/// let v = coseg::generate::smooth_features(100, 3, 1);
/// assert_eq!(v.len(), 300);
/// assert!(v.iter().all(|x| x.abs() <= 1.0));
/// ```
pub fn smooth_features(vertices: usize, features: usize, seed: u64) -> Vec<f64> {
    SmoothFeatures::new(vertices, features, seed)
        .flatten()
        .collect()
}

/// An `n × n` grid of unit squares (`n ≥ 2` points a side), each cut into two triangles,
/// gently bent (`z = 0.1 sin(0.3 x) cos(0.2 y)`): an open surface with `n²` vertices.
///
/// ```
/// let m = coseg::generate::grid_mesh(10).unwrap();
/// assert_eq!((m.vertex_count(), m.face_count()), (100, 162));
/// ```
pub fn grid_mesh(n: u32) -> Result<TriMesh, MeshError> {
    let pos = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64, (i / n) as f64);
            [x, y, 0.1 * (x * 0.3).sin() * (y * 0.2).cos()]
        })
        .collect();
    let mut faces = Vec::new();
    for y in 0..n.saturating_sub(1) {
        for x in 0..n - 1 {
            let v = y * n + x;
            faces.push([v, v + 1, v + n + 1]);
            faces.push([v, v + n + 1, v + n]);
        }
    }
    TriMesh::new(pos, faces)
}

/// A finer copy of `mesh`: every triangle cut into `n²` (each edge into `n` segments, `n ≥ 1`),
/// the new points placed by Phong tessellation (shape factor 3/4: the barycentric blend of the
/// point's projections onto the corners' tangent planes, from area-weighted vertex normals),
/// so the surface stays curved rather than piecewise flat. Points on an edge depend only on
/// that edge's two ends, so neighbouring triangles agree and a closed manifold stays one. The
/// original vertices keep their indices and positions; about `n²` times the vertices.
///
/// ```
/// let m = coseg::generate::grid_mesh(3).unwrap();
/// let f = coseg::generate::refine_mesh(&m, 2).unwrap();
/// assert_eq!((f.vertex_count(), f.face_count()), (25, 32));
/// assert_eq!(&f.positions()[..9], m.positions());
/// ```
pub fn refine_mesh(mesh: &TriMesh, n: u32) -> Result<TriMesh, MeshError> {
    let n = n.max(1);
    let normals = mesh.vertex_normals();
    let corners = mesh.positions();
    let mut positions = corners.to_vec();
    // Phong point of barycentric (u, v, w) on corners (a, b, c).
    let phong = |[a, b, c]: [u32; 3], [u, v, w]: [f64; 3]| -> [f64; 3] {
        let (pa, pb, pc) = (
            corners[a as usize],
            corners[b as usize],
            corners[c as usize],
        );
        let p: [f64; 3] = std::array::from_fn(|d| u * pa[d] + v * pb[d] + w * pc[d]);
        let project = |q: [f64; 3], nq: [f64; 3]| -> [f64; 3] {
            let h: f64 = (0..3).map(|d| (p[d] - q[d]) * nq[d]).sum();
            std::array::from_fn(|d| p[d] - h * nq[d])
        };
        let (qa, qb, qc) = (
            project(pa, normals[a as usize]),
            project(pb, normals[b as usize]),
            project(pc, normals[c as usize]),
        );
        std::array::from_fn(|d| 0.25 * p[d] + 0.75 * (u * qa[d] + v * qb[d] + w * qc[d]))
    };
    // Interior points of each edge, from its lower-indexed end.
    let mut edge_points: HashMap<(u32, u32), u32> = HashMap::new();
    let mut faces = Vec::with_capacity(mesh.face_count() * (n * n) as usize);
    let nf = n as f64;
    for &face in mesh.faces() {
        // Index of lattice point (i, j) (weights (n−i−j, i, j)/n on the face's corners).
        let mut lattice = vec![0u32; ((n + 1) * (n + 2) / 2) as usize];
        let slot = |i: u32, j: u32| (i * (2 * n + 3 - i) / 2 + j) as usize;
        for i in 0..=n {
            for j in 0..=n - i {
                let k = n - i - j;
                let index = match (i, j, k) {
                    (0, 0, _) => face[0],
                    (_, 0, 0) => face[1],
                    (0, _, 0) => face[2],
                    _ => {
                        let edge = match (i, j, k) {
                            (_, 0, _) => Some((face[0], face[1], i)),
                            (0, _, _) => Some((face[0], face[2], j)),
                            (_, _, 0) => Some((face[1], face[2], j)),
                            _ => None,
                        };
                        let w = [k as f64 / nf, i as f64 / nf, j as f64 / nf];
                        match edge {
                            Some((s, t, step)) => {
                                let (lo, hi, step) = if s < t {
                                    (s, t, step)
                                } else {
                                    (t, s, n - step)
                                };
                                let first = *edge_points.entry((lo, hi)).or_insert_with(|| {
                                    let first = positions.len() as u32;
                                    for m in 1..n {
                                        let t = m as f64 / nf;
                                        // Same points from either face: corners (lo, hi, hi).
                                        positions.push(phong([lo, hi, hi], [1.0 - t, t, 0.0]));
                                    }
                                    first
                                });
                                first + step - 1
                            }
                            None => {
                                positions.push(phong(face, w));
                                positions.len() as u32 - 1
                            }
                        }
                    }
                };
                lattice[slot(i, j)] = index;
            }
        }
        for i in 0..n {
            for j in 0..n - i {
                let (p, q, r) = (
                    lattice[slot(i, j)],
                    lattice[slot(i + 1, j)],
                    lattice[slot(i, j + 1)],
                );
                faces.push([p, q, r]);
                if i + j + 1 < n {
                    let s = lattice[slot(i + 1, j + 1)];
                    faces.push([q, s, r]);
                }
            }
        }
    }
    TriMesh::new(positions, faces)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{connected_components, edges};

    #[test]
    fn refined_closed_mesh_stays_closed_and_curved() {
        // An octahedron: closed, every edge shared by two faces.
        let pos = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let faces = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        let m = TriMesh::new(pos, faces).unwrap();
        for n in 1..=4 {
            let f = refine_mesh(&m, n).unwrap();
            let n = n as usize;
            assert_eq!(f.face_count(), 8 * n * n);
            // Euler: V − E + F = 2 with E = 3F/2.
            assert_eq!(f.vertex_count(), 2 + 4 * n * n);
            assert!(edges(&f).1.iter().all(|&c| c == 2));
            assert_eq!(connected_components(&f).count, 1);
            // Curved outwards: more area than the octahedron, less than the unit sphere's.
            let area = f.total_area();
            assert!(area >= m.total_area() - 1e-9 && area < 4.0 * std::f64::consts::PI);
        }
        // New points bulge outwards towards the sphere through the corners.
        let f = refine_mesh(&m, 4).unwrap();
        let r = |p: &[f64; 3]| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        let face_centre = 1.0 / 3f64.sqrt();
        assert!(f.positions().iter().all(|p| r(p) > face_centre - 1e-12));
        assert!(f.positions()[6..].iter().any(|p| r(p) > 0.6));
    }
}
