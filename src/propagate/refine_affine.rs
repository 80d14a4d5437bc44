//! [`refine_affine`]: a similarity registration relaxed to an affine map by trimmed,
//! symmetric ICP, so that shapes of one class with other proportions (a taller back, a wider
//! seat) overlay part on part.

use crate::align::{Similarity, SurfaceIndex, SurfacePoint};
use crate::mesh::TriMesh;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

/// An affine map `x ↦ A x + t` (target points into the source's frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AffineMap {
    /// The linear part `A`, row-major.
    pub matrix: [[f64; 3]; 3],
    /// The translation `t`, applied last, in source units.
    pub translation: [f64; 3],
}

impl AffineMap {
    /// The similarity as an affine map.
    pub fn from_similarity(s: &Similarity) -> Self {
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = s.scale * s.rotation[i][j];
            }
        }
        AffineMap {
            matrix: m,
            translation: s.translation,
        }
    }

    /// The image of one point.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let m = &self.matrix;
        let mut out = [0.0; 3];
        for (i, o) in out.iter_mut().enumerate() {
            *o = m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + self.translation[i];
        }
        out
    }

    fn linear(&self) -> Matrix3<f64> {
        Matrix3::from_fn(|i, j| self.matrix[i][j])
    }
}

/// The result of [`refine_affine`].
#[derive(Debug, Clone, PartialEq)]
pub struct AffineFit {
    /// Target points into the source's frame.
    pub map: AffineMap,
    /// Symmetric trimmed chamfer after the fit (mean of the kept nearest-point distances of
    /// both directions, each weighted by area), in source units.
    pub residual: f64,
    /// The same measure for the starting similarity, for comparison.
    pub start_residual: f64,
}

/// ICP iterations at most: the affine fit from a good similarity settles in a few steps.
const ITERATIONS: usize = 8;
/// Largest ratio of the fitted map's singular values: a class's shapes differ in proportions
/// by well under this; a fit stretching one axis more than this against another is sliding
/// into a degenerate overlay (a flat collapse onto one part) and is stopped.
const MAX_ANISOTROPY: f64 = 3.0;

/// Relaxes the similarity `start` (target onto source, as
/// [`register_pair`](crate::align::register_pair) returns it) to the affine map that best
/// overlays `target` on `source`: trimmed, symmetric, area-weighted ICP (each target vertex
/// paired with its nearest source surface point, each source vertex with its nearest point of
/// the mapped target surface; the farthest `1 − trim` of each direction by area dropped as
/// parts one shape lacks), the affine map solved by weighted least squares at each step.
///
/// Why affine: shapes of one man-made class differ in proportions more than in anything a
/// similarity can absorb (a bar stool against an armchair); after the similarity a chair's
/// seat of another height lands in the source's legs. Twelve parameters still cannot bend a
/// posed limb, so the fit stays a global overlay; the step is kept only while it lowers the
/// symmetric residual and stays within [`MAX_ANISOTROPY`].
///
/// Inputs: `source` and its `index` ([`SurfaceIndex::new`]`(source)`), `target` (`T`
/// vertices), `start`, `trim` in `(0, 1]` (share of pairs kept per direction). Output: an
/// [`AffineFit`]. Cost: per iteration `T + S` closest-point queries and one hierarchy over the
/// mapped target.
///
/// Deterministic: exact closest points, fixed orders.
///
/// See also: [`super::rigid_route`] (its user), [`crate::align::register_pair`].
pub fn refine_affine(
    source: &TriMesh,
    index: &SurfaceIndex,
    target: &TriMesh,
    start: &Similarity,
    trim: f64,
) -> AffineFit {
    refine_affine_reading(source, index, target, start, trim).0
}

/// [`refine_affine`] and, when the returned map is one the iterations paired (not the start
/// kept because no pairing could be made), the closest source surface point of every target
/// vertex under it (`index.closest(map.apply(x))`, target order): the rigid route reads its
/// labels off exactly these points, and they were computed already.
pub(crate) fn refine_affine_reading(
    source: &TriMesh,
    index: &SurfaceIndex,
    target: &TriMesh,
    start: &Similarity,
    trim: f64,
) -> (AffineFit, Option<Vec<SurfacePoint>>) {
    let ts = target.positions();
    let ss = source.positions();
    let ta = normalised(target.vertex_areas());
    let sa = normalised(source.vertex_areas());
    let mut map = AffineMap::from_similarity(start);
    let mut best: Option<(f64, AffineMap)> = None;
    let mut best_points: Option<Vec<SurfacePoint>> = None;
    let mut start_residual = f64::INFINITY;
    for it in 0..=ITERATIONS {
        let pairs = correspondences(source, index, target, &map, ts, ss, &ta, &sa, trim);
        let Some(pairs) = pairs else { break };
        if it == 0 {
            start_residual = pairs.residual;
        }
        if best.as_ref().is_some_and(|b| pairs.residual >= b.0) {
            break;
        }
        best = Some((pairs.residual, map));
        best_points = Some(pairs.closest);
        if it == ITERATIONS {
            break;
        }
        match solve(&pairs.pairs) {
            Some(next) if within_anisotropy(&next) => map = next,
            _ => break,
        }
    }
    let (residual, map) = best.unwrap_or((start_residual, AffineMap::from_similarity(start)));
    let fit = AffineFit {
        map,
        residual,
        start_residual,
    };
    (fit, best_points)
}

