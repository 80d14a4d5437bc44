//! [`snap_part_boundaries`]: moves the boundaries between parts onto the surface's concave
//! creases, by a minimum cut in a band around each boundary (the fuzzy-region cut of Katz and
//! Tal 2003, "Hierarchical mesh decomposition using fuzzy clustering and cuts").
//!
//! Why: `--parts N --parts-from geometry` groups equal-area regions, so its part boundaries
//! are where the regions happened to end: a few rings off the junction of a leg and a seat,
//! an arm and a shoulder. The grouping is right more often than the boundaries are (the
//! purity of the grouped parts, not their coverage, kept most generated sets under the bar).
//! Where two parts meet, the surface folds inwards (the minima rule), so among the closed
//! cuts near a boundary the one running along concave edges is the likeliest part boundary.

use crate::graph::{Cosegmentation, GraphError};
use crate::mesh::{TriMesh, dot, edge_adjacency, norm, sub};
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::{BinaryHeap, VecDeque};

/// Each band vertex's pull towards its current side, × its mean edge length: a cut may move
/// a boundary by about 1 / (2 STAY) rings to reach a crease that halves its cost.
const STAY: f64 = 0.05;

/// `coseg` with each shape's part boundaries moved onto the surface's concave creases.
///
/// For each pair of parts `(a, b)` that touch (in order of their ids), the vertices of `a`
/// and `b` within geodesic distance `band × √(shape area)` of their common boundary (along
/// mesh edges) are relabelled by a minimum cut separating the rest of `a` from the rest of
/// `b`. Each edge has a concavity `α = 1 − cos θ` of its dihedral angle θ where it is concave,
/// 0 where it is convex, each vertex `κ_v` = the largest α of its edges, and cutting edge
/// `(u, v)` costs its length over
/// `1 + ((κ_u + κ_v) / 2) / ᾱ`, `ᾱ` the mean α over the shape's edges: a cut through the
/// vertices of a sharp concave crease costs a fraction of one across a smooth or convex
/// stretch. (The vertices, not the edges: a cut between vertex labels crosses a crease, the
/// crease's own edges join vertices of one side. Convex folds count for nothing, unlike Katz
/// and Tal's small weight for them: a sharp convex rim, a chair seat's edge, would otherwise
/// attract cuts; measured without effect on the generated sets, docs/PARTS.md.) Each band
/// vertex is also pulled towards its current side by 0.05 × its mean edge length, so
/// where no crease decides the boundary stays. A pair one of whose parts lies wholly within the band
/// is left as it is (nothing would anchor that part). Normals are oriented outwards per
/// connected component (inward-wound components are flipped), so a mesh's winding does not
/// change the result.
///
/// Inputs: `meshes` (#shapes, graph order; #V_i vertices each), `coseg` (its tuples, one region
/// per shape each), `band` (≥ 0; 0 returns `coseg` unchanged). Output: the same tuples with
/// new regions and area fractions (every vertex keeps a part; the other fields are kept).
///
/// Errors: [`GraphError::BadOption`] when the meshes do not match `coseg` or `band` is
/// negative or not finite.
///
/// Cost: per shape and touching pair, a Dijkstra and a maximum flow (Dinic) on the band's
/// vertices; shapes in parallel, so the result does not depend on the thread count.
///
/// See also: [`super::geometric_part_tree`], [`super::PartsFrom::Geometry`].
///
/// Known issue: a crease that is not a part boundary (a fold of cloth, a sharp rim) within the
/// band attracts the cut as well; the band keeps such a cut close to where it was.
///
/// ```
/// use coseg::graph::{Cosegmentation, RegionTuple};
/// use coseg::parts::{snap_part_boundaries};
/// use coseg::mesh::TriMesh;
/// // A column of octagonal rings: radius 1 for rings 0–7, 0.4 above; ring 8 lies in the
/// // thick part's top face (a washer from ring 7), so the surface folds inwards at ring 8,
/// // where the thin top rises from it.
/// let mut p = Vec::new();
/// for k in 0..20 {
///     let r = if k < 8 { 1.0 } else { 0.4 };
///     let y = if k < 8 { 0.25 * k as f64 } else { 1.75 + 0.25 * (k - 8) as f64 };
///     for j in 0..8 {
///         let a = j as f64 * std::f64::consts::FRAC_PI_4;
///         p.push([r * a.cos(), y, r * a.sin()]);
///     }
/// }
/// p.push([0.0, 0.0, 0.0]);
/// p.push([0.0, 4.75, 0.0]);
/// let mut f = Vec::new();
/// for k in 0..19u32 {
///     for j in 0..8u32 {
///         let (a, b) = (8 * k + j, 8 * k + (j + 1) % 8);
///         f.push([a, a + 8, b]);
///         f.push([b, a + 8, b + 8]);
///     }
/// }
/// for j in 0..8u32 {
///     f.push([160, j, (j + 1) % 8]);
///     f.push([161, 152 + (j + 1) % 8, 152 + j]);
/// }
/// let mesh = TriMesh::new(p, f).unwrap();
/// // Parts cut two rings too high: rings 0–9 and 10–19.
/// let ring = |v: u32| if v < 160 { v / 8 } else if v == 160 { 0 } else { 19 };
/// let part = |lo: u32, hi: u32| (0..162).filter(|&v| ring(v) >= lo && ring(v) <= hi).collect();
/// let tuple = |r: Vec<u32>| RegionTuple { area_fractions: vec![0.5], regions: vec![r],
///     sweeps: 0, converged: true, cycled: false, objective: 0.0, confidence: 1.0,
///     cycle_consistency: None, leftover: false };
/// let coseg = Cosegmentation { names: vec!["s".into()], vertices: vec![162], root: 0,
///     order: vec![0], parent: vec![None], alpha: 0.5,
///     tuples: vec![tuple(part(0, 9)), tuple(part(10, 19))] };
/// let snapped = snap_part_boundaries(&[mesh], &coseg, 0.15).unwrap();
/// // The boundary now crosses the fold: the thin top starts just above it, at ring 9 (the
/// // tube's cut is shorter than the washer's).
/// assert_eq!(snapped.tuples[1].regions[0], part(9, 19));
/// ```
pub fn snap_part_boundaries(
    meshes: &[TriMesh],
    coseg: &Cosegmentation,
    band: f64,
) -> Result<Cosegmentation, GraphError> {
    if !coseg.matches(meshes) {
        return Err(GraphError::BadOption(
            "snapping part boundaries: one mesh per shape, with the shape's vertex count, is needed"
                .into(),
        ));
    }
    check_band(band)?;
    if band == 0.0 {
        return Ok(coseg.clone());
    }
    let labels: Vec<Vec<i32>> = meshes
        .par_iter()
        .enumerate()
        .map(|(i, mesh)| snap_shape(mesh, &coseg.labels(i), band))
        .collect();
    let mut out = coseg.clone();
    for (i, (mesh, labels)) in meshes.iter().zip(&labels).enumerate() {
        let w = mesh.vertex_areas();
        let total: f64 = w.iter().sum();
        for (r, t) in out.tuples.iter_mut().enumerate() {
            t.regions[i] = (0..labels.len() as u32)
                .filter(|&v| labels[v as usize] == r as i32)
                .collect();
            t.area_fractions[i] = t.regions[i].iter().map(|&v| w[v as usize]).sum::<f64>() / total;
        }
    }
    Ok(out)
}

