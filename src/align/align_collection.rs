//! [`align_collection`]: one similarity per shape into a common collection frame, synchronised
//! over a shape graph.

use super::AlignError;
use super::register_pair::{
    Pose, RegisterOptions, angle, coarse_icp, icp, signed_permutations, to_rows,
};
use super::similarity::Similarity;
use super::surface_samples::{PointIndex, Prepared};
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
    /// The shape's own symmetries: rotations (row-major, in the collection frame, about the
    /// shape's centre) that overlay the shape on itself within sampling — a stool turned a
    /// quarter, a table turned a half. The alignment cannot tell these poses apart: composing
    /// the transform with one of them is as right. Empty for most shapes.
    #[serde(default)]
    pub symmetries: Vec<[[f64; 3]; 3]>,
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
    /// Share of the registration graph's edges that agree with the given frames (their best
    /// pose is the given one within 20°, up to the target's own symmetries, or ICP from the
    /// given frames stays there and fits within 5 % of the best): the evidence for [`FrameCase::AlreadyAligned`] (at least one half).
    pub given_frame_share: f64,
    /// Registration-graph edges `(source, target)`, as registered.
    pub edges: Vec<(usize, usize)>,
    /// The collection's axis of revolution (a unit vector, in the frame of
    /// [`CollectionAlignment::up`]) when its shapes are surfaces of revolution about one axis
    /// (goblets, vases): rotations about it fit equally well, so the transforms leave them
    /// undetermined. `None` otherwise.
    #[serde(default)]
    pub symmetry_axis: Option<[f64; 3]>,
}

