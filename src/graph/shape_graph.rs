//! [`ShapeGraph`]: the shapes of a collection and the affinity edges between them.

use super::GraphError;
use crate::affinity::{BandAffinity, Direction, FeaturePairing};
use crate::bands::BandTable;
use petgraph::graph::{NodeIndex, UnGraph};
use petgraph::visit::EdgeRef;
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::sync::Arc;

/// A shape of the collection: everything the co-segmentation needs, from the per-shape cache.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeNode {
    /// Display name (the file stem for a folder).
    pub name: String,
    /// `d × N` band labels, shared: the graphs a collection stage builds over the same shapes
    /// (the propagation's, the parts route's candidates) hold one table per shape, not a copy
    /// each.
    pub bands: Arc<BandTable>,
    /// Unit-normalised vertex areas (length `d`, sum 1).
    pub areas: Vec<f64>,
}

impl ShapeNode {
    /// A node from a band table and raw per-vertex areas (any positive scale; they are divided
    /// by their sum).
    pub fn new(
        name: impl Into<String>,
        bands: impl Into<Arc<BandTable>>,
        areas: &[f64],
    ) -> Result<Self, GraphError> {
        let name = name.into();
        let bands = bands.into();
        if areas.len() != bands.vertices {
            return Err(GraphError::Incompatible {
                name,
                reason: format!(
                    "{} vertex areas for {} vertices",
                    areas.len(),
                    bands.vertices
                ),
            });
        }
        let total: f64 = areas.iter().sum();
        if !(total.is_finite() && total > 0.0) || areas.iter().any(|a| !a.is_finite() || *a < 0.0) {
            return Err(GraphError::Incompatible {
                name,
                reason: "vertex areas must be finite, non-negative, with a positive sum".into(),
            });
        }
        Ok(Self {
            name,
            areas: areas.iter().map(|a| a / total).collect(),
            bands,
        })
    }
}

/// An edge between two shapes: how their features pair, and how much the co-segmentation trusts
/// it.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeEdge {
    /// Feature pairs `(k_lo, k_hi)` from the lower-index node to the higher-index one.
    pub pairs: Vec<(u32, u32)>,
    /// Weight of each pair (`None`: equal weights).
    pub pair_weights: Option<Vec<f64>>,
    /// Summary distance between the two shapes (see [`shape_summary`]); 0 for identical
    /// summaries.
    pub distance: f64,
    /// Weight of the edge in the co-segmentation, `1 / (1 + distance / median distance)`, in
    /// `(0, 1]` (all 1 when every distance is 0).
    pub weight: f64,
}

impl ShapeEdge {
    /// The feature pairing as the affinity operator takes it.
    pub fn pairing(&self) -> FeaturePairing {
        FeaturePairing::new(self.pairs.clone(), self.pair_weights.clone())
    }
}

/// Whether the graph is complete or a sparse nearest-neighbour graph.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum GraphKind {
    /// Every pair of shapes is an edge.
    Complete,
    /// Each shape linked to its `k` nearest by summary distance, plus a minimum spanning tree of
    /// the summary distances (so the graph is connected).
    Nearest(usize),
}

/// Options of [`ShapeGraph::build`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct GraphOptions {
    /// Collections of at most this many shapes get a complete graph (default 12: 66 edges).
    pub complete_limit: usize,
    /// Neighbours per shape of the sparse graph (default 6).
    pub neighbours: usize,
    /// Features sampled by [`shape_summary`] (default 32).
    pub summary_features: usize,
}

impl Default for GraphOptions {
    fn default() -> Self {
        Self {
            complete_limit: 12,
            neighbours: 6,
            summary_features: 32,
        }
    }
}

/// The shape graph: an undirected petgraph whose node `i` is the `i`-th shape given to
/// [`ShapeGraph::build`]. Pairwise affinities are never stored: [`ShapeGraph::affinity`] builds
/// the band-table operator of an edge on demand.
#[derive(Debug, Clone)]
pub struct ShapeGraph {
    graph: UnGraph<ShapeNode, ShapeEdge>,
    kind: GraphKind,
    /// Per node, its [`shape_summary`] (kept for distances between shapes no edge joins).
    summaries: Vec<Vec<f64>>,
}