/// The band's one rule, shared with the options that carry it: finite and ≥ 0.
pub(crate) fn check_band(band: f64) -> Result<(), GraphError> {
    if band.is_finite() && band >= 0.0 {
        Ok(())
    } else {
        Err(GraphError::BadOption(format!(
            "snap band {band}: expected a finite value ≥ 0"
        )))
    }
}

/// Per edge (sorted pairs): its cut weight ([`snap_part_boundaries`]).
fn edge_weights(mesh: &TriMesh) -> (Vec<[u32; 2]>, Vec<f64>, Vec<f64>) {
    let p = mesh.positions();
    let flipped = crate::features::inward_wound(mesh);
    let normals: Vec<[f64; 3]> = mesh
        .face_normals()
        .into_iter()
        .zip(mesh.faces())
        .map(|(n, f)| {
            if flipped[f[0] as usize] {
                n.map(|x| -x)
            } else {
                n
            }
        })
        .collect();
    let mut half: Vec<([u32; 2], u32)> = Vec::with_capacity(mesh.face_count() * 3);
    for (f, face) in mesh.faces().iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            half.push(([a.min(b), a.max(b)], f as u32));
        }
    }
    half.sort_unstable();
    let mut edges = Vec::new();
    let mut ang = Vec::new();
    let mut len = Vec::new();
    let mut k = 0;
    while k < half.len() {
        let e = half[k].0;
        let mut j = k;
        while j < half.len() && half[j].0 == e {
            j += 1;
        }
        let d = if j - k == 2 {
            let (f1, f2) = (half[k].1 as usize, half[k + 1].1 as usize);
            let (n1, n2) = (normals[f1], normals[f2]);
            let opp = mesh.faces()[f2]
                .iter()
                .copied()
                .find(|&v| v != e[0] && v != e[1])
                .unwrap_or(e[0]);
            let rise = dot(n1, sub(p[opp as usize], p[e[0] as usize]));
            if rise > 0.0 {
                1.0 - dot(n1, n2).clamp(-1.0, 1.0)
            } else {
                0.0
            }
        } else {
            0.0
        };
        edges.push(e);
        ang.push(d);
        len.push(norm(sub(p[e[0] as usize], p[e[1] as usize])));
        k = j;
    }
    let mean = ang.iter().sum::<f64>() / ang.len().max(1) as f64;
    // A vertex cut crosses a crease rather than running along it (the crease's own edges join
    // vertices of one side), so an edge is as cheap to cut as the sharpest concave fold at its
    // ends: κ_v = the largest α of v's edges, and the edge's α is the mean of its ends' κ.
    let mut kappa = vec![0.0f64; mesh.vertex_count()];
    for (e, &a) in edges.iter().zip(&ang) {
        for &v in e {
            kappa[v as usize] = kappa[v as usize].max(a);
        }
    }
    let ang: Vec<f64> = edges
        .iter()
        .map(|e| 0.5 * (kappa[e[0] as usize] + kappa[e[1] as usize]))
        .collect();
    let w = ang
        .iter()
        .zip(&len)
        .map(|(&a, &l)| if mean > 0.0 { l / (1.0 + a / mean) } else { l })
        .collect();
    (edges, w, len)
}

