//! The shape diameter function (Shapira, Shamir, Cohen-Or 2008): the local thickness of the
//! volume under each vertex, from rays cast inwards in a cone around the inner normal.
//!
//! Intrinsic-free: it needs neither a manifold nor a connected mesh, so it keeps working on
//! CAD-like meshes made of many closed parts, where the Laplacian spectrum does not.

use super::{FeatureColumns, FeatureError};
use crate::mesh::{BvhTriangle, TriMesh, connected_components};
use bvh::aabb::Bounded;
use bvh::bvh::Bvh;
use bvh::ray::Ray;
use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

/// Options of [`shape_diameter`]. Every field changes the result.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct SdfOptions {
    /// Rays per vertex (default 30, as Shapira et al.).
    pub rays: usize,
    /// Full opening angle of the cone, degrees (default 120, as Shapira et al.).
    pub cone_degrees: f64,
    /// One column per entry: the SDF smoothed by this many rounds of area-weighted averaging
    /// over the one-ring (default `[1, 8, 32]`, columns `sdf_000`…).
    pub smoothing_rounds: Vec<usize>,
}

impl Default for SdfOptions {
    fn default() -> Self {
        SdfOptions {
            rays: 30,
            cone_degrees: 120.0,
            smoothing_rounds: vec![1, 8, 32],
        }
    }
}

/// A triangle of the hierarchy, with its face's outward normal.
type Tri = BvhTriangle<Vector3<f64>>;

