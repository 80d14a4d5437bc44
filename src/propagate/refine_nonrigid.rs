//! [`refine_nonrigid`]: an affine registration relaxed to a smooth non-rigid deformation of the
//! source (an embedded deformation graph fitted by trimmed, symmetric ICP with its stiffness
//! lowered while held-out samples keep improving), so that shapes of one class whose parts
//! differ in length or tilt overlay part on part.

use super::refine_affine::{AffineMap, trimmed};
use crate::align::{SurfaceIndex, SurfacePoint};
use crate::mesh::TriMesh;
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use rayon::prelude::*;
use std::collections::BTreeSet;

/// The result of [`refine_nonrigid`].
#[derive(Debug, Clone, PartialEq)]
pub struct NonrigidFit {
    /// The source's vertices deformed onto the target (source order), in the source's frame
    /// and units: the target lies there under the starting affine map.
    pub deformed: Vec<[f64; 3]>,
    /// Symmetric trimmed chamfer of the fitting samples at the kept deformation (mean of the
    /// kept nearest-point distances of both directions, each weighted by area), in source
    /// units.
    pub residual: f64,
    /// The same measure for the start (the affine map, no deformation).
    pub start_residual: f64,
    /// How many stiffness levels were kept: `0` when no level improved the held-out samples
    /// (then `deformed` is the source itself).
    pub levels: usize,
}

/// Nodes of the deformation graph at most. A node per tenth or so of a shape's extent along
/// each part is the scale at which the parts of one class differ (a longer leg, a tilted
/// back); more nodes add freedom the trimmed data cannot constrain and cost a dense solve of
/// `4 × nodes` unknowns per step.
const NODES: usize = 96;
/// Samples per shape at most (farthest-point, each weighted by the area it stands for): the
/// correspondences cost a closest-point query each, and a few per node are enough to fit it.
const SAMPLES: usize = 800;
/// Nodes influencing each vertex (Sumner et al. 2007 use four).
const NEIGHBOURS: usize = 4;
/// Every this-many-th sample of each shape is held out of the fit and only scores it.
const HOLD_OUT_EVERY: usize = 5;
/// First stiffness (smoothness per edge against the data misfit, both as mean squared
/// lengths): high enough that the graph first moves as nearly one affine map, so the
/// deformation grows from the start instead of jumping.
const START_STIFFNESS: f64 = 16.0;
/// Stiffness factor between levels (the halving of the optimal-step schedule).
const STIFFNESS_STEP: f64 = 0.5;
/// Levels at most: from [`START_STIFFNESS`] to a thousandth of it; the held-out samples stop
/// the schedule long before on every shape measured.
const MAX_LEVELS: usize = 10;
/// Re-pairings per level at most (each one a least-squares solve); a level stops earlier when
/// the fitting residual stops falling.
const STEPS_PER_LEVEL: usize = 3;
/// Pull of every node's map towards the start, relative to the data: keeps the normal
/// equations definite where a node sees no sample and its graph component is cut off. Small
/// enough to change no fit that the data determine.
const ANCHOR: f64 = 1e-4;

