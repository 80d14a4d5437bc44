//! [`mirror_pairs`]: which parts of a co-segmentation are left/right copies of each other.
//!
//! Intrinsic features cannot tell a left arm from a right one, so a tuple found with them holds
//! both (reported as a mirror candidate by its pieces, [`super::PartsReport`]); an extrinsic
//! family (heights along tilted directions) splits them into two tuples. The second case is
//! the one found here: tuples `a` and `b` are a mirror pair when, on most shapes, reflecting
//! `a`'s centroid across a plane of the shape lands near `b`'s, relative to how far apart they
//! are, and the two look alike to the features a mirror image leaves unchanged ([`Likeness`]).
//! Each shape uses its own plane, so the test needs no correspondence beyond the tuples.
//!
//! Entry points: [`mirror_plane`] (one mesh), [`mirror_pairs`] (a co-segmentation over its
//! meshes, with each shape's plane or, for an aligned collection, vertical planes). The part tree merges mirror pairs before anything else
//! ([`super::AdaptiveCosegmentation::regroup`]), so `--parts N` keeps the two sides of a part
//! together.

use super::adaptive_cosegment::median;
use crate::graph::{Cosegmentation, ShapeGraph};
use crate::mesh::{TriMesh, dot, norm, sub};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A plane of approximate mirror symmetry of one shape.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MirrorPlane {
    /// A point of the plane: the surface's area centroid (file units).
    pub point: [f64; 3],
    /// Unit normal (one of the surface's principal axes).
    pub normal: [f64; 3],
    /// Asymmetry: area-weighted mean distance from each reflected vertex to the nearest vertex,
    /// capped at `DISTANCE_CAP`, over the RMS radius of the surface (0 = exact
    /// mirror symmetry; dimensionless).
    pub error: f64,
}

impl MirrorPlane {
    /// Distances from a reflected vertex to the surface are counted up to this share of the
    /// RMS radius: far is far, and the cap bounds the nearest-vertex search.
    const DISTANCE_CAP: f64 = 0.25;

    /// Planes with an asymmetry up to this are used by [`mirror_pairs`]. A shape whose best
    /// plane is worse has no usable symmetry (the level sits between the generated families'
    /// plane errors, 0.01–0.03 with independent left/right poses, and the error of a plane
    /// across an asymmetric axis, 0.08 and more: docs/PARTS.md).
    const MAX_ERROR: f64 = 0.05;

    /// `p` reflected across the plane.
    pub fn reflect(&self, p: [f64; 3]) -> [f64; 3] {
        let d = dot(sub(p, self.point), self.normal);
        [
            p[0] - 2.0 * d * self.normal[0],
            p[1] - 2.0 * d * self.normal[1],
            p[2] - 2.0 * d * self.normal[2],
        ]
    }
}

/// The best plane of mirror symmetry of `mesh` among the three planes through its area
/// centroid normal to its principal axes (a mirror symmetry's plane is always one of these);
/// `None` for a mesh without area. Cost: one nearest-vertex query per vertex and candidate,
/// on a uniform grid.
///
/// Inputs: `mesh` (#V vertices). Output: the plane of least [`MirrorPlane::error`]. See also
/// [`mirror_pairs`].
///
/// ```
/// use coseg::parts::mirror_plane;
/// use coseg::mesh::TriMesh;
/// // A prism along x with a scalene cross-section: mirror-symmetric across x = 1 only.
/// let ring = [(0.0, 0.0), (0.5, 0.0), (0.2, 0.3)];
/// let mut p = Vec::new();
/// for i in 0..=4 { for (y, z) in ring { p.push([i as f64 * 0.5, y, z]); } }
/// // Each quad is cut along the diagonal that the mirror image of its partner quad uses, so
/// // the triangulation (and the vertex areas) are symmetric too.
/// let mut f = Vec::new();
/// for i in 0..4u32 { for k in 0..3u32 {
///     let (a, b, c, d) = (3 * i + k, 3 * i + (k + 1) % 3, 3 * (i + 1) + (k + 1) % 3, 3 * (i + 1) + k);
///     if i < 2 { f.push([a, b, c]); f.push([a, c, d]); } else { f.push([a, b, d]); f.push([b, c, d]); }
/// } }
/// let plane = mirror_plane(&TriMesh::new(p, f).unwrap()).unwrap();
/// assert!(plane.error < 1e-12);
/// assert!(plane.normal[0].abs() > 0.999 && (plane.point[0] - 1.0).abs() < 1e-12);
/// ```
pub fn mirror_plane(mesh: &TriMesh) -> Option<MirrorPlane> {
    let Moments {
        centroid: c,
        cov,
        areas: w,
        radius,
    } = moments(mesh)?;
    let pos = mesh.positions();
    let total: f64 = w.iter().sum();
    let cap = MirrorPlane::DISTANCE_CAP * radius;
    let grid = Grid::new(pos, cap / 4.0);
    let eig = nalgebra::SymmetricEigen::new(nalgebra::Matrix3::from_fn(|i, j| cov[i][j]));
    let mut order = [0usize, 1, 2];
    // Largest variance first, so that ties between equal errors pick a stable axis.
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    order
        .iter()
        .map(|&k| {
            let e = eig.eigenvectors.column(k);
            let mut plane = MirrorPlane {
                point: c,
                normal: [e[0], e[1], e[2]],
                error: 0.0,
            };
            let err: f64 = pos
                .iter()
                .zip(&w)
                .map(|(p, &a)| a * grid.nearest(pos, plane.reflect(*p), cap))
                .sum();
            plane.error = err / total / radius;
            plane
        })
        .min_by(|a, b| a.error.total_cmp(&b.error))
}