/// A cheap affinity summary of a shape: the area-weighted correlations between the band labels
/// of `m = min(features, N)` evenly spaced features (`k_s = ⌊s N / m⌋`), upper triangle in
/// row order (`m (m − 1) / 2` values in `[−1, 1]`). Band labels are ranks, so these are coarse
/// Spearman correlations: invariant to vertex order and to any monotone change of a feature,
/// similar for shapes whose features co-vary alike. Cost `O(m² d)`.
///
/// ```
/// use coseg::bands::equal_count_bands;
/// use coseg::graph::shape_summary;
/// // Two features, the second the reverse of the first: correlation −1.
/// let vals = [0.0, 1.0, 2.0, 3.0, 3.0, 2.0, 1.0, 0.0];
/// let t = equal_count_bands(&vals, 2, 4, 4).unwrap();
/// let s = shape_summary(&t, &[0.25; 4], 2);
/// assert!((s[0] + 1.0).abs() < 1e-12);
/// ```
pub fn shape_summary(bands: &BandTable, areas: &[f64], features: usize) -> Vec<f64> {
    let n = bands.features;
    let m = features.min(n);
    if m < 2 || bands.vertices == 0 {
        return Vec::new();
    }
    let idx: Vec<usize> = (0..m).map(|s| s * n / m).collect();
    let total: f64 = areas.iter().sum();
    let mut mean = vec![0.0; m];
    for (v, &av) in areas.iter().enumerate().take(bands.vertices) {
        let row = bands.row(v);
        for (s, &k) in idx.iter().enumerate() {
            mean[s] += av * row[k] as f64;
        }
    }
    mean.iter_mut().for_each(|x| *x /= total);
    let mut cov = vec![0.0; m * m];
    let mut c = vec![0.0; m];
    for (v, &av) in areas.iter().enumerate().take(bands.vertices) {
        let row = bands.row(v);
        for (s, &k) in idx.iter().enumerate() {
            c[s] = row[k] as f64 - mean[s];
        }
        for s in 0..m {
            let a = av * c[s];
            for t in s..m {
                cov[s * m + t] += a * c[t];
            }
        }
    }
    let mut out = Vec::with_capacity(m * (m - 1) / 2);
    for s in 0..m {
        for t in s + 1..m {
            let den = (cov[s * m + s] * cov[t * m + t]).sqrt();
            out.push(if den > 0.0 { cov[s * m + t] / den } else { 0.0 });
        }
    }
    out
}

fn summary_distance(a: &[f64], b: &[f64]) -> f64 {
    if a.is_empty() {
        return 0.0;
    }
    (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / a.len() as f64).sqrt()
}

impl ShapeGraph {
    /// Builds the graph over `nodes` (node `i` = `nodes[i]`). All shapes must share the band
    /// count `K` and the feature count `N`; edges pair features by identity with equal weights.
    ///
    /// - `n ≤ complete_limit`: the complete graph.
    /// - otherwise: each shape linked to its `neighbours` nearest shapes by
    ///   [`shape_summary`] distance (RMS difference of the summaries; ties by index), plus the
    ///   minimum spanning tree of the complete summary-distance graph (Prim from node 0, ties by
    ///   index), which keeps the graph connected.
    ///
    /// Edge weights are `1 / (1 + distance / median)` over the graph's edges. Edges are added in
    /// ascending `(i, j)` order, so the graph is deterministic.
    ///
    /// ```
    /// use coseg::bands::equal_count_bands;
    /// use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode, GraphKind};
    /// let t = equal_count_bands(&[0.0, 1.0, 2.0, 3.0], 1, 4, 2).unwrap();
    /// let nodes = (0..3).map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &[1.0; 4]).unwrap()).collect();
    /// let g = ShapeGraph::build(nodes, &GraphOptions::default()).unwrap();
    /// assert_eq!(g.kind(), GraphKind::Complete);
    /// assert_eq!(g.edge_count(), 3);
    /// ```
    pub fn build(nodes: Vec<ShapeNode>, options: &GraphOptions) -> Result<Self, GraphError> {
        check_nodes(&nodes)?;
        let n = nodes.len();
        let features = nodes.first().map_or(0, |f| f.bands.features);
        let summaries: Vec<Vec<f64>> = {
            use rayon::prelude::*;
            nodes
                .par_iter()
                .map(|s| shape_summary(&s.bands, &s.areas, options.summary_features))
                .collect()
        };
        let dist = |i: usize, j: usize| summary_distance(&summaries[i], &summaries[j]);
        let (kind, pairs): (GraphKind, BTreeSet<(usize, usize)>) = if n <= options.complete_limit {
            (
                GraphKind::Complete,
                (0..n)
                    .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
                    .collect(),
            )
        } else {
            let k = options.neighbours.max(1);
            let mut set = nearest_pairs(n, k, &dist);
            add_spanning_tree(n, &dist, &mut set);
            (GraphKind::Nearest(k), set)
        };
        let mut ds: Vec<f64> = pairs.iter().map(|&(i, j)| dist(i, j)).collect();
        ds.sort_by(f64::total_cmp);
        let median = if ds.is_empty() { 0.0 } else { ds[ds.len() / 2] };
        let mut graph = UnGraph::with_capacity(n, pairs.len());
        for node in nodes {
            graph.add_node(node);
        }
        for &(i, j) in &pairs {
            let d = dist(i, j);
            let weight = if median > 0.0 {
                1.0 / (1.0 + d / median)
            } else {
                1.0
            };
            graph.add_edge(
                NodeIndex::new(i),
                NodeIndex::new(j),
                ShapeEdge {
                    pairs: (0..features as u32).map(|k| (k, k)).collect(),
                    pair_weights: None,
                    distance: d,
                    weight,
                },
            );
        }
        Ok(Self {
            graph,
            kind,
            summaries,
        })
    }