/// Poses within this angle (degrees) are one pose: ICP from different starts into one minimum
/// ends within a degree or two; distinct symmetric poses are 90° or 180° apart.
const SAME_POSE_DEGREES: f64 = 20.0;
/// Bins of the D2 descriptor (distances between sample pairs, in RMS radii, over `[0, 4)`):
/// enough to tell a chair from a table; coarse enough to be stable under resampling.
const D2_BINS: usize = 32;
/// The given frames fit an edge "about as well as its best pose" within this share of the
/// best residual: two coarse registrations of one pose differ by a few percent (sampling),
/// while a wrong frame of a random motion costs a multiple of it.
const GIVEN_FRAME_SLACK: f64 = 0.05;
/// Roots tried by the labelling at most: every shape of a small collection; beyond, evenly
/// spread ones (each root costs a greedy pass and a few sweeps over the graph).
const LABEL_ROOTS: usize = 32;
/// Sweeps of iterated conditional modes at most: a label changes only when its summed cost
/// drops, so it settles in a few sweeps.
const ICM_SWEEPS: usize = 20;
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
/// 2. each shape's **own symmetries**: the turns of its inertia frame (and the turns about a
///    principal axis, for a surface of revolution) that overlay it on itself as closely as an
///    independent resampling does — a stool's quarter turn, a goblet's stem;
/// 3. a registration graph: each shape's [`AlignOptions::neighbours`] nearest shapes by a
///    rigid-invariant descriptor (the D2 histogram of sample distances and the inertia
///    spectrum), plus a minimum spanning tree of the descriptor distances so that the graph
///    is connected; every edge registered by coarse trimmed ICP from the 24 starts
///    `F_a P F_bᵀ` (the inertia frames turned by each cube rotation `P`) and from the given
///    frames, each result kept under the start it ended nearest (a cost per relative label);
/// 4. **already aligned?** an edge agrees with the given frames when its best pose is the
///    given one up to the target's own symmetries, or ICP from the given frames stays there
///    within [`GIVEN_FRAME_SLACK`] of the best residual; when at least half of the edges
///    agree, every transform is the identity, bit for bit;
/// 5. otherwise **joint labelling**: every shape `i` gets a cube rotation `P_i` (its candidate
///    rotation into the collection frame is `P_i F_iᵀ`), chosen to minimise the summed
///    label costs (log residual ratios) of all edges at once — greedy from a root, then
///    iterated conditional modes, every shape tried as the root, the lowest total kept — so
///    that an edge whose front/back alternative fits a little better is outvoted by the
///    cycles through it; then each edge refined by trimmed ICP from its chosen pose on all
///    samples, and the rotations averaged (chordal mean of what each shape's edges say);
/// 6. the **up and forward axes** by a stated rule on the pooled, aligned samples: the up axis
///    is the principal axis (of the pooled covariance) along which the surface is most
///    lopsided (largest |third moment|), pointing away from the thin tail (chair legs, a
///    goblet's stem, an animal's legs: the light side is down); forward is the most lopsided
///    of the two others, pointing to its heavy side. Synchronised frames are then rotated so
///    that up is `+y` and forward `+z`, centred on each shape's centroid and scaled by the
///    collection's geometric-mean RMS radius over the shape's.
///
/// Cost: per edge (about `n × neighbours` edges) 25 coarse ICP runs and one refinement; per
/// shape 25 self-comparisons; independent of the mesh sizes beyond the moments and samples.
///
/// Deterministic: seeded samples, fixed orders, ties to the lower index.
///
/// Errors: [`AlignError::Degenerate`] naming the shape index when a shape has no area;
/// [`AlignError::BadOption`]; no shapes.
///
/// Known issues: rigid: posed non-rigid shapes are placed by their overall shape only. Shapes
/// of one class that differ (a chair's back tilt) are placed by their best overlay on their
/// neighbours, which can lie several degrees from the designer's frame. The
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
                symmetries: Vec::new(),
            }],
            up: to_arr(&up),
            forward: to_arr(&forward),
            given_frame_share: 1.0,
            edges: Vec::new(),
            symmetry_axis: own_symmetries(&prepared[0], &Cube::new())
                .revolution
                .map(|a| to_arr(&a)),
        });
    }
    let edges = registration_graph(&prepared, options.neighbours.max(1));
    let cube = Cube::new();
    let own: Vec<OwnSymmetries> = prepared
        .par_iter()
        .map(|p| own_symmetries(p, &cube))
        .collect();
    let tables: Vec<EdgeTable> = edges
        .par_iter()
        .map(|&(a, b)| edge_table(&prepared[a], &prepared[b], &cube, &options.register))
        .collect();
    // The given frames agree on an edge when ICP from them stays there and fits about as well
    // as the edge's best pose.
    // The given frames agree on an edge when its best pose is the given one, up to the
    // target's own symmetries (a stool turned a quarter, a goblet about its stem).
    let given_agrees: Vec<bool> = edges
        .iter()
        .zip(&tables)
        .map(|(&(_, b), t)| {
            let k = (0..24)
                .min_by(|&x, &y| t.cost[x].total_cmp(&t.cost[y]).then(x.cmp(&y)))
                .unwrap_or(cube.identity);
            let r = t.pose[k].rotation;
            let near = |m: &Matrix3<f64>| angle(m, &Matrix3::identity()) < SAME_POSE_DEGREES;
            let given_fits = angle(&t.given.rotation, &Matrix3::identity()) < SAME_POSE_DEGREES
                && t.given.residual <= t.cost[k] * (1.0 + GIVEN_FRAME_SLACK);
            given_fits
                || near(&r)
                || own[b].turns.iter().any(|s| near(&(r * s)))
                || own[b]
                    .revolution
                    .is_some_and(|u| (r * u).dot(&u) >= SAME_POSE_DEGREES.to_radians().cos())
        })
        .collect();
    let given = given_agrees.iter().filter(|&&x| x).count() as f64 / tables.len() as f64;
    if given >= 0.5 {
        let rotations = vec![Matrix3::identity(); n];
        let regs: Vec<Vec<(Matrix3<f64>, f64)>> = tables
            .iter()
            .map(|t| candidate_list(Some(&t.given), t))
            .collect();
        let support = supports(n, &edges, &regs, &rotations);
        let (up, forward) = up_forward(&prepared, &rotations);
        return Ok(CollectionAlignment {
            case: FrameCase::AlreadyAligned,
            shapes: support
                .into_iter()
                .zip(&own)
                .map(|(s, o)| ShapeAlignment {
                    transform: Similarity::identity(),
                    symmetries: o.turns.iter().map(to_rows).collect(),
                    ..s
                })
                .collect(),
            up: to_arr(&up),
            forward: to_arr(&forward),
            given_frame_share: given,
            edges,
            symmetry_axis: collection_revolution_axis(&own, &rotations).map(|a| to_arr(&a)),
        });
    }
    let w: Vec<[f64; 24]> = tables.iter().map(label_costs).collect();
    let labels = label_shapes(n, &edges, &w, &cube);
    let refined: Vec<Pose> = edges
        .par_iter()
        .zip(&tables)
        .map(|(&(a, b), t)| {
            let q = cube.rel[labels[a]][labels[b]];
            icp(
                &prepared[a],
                &prepared[b],
                options.register.samples,
                t.pose[q],
                options.register.max_iterations,
                options.register.trim,
            )
        })
        .collect();
    let start: Vec<Matrix3<f64>> = labels
        .iter()
        .zip(&prepared)
        .map(|(&l, p)| cube.perms[l] * p.moments.frame.transpose())
        .collect();
    let rotations = average_rotations(start, &edges, &refined);
    let regs: Vec<Vec<(Matrix3<f64>, f64)>> = tables
        .iter()
        .zip(&refined)
        .map(|(t, r)| candidate_list(Some(r), t))
        .collect();
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
        .zip(&own)
        .map(|(((s, p), g), o)| {
            let r = frame * g;
            let symmetries = o
                .turns
                .iter()
                .map(|t| to_rows(&(r * t * r.transpose())))
                .collect();
            let scale = mean_radius / p.moments.radius;
            let t = -(r * p.moments.centroid) * scale;
            ShapeAlignment {
                transform: Similarity {
                    rotation: to_rows(&r),
                    scale,
                    translation: to_arr(&t),
                },
                symmetries,
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
        symmetry_axis: collection_revolution_axis(&own, &rotations).map(|a| to_arr(&(frame * a))),
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
                symmetries: Vec::new(),
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

fn to_arr(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}
/// One edge's registrations: for each of the 24 relative inertia-frame labels, the best
/// coarse pose that ICP reached nearest that label's start, and the pose reached from the
/// given frames.
struct EdgeTable {
    /// Coarse symmetric trimmed chamfer per relative label (`INFINITY` when no start ended
    /// nearest that label: it is no local minimum).
    cost: [f64; 24],
    /// The pose per relative label (its start when no start ended there).
    pose: [Pose; 24],
    /// ICP from the given frames (the identity start).
    given: Pose,
}

/// The 24 rotations of the cube and their composition table `rel[a][b]` = index of
/// `P_aᵀ P_b`.
struct Cube {
    perms: Vec<Matrix3<f64>>,
    rel: Vec<[usize; 24]>,
    identity: usize,
}

impl Cube {
    fn new() -> Self {
        let perms = signed_permutations();
        let find = |m: &Matrix3<f64>| {
            perms
                .iter()
                .position(|p| (p - m).abs().max() < 1e-9)
                .expect("the cube rotations form a group")
        };
        let rel = (0..24)
            .map(|a| std::array::from_fn(|b| find(&(perms[a].transpose() * perms[b]))))
            .collect();
        let identity = find(&Matrix3::identity());
        Self {
            perms,
            rel,
            identity,
        }
    }
}

/// Registers target `b` onto source `a` from every relative label's start and from the given
/// frames (coarse ICP), attributing each result to the label whose start it ended nearest.
fn edge_table(s: &Prepared, t: &Prepared, cube: &Cube, options: &RegisterOptions) -> EdgeTable {
    let starts: Vec<Matrix3<f64>> = cube
        .perms
        .iter()
        .map(|p| s.moments.frame * p * t.moments.frame.transpose())
        .chain(std::iter::once(Matrix3::identity()))
        .collect();
    let results: Vec<Pose> = starts
        .iter()
        .map(|r| coarse_icp(s, t, r, options))
        .collect();
    let mut cost = [f64::INFINITY; 24];
    let mut pose: [Pose; 24] = std::array::from_fn(|k| Pose {
        rotation: starts[k],
        translation: Vector3::zeros(),
        residual: f64::INFINITY,
    });
    for r in &results[..24] {
        let k = (0..24)
            .min_by(|&x, &y| {
                angle(&starts[x], &r.rotation).total_cmp(&angle(&starts[y], &r.rotation))
            })
            .unwrap_or(0);
        if r.residual < cost[k] {
            cost[k] = r.residual;
            pose[k] = *r;
        }
    }
    EdgeTable {
        cost,
        pose,
        given: results[24],
    }
}

/// Per edge, the labelling cost of each relative label: `ln(cost / best cost)` (0 for the
/// edge's best pose), labels that are no local minimum at the edge's worst. A log ratio, so
/// that a pair of dissimilar shapes (large residuals everywhere) weighs no more than a pair of
/// similar ones.
fn label_costs(table: &EdgeTable) -> [f64; 24] {
    let finite = table.cost.iter().copied().filter(|c| c.is_finite());
    let best = finite.clone().fold(f64::INFINITY, f64::min).max(1e-12);
    let worst = finite.fold(best, f64::max);
    table
        .cost
        .map(|c| (if c.is_finite() { c } else { worst } / best).ln())
}

/// A label per shape (an index into the cube rotations: shape `i` goes to the collection
/// frame by `P_{lᵢ} F_iᵀ`) minimising the summed label costs over the edges: greedy from a
/// root, then iterated conditional modes; every shape (at most [`LABEL_ROOTS`]) tried as the
/// root, the lowest total kept (ties to the lower root).
fn label_shapes(n: usize, edges: &[(usize, usize)], w: &[[f64; 24]], cube: &Cube) -> Vec<usize> {
    let incident: Vec<Vec<usize>> = (0..n)
        .map(|v| {
            (0..edges.len())
                .filter(|&e| edges[e].0 == v || edges[e].1 == v)
                .collect()
        })
        .collect();
    let local = |v: usize, l: usize, labels: &[Option<usize>]| -> f64 {
        incident[v]
            .iter()
            .filter_map(|&e| {
                let (a, b) = edges[e];
                if a == v {
                    labels[b].map(|lb| w[e][cube.rel[l][lb]])
                } else {
                    labels[a].map(|la| w[e][cube.rel[la][l]])
                }
            })
            .sum()
    };
    let step = n.div_ceil(LABEL_ROOTS).max(1);
    let mut best: Option<(f64, Vec<usize>)> = None;
    for root in (0..n).step_by(step) {
        let mut labels: Vec<Option<usize>> = vec![None; n];
        labels[root] = Some(cube.identity);
        for _ in 1..n {
            // The next shape: the one with the most placed neighbours.
            let placed = |v: usize| {
                incident[v]
                    .iter()
                    .filter(|&&e| {
                        let o = if edges[e].0 == v {
                            edges[e].1
                        } else {
                            edges[e].0
                        };
                        labels[o].is_some()
                    })
                    .count()
            };
            let Some(v) = (0..n)
                .filter(|&v| labels[v].is_none())
                .max_by(|&x, &y| placed(x).cmp(&placed(y)).then(y.cmp(&x)))
            else {
                break;
            };
            let l = (0..24)
                .min_by(|&x, &y| local(v, x, &labels).total_cmp(&local(v, y, &labels)))
                .unwrap_or(cube.identity);
            labels[v] = Some(l);
        }
        for _ in 0..ICM_SWEEPS {
            let mut changed = false;
            for v in 0..n {
                let current = labels[v].unwrap_or(cube.identity);
                let mut pick = (local(v, current, &labels), current);
                for l in 0..24 {
                    let c = local(v, l, &labels);
                    if c < pick.0 - 1e-12 {
                        pick = (c, l);
                    }
                }
                if pick.1 != current {
                    labels[v] = Some(pick.1);
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        let labels: Vec<usize> = labels
            .into_iter()
            .map(|l| l.unwrap_or(cube.identity))
            .collect();
        let energy: f64 = edges
            .iter()
            .enumerate()
            .map(|(e, &(a, b))| w[e][cube.rel[labels[a]][labels[b]]])
            .sum();
        if best.as_ref().is_none_or(|(b, _)| energy < b - 1e-12) {
            best = Some((energy, labels));
        }
    }
    best.map(|b| b.1).unwrap_or_else(|| vec![cube.identity; n])
}

/// Rotation averaging: each shape's rotation set to the chordal mean of what its refined
/// edges say it is (those within [`SAME_POSE_DEGREES`] of its current rotation), a few
/// sweeps from the labelling's rotations.
fn average_rotations(
    mut g: Vec<Matrix3<f64>>,
    edges: &[(usize, usize)],
    refined: &[Pose],
) -> Vec<Matrix3<f64>> {
    let n = g.len();
    for _ in 0..SYNC_SWEEPS {
        let mut moved = 0.0f64;
        for v in 0..n {
            let says: Vec<Matrix3<f64>> = edges
                .iter()
                .zip(refined)
                .filter_map(|(&(a, b), p)| {
                    if b == v {
                        Some(g[a] * p.rotation)
                    } else if a == v {
                        Some(g[b] * p.rotation.transpose())
                    } else {
                        None
                    }
                })
                .filter(|h| angle(h, &g[v]) < SAME_POSE_DEGREES)
                .collect();
            if !says.is_empty() {
                let new = chordal_mean(&says);
                moved = moved.max(angle(&new, &g[v]));
                g[v] = new;
            }
        }
        if moved < 1e-3 {
            break;
        }
    }
    g
}

/// An edge's distinct poses, best first: `first` (the refined or the given pose), then the
/// coarse label poses more than [`SAME_POSE_DEGREES`] from it and from each other.
fn candidate_list(first: Option<&Pose>, t: &EdgeTable) -> Vec<(Matrix3<f64>, f64)> {
    let mut order: Vec<usize> = (0..24).filter(|&k| t.cost[k].is_finite()).collect();
    order.sort_by(|&x, &y| t.cost[x].total_cmp(&t.cost[y]).then(x.cmp(&y)));
    let mut out: Vec<(Matrix3<f64>, f64)> = first
        .map(|p| (p.rotation, p.residual))
        .into_iter()
        .collect();
    for k in order {
        if out
            .iter()
            .all(|(r, _)| angle(r, &t.pose[k].rotation) >= SAME_POSE_DEGREES)
        {
            out.push((t.pose[k].rotation, t.cost[k]));
        }
    }
    out
}

/// Angles (degrees) at which a shape is compared with itself turned about an axis: none of
/// them a symmetry of a box, an n-gon prism of small n or a chair, all of them of a surface of
/// revolution.
const SYMMETRY_TEST_DEGREES: [f64; 3] = [37.0, 101.0, 163.0];
/// A turned shape overlays itself "as well as an independent resampling does" within this
/// factor of the resampling's chamfer: a surface of revolution faceted in 16 or more sectors
/// stays within it, a shape with any distinct side (a handle, a chair back) doubles it.
const SYMMETRY_SLACK: f64 = 1.5;

/// A shape's own symmetries, in its normalised frame: the proper rotations among
/// `F P Fᵀ` (its inertia frame `F` turned by a non-identity cube rotation `P`: a symmetry of a
/// shape always maps its inertia frame onto itself) that overlay the shape on itself, and the
/// axis about which it is a surface of revolution, if any.
///
/// Test: the first half of the samples against the second half turned (symmetric chamfer);
/// a turn is a symmetry when it stays within [`SYMMETRY_SLACK`] times the chamfer of the
/// unturned halves (the resampling floor); an axis is one of revolution when every turn of
/// [`SYMMETRY_TEST_DEGREES`] about it is a symmetry.
pub(crate) struct OwnSymmetries {
    turns: Vec<Matrix3<f64>>,
    revolution: Option<Vector3<f64>>,
}

fn own_symmetries(p: &Prepared, cube: &Cube) -> OwnSymmetries {
    let half = p.samples.len() / 2;
    if half < 10 {
        return OwnSymmetries {
            turns: Vec::new(),
            revolution: None,
        };
    }
    let (a, b) = p.samples.split_at(half);
    let ia = PointIndex::new(a);
    let ib = PointIndex::new(b);
    let chamfer = |r: &Matrix3<f64>| {
        let rt = r.transpose();
        let f = b.iter().map(|y| ia.nearest(&(r * y)).1).sum::<f64>() / b.len() as f64;
        let g = a.iter().map(|x| ib.nearest(&(rt * x)).1).sum::<f64>() / a.len() as f64;
        0.5 * (f + g)
    };
    let limit = SYMMETRY_SLACK * chamfer(&Matrix3::identity());
    let frame = p.moments.frame;
    let turns = (0..24)
        .filter(|&k| k != cube.identity)
        .map(|k| frame * cube.perms[k] * frame.transpose())
        .filter(|r| chamfer(r) <= limit)
        .collect();
    let revolution = (0..3).map(|k| Vector3::from(frame.column(k))).find(|axis| {
        SYMMETRY_TEST_DEGREES.iter().all(|deg| {
            let r = nalgebra::Rotation3::from_axis_angle(
                &nalgebra::Unit::new_normalize(*axis),
                deg.to_radians(),
            );
            chamfer(r.matrix()) <= limit
        })
    });
    OwnSymmetries { turns, revolution }
}

/// The collection's axis of revolution in the collection frame (rows of `g` take each shape
/// into it): when at least half of the shapes are surfaces of revolution and their axes agree
/// within [`SAME_POSE_DEGREES`] (up to sign) — rotations about it are then undetermined and
/// not an error of the alignment.
fn collection_revolution_axis(own: &[OwnSymmetries], g: &[Matrix3<f64>]) -> Option<Vector3<f64>> {
    let axes: Vec<Vector3<f64>> = own
        .iter()
        .zip(g)
        .filter_map(|(o, r)| o.revolution.map(|a| r * a))
        .collect();
    if axes.is_empty() || 2 * axes.len() < own.len() {
        return None;
    }
    let mut sum = Vector3::zeros();
    for a in &axes {
        sum += if a.dot(&axes[0]) < 0.0 { -a } else { *a };
    }
    let mean = sum.normalize();
    let limit = SAME_POSE_DEGREES.to_radians().cos();
    axes.iter()
        .all(|a| a.dot(&mean).abs() >= limit)
        .then_some(mean)
}