/// Deforms `source` onto `target` (mapped into the source's frame by `start`, an affine map
/// as [`super::refine_affine`] returns it) by an embedded deformation graph (Sumner, Schmid
/// and Pauly 2007): nodes are farthest-point samples of the source, each carrying an affine
/// map; a vertex moves by the maps of its nearest nodes, blended. The maps are fitted by
/// trimmed, symmetric, area-weighted ICP (each source sample paired with its nearest point of
/// the target surface, each target sample with its nearest deformed source sample; the
/// farthest `1 − trim` of each direction by area dropped as parts one shape lacks) against a
/// smoothness term (neighbouring nodes must predict each other's positions), whose weight —
/// the stiffness — starts high and is halved level by level, as in the optimal-step
/// non-rigid ICP of Amberg, Romdhani and Vetter (2007). Each level is a linear least-squares
/// problem per coordinate, all three sharing one matrix.
///
/// When to stop is the data's: a fifth of each shape's samples is held out of the fit, and the
/// stiffness is lowered only while their symmetric trimmed residual falls; the deformation
/// kept is the one of the best held-out residual (the start itself when no level improves it).
///
/// Why: the parts of a class's shapes differ by more than an affine map (legs longer, a back
/// taller and tilted), and after twelve parameters a label spills across a part boundary.
///
/// Inputs: `source` (`S` vertices), `target` (`T` vertices), `start` (target → source frame),
/// `trim` in `(0, 1]`. Output: a [`NonrigidFit`] (the deformed source, `S` points).
/// Cost: two farthest-point samplings (`O(800 (S + T))`), per step 640 closest-point
/// queries, 640 × 800 point distances and one dense Cholesky of `4 × 96` unknowns; at most
/// thirty steps.
///
/// Deterministic: exact closest points, fixed orders, no randomness. Degenerate input (fewer
/// source vertices than a node neighbourhood, a map that fails) keeps the start (`levels = 0`).
///
/// See also: [`super::refine_affine`] (its start), [`super::rigid_route`] (its user).
pub fn refine_nonrigid(
    source: &TriMesh,
    target: &TriMesh,
    start: &AffineMap,
    trim: f64,
) -> NonrigidFit {
    let kept = NonrigidFit {
        deformed: source.positions().to_vec(),
        residual: f64::NAN,
        start_residual: f64::NAN,
        levels: 0,
    };
    let Ok(mapped) = target.map_positions(|p| start.apply(p)) else {
        return kept;
    };
    let sp = source.positions();
    if sp.len() <= NEIGHBOURS || !(trim > 0.0 && trim <= 1.0) {
        return kept;
    }
    let index = SurfaceIndex::new(&mapped);
    let (s_samples, s_weights) = area_samples(sp, &source.vertex_areas(), SAMPLES);
    let (t_samples, t_weights) = area_samples(mapped.positions(), &mapped.vertex_areas(), SAMPLES);
    let nodes: Vec<[f64; 3]> = s_samples
        .iter()
        .take(NODES.min(s_samples.len()))
        .map(|&v| sp[v])
        .collect();
    let skin: Vec<Skin> = sp.par_iter().map(|&p| skin_of(p, &nodes)).collect();
    let edges = graph_edges(&skin, nodes.len());
    let split = |n: usize| -> (Vec<usize>, Vec<usize>) {
        (0..n).partition(|k| k % HOLD_OUT_EVERY != HOLD_OUT_EVERY - 1)
    };
    let (s_fit, s_held) = split(s_samples.len());
    let (t_fit, t_held) = split(t_samples.len());
    let tp = mapped.positions();
    let problem = Problem {
        sp,
        tp,
        tf: mapped.faces(),
        index: &index,
        nodes: &nodes,
        skin: &skin,
        edges: &edges,
        s_samples: &s_samples,
        s_weights: &s_weights,
        t_samples: &t_samples,
        t_weights: &t_weights,
        trim,
    };
    let mut state = identity(nodes.len());
    let score = |state: &[NodeMap], s: &[usize], t: &[usize], partners: &[usize]| {
        problem.pairs(state, s, t, partners)
    };
    let all_source: Vec<usize> = (0..s_samples.len()).collect();
    let Some(first) = score(&state, &s_fit, &t_fit, &s_fit) else {
        return kept;
    };
    let Some(held) = score(&state, &s_held, &t_held, &all_source) else {
        return kept;
    };
    let start_residual = first.residual;
    let mut best = (held.residual, state.clone(), first.residual, 0);
    // The pairs of the current state, when made: a step that ends a level (no solve after
    // it) leaves them for the level's score and that score for the next level's first step.
    let mut at_state = Some(first);
    let mut stiffness = START_STIFFNESS;
    for level in 0..MAX_LEVELS {
        let mut last = f64::INFINITY;
        for _ in 0..STEPS_PER_LEVEL {
            let Some(pairs) = at_state
                .take()
                .or_else(|| score(&state, &s_fit, &t_fit, &s_fit))
            else {
                break;
            };
            if pairs.residual >= last {
                at_state = Some(pairs);
                break;
            }
            last = pairs.residual;
            match problem.solve(&pairs, stiffness) {
                Some(next) => state = next,
                None => {
                    at_state = Some(pairs);
                    break;
                }
            }
        }
        let (Some(h), Some(f)) = (
            score(&state, &s_held, &t_held, &all_source),
            at_state
                .take()
                .or_else(|| score(&state, &s_fit, &t_fit, &s_fit)),
        ) else {
            break;
        };
        if h.residual.is_nan() || best.0.is_nan() || h.residual >= best.0 {
            break;
        }
        best = (h.residual, state.clone(), f.residual, level + 1);
        at_state = Some(f);
        stiffness *= STIFFNESS_STEP;
    }
    let (_, state, residual, levels) = best;
    if levels == 0 {
        return NonrigidFit {
            residual: start_residual,
            start_residual,
            ..kept
        };
    }
    let deformed: Vec<[f64; 3]> = (0..sp.len())
        .map(|v| deform(sp[v], &skin[v], &nodes, &state))
        .collect();
    if deformed.iter().flatten().any(|x| !x.is_finite()) {
        return NonrigidFit {
            residual: start_residual,
            start_residual,
            ..kept
        };
    }
    NonrigidFit {
        deformed,
        residual,
        start_residual,
        levels,
    }
}

