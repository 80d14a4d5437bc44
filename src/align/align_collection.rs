//! [`align_collection`]: one similarity per shape into a common collection frame, synchronised
//! over a shape graph.

use super::AlignError;
use super::register_pair::{RegisterOptions, register_prepared};
use super::similarity::{Similarity, rotation_angle};
use super::surface_samples::Prepared;
use crate::mesh::TriMesh;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Options of [`align_collection`] (`coseg align`).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct AlignOptions {
    /// Each pairwise registration (samples, trim, iterations, seed); default
    /// [`RegisterOptions::default`].
    pub register: RegisterOptions,
    /// Neighbours per shape in the registration graph (default 4): each shape is registered
    /// against its `neighbours` nearest shapes by a rigid-invariant descriptor, plus the edges
    /// of a spanning tree that keep the graph connected. More is slower and more robust.
    pub neighbours: usize,
}

impl Default for AlignOptions {
    fn default() -> Self {
        Self {
            register: RegisterOptions::default(),
            neighbours: 4,
        }
    }
}

/// How the collection frame was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FrameCase {
    /// The given frames already agree: every transform is exactly the identity.
    AlreadyAligned,
    /// The frames were found by registration and synchronisation.
    Synchronised,
    /// One shape: its own normalised frame.
    Single,
}

/// One shape's place in the collection frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShapeAlignment {
    /// The shape's points into the collection frame.
    pub transform: Similarity,
    /// Share (0–1) of the shape's registration-graph neighbours whose registration agrees with
    /// its placement (a candidate pose within 20° of it): 1 = every neighbour confirms it; a
    /// shape that matches nothing well gets a low confidence and is placed by its neighbours.
    pub confidence: f64,
    /// Mean residual (symmetric trimmed chamfer, in RMS radii) of the agreeing registrations;
    /// `None` when no neighbour agrees.
    pub residual: Option<f64>,
    /// The best placement rotated away (by more than 20°) from the chosen one, as its
    /// disagreement score over the chosen one's (0–1]: near 1, another pose fits the
    /// neighbours about as well (a symmetric shape); `None` when no other pose was found.
    pub ambiguity: Option<f64>,
    /// The angle (degrees) of [`ShapeAlignment::ambiguity`]'s pose from the chosen one.
    pub ambiguity_angle: Option<f64>,
}

/// The result of [`align_collection`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CollectionAlignment {
    /// Which case was found.
    pub case: FrameCase,
    /// Per shape, in input order.
    pub shapes: Vec<ShapeAlignment>,
    /// The collection frame's up axis, a unit vector in the collection frame (`[0, 1, 0]` when
    /// the frames were synchronised; in the files' frame when already aligned).
    pub up: [f64; 3],
    /// The collection frame's forward axis, a unit vector orthogonal to `up` (`[0, 0, 1]`
    /// when synchronised).
    pub forward: [f64; 3],
    /// Share of the registration graph's edges whose best pose is the given frame (within 20°):
    /// the evidence for [`FrameCase::AlreadyAligned`] (at least one half).
    pub given_frame_share: f64,
    /// Registration-graph edges `(source, target)`, as registered.
    pub edges: Vec<(usize, usize)>,
}

/// Poses within this angle (degrees) are one pose: ICP from different starts into one minimum
/// ends within a degree or two; distinct symmetric poses are 90° or 180° apart.
const SAME_POSE_DEGREES: f64 = 20.0;
/// Bins of the D2 descriptor (distances between sample pairs, in RMS radii, over `[0, 4)`):
/// enough to tell a chair from a table; coarse enough to be stable under resampling.
const D2_BINS: usize = 32;
/// Sweeps of the synchronisation at most: each node's pose depends on its neighbours',
/// settled in a few sweeps on graphs of diameter < 10.
const SYNC_SWEEPS: usize = 10;