    /// Summary distance between shapes `i` and `j` (RMS difference of their
    /// [`shape_summary`]s, as the edges' [`ShapeEdge::distance`]), whether or not an edge joins
    /// them.
    ///
    /// ```
    /// use coseg::bands::equal_count_bands;
    /// use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
    /// let t = equal_count_bands(&[0.0, 1.0, 2.0, 3.0, 0.5, 2.5, 1.5, 3.5], 2, 4, 2).unwrap();
    /// let nodes = (0..2).map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &[1.0; 4]).unwrap()).collect();
    /// let g = ShapeGraph::build(nodes, &GraphOptions::default()).unwrap();
    /// assert_eq!(g.summary_distance(0, 1), 0.0);
    /// assert_eq!(g.summary_distance(0, 1), g.edge(0, 1).unwrap().distance);
    /// ```
    pub fn summary_distance(&self, i: usize, j: usize) -> f64 {
        summary_distance(&self.summaries[i], &self.summaries[j])
    }

    /// Sets the weight of every feature pair on every edge (`None`: equal weights), e.g. a
    /// per-feature reliability. Weights must be finite, non-negative, not all zero, one per
    /// feature pair (checked when an operator is built).
    pub fn set_feature_weights(&mut self, weights: Option<Vec<f64>>) -> Result<(), GraphError> {
        if let Some(w) = &weights {
            let ok = w.iter().all(|x| x.is_finite() && *x >= 0.0) && w.iter().sum::<f64>() > 0.0;
            let len_ok = self.graph.edge_weights().all(|e| e.pairs.len() == w.len());
            if !ok || !len_ok {
                return Err(GraphError::BadOption(
                    "feature weights must be finite, non-negative, not all zero, one per pair"
                        .into(),
                ));
            }
        }
        for e in self.graph.edge_weights_mut() {
            e.pair_weights.clone_from(&weights);
        }
        Ok(())
    }

    /// The underlying petgraph (node `i` is shape `i`).
    pub fn graph(&self) -> &UnGraph<ShapeNode, ShapeEdge> {
        &self.graph
    }

    /// Complete or nearest-neighbour.
    pub fn kind(&self) -> GraphKind {
        self.kind
    }

    /// Number of shapes.
    pub fn node_count(&self) -> usize {
        self.graph.node_count()
    }

    /// Number of edges.
    pub fn edge_count(&self) -> usize {
        self.graph.edge_count()
    }

    /// Shape `i`.
    pub fn node(&self, i: usize) -> &ShapeNode {
        &self.graph[NodeIndex::new(i)]
    }

    /// The edge between `i` and `j`, if any.
    pub fn edge(&self, i: usize, j: usize) -> Option<&ShapeEdge> {
        self.graph
            .find_edge(NodeIndex::new(i), NodeIndex::new(j))
            .map(|e| &self.graph[e])
    }

    /// Every edge as `(i, j, edge)` with `i < j`, ascending.
    pub fn edges(&self) -> Vec<(usize, usize, &ShapeEdge)> {
        let mut out: Vec<(usize, usize, &ShapeEdge)> = self
            .graph
            .edge_references()
            .map(|e| {
                let (a, b) = (e.source().index(), e.target().index());
                (a.min(b), a.max(b), e.weight())
            })
            .collect();
        out.sort_by_key(|e| (e.0, e.1));
        out
    }

    /// Neighbours of `i`, ascending, with the edge to each.
    pub fn neighbours(&self, i: usize) -> Vec<(usize, &ShapeEdge)> {
        let mut out: Vec<(usize, &ShapeEdge)> = self
            .graph
            .edges(NodeIndex::new(i))
            .map(|e| {
                let other = if e.source().index() == i {
                    e.target().index()
                } else {
                    e.source().index()
                };
                (other, e.weight())
            })
            .collect();
        out.sort_by_key(|e| e.0);
        out
    }

    /// Whether every shape is reachable from shape 0.
    pub fn is_connected(&self) -> bool {
        petgraph::algo::connected_components(&self.graph) <= 1
    }