/// A surface's moments ([`crate::features::surface_moments`]) and its RMS radius.
struct Moments {
    centroid: [f64; 3],
    cov: [[f64; 3]; 3],
    areas: Vec<f64>,
    radius: f64,
}

/// The moments of `mesh`; `None` for a mesh without area or extent.
fn moments(mesh: &TriMesh) -> Option<Moments> {
    let (centroid, cov, areas) = crate::features::surface_moments(mesh);
    let total: f64 = areas.iter().sum();
    if total.is_nan() || total <= 0.0 || areas.is_empty() {
        return None;
    }
    let radius = (cov[0][0] + cov[1][1] + cov[2][2]).sqrt();
    if radius.is_nan() || radius <= 0.0 {
        return None;
    }
    Some(Moments {
        centroid,
        cov,
        areas,
        radius,
    })
}

/// Uniform grid over the vertices for capped nearest-vertex queries.
struct Grid {
    cell: f64,
    cells: HashMap<[i64; 3], Vec<u32>, BuildHasherDefault<CellHasher>>,
}

/// A multiplicative hash of a cell's three coordinates (FxHash's round). The grid's lookups
/// were most of a `--parts-from geometry` run with SipHash (perf, TOSCA michael: 14 % of the
/// samples in the hasher alone, 34 % in the lookups); nothing iterates the map, so the order
/// it would give does not matter.
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut w = [0u8; 8];
            w[..chunk.len()].copy_from_slice(chunk);
            self.0 = (self.0.rotate_left(5) ^ u64::from_le_bytes(w))
                .wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
        }
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

impl Grid {
    fn new(pos: &[[f64; 3]], cell: f64) -> Self {
        let mut cells: HashMap<[i64; 3], Vec<u32>, BuildHasherDefault<CellHasher>> =
            HashMap::default();
        for (v, p) in pos.iter().enumerate() {
            cells.entry(Self::key(p, cell)).or_default().push(v as u32);
        }
        Self { cell, cells }
    }

    fn key(p: &[f64; 3], cell: f64) -> [i64; 3] {
        [0, 1, 2].map(|k| (p[k] / cell).floor() as i64)
    }

    /// Distance from `q` to the nearest vertex, or `cap` when none is closer.
    fn nearest(&self, pos: &[[f64; 3]], q: [f64; 3], cap: f64) -> f64 {
        let k = Self::key(&q, self.cell);
        let rings = (cap / self.cell).ceil() as i64;
        let mut best = cap * cap;
        for r in 0..=rings {
            // Every point in ring r is at least (r − 1) cells away.
            let near = ((r - 1).max(0) as f64) * self.cell;
            if near * near >= best {
                break;
            }
            for dx in -r..=r {
                for dy in -r..=r {
                    for dz in -r..=r {
                        if dx.abs().max(dy.abs()).max(dz.abs()) != r {
                            continue;
                        }
                        if let Some(vs) = self.cells.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                            for &v in vs {
                                let p = pos[v as usize];
                                let d = dot(sub(p, q), sub(p, q));
                                best = best.min(d);
                            }
                        }
                    }
                }
            }
        }
        best.sqrt()
    }
}