/// [`refine_nonrigid`] after the affine map `start`, and the closest point of the deformed
/// source surface to every target vertex under `start` (target order): the rigid route reads
/// the labels off these. `None` where the deformation kept the start (the caller's own
/// closest points stand) or the deformed source is not a valid mesh.
pub(crate) fn refine_nonrigid_reading(
    source: &TriMesh,
    target: &TriMesh,
    start: &AffineMap,
    trim: f64,
) -> Option<(NonrigidFit, Vec<SurfacePoint>)> {
    let fit = refine_nonrigid(source, target, start, trim);
    if fit.levels == 0 {
        return None;
    }
    let deformed = TriMesh::new(fit.deformed.clone(), source.faces().to_vec()).ok()?;
    let index = SurfaceIndex::new(&deformed);
    let closest = target
        .positions()
        .par_iter()
        .map(|&x| index.closest(start.apply(x)))
        .collect();
    Some((fit, closest))
}

/// One node's affine map, row by row: `[a_d0, a_d1, a_d2, t_d]` for output coordinate `d`.
type NodeMap = [[f64; 4]; 3];

/// A vertex's nodes and their blending weights (summing to 1).
type Skin = Vec<(usize, f64)>;

fn identity(n: usize) -> Vec<NodeMap> {
    let mut m = [[0.0; 4]; 3];
    for (d, row) in m.iter_mut().enumerate() {
        row[d] = 1.0;
    }
    vec![m; n]
}

/// Farthest-point samples of `positions` (from vertex 0, ties to the lowest index; at most
/// `count`) and per sample the area of the vertices nearest to it, so that the samples weigh
/// the surface they stand for whatever the meshing.
fn area_samples(positions: &[[f64; 3]], areas: &[f64], count: usize) -> (Vec<usize>, Vec<f64>) {
    let n = positions.len();
    let count = count.min(n);
    let mut dist = vec![f64::INFINITY; n];
    let mut owner = vec![0usize; n];
    let mut out = Vec::with_capacity(count);
    let mut current = 0usize;
    for k in 0..count {
        out.push(current);
        let c = positions[current];
        let mut far = (-1.0, 0usize);
        for (v, p) in positions.iter().enumerate() {
            let d2 = (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2);
            if d2 < dist[v] {
                dist[v] = d2;
                owner[v] = k;
            }
            if dist[v] > far.0 {
                far = (dist[v], v);
            }
        }
        current = far.1;
    }
    let mut weights = vec![0.0; out.len()];
    for (v, &o) in owner.iter().enumerate() {
        weights[o] += areas.get(v).copied().unwrap_or(0.0);
    }
    (out, weights)
}

/// The [`NEIGHBOURS`] nearest nodes of `p`, weighted `(1 − d / d_next)²` (`d_next` the distance
/// of the next nearest node, Sumner et al.), normalised; equal weights where all vanish.
fn skin_of(p: [f64; 3], nodes: &[[f64; 3]]) -> Skin {
    let mut near: Vec<(f64, usize)> = nodes
        .iter()
        .enumerate()
        .map(|(k, g)| (dist(p, *g), k))
        .collect();
    let order = |a: &(f64, usize), b: &(f64, usize)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
    // Only the nearest nodes and the next one are read: select them, then order those.
    if near.len() > NEIGHBOURS + 1 {
        near.select_nth_unstable_by(NEIGHBOURS, order);
        near.truncate(NEIGHBOURS + 1);
    }
    near.sort_by(order);
    let k = NEIGHBOURS.min(near.len());
    let next = near.get(k).map_or(f64::INFINITY, |x| x.0);
    let mut skin: Skin = near[..k]
        .iter()
        .map(|&(d, j)| {
            let w = if next > 0.0 && next.is_finite() {
                (1.0 - d / next).max(0.0).powi(2)
            } else {
                1.0
            };
            (j, w)
        })
        .collect();
    let total: f64 = skin.iter().map(|x| x.1).sum();
    if total > 0.0 {
        skin.iter_mut().for_each(|x| x.1 /= total);
    } else {
        skin.iter_mut().for_each(|x| x.1 = 1.0 / k as f64);
    }
    skin
}