/// A similarity per shape into one collection frame, synchronised over a shape graph.
///
/// - `meshes`: `n ≥ 1` validated meshes, any poses and sizes;
/// - returns a [`CollectionAlignment`]: per shape the transform into the collection frame,
///   a confidence, a residual and an ambiguity; the frame case; the up and forward axes.
///
/// Method (docs/ALIGN.md):
/// 1. per shape, exact area moments and seeded area-weighted samples in its normalised frame
///    (centroid at 0, unit RMS radius);
/// 2. a registration graph: each shape's [`AlignOptions::neighbours`] nearest shapes by a
///    rigid-invariant descriptor (the D2 histogram of sample distances and the inertia
///    spectrum), plus a minimum spanning tree of the descriptor distances so that the graph
///    is connected; every edge registered by the pairwise method of
///    [`register_pair`](super::register_pair), keeping each edge's distinct candidate poses;
/// 3. **already aligned?** when at least half of the edges find their best pose at the given
///    frames, the frames agree: every transform is the identity, bit for bit;
/// 4. otherwise **synchronisation**: a spanning tree of the best edges from the shape with
///    the lowest mean residual places every shape; then sweeps choose, for each shape, the
///    pose that its neighbours' candidate poses (all of them, not only the best) support with
///    the lowest total residual, and average the supporting poses (chordal mean) — so a
///    symmetric shape follows its neighbours and one matching nothing well is placed by them;
/// 5. the **up and forward axes** by a stated rule on the pooled, aligned samples: the up axis
///    is the principal axis (of the pooled covariance) along which the surface is most
///    lopsided (largest |third moment|), pointing away from the thin tail (chair legs, a
///    goblet's stem, an animal's legs: the light side is down); forward is the most lopsided
///    of the two others, pointing to its heavy side. Synchronised frames are then rotated so
///    that up is `+y` and forward `+z`, centred on each shape's centroid and scaled by the
///    collection's geometric-mean RMS radius over the shape's.
///
/// Cost: one registration per edge (about `n × neighbours` edges, ≈ 0.1 s each on one core
/// for 1000 samples), independent of the mesh sizes beyond the moments.
///
/// Deterministic: seeded samples, fixed orders, ties to the lower index.
///
/// Errors: [`AlignError::Degenerate`] naming the shape index when a shape has no area;
/// [`AlignError::BadOption`]; no shapes.
///
/// Known issues: rigid: posed non-rigid shapes are placed by their overall shape only. The
/// up rule reads the geometry, not the files: on a collection whose files are upright it may
/// still name another axis up (docs/ALIGN.md has the measured cases).
pub fn align_collection(
    meshes: &[TriMesh],
    options: &AlignOptions,
) -> Result<CollectionAlignment, AlignError> {
    options.register.check()?;
    if meshes.is_empty() {
        return Err(AlignError::BadOption("no shapes to align".into()));
    }
    let prepared: Vec<Prepared> = meshes
        .par_iter()
        .enumerate()
        .map(|(i, m)| {
            Prepared::new(m, options.register.samples, options.register.seed)
                .map_err(|e| AlignError::Degenerate(format!("shape {i}: {e}")))
        })
        .collect::<Result<_, _>>()?;
    let n = meshes.len();
    if n == 1 {
        let (up, forward) = up_forward(&prepared, &[Matrix3::identity()]);
        return Ok(CollectionAlignment {
            case: FrameCase::Single,
            shapes: vec![ShapeAlignment {
                transform: Similarity::identity(),
                confidence: 1.0,
                residual: None,
                ambiguity: None,
                ambiguity_angle: None,
            }],
            up: to_arr(&up),
            forward: to_arr(&forward),
            given_frame_share: 1.0,
            edges: Vec::new(),
        });
    }
    let edges = registration_graph(&prepared, options.neighbours.max(1));
    let regs: Vec<Vec<(Matrix3<f64>, f64)>> = edges
        .par_iter()
        .map(|&(a, b)| {
            let r = register_prepared(&prepared[a], &prepared[b], &options.register);
            r.candidates
                .iter()
                .map(|c| (to_mat(&c.transform.rotation), c.residual))
                .collect()
        })
        .collect();
    let given = regs
        .iter()
        .filter(|c| angle(&c[0].0, &Matrix3::identity()) < SAME_POSE_DEGREES)
        .count() as f64
        / regs.len() as f64;
    if given >= 0.5 {
        let rotations = vec![Matrix3::identity(); n];
        let support = supports(n, &edges, &regs, &rotations);
        let (up, forward) = up_forward(&prepared, &rotations);
        return Ok(CollectionAlignment {
            case: FrameCase::AlreadyAligned,
            shapes: support
                .into_iter()
                .map(|s| ShapeAlignment {
                    transform: Similarity::identity(),
                    ..s
                })
                .collect(),
            up: to_arr(&up),
            forward: to_arr(&forward),
            given_frame_share: given,
            edges,
        });
    }
    let rotations = synchronise(n, &edges, &regs);
    let support = supports(n, &edges, &regs, &rotations);
    let (up, forward) = up_forward(&prepared, &rotations);
    // Rows of the frame are its axes (right, up, forward) in the synchronised frame.
    let right = up.cross(&forward);
    let frame = Matrix3::from_rows(&[right.transpose(), up.transpose(), forward.transpose()]);
    let mean_radius =
        (prepared.iter().map(|p| p.moments.radius.ln()).sum::<f64>() / n as f64).exp();
    let shapes = support
        .into_iter()
        .zip(&prepared)
        .zip(&rotations)
        .map(|((s, p), g)| {
            let r = frame * g;
            let scale = mean_radius / p.moments.radius;
            let t = -(r * p.moments.centroid) * scale;
            ShapeAlignment {
                transform: Similarity {
                    rotation: to_rows(&r),
                    scale,
                    translation: to_arr(&t),
                },
                ..s
            }
        })
        .collect();
    Ok(CollectionAlignment {
        case: FrameCase::Synchronised,
        shapes,
        up: [0.0, 1.0, 0.0],
        forward: [0.0, 0.0, 1.0],
        given_frame_share: given,
        edges,
    })
}