fn snap_shape(mesh: &TriMesh, labels: &[i32], band: f64) -> Vec<i32> {
    let d = mesh.vertex_count();
    let (edges, weight, length) = edge_weights(mesh);
    let (deg, adj) = edge_adjacency(d, &edges);
    let radius = band * mesh.total_area().sqrt();
    let mut labels = labels.to_vec();
    let parts = labels.iter().copied().max().unwrap_or(-1) + 1;
    for a in 0..parts {
        for b in a + 1..parts {
            let seeds: Vec<usize> = (0..d)
                .filter(|&v| {
                    (labels[v] == a || labels[v] == b)
                        && adj[deg[v]..deg[v + 1]].iter().any(|&(u, _)| {
                            let lu = labels[u as usize];
                            (lu == a || lu == b) && lu != labels[v]
                        })
                })
                .collect();
            if seeds.is_empty() {
                continue;
            }
            // The band: vertices of a or b within `radius` of the a–b boundary.
            let mut dist = vec![f64::INFINITY; d];
            let mut heap = BinaryHeap::new();
            for &s in &seeds {
                dist[s] = 0.0;
                heap.push(Near(0.0, s));
            }
            while let Some(Near(dv, v)) = heap.pop() {
                if dv > dist[v] {
                    continue;
                }
                for &(u, e) in &adj[deg[v]..deg[v + 1]] {
                    let u = u as usize;
                    if labels[u] != a && labels[u] != b {
                        continue;
                    }
                    let du = dv + length[e as usize];
                    if du <= radius && du < dist[u] {
                        dist[u] = du;
                        heap.push(Near(du, u));
                    }
                }
            }
            let in_band: Vec<usize> = (0..d).filter(|&v| dist[v].is_finite()).collect();
            let mut index = vec![usize::MAX; d];
            for (k, &v) in in_band.iter().enumerate() {
                index[v] = k;
            }
            let n = in_band.len();
            let (source, sink) = (n, n + 1);
            let mut flow = MaxFlow::new(n + 2);
            let (mut has_source, mut has_sink) = (false, false);
            for &v in &in_band {
                // A weak pull towards the vertex's current side, so that where no crease
                // decides (a smooth tube) the boundary stays instead of sliding to the band's
                // edge (a minimum cut's ties go to the smallest source side).
                let ring = &adj[deg[v]..deg[v + 1]];
                let pull = STAY * ring.iter().map(|&(_, e)| length[e as usize]).sum::<f64>()
                    / ring.len().max(1) as f64;
                if labels[v] == a {
                    flow.add(source, index[v], pull, 0.0);
                } else {
                    flow.add(index[v], sink, pull, 0.0);
                }
                for &(u, e) in ring {
                    let u = u as usize;
                    let w = weight[e as usize];
                    if index[u] != usize::MAX {
                        if v < u {
                            flow.add(index[v], index[u], w, w);
                        }
                    } else if labels[u] == a {
                        flow.add(source, index[v], w, 0.0);
                        has_source = true;
                    } else if labels[u] == b {
                        flow.add(index[v], sink, w, 0.0);
                        has_sink = true;
                    }
                }
            }
            // A part lying wholly in the band has nothing to anchor it: leave the pair.
            if !(has_source && has_sink) {
                continue;
            }
            let side = flow.min_cut(source, sink);
            for (k, &v) in in_band.iter().enumerate() {
                labels[v] = if side[k] { a } else { b };
            }
        }
    }
    labels
}