/// Two tuples that are mirror images of each other (left and right copies of one part).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MirrorPair {
    /// The first tuple (the smaller index).
    pub a: usize,
    /// The second tuple.
    pub b: usize,
    /// Median over the shapes used of `|R c_a − c_b| / |c_a − c_b|` (`R` the shape's
    /// reflection, `c` the regions' area centroids): 0 for exact mirror images, about 1 for
    /// two regions on the plane or on one side.
    pub ratio: f64,
    /// Median over the same shapes of the smaller region's area over the larger's (1 for
    /// copies of one size).
    pub area_balance: f64,
    /// Median over the shapes of the two regions' [`Likeness`] (`None`: not compared, no
    /// mirror-invariant feature).
    pub likeness: Option<f64>,
}

/// Mirror pairs are pairs whose median ratio is below this: the reflected centroid lands
/// closer to the other region than a third of their distance.
const MIRROR_PAIR_RATIO: f64 = 1.0 / 3.0;

/// Mirror pairs have a median area balance of at least this: copies have one size. What rules
/// out parts that merely sit opposite each other at one height (a quadruped's head and tail,
/// about 2 : 1).
const MIRROR_AREA_BALANCE: f64 = 2.0 / 3.0;

/// Mirror pairs are pairs whose median likeness ([`Likeness`]) is at least this, when the
/// likeness is known. Measured on the generated families (spectral features): left/right
/// copies 0.62–0.90, a quadruped's head and tail 0.32–0.33 (docs/PARTS.md).
const MIRROR_LIKENESS: f64 = 0.5;

/// What two parts of one shape are compared on: the band tables of `graph` (the one the
/// co-segmentation was found on), restricted to `columns`, features a mirror image leaves
/// unchanged ([`crate::pipeline::ShapePipelineOptions::mirror_invariant_columns`]). The
/// likeness of regions `a` and `b` is `1 − mean_k TV(h_a^k, h_b^k)`, `h^k` the area-weighted
/// histogram of feature `k`'s bands over the region, TV the total variation distance: 1 for
/// parts that look alike to intrinsic features (a left and a right arm), less for parts that
/// merely sit opposite each other (a head and a tail).
#[derive(Debug, Clone, Copy)]
pub struct Likeness<'a> {
    /// The shape graph (its nodes' band tables and areas, graph order).
    pub graph: &'a ShapeGraph,
    /// Mirror-invariant feature columns.
    pub columns: &'a [usize],
}

impl Likeness<'_> {
    /// The likeness of vertex sets `a` and `b` of shape `i` (module docs); `None` without
    /// columns, for an empty region, or past the graph.
    pub fn of(&self, i: usize, a: &[u32], b: &[u32]) -> Option<f64> {
        if self.columns.is_empty() || i >= self.graph.node_count() {
            return None;
        }
        let node = self.graph.node(i);
        let t = &node.bands;
        let hist = |r: &[u32], k: usize| -> Option<Vec<f64>> {
            let mut h = vec![0.0; t.bands];
            for &v in r {
                h[t.label(v as usize, k) as usize] += node.areas[v as usize];
            }
            let total: f64 = h.iter().sum();
            (total > 0.0).then(|| h.iter().map(|x| x / total).collect())
        };
        let mut tv = 0.0;
        for &k in self.columns.iter().filter(|&&k| k < t.features) {
            let (ha, hb) = (hist(a, k)?, hist(b, k)?);
            tv += 0.5 * ha.iter().zip(&hb).map(|(x, y)| (x - y).abs()).sum::<f64>();
        }
        Some(1.0 - tv / self.columns.len() as f64)
    }
}