/// The shape's pose hypotheses from one edge: `(rotation of the shape into the collection,
/// residual)` for every candidate, given the other end's rotation `g_other`.
fn hypotheses(
    node: usize,
    edge: (usize, usize),
    cands: &[(Matrix3<f64>, f64)],
    g_other: &Matrix3<f64>,
) -> Vec<(Matrix3<f64>, f64)> {
    // A candidate R maps the target's normalised frame into the source's: G_target = G_source R.
    cands
        .iter()
        .map(|(r, res)| {
            if edge.1 == node {
                (g_other * r, *res)
            } else {
                (g_other * r.transpose(), *res)
            }
        })
        .collect()
}

/// Cost of placing `node` at `h` for one edge: the residual of the candidate that agrees with
/// it, else the edge's worst candidate residual (no registration supports that pose).
fn edge_cost(h: &Matrix3<f64>, hyps: &[(Matrix3<f64>, f64)]) -> (f64, Option<usize>) {
    let worst = hyps.iter().map(|x| x.1).fold(0.0, f64::max);
    hyps.iter()
        .enumerate()
        .filter(|(_, x)| angle(&x.0, h) < SAME_POSE_DEGREES)
        .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
        .map_or((worst, None), |(k, x)| (x.1, Some(k)))
}

fn synchronise(
    n: usize,
    edges: &[(usize, usize)],
    regs: &[Vec<(Matrix3<f64>, f64)>],
) -> Vec<Matrix3<f64>> {
    let incident: Vec<Vec<usize>> = (0..n)
        .map(|v| {
            (0..edges.len())
                .filter(|&e| edges[e].0 == v || edges[e].1 == v)
                .collect()
        })
        .collect();
    // Root: the lowest mean best residual over its edges.
    let mean_best = |v: usize| {
        incident[v].iter().map(|&e| regs[e][0].1).sum::<f64>() / incident[v].len().max(1) as f64
    };
    let root = (0..n)
        .min_by(|&a, &b| mean_best(a).total_cmp(&mean_best(b)))
        .unwrap_or(0);
    // Prim's tree over the best residuals.
    let mut g: Vec<Option<Matrix3<f64>>> = vec![None; n];
    g[root] = Some(Matrix3::identity());
    loop {
        let next = (0..edges.len())
            .filter(|&e| g[edges[e].0].is_some() != g[edges[e].1].is_some())
            .min_by(|&a, &b| regs[a][0].1.total_cmp(&regs[b][0].1));
        let Some(e) = next else { break };
        let (a, b) = edges[e];
        let (node, other) = if g[a].is_some() { (b, a) } else { (a, b) };
        let h = hypotheses(node, edges[e], &regs[e][..1], &g[other].unwrap());
        g[node] = Some(h[0].0);
    }
    let mut g: Vec<Matrix3<f64>> = g
        .into_iter()
        .map(|x| x.unwrap_or_else(Matrix3::identity))
        .collect();
    for _ in 0..SYNC_SWEEPS {
        let mut changed = false;
        for v in 0..n {
            let per_edge: Vec<Vec<(Matrix3<f64>, f64)>> = incident[v]
                .iter()
                .map(|&e| {
                    let other = if edges[e].0 == v {
                        edges[e].1
                    } else {
                        edges[e].0
                    };
                    hypotheses(v, edges[e], &regs[e], &g[other])
                })
                .collect();
            let all: Vec<Matrix3<f64>> = per_edge.iter().flatten().map(|x| x.0).collect();
            let score =
                |h: &Matrix3<f64>| per_edge.iter().map(|hy| edge_cost(h, hy).0).sum::<f64>();
            let mut best = g[v];
            let mut best_score = score(&g[v]);
            for h in &all {
                let s = score(h);
                if s < best_score - 1e-12 {
                    best = *h;
                    best_score = s;
                }
            }
            let agreeing: Vec<Matrix3<f64>> = per_edge
                .iter()
                .filter_map(|hy| edge_cost(&best, hy).1.map(|k| hy[k].0))
                .collect();
            let new = if agreeing.is_empty() {
                best
            } else {
                chordal_mean(&agreeing)
            };
            if angle(&new, &g[v]) > 1e-6 {
                changed = true;
            }
            g[v] = new;
        }
        if !changed {
            break;
        }
    }
    g
}