struct Pairs {
    /// `(target point in target coordinates, source point, weight)`.
    pairs: Vec<([f64; 3], [f64; 3], f64)>,
    residual: f64,
    /// Per target vertex, its closest source surface point under the map.
    closest: Vec<SurfacePoint>,
}

#[allow(clippy::too_many_arguments)]
fn correspondences(
    source: &TriMesh,
    index: &SurfaceIndex,
    target: &TriMesh,
    map: &AffineMap,
    ts: &[[f64; 3]],
    ss: &[[f64; 3]],
    ta: &[f64],
    sa: &[f64],
    trim: f64,
) -> Option<Pairs> {
    // Target → source: each target vertex and its nearest source surface point.
    let closest: Vec<SurfacePoint> = ts
        .par_iter()
        .map(|&x| index.closest(map.apply(x)))
        .collect();
    let forward: Vec<([f64; 3], [f64; 3], f64, f64)> = ts
        .iter()
        .zip(ta)
        .zip(&closest)
        .map(|((&x, &w), c)| {
            let p = point_on(source, c.face, c.barycentric);
            (x, p, w, c.distance)
        })
        .collect();
    // Source → target: each source vertex and its nearest point of the mapped target; the
    // pre-image of that point is the same barycentric combination of the target's corners
    // (an affine map keeps barycentric coordinates).
    let mapped = target.map_positions(|p| map.apply(p)).ok()?;
    let back = SurfaceIndex::new(&mapped);
    let backward: Vec<([f64; 3], [f64; 3], f64, f64)> = ss
        .par_iter()
        .zip(sa)
        .map(|(&y, &w)| {
            let c = back.closest(y);
            let x = point_on(target, c.face, c.barycentric);
            (x, y, w, c.distance)
        })
        .collect();
    let mut pairs = Vec::with_capacity(forward.len() + backward.len());
    let mut residual = 0.0;
    for dir in [forward, backward] {
        let kept = trimmed(&dir, trim);
        let total: f64 = kept.iter().map(|&k| dir[k].2).sum();
        if total <= 0.0 {
            return None;
        }
        residual += kept.iter().map(|&k| dir[k].2 * dir[k].3).sum::<f64>() / total / 2.0;
        pairs.extend(kept.iter().map(|&k| (dir[k].0, dir[k].1, dir[k].2 / total)));
    }
    Some(Pairs {
        pairs,
        residual,
        closest,
    })
}

/// Indices of the pairs kept: the nearest ones holding a share `trim` of the weight (each
/// pair: two ends, its weight, its distance; ties by index). The non-rigid step trims the same way.
pub(super) fn trimmed<A, B>(pairs: &[(A, B, f64, f64)], trim: f64) -> Vec<usize> {
    let mut order: Vec<usize> = (0..pairs.len()).collect();
    order.sort_by(|&a, &b| pairs[a].3.total_cmp(&pairs[b].3).then(a.cmp(&b)));
    let total: f64 = pairs.iter().map(|p| p.2).sum();
    let mut kept = Vec::with_capacity(order.len());
    let mut acc = 0.0;
    for k in order {
        if acc >= trim * total {
            break;
        }
        acc += pairs[k].2;
        kept.push(k);
    }
    kept
}

/// The weighted least-squares affine map taking each pair's first point onto its second.
fn solve(pairs: &[([f64; 3], [f64; 3], f64)]) -> Option<AffineMap> {
    let total: f64 = pairs.iter().map(|p| p.2).sum();
    if total <= 0.0 {
        return None;
    }
    let mut mx = Vector3::zeros();
    let mut my = Vector3::zeros();
    for (x, y, w) in pairs {
        mx += Vector3::from(*x) * *w;
        my += Vector3::from(*y) * *w;
    }
    mx /= total;
    my /= total;
    let mut cxx = Matrix3::zeros();
    let mut cyx = Matrix3::zeros();
    for (x, y, w) in pairs {
        let dx = Vector3::from(*x) - mx;
        let dy = Vector3::from(*y) - my;
        cxx += dx * dx.transpose() * *w;
        cyx += dy * dx.transpose() * *w;
    }
    let a = cyx * cxx.try_inverse()?;
    let t = my - a * mx;
    if !a.iter().chain(t.iter()).all(|v| v.is_finite()) || a.determinant() <= 0.0 {
        return None;
    }
    Some(AffineMap {
        matrix: [
            [a[(0, 0)], a[(0, 1)], a[(0, 2)]],
            [a[(1, 0)], a[(1, 1)], a[(1, 2)]],
            [a[(2, 0)], a[(2, 1)], a[(2, 2)]],
        ],
        translation: [t[0], t[1], t[2]],
    })
}

fn within_anisotropy(map: &AffineMap) -> bool {
    let sv = map.linear().singular_values();
    let (lo, hi) = (sv.min(), sv.max());
    lo > 0.0 && hi / lo <= MAX_ANISOTROPY
}

fn point_on(mesh: &TriMesh, face: usize, b: [f64; 3]) -> [f64; 3] {
    let f = mesh.faces()[face];
    let p = mesh.positions();
    let mut out = [0.0; 3];
    for (k, &v) in f.iter().enumerate() {
        for (o, c) in out.iter_mut().zip(p[v as usize]) {
            *o += b[k] * c;
        }
    }
    out
}

fn normalised(mut w: Vec<f64>) -> Vec<f64> {
    let total: f64 = w.iter().sum();
    if total > 0.0 {
        w.iter_mut().for_each(|x| *x /= total);
    }
    w
}