/// The mirror pairs among the tuples of `coseg` (graph order; `meshes[i]` is shape `i`).
///
/// On each shape, tuples `a` and `b` are compared by the ratio of [`MirrorPair::ratio`] under
/// a reflection:
/// - `up = None`: the shape's own [`mirror_plane`], and only on shapes where its error is
///   ≤ `MAX_ERROR`;
/// - `up = Some(u)` (an aligned collection, `u` the up direction in file coordinates; any
///   length): the vertical plane through the shape's area centroid whose normal is the
///   horizontal part of `c_a − c_b`. Articulated shapes (a humanoid with its arms in
///   different poses) have no global mirror plane, but their left and right parts still sit
///   at about the same height, at about the same distance on either side of the centroid.
///
/// A shape takes part when both regions are non-empty on it; a pair needs at least half of
/// all shapes to take part, a median ratio below `MIRROR_PAIR_RATIO`, a median area
/// balance of at least `MIRROR_AREA_BALANCE` and, with `likeness` (and columns to compare
/// on), a median [`Likeness`] of at least `MIRROR_LIKENESS`. Pairs are then matched
/// greedily, lowest ratio first, so a tuple is in at most one pair. Output sorted by ratio.
///
/// Known issue: with `up` and no likeness the test only asks that two parts of one size sit
/// opposite each other at one height, which a quadruped's head and tail do; the likeness rules
/// them out (docs/PARTS.md). Copies exchanged by a half turn about the vertical (a front leg
/// and the diagonal back leg) are pairs too.
///
/// Inputs: `meshes` (#shapes, #V_i vertices each), `coseg` (its regions index the meshes'
/// vertices). Empty when the meshes do not match `coseg`. See also
/// [`super::AdaptiveCosegmentation::regroup`], [`super::PartsReport::mirror_pairs`].
///
/// ```
/// use coseg::graph::{Cosegmentation, RegionTuple};
/// use coseg::parts::{mirror_pairs};
/// use coseg::mesh::TriMesh;
/// // A flat strip along x (up = y): a left end, a middle and a right end.
/// let p: Vec<[f64; 3]> = (0..10).map(|i| [(i / 2) as f64, (i % 2) as f64, 0.0]).collect();
/// let f: Vec<[u32; 3]> = (0..4u32).flat_map(|k| { let a = 2 * k;
///     if k < 2 { [[a, a + 2, a + 1], [a + 1, a + 2, a + 3]] } else { [[a, a + 3, a + 1], [a, a + 2, a + 3]] } }).collect();
/// let mesh = TriMesh::new(p, f).unwrap();
/// let tuple = |r: Vec<u32>| RegionTuple { area_fractions: vec![0.0], regions: vec![r], sweeps: 0,
///     converged: true, cycled: false, objective: 0.0, confidence: 1.0, cycle_consistency: None,
///     leftover: false };
/// let coseg = Cosegmentation { names: vec!["s".into()], vertices: vec![10], root: 0, order: vec![0],
///     parent: vec![None], alpha: 0.25,
///     tuples: vec![tuple(vec![0, 1]), tuple(vec![2, 3, 4, 5, 6, 7]), tuple(vec![8, 9])] };
/// let pairs = mirror_pairs(&[mesh], &coseg, Some([0.0, 1.0, 0.0]), None);
/// assert_eq!((pairs.len(), pairs[0].a, pairs[0].b), (1, 0, 2));
/// assert!(pairs[0].ratio < 1e-12);
/// ```
pub fn mirror_pairs(
    meshes: &[TriMesh],
    coseg: &Cosegmentation,
    up: Option<[f64; 3]>,
    likeness: Option<Likeness<'_>>,
) -> Vec<MirrorPair> {
    let up = up.and_then(unit);
    let n = coseg.names.len();
    if !coseg.matches(meshes) {
        return Vec::new();
    }
    let l = coseg.tuples.len();
    // Per shape with a usable plane: the plane and each tuple's area centroid.
    // One task per shape: the mirror plane's nearest-vertex queries are most of the cost.
    let shapes: Vec<Option<ShapeCentroids>> = meshes
        .par_iter()
        .enumerate()
        .map(|(i, mesh)| {
            let (reflection, w) = match up {
                // Each pair gets its own vertical plane through the centroid: no global plane
                // (and no reflection error) is needed.
                Some(up) => {
                    let m = moments(mesh)?;
                    let point = m.centroid;
                    (Reflection::Vertical { point, up }, m.areas)
                }
                None => (
                    Reflection::Plane(
                        mirror_plane(mesh).filter(|p| p.error <= MirrorPlane::MAX_ERROR)?,
                    ),
                    mesh.vertex_areas(),
                ),
            };
            let pos = mesh.positions();
            let centroids = coseg
                .tuples
                .iter()
                .map(|t| {
                    let r = &t.regions[i];
                    let a: f64 = r.iter().map(|&v| w[v as usize]).sum();
                    (a > 0.0).then(|| {
                        let mut c = [0.0; 3];
                        for &v in r {
                            (0..3).for_each(|k| c[k] += w[v as usize] * pos[v as usize][k]);
                        }
                        (c.map(|x| x / a), a)
                    })
                })
                .collect();
            Some((reflection, centroids))
        })
        .collect();
    let mut candidates = Vec::new();
    for a in 0..l {
        for b in a + 1..l {
            let (ratios, balances): (Vec<f64>, Vec<f64>) = shapes
                .iter()
                .flatten()
                .filter_map(|(reflection, c)| {
                    let ((ca, wa), (cb, wb)) = (c[a]?, c[b]?);
                    let apart = norm(sub(ca, cb));
                    if apart.is_nan() || apart <= 0.0 {
                        return None;
                    }
                    let plane = match *reflection {
                        Reflection::Vertical { point, up } => vertical_plane(point, up, ca, cb)?,
                        Reflection::Plane(plane) => plane,
                    };
                    Some((
                        norm(sub(plane.reflect(ca), cb)) / apart,
                        wa.min(wb) / wa.max(wb),
                    ))
                })
                .unzip();
            if 2 * ratios.len() < n || ratios.is_empty() {
                continue;
            }
            let (ratio, area_balance) = (median(&ratios), median(&balances));
            if ratio >= MIRROR_PAIR_RATIO || area_balance < MIRROR_AREA_BALANCE {
                continue;
            }
            let alike: Vec<f64> = likeness
                .iter()
                .flat_map(|l| {
                    (0..n).filter_map(move |i| {
                        l.of(i, &coseg.tuples[a].regions[i], &coseg.tuples[b].regions[i])
                    })
                })
                .collect();
            let likeness = (!alike.is_empty()).then(|| median(&alike));
            if likeness.is_none_or(|x| x >= MIRROR_LIKENESS) {
                candidates.push(MirrorPair {
                    a,
                    b,
                    ratio,
                    area_balance,
                    likeness,
                });
            }
        }
    }
    candidates.sort_by(|x, y| x.ratio.total_cmp(&y.ratio));
    let mut used = vec![false; l];
    candidates
        .into_iter()
        .filter(|p| {
            let free = !used[p.a] && !used[p.b];
            if free {
                used[p.a] = true;
                used[p.b] = true;
            }
            free
        })
        .collect()
}