/// Per shape: confidence, residual and ambiguity of the placement `g`.
fn supports(
    n: usize,
    edges: &[(usize, usize)],
    regs: &[Vec<(Matrix3<f64>, f64)>],
    g: &[Matrix3<f64>],
) -> Vec<ShapeAlignment> {
    (0..n)
        .map(|v| {
            let per_edge: Vec<Vec<(Matrix3<f64>, f64)>> = (0..edges.len())
                .filter(|&e| edges[e].0 == v || edges[e].1 == v)
                .map(|e| {
                    let other = if edges[e].0 == v {
                        edges[e].1
                    } else {
                        edges[e].0
                    };
                    hypotheses(v, edges[e], &regs[e], &g[other])
                })
                .collect();
            let costs: Vec<(f64, Option<usize>)> =
                per_edge.iter().map(|hy| edge_cost(&g[v], hy)).collect();
            let agree: Vec<f64> = costs
                .iter()
                .filter(|c| c.1.is_some())
                .map(|c| c.0)
                .collect();
            let score = costs.iter().map(|c| c.0).sum::<f64>();
            // The best other pose: among all hypotheses rotated away from g[v].
            let other = per_edge
                .iter()
                .flatten()
                .filter(|h| angle(&h.0, &g[v]) >= SAME_POSE_DEGREES)
                .map(|h| {
                    let s = per_edge.iter().map(|hy| edge_cost(&h.0, hy).0).sum::<f64>();
                    (s, angle(&h.0, &g[v]))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0));
            ShapeAlignment {
                transform: Similarity::identity(),
                confidence: agree.len() as f64 / per_edge.len().max(1) as f64,
                residual: (!agree.is_empty())
                    .then(|| agree.iter().sum::<f64>() / agree.len() as f64),
                ambiguity: other.map(|(s, _)| if s > 0.0 { (score / s).min(1.0) } else { 1.0 }),
                ambiguity_angle: other.map(|(_, a)| a),
            }
        })
        .collect()
}