/// A heap entry ordered by smallest distance first (ties: smallest vertex).
#[derive(PartialEq)]
struct Near(f64, usize);

impl Eq for Near {}

impl PartialOrd for Near {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Near {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .0
            .total_cmp(&self.0)
            .then_with(|| other.1.cmp(&self.1))
    }
}

/// Dinic's maximum flow on a small graph.
struct MaxFlow {
    head: Vec<usize>,
    next: Vec<usize>,
    to: Vec<usize>,
    cap: Vec<f64>,
}

impl MaxFlow {
    fn new(n: usize) -> Self {
        MaxFlow {
            head: vec![usize::MAX; n],
            next: Vec::new(),
            to: Vec::new(),
            cap: Vec::new(),
        }
    }

    fn add(&mut self, u: usize, v: usize, forward: f64, backward: f64) {
        for (x, y, c) in [(u, v, forward), (v, u, backward)] {
            self.to.push(y);
            self.cap.push(c);
            self.next.push(self.head[x]);
            self.head[x] = self.to.len() - 1;
        }
    }

    /// Runs the flow; true for the nodes on the source's side of a minimum cut.
    fn min_cut(&mut self, s: usize, t: usize) -> Vec<bool> {
        let n = self.head.len();
        loop {
            let mut level = vec![usize::MAX; n];
            level[s] = 0;
            let mut queue = VecDeque::from([s]);
            while let Some(u) = queue.pop_front() {
                let mut e = self.head[u];
                while e != usize::MAX {
                    if self.cap[e] > 1e-15 && level[self.to[e]] == usize::MAX {
                        level[self.to[e]] = level[u] + 1;
                        queue.push_back(self.to[e]);
                    }
                    e = self.next[e];
                }
            }
            if level[t] == usize::MAX {
                return level.iter().map(|&l| l != usize::MAX).collect();
            }
            let mut it = self.head.clone();
            while self.augment(s, t, f64::INFINITY, &level, &mut it) > 1e-15 {}
        }
    }

    fn augment(&mut self, u: usize, t: usize, f: f64, level: &[usize], it: &mut [usize]) -> f64 {
        if u == t {
            return f;
        }
        while it[u] != usize::MAX {
            let e = it[u];
            let v = self.to[e];
            if self.cap[e] > 1e-15 && level[v] == level[u] + 1 {
                let got = self.augment(v, t, f.min(self.cap[e]), level, it);
                if got > 1e-15 {
                    self.cap[e] -= got;
                    self.cap[e ^ 1] += got;
                    return got;
                }
            }
            it[u] = self.next[e];
        }
        0.0
    }
}