/// Node pairs that move a common vertex (the deformation graph's edges, Sumner et al.).
fn graph_edges(skin: &[Skin], nodes: usize) -> Vec<(usize, usize)> {
    let mut edges = BTreeSet::new();
    for s in skin {
        for (a, &(i, wi)) in s.iter().enumerate() {
            for &(j, wj) in &s[a + 1..] {
                if wi > 0.0 && wj > 0.0 && i != j && i < nodes && j < nodes {
                    edges.insert((i.min(j), i.max(j)));
                }
            }
        }
    }
    edges.into_iter().collect()
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The image of `p` (skinned by `skin`) under the node maps `state`.
fn deform(p: [f64; 3], skin: &Skin, nodes: &[[f64; 3]], state: &[NodeMap]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for &(k, w) in skin {
        let g = nodes[k];
        let x = [p[0] - g[0], p[1] - g[1], p[2] - g[2], 1.0];
        for (d, o) in out.iter_mut().enumerate() {
            let row = &state[k][d];
            *o += w * (row[0] * x[0] + row[1] * x[1] + row[2] * x[2] + row[3] + g[d]);
        }
    }
    out
}

/// Everything one fit reads.
struct Problem<'a> {
    sp: &'a [[f64; 3]],
    tp: &'a [[f64; 3]],
    tf: &'a [[u32; 3]],
    index: &'a SurfaceIndex,
    nodes: &'a [[f64; 3]],
    skin: &'a [Skin],
    edges: &'a [(usize, usize)],
    s_samples: &'a [usize],
    s_weights: &'a [f64],
    t_samples: &'a [usize],
    t_weights: &'a [f64],
    trim: f64,
}

/// Trimmed correspondences: `(source vertex, target point, weight)` with the weights of each
/// direction summing to 1, and their symmetric residual.
struct Pairs {
    pairs: Vec<(usize, [f64; 3], f64)>,
    residual: f64,
}