    /// The band-table operator of edge `{i, j}` and the direction that carries an indicator
    /// from shape `i` to shape `j` (`None` when there is no edge). The operator's A is the
    /// lower-index shape.
    pub fn affinity(
        &self,
        i: usize,
        j: usize,
    ) -> Option<Result<(BandAffinity<'_>, Direction), GraphError>> {
        let edge = self.edge(i, j)?;
        let (lo, hi) = (i.min(j), i.max(j));
        let dir = if i < j {
            Direction::AtoB
        } else {
            Direction::BtoA
        };
        Some(
            BandAffinity::with_pairing(&self.node(lo).bands, &self.node(hi).bands, &edge.pairing())
                .map(|w| (w, dir))
                .map_err(GraphError::from),
        )
    }
}

/// Rejects nodes whose band tables disagree with the first node's `K` and `N`, whose area
/// vector does not match the vertex count, or whose labels are not `vertices × features`
/// values below `K`.
fn check_nodes(nodes: &[ShapeNode]) -> Result<(), GraphError> {
    if let Some(first) = nodes.first() {
        for node in nodes {
            if node.bands.bands != first.bands.bands || node.bands.features != first.bands.features
            {
                return Err(GraphError::Incompatible {
                    name: node.name.clone(),
                    reason: format!(
                        "K = {}, N = {} but {} has K = {}, N = {}",
                        node.bands.bands,
                        node.bands.features,
                        first.name,
                        first.bands.bands,
                        first.bands.features
                    ),
                });
            }
            if node.areas.len() != node.bands.vertices {
                return Err(GraphError::Incompatible {
                    name: node.name.clone(),
                    reason: "area vector does not match the vertex count".into(),
                });
            }
            // Every stage indexes per-band tables by these labels; the graph owns its nodes
            // immutably, so one check here covers them all.
            let t = &node.bands;
            if t.labels.len() != t.vertices * t.features
                || t.labels.iter().any(|&l| l as usize >= t.bands)
            {
                return Err(GraphError::Incompatible {
                    name: node.name.clone(),
                    reason: format!(
                        "band table is not {} × {} labels below K = {}",
                        t.vertices, t.features, t.bands
                    ),
                });
            }
        }
    }
    Ok(())
}

/// The edges linking each of the `n` shapes to its `k` nearest by `dist` (ties by index), as
/// `(min, max)` pairs.
fn nearest_pairs(
    n: usize,
    k: usize,
    dist: &(impl Fn(usize, usize) -> f64 + Sync),
) -> BTreeSet<(usize, usize)> {
    use rayon::prelude::*;
    // Each shape's neighbours are found independently (in parallel) and merged in index
    // order: the set is the same whatever the thread count. A partial selection keeps the
    // `k` smallest `(distance, index)` without sorting all `n`.
    let nearest: Vec<Vec<usize>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut others: Vec<(f64, usize)> = (0..n)
                .filter(|&j| j != i)
                .map(|j| (dist(i, j), j))
                .collect();
            let order =
                |a: &(f64, usize), b: &(f64, usize)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
            if others.len() > k {
                others.select_nth_unstable_by(k, order);
                others.truncate(k);
            }
            others.sort_by(order);
            others.into_iter().map(|(_, j)| j).collect()
        })
        .collect();
    let mut set = BTreeSet::new();
    for (i, js) in nearest.into_iter().enumerate() {
        for j in js {
            set.insert((i.min(j), i.max(j)));
        }
    }
    set
}

/// Shapes per parallel task of Prim's distance update: one distance is a few hundred flops, so
/// smaller tasks would cost more in scheduling than they save.
const PRIM_CHUNK: usize = 256;

/// Adds to `set` the edges of the minimum spanning tree of the complete `dist` graph on `n`
/// shapes (Prim from node 0, ties by index).
fn add_spanning_tree(
    n: usize,
    dist: &(impl Fn(usize, usize) -> f64 + Sync),
    set: &mut BTreeSet<(usize, usize)>,
) {
    use rayon::prelude::*;
    // Prim's minimum spanning tree on the complete distance graph.
    let mut in_tree = vec![false; n];
    let mut best = vec![(f64::INFINITY, usize::MAX); n];
    in_tree[0] = true;
    for (j, b) in best.iter_mut().enumerate().skip(1) {
        *b = (dist(0, j), 0);
    }
    for _ in 1..n {
        let mut pick = usize::MAX;
        for j in 0..n {
            if !in_tree[j] && (pick == usize::MAX || best[j].0.total_cmp(&best[pick].0).is_lt()) {
                pick = j;
            }
        }
        in_tree[pick] = true;
        let p = best[pick].1;
        set.insert((p.min(pick), p.max(pick)));
        // Each entry is updated from its own distance alone: the same in parallel.
        best.par_iter_mut()
            .zip(in_tree.par_iter())
            .enumerate()
            .with_min_len(PRIM_CHUNK)
            .for_each(|(j, (b, &done))| {
                if !done {
                    let d = dist(pick, j);
                    if d.total_cmp(&b.0).is_lt() {
                        *b = (d, pick);
                    }
                }
            });
    }
}