/// The registration graph: each shape's `k` nearest by descriptor, plus a minimum spanning
/// tree of the descriptor distances; `(source, target)` with `source < target`, sorted.
fn registration_graph(prepared: &[Prepared], k: usize) -> Vec<(usize, usize)> {
    let n = prepared.len();
    let desc: Vec<Vec<f64>> = prepared.iter().map(descriptor).collect();
    let dist = |a: usize, b: usize| -> f64 {
        desc[a]
            .iter()
            .zip(&desc[b])
            .map(|(x, y)| (x - y).abs())
            .sum()
    };
    let mut set = std::collections::BTreeSet::new();
    for a in 0..n {
        let mut others: Vec<usize> = (0..n).filter(|&b| b != a).collect();
        others.sort_by(|&x, &y| dist(a, x).total_cmp(&dist(a, y)).then(x.cmp(&y)));
        for &b in others.iter().take(k) {
            set.insert((a.min(b), a.max(b)));
        }
    }
    // Prim: connect every shape.
    let mut inside = vec![false; n];
    inside[0] = true;
    let mut best: Vec<(f64, usize)> = (0..n).map(|b| (dist(0, b), 0)).collect();
    for _ in 1..n {
        let Some(v) = (0..n)
            .filter(|&v| !inside[v])
            .min_by(|&x, &y| best[x].0.total_cmp(&best[y].0).then(x.cmp(&y)))
        else {
            break;
        };
        inside[v] = true;
        let u = best[v].1;
        set.insert((u.min(v), u.max(v)));
        for b in 0..n {
            if !inside[b] {
                let d = dist(v, b);
                if d < best[b].0 {
                    best[b] = (d, v);
                }
            }
        }
    }
    set.into_iter().collect()
}

/// Rigid-invariant shape descriptor: the D2 histogram of the coarse samples' pairwise
/// distances (normalised frame, so scale-invariant too) and the inertia spectrum.
fn descriptor(p: &Prepared) -> Vec<f64> {
    let s = &p.samples[..p.coarse.len()];
    let mut h = vec![0.0; D2_BINS + 3];
    let mut count = 0.0f64;
    for i in 0..s.len() {
        for j in i + 1..s.len() {
            let d = (s[i] - s[j]).norm();
            let b = ((d / 4.0) * D2_BINS as f64) as usize;
            h[b.min(D2_BINS - 1)] += 1.0;
            count += 1.0;
        }
    }
    for x in h.iter_mut().take(D2_BINS) {
        *x /= count.max(1.0);
    }
    h[D2_BINS..].copy_from_slice(&p.moments.spectrum);
    h
}

/// Up and forward axes of the pooled samples, each shape's samples rotated by `g`.
fn up_forward(prepared: &[Prepared], g: &[Matrix3<f64>]) -> (Vector3<f64>, Vector3<f64>) {
    let pts: Vec<Vector3<f64>> = prepared
        .iter()
        .zip(g)
        .flat_map(|(p, r)| p.samples.iter().map(move |s| r * s))
        .collect();
    let m = pts.len() as f64;
    let mean = pts.iter().sum::<Vector3<f64>>() / m;
    let mut cov = Matrix3::zeros();
    for p in &pts {
        let d = p - mean;
        cov += d * d.transpose();
    }
    let eig = nalgebra::SymmetricEigen::new(cov / m);
    let axes: Vec<Vector3<f64>> = (0..3).map(|k| eig.eigenvectors.column(k).into()).collect();
    let skew = |a: &Vector3<f64>| {
        let sd = (pts.iter().map(|p| (p - mean).dot(a).powi(2)).sum::<f64>() / m).sqrt();
        pts.iter()
            .map(|p| ((p - mean).dot(a) / sd.max(1e-12)).powi(3))
            .sum::<f64>()
            / m
    };
    let mut order: Vec<(f64, usize)> = axes.iter().enumerate().map(|(k, a)| (skew(a), k)).collect();
    order.sort_by(|x, y| y.0.abs().total_cmp(&x.0.abs()).then(x.1.cmp(&y.1)));
    // A negative skew: the tail (the light side) is towards −a, so up is +a.
    let up = axes[order[0].1] * if order[0].0 <= 0.0 { 1.0 } else { -1.0 };
    // Forward: to the heavy side is against the tail too.
    let forward = axes[order[1].1] * if order[1].0 <= 0.0 { 1.0 } else { -1.0 };
    (up, forward)
}

/// The rotation nearest (Frobenius) to the mean of `rs`.
fn chordal_mean(rs: &[Matrix3<f64>]) -> Matrix3<f64> {
    let m = rs.iter().sum::<Matrix3<f64>>() / rs.len() as f64;
    let svd = m.svd(true, true);
    let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
    let d = (u * vt).determinant().signum();
    u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * vt
}

fn angle(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    rotation_angle(&to_rows(a), &to_rows(b))
}

fn to_rows(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [
        [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
        [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
        [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
    ]
}

fn to_mat(r: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| r[i][j])
}

fn to_arr(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}