impl Problem<'_> {
    /// The trimmed pairs of the source samples `s` (to the target surface) and the target
    /// samples `t` (to the nearest of the deformed source samples `partners`) under `state`.
    fn pairs(
        &self,
        state: &[NodeMap],
        s: &[usize],
        t: &[usize],
        partners: &[usize],
    ) -> Option<Pairs> {
        let moved = |k: usize| {
            let v = self.s_samples[k];
            deform(self.sp[v], &self.skin[v], self.nodes, state)
        };
        let forward: Vec<(usize, [f64; 3], f64, f64)> = s
            .par_iter()
            .map(|&k| {
                let y = moved(k);
                let c = self.index.closest(y);
                (
                    self.s_samples[k],
                    self.surface_point(&c),
                    self.s_weights[k],
                    c.distance,
                )
            })
            .collect();
        let partner_points: Vec<[f64; 3]> = partners.iter().map(|&k| moved(k)).collect();
        let backward: Vec<(usize, [f64; 3], f64, f64)> = t
            .par_iter()
            .map(|&k| {
                let x = self.tp[self.t_samples[k]];
                let mut near = (f64::INFINITY, 0usize);
                for (j, y) in partner_points.iter().enumerate() {
                    let d2 = (x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2) + (x[2] - y[2]).powi(2);
                    if d2 < near.0 {
                        near = (d2, j);
                    }
                }
                let v = self.s_samples[partners[near.1]];
                (v, x, self.t_weights[k], near.0.sqrt())
            })
            .collect();
        let mut pairs = Vec::with_capacity(forward.len() + backward.len());
        let mut residual = 0.0;
        for dir in [forward, backward] {
            let kept = trimmed(&dir, self.trim);
            let total: f64 = kept.iter().map(|&k| dir[k].2).sum();
            if total.is_nan() || total <= 0.0 {
                return None;
            }
            residual += kept.iter().map(|&k| dir[k].2 * dir[k].3).sum::<f64>() / total / 2.0;
            pairs.extend(kept.iter().map(|&k| (dir[k].0, dir[k].1, dir[k].2 / total)));
        }
        Some(Pairs { pairs, residual })
    }

    /// The target surface point `c` lies at.
    fn surface_point(&self, c: &SurfacePoint) -> [f64; 3] {
        let f = self.tf[c.face];
        let mut out = [0.0; 3];
        for (k, &v) in f.iter().enumerate() {
            for (o, x) in out.iter_mut().zip(self.tp[v as usize]) {
                *o += c.barycentric[k] * x;
            }
        }
        out
    }

    /// The node maps minimising the weighted squared distances of `pairs` plus `stiffness`
    /// times the mean squared disagreement of neighbouring nodes (and the small pull
    /// [`ANCHOR`] towards the start); `None` when the normal equations are not definite.
    fn solve(&self, pairs: &Pairs, stiffness: f64) -> Option<Vec<NodeMap>> {
        let n = self.nodes.len();
        let u = 4 * n;
        let mut m = Normal {
            u,
            lhs: vec![0.0; u * u],
            rhs: vec![0.0; u * 3],
        };
        let mut row: Vec<(usize, f64)> = Vec::with_capacity(4 * NEIGHBOURS);
        for &(v, q, w) in &pairs.pairs {
            row.clear();
            let p = self.sp[v];
            let mut constant = [0.0; 3];
            for &(k, b) in &self.skin[v] {
                let g = self.nodes[k];
                row.extend([
                    (4 * k, b * (p[0] - g[0])),
                    (4 * k + 1, b * (p[1] - g[1])),
                    (4 * k + 2, b * (p[2] - g[2])),
                    (4 * k + 3, b),
                ]);
                for d in 0..3 {
                    constant[d] += b * g[d];
                }
            }
            m.add(
                &row,
                w,
                [q[0] - constant[0], q[1] - constant[1], q[2] - constant[2]],
            );
        }
        if !self.edges.is_empty() {
            let w = stiffness * 2.0 / (2 * self.edges.len()) as f64;
            for &(a, b) in self.edges {
                for (j, k) in [(a, b), (b, a)] {
                    let (gj, gk) = (self.nodes[j], self.nodes[k]);
                    let e = [gk[0] - gj[0], gk[1] - gj[1], gk[2] - gj[2]];
                    row.clear();
                    row.extend([
                        (4 * j, e[0]),
                        (4 * j + 1, e[1]),
                        (4 * j + 2, e[2]),
                        (4 * j + 3, 1.0),
                        (4 * k + 3, -1.0),
                    ]);
                    m.add(&row, w, e);
                }
            }
        }
        let scale = self.extent2();
        for k in 0..n {
            for c in 0..3 {
                m.lhs[(4 * k + c) * u + 4 * k + c] += ANCHOR * scale;
                m.rhs[(4 * k + c) * 3 + c] += ANCHOR * scale;
            }
            m.lhs[(4 * k + 3) * u + 4 * k + 3] += ANCHOR;
        }
        let lhs = Mat::from_fn(u, u, |i, j| m.lhs[i * u + j]);
        let rhs = Mat::from_fn(u, 3, |i, d| m.rhs[i * 3 + d]);
        let x = lhs.llt(Side::Lower).ok()?.solve(&rhs);
        if !(0..u).all(|i| (0..3).all(|d| x[(i, d)].is_finite())) {
            return None;
        }
        Some(
            (0..n)
                .map(|k| {
                    let mut map = [[0.0; 4]; 3];
                    for (d, r) in map.iter_mut().enumerate() {
                        for (c, e) in r.iter_mut().enumerate() {
                            *e = x[(4 * k + c, d)];
                        }
                    }
                    map
                })
                .collect(),
        )
    }

    /// Mean squared distance of the nodes from their centroid: the length² that puts the
    /// anchor of a node's linear part on the scale of its translation.
    fn extent2(&self) -> f64 {
        let n = self.nodes.len().max(1) as f64;
        let mut c = [0.0; 3];
        for g in self.nodes {
            for d in 0..3 {
                c[d] += g[d] / n;
            }
        }
        let s = self.nodes.iter().map(|g| dist(*g, c).powi(2)).sum::<f64>() / n;
        if s > 0.0 { s } else { 1.0 }
    }
}

/// Normal equations of `u` unknowns with three right-hand sides (one per coordinate, all
/// sharing the matrix), row-major. Dense: `4 × NODES` unknowns factor in a few milliseconds,
/// less than a sparse ordering would take to set up at this size.
struct Normal {
    u: usize,
    lhs: Vec<f64>,
    rhs: Vec<f64>,
}

impl Normal {
    /// Adds the weighted row `row · θ_d = value_d` (one row, three right-hand sides).
    fn add(&mut self, row: &[(usize, f64)], w: f64, value: [f64; 3]) {
        for &(i, a) in row {
            for &(j, b) in row {
                self.lhs[i * self.u + j] += w * a * b;
            }
            for (d, v) in value.iter().enumerate() {
                self.rhs[i * 3 + d] += w * a * v;
            }
        }
    }
}