/// The vertical plane (containing `up`, unit) through `point` across which `ca` and `cb` come
/// closest to exchanging: its normal is the horizontal part of `ca − cb`. `None` when the two
/// are on one vertical line (no vertical plane exchanges them).
fn vertical_plane(
    point: [f64; 3],
    up: [f64; 3],
    ca: [f64; 3],
    cb: [f64; 3],
) -> Option<MirrorPlane> {
    let d = [0, 1, 2].map(|k| ca[k] - cb[k]);
    let h: f64 = (0..3).map(|k| d[k] * up[k]).sum();
    let normal = unit([0, 1, 2].map(|k| d[k] - h * up[k]))?;
    Some(MirrorPlane {
        point,
        normal,
        error: 0.0,
    })
}

fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let len = norm(v);
    (len > 1e-12 * (1.0 + v.iter().map(|x| x.abs()).fold(0.0, f64::max)))
        .then(|| v.map(|x| x / len))
}

/// How a shape's regions are reflected: across its own plane, or (aligned collections) across
/// the vertical plane through its centroid chosen per pair ([`vertical_plane`]).
#[derive(Clone, Copy)]
enum Reflection {
    Plane(MirrorPlane),
    Vertical { point: [f64; 3], up: [f64; 3] },
}

/// A shape's reflection and each tuple's area centroid and area on it (`None`: empty there).
type ShapeCentroids = (Reflection, Vec<Option<([f64; 3], f64)>>);