/// Two-sided Möller–Trumbore: the distance along `dir` to the triangle, if hit at `t > eps`.
fn hit_distance(o: &Point3<f64>, dir: &Vector3<f64>, t: &Tri, eps: f64) -> Option<f64> {
    let [a, b, c] = &t.corners;
    let (e1, e2) = (b - a, c - a);
    let p = dir.cross(&e2);
    let det = e1.dot(&p);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - a;
    let u = s.dot(&p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(&e1);
    let v = dir.dot(&q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let dist = e2.dot(&q) * inv;
    (dist > eps).then_some(dist)
}

/// Unit cone directions around `+z` with half-angle `half` (radians): a Fibonacci spiral on the
/// spherical cap, the same set for every vertex.
fn cone_directions(n: usize, half: f64) -> Vec<Vector3<f64>> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let zmin = half.cos();
    (0..n)
        .map(|i| {
            let z = 1.0 - (1.0 - zmin) * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            Vector3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// An orthonormal basis `(t, b)` completing the unit vector `n` (Duff et al. 2017): continuous
/// except across `n.z = 0`'s sign flip, and a function of `n` alone.
fn basis(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    (
        Vector3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
        Vector3::new(b, s + n.y * n.y * a, -n.y),
    )
}

/// The cone's tangent frame `(t, b)` at a vertex at `p` with unit inner normal `inner`: `t`
/// along the edge to `neighbour` projected onto the tangent plane, `b = inner × t`; so the
/// rays turn with the mesh and a moved mesh casts the same rays (up to rounding). Without a
/// neighbour, or with an edge within `EDGE_ALONG_NORMAL` of the normal, [`basis`] (a
/// function of the normal alone).
fn cone_frame(
    inner: &Vector3<f64>,
    p: &[f64; 3],
    neighbour: Option<&[f64; 3]>,
) -> (Vector3<f64>, Vector3<f64>) {
    if let Some(q) = neighbour {
        let e = Vector3::new(q[0] - p[0], q[1] - p[1], q[2] - p[2]);
        let t = e - inner * inner.dot(&e);
        let (tn, en) = (t.norm(), e.norm());
        if en > 0.0 && tn > EDGE_ALONG_NORMAL * en {
            let t = t / tn;
            return (t, inner.cross(&t));
        }
    }
    basis(inner)
}

/// An edge whose part in the tangent plane is shorter than this share of its length runs
/// along the normal (a needle, a degenerate ring): its direction in the tangent plane is
/// rounding, so the cone falls back to [`basis`]. A numerical guard, not a tuned level.
const EDGE_ALONG_NORMAL: f64 = 1e-6;

/// Per vertex: does its connected component enclose a negative signed volume (faces wound
/// inwards)? Such components get their normals flipped so that every normal points outwards.
pub(crate) fn inward_wound(mesh: &TriMesh) -> Vec<bool> {
    let comps = connected_components(mesh);
    let mut volume = vec![0.0f64; comps.count];
    let p = mesh.positions();
    for f in mesh.faces() {
        let [a, b, c] = [p[f[0] as usize], p[f[1] as usize], p[f[2] as usize]];
        let v = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]);
        volume[comps.labels[f[0] as usize] as usize] += v;
    }
    comps
        .labels
        .iter()
        .map(|&c| volume[c as usize] < 0.0)
        .collect()
}

/// The shape diameter function of `mesh`, one column per entry of
/// [`SdfOptions::smoothing_rounds`] (`sdf_000`…).
///
/// For each vertex, `rays` rays leave the vertex inside a cone around the inner normal
/// (normals oriented outwards per connected component by the sign of its enclosed volume).
/// A ray's length is its nearest hit on a triangle facing away from the ray origin's side
/// (whose outward normal makes a positive dot product with the ray), which skips hits
/// through the wrong side of thin walls. The raw SDF is the median of the hit lengths;
/// vertices whose rays all miss take the median of the shape's raw SDF. The raw values are
/// then smoothed by rounds of area-weighted averaging over each vertex and its one-ring.
///
/// Collection-consistent scale: lengths are divided by `√(total area)`, so the SDF of every
/// shape is that of the shape scaled to unit area. Invariant to rigid motions and uniform
/// scaling up to floating-point rounding: each cone is turned about the normal by the
/// vertex's first edge, so it moves with the mesh. A vertex permutation may change the values
/// by the cones' sampling (each vertex's first edge may change).
///
/// Cost: one BVH (from the `bvh` crate) over the triangles, then `d × rays` ray casts in
/// parallel (rayon, one task per vertex, so the result does not depend on the thread count).
///
/// ```
/// use coseg::{mesh::TriMesh, features::{shape_diameter, SdfOptions}};
/// // A unit cube: thickness 1 below the centre of every face.
/// let p = vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.],[0.,0.,1.],[1.,0.,1.],[1.,1.,1.],[0.,1.,1.]];
/// let f = vec![[0,2,1],[0,3,2],[4,5,6],[4,6,7],[0,1,5],[0,5,4],[1,2,6],[1,6,5],[2,3,7],[2,7,6],[3,0,4],[3,4,7]];
/// let m = TriMesh::new(p, f).unwrap();
/// let c = shape_diameter(&m, &SdfOptions::default()).unwrap();
/// assert_eq!(c.names, ["sdf_000", "sdf_001", "sdf_002"]);
/// assert!(c.values.iter().all(|&x| x > 0.0));
/// ```
pub fn shape_diameter(
    mesh: &TriMesh,
    options: &SdfOptions,
) -> Result<FeatureColumns, FeatureError> {
    let half = options.cone_degrees.to_radians() / 2.0;
    if options.rays == 0 || !(half > 0.0 && half < std::f64::consts::FRAC_PI_2) {
        return Err(FeatureError::BadOption(format!(
            "sdf: need rays ≥ 1 and a cone angle in (0°, 180°), got {} rays and {}°",
            options.rays, options.cone_degrees
        )));
    }
    if options.smoothing_rounds.is_empty() {
        return Err(FeatureError::BadOption(
            "sdf: smoothing_rounds is empty (no column)".into(),
        ));
    }
    let raw = raw_sdf(mesh, options.rays, half);
    let scale = 1.0 / mesh.total_area().sqrt();
    let raw: Vec<f64> = raw.iter().map(|x| x * scale).collect();
    let d = mesh.vertex_count();
    let mut rounds: Vec<(usize, usize)> = options
        .smoothing_rounds
        .iter()
        .copied()
        .enumerate()
        .collect();
    rounds.sort_by_key(|&(_, r)| r);
    let mut columns = vec![Vec::new(); rounds.len()];
    let smoother = OneRing::new(mesh);
    let (mut cur, mut done) = (raw, 0usize);
    for (slot, r) in rounds {
        for _ in done..r {
            cur = smoother.apply(&cur);
        }
        done = r;
        columns[slot] = cur.clone();
    }
    let names = (0..columns.len()).map(|i| format!("sdf_{i:03}")).collect();
    FeatureColumns::new(d, names, columns.concat())
}

/// Raw (unsmoothed, file units) SDF per vertex.
fn raw_sdf(mesh: &TriMesh, rays: usize, half: f64) -> Vec<f64> {
    let flipped = inward_wound(mesh);
    let sign = |v: usize| if flipped[v] { -1.0 } else { 1.0 };
    let normals: Vec<[f64; 3]> = mesh
        .vertex_normals()
        .into_iter()
        .enumerate()
        .map(|(v, n)| n.map(|x| x * sign(v)))
        .collect();
    let face_normals = mesh.face_normals();
    let mut tris: Vec<Tri> = (0..mesh.face_count())
        .map(|f| {
            let n = face_normals[f];
            Tri::new(
                mesh,
                f,
                Vector3::new(n[0], n[1], n[2]) * sign(mesh.faces()[f][0] as usize),
            )
        })
        .collect();
    let bvh = Bvh::build(&mut tris);
    let diag = bbox_diagonal(mesh);
    let eps = 1e-9 * diag;
    let cone = cone_directions(rays, half);
    let positions = mesh.positions();
    // Each vertex's cone turns with the mesh: its first direction points along the vertex's
    // first edge (its first face's next corner), not along a file axis.
    let mut first_neighbour: Vec<Option<usize>> = vec![None; mesh.vertex_count()];
    for f in mesh.faces() {
        for k in 0..3 {
            let v = f[k] as usize;
            if first_neighbour[v].is_none() {
                first_neighbour[v] = Some(f[(k + 1) % 3] as usize);
            }
        }
    }
    let values: Vec<Option<f64>> = positions
        .par_iter()
        .zip(normals.par_iter())
        .enumerate()
        .map(|(v, (p, n))| {
            let inner = -Vector3::new(n[0], n[1], n[2]);
            if inner.norm_squared() < 0.5 {
                return None;
            }
            let (t, b) = cone_frame(&inner, p, first_neighbour[v].map(|u| &positions[u]));
            let origin = Point3::new(p[0], p[1], p[2]);
            let mut hits: Vec<f64> = cone
                .iter()
                .filter_map(|c| {
                    let dir = t * c.x + b * c.y + inner * c.z;
                    nearest_hit(&bvh, &tris, &origin, &dir, eps)
                })
                .collect();
            if hits.is_empty() {
                return None;
            }
            hits.sort_by(f64::total_cmp);
            let m = hits.len();
            Some(if m % 2 == 1 {
                hits[m / 2]
            } else {
                0.5 * (hits[m / 2 - 1] + hits[m / 2])
            })
        })
        .collect();
    let mut known: Vec<f64> = values.iter().flatten().copied().collect();
    known.sort_by(f64::total_cmp);
    let fallback = known.get(known.len() / 2).copied().unwrap_or(diag);
    values.into_iter().map(|v| v.unwrap_or(fallback)).collect()
}

fn nearest_hit(
    bvh: &Bvh<f64, 3>,
    tris: &[Tri],
    origin: &Point3<f64>,
    dir: &Vector3<f64>,
    eps: f64,
) -> Option<f64> {
    let ray = Ray::new(*origin, *dir);
    let mut best: Option<f64> = None;
    for tri in bvh.nearest_traverse_iterator(&ray, tris) {
        if let (Some(b), Some((entry, _))) = (best, ray.intersection_slice_for_aabb(&tri.aabb()))
            && entry > b
        {
            break;
        }
        // Only walls seen from the inside count: the hit face's outward normal goes along the ray.
        if tri.data.dot(dir) <= 0.0 {
            continue;
        }
        if let Some(t) = hit_distance(origin, dir, tri, eps)
            && best.is_none_or(|b| t < b)
        {
            best = Some(t);
        }
    }
    best
}

fn bbox_diagonal(mesh: &TriMesh) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in mesh.positions() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
}

/// Area-weighted one-ring averaging: `f ← (aᵥ fᵥ + Σ_{u ~ v} aᵤ fᵤ) / (aᵥ + Σ_{u ~ v} aᵤ)`.
struct OneRing {
    offsets: Vec<usize>,
    neighbours: Vec<u32>,
    areas: Vec<f64>,
}

impl OneRing {
    fn new(mesh: &TriMesh) -> Self {
        let (edges, _) = crate::mesh::edges(mesh);
        let (offsets, adjacent) = crate::mesh::edge_adjacency(mesh.vertex_count(), &edges);
        let neighbours = adjacent.into_iter().map(|(u, _)| u).collect();
        Self {
            offsets,
            neighbours,
            areas: mesh.vertex_areas(),
        }
    }

    fn apply(&self, f: &[f64]) -> Vec<f64> {
        (0..f.len())
            .into_par_iter()
            .map(|v| {
                let (mut num, mut den) = (self.areas[v] * f[v], self.areas[v]);
                for &u in &self.neighbours[self.offsets[v]..self.offsets[v + 1]] {
                    num += self.areas[u as usize] * f[u as usize];
                    den += self.areas[u as usize];
                }
                if den > 0.0 { num / den } else { f[v] }
            })
            .collect()
    }
}
