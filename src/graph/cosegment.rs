//! [`cosegment`]: consistent region tuples across every shape of a [`ShapeGraph`].
//!
//! # Design
//! A region tuple `(f_1, …, f_n)` (one indicator per shape) is *graph-stable* when every shape's
//! region is what its neighbours, transported onto it, select:
//!
//! `f_i = P_i( Σ_{j ~ i} w_ij · W_ij f_j / (N_ij |f_j|) )`  for every shape `i`,
//!
//! with `W_ij f_j` the raw band-match counts of the edge operator (so `W_ij f_j / (N_ij |f_j|)`
//! is, per vertex of `i`, the mean fraction of features whose bands agree with `f_j`'s vertices:
//! a score in `[0, 1]` whatever the region's size), `w_ij` the edge weight and `P_i` the area
//! rule `P_α` on the remaining vertices of shape `i` (`α` a fraction of the shape's total area,
//! so every region has the same size on every shape, as the paper's "10 % cutoff").
//!
//! This is the simultaneous update of docs/METHOD.md §5. We solve it by Gauss–Seidel sweeps in the
//! breadth-first order of a spanning tree rooted at the most central shape, always using the
//! newest regions, until a whole sweep changes nothing. Why this design rather than covering the
//! graph with cycles:
//! - On two shapes it *is* Algorithm 1 (after the start): shape 1 gets `P_1(W_10 f_0)`, shape 0
//!   gets `P_0(W_01 f_1)` — positive scalings of the scores do not change a threshold. On a
//!   3-cycle it is the cycle solver's update with every shape also hearing its other neighbour,
//!   i.e. the consistency that cycles sharing shapes must agree on is imposed directly.
//! - A fixed point is consistent everywhere at once; there is no choice of cycle basis and no
//!   reconciliation step where cycles overlap.
//! - One sweep costs a histogram update per changed region (`O(N)` per vertex entering or
//!   leaving it), one `N × K` mix per edge, and one gather over each shape's remaining vertices
//!   (`O(N d_i)`; in late sweeps only over the vertices whose score could cross the area
//!   cut-off, an exact pruning): it scales with the number of shapes, not with the number of
//!   cycles. Shapes whose neighbours did not change since their last update are skipped.
//! - The stop test is exact: when a sweep changes nothing, every `f_i` was recomputed from the
//!   final neighbours, so the tuple satisfies the equations above simultaneously
//!   ([`cosegment_update`] checks it). A guard as in Algorithm 1: a sweep cap and cycle
//!   detection (a tuple seen before); then the visited tuple of highest objective
//!   `Σ_i Σ_{q ∈ f_i} score_i(q)` is kept and reported as not converged.
//!
//! Start of each tuple: a seed on the root shape (by default its remaining vertex with the most
//! extreme band labels, `argmax_p Σ_k |2 band[k][p] − (K − 1)|`, a distinctive point such as a
//! limb tip; or a seeded random half of the remaining vertices, the paper's choice) is carried
//! along the spanning tree (`f_child = P_child(W f_parent)`), which gives every shape a start
//! consistent with the root's; the sweeps then settle the tuple.
//!
//! As Algorithms 2 and 3 do for pairs, each found tuple is removed from every shape and the next
//! is sought on the remainder; after `regions − 1` tuples, the leftovers form the last region.
//! Region `r` means the same part on every shape.
//!
//! Confidence of a tuple: the mean, over the spanning-tree edges in both directions, of the
//! area IoU between `f_i` and `P_p(W_ij f_j)` (the neighbour's region carried alone, keeping
//! as many vertices as `f_i` has); and separately the mean [`super::cycle_consistency`] IoU over a
//! deterministic sample of the graph's triangles.

use super::shape_graph::ShapeGraph;
use super::stable_cycle::{CycleShape, CycleStep};
use super::{GraphError, cycle_consistency};
use crate::affinity::BandAffinity;
use crate::affinity::kernel::row_sum;
use crate::stable::{Threshold, most_extreme_vertex, random_half, threshold};
use crate::vertex_sets::{intersect_sorted, remove_sorted};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// Options of [`cosegment`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct CosegmentOptions {
    /// Number of regions per shape, the last being the leftovers (default 6).
    pub regions: usize,
    /// Area of each extracted region as a fraction of its shape's total area (default `None`:
    /// `1 / regions`, so the leftovers are about as large as the others).
    pub area_fraction: Option<f64>,
    /// Root of the spanning tree (default `None`: the shape with the largest total edge weight,
    /// ties by lowest index).
    pub root: Option<usize>,
    /// Sweep cap per tuple (default 100).
    pub max_sweeps: usize,
    /// `None` (default): each tuple starts from the root's most extreme remaining vertex.
    /// `Some(s)`: from a random half of the root's remaining vertices (ChaCha8 seeded with `s`
    /// and the tuple index).
    pub seed: Option<u64>,
    /// Triangles of the graph sampled for each tuple's cycle consistency (default 8; 0 skips).
    pub triangles: usize,
}

impl Default for CosegmentOptions {
    fn default() -> Self {
        Self {
            regions: 6,
            area_fraction: None,
            root: None,
            max_sweeps: 100,
            seed: None,
            triangles: 8,
        }
    }
}

impl CosegmentOptions {
    /// The area fraction actually used.
    pub fn alpha(&self) -> f64 {
        self.area_fraction
            .unwrap_or(1.0 / self.regions.max(1) as f64)
    }
}

/// One region per shape, the same part on every shape.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RegionTuple {
    /// `regions[i]`: vertices of shape `i`, ascending.
    pub regions: Vec<Vec<u32>>,
    /// Area of each region over its shape's total area.
    pub area_fractions: Vec<f64>,
    /// Gauss–Seidel sweeps run (0 for the leftovers).
    pub sweeps: usize,
    /// Whether a sweep changed nothing (a fixed point); `true` for the leftovers.
    pub converged: bool,
    /// Whether the sweeps revisited a tuple (limit cycle).
    pub cycled: bool,
    /// `Σ_i Σ_{q ∈ f_i} score_i(q)` at the end (see the module docs).
    pub objective: f64,
    /// Mean area IoU between each region and its tree neighbour's region carried onto it
    /// (both directions of every spanning-tree edge), in `[0, 1]`.
    pub confidence: f64,
    /// Mean area IoU of the region carried around sampled triangles of the graph
    /// ([`super::cycle_consistency`], each step keeping as many vertices as the tuple's region
    /// on that shape); `None` when the graph has no triangle or none sampled.
    pub cycle_consistency: Option<f64>,
    /// `true` for the last tuple, made of the leftovers.
    pub leftover: bool,
}

impl RegionTuple {
    /// A tuple given from outside the solver (regions drawn or read, not co-segmented): no
    /// sweeps, a fixed point, objective 0, full confidence, no cycle measure, not the leftovers.
    ///
    /// ```
    /// let t = coseg::graph::RegionTuple::given(vec![vec![0, 1], vec![2]], vec![0.5, 0.25]);
    /// assert!(t.converged && !t.leftover && t.confidence == 1.0);
    /// ```
    pub fn given(regions: Vec<Vec<u32>>, area_fractions: Vec<f64>) -> Self {
        Self {
            regions,
            area_fractions,
            sweeps: 0,
            converged: true,
            cycled: false,
            objective: 0.0,
            confidence: 1.0,
            cycle_consistency: None,
            leftover: false,
        }
    }
}

/// The co-segmentation of a collection.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Cosegmentation {
    /// Shape names, in graph order.
    pub names: Vec<String>,
    /// Vertex count of each shape.
    pub vertices: Vec<usize>,
    /// Root of the spanning tree.
    pub root: usize,
    /// Breadth-first order of the sweeps (starts with the root).
    pub order: Vec<usize>,
    /// Spanning-tree parent of each shape (`None` for the root).
    pub parent: Vec<Option<usize>>,
    /// The area fraction used per region.
    pub alpha: f64,
    /// The region tuples in extraction order; tuple `r` is region id `r` on every shape.
    pub tuples: Vec<RegionTuple>,
}

impl Cosegmentation {
    /// Whether `meshes` are this co-segmentation's shapes: one per shape, in graph order, each
    /// with the shape's vertex count (what its regions index).
    pub fn matches(&self, meshes: &[crate::mesh::TriMesh]) -> bool {
        meshes.len() == self.names.len()
            && meshes
                .iter()
                .zip(&self.vertices)
                .all(|(m, &d)| m.vertex_count() == d)
    }

    /// Region id of every vertex of shape `i` (`-1` for a vertex in no region, which does not
    /// happen once the leftovers are assigned).
    pub fn labels(&self, i: usize) -> Vec<i32> {
        let mut out = vec![-1; self.vertices[i]];
        for (r, t) in self.tuples.iter().enumerate() {
            for &v in &t.regions[i] {
                out[v as usize] = r as i32;
            }
        }
        out
    }

    /// The vertices of shape `i` still remaining when tuple `r` was extracted (all vertices
    /// minus the regions of tuples `0..r`), ascending.
    pub fn remaining_before(&self, r: usize, i: usize) -> Vec<u32> {
        let mut taken = vec![false; self.vertices[i]];
        for t in &self.tuples[..r.min(self.tuples.len())] {
            for &v in &t.regions[i] {
                taken[v as usize] = true;
            }
        }
        (0..self.vertices[i] as u32)
            .filter(|&v| !taken[v as usize])
            .collect()
    }
}

/// Per-shape histograms and score tables: the engine of the sweeps (also of
/// [`super::refine_cosegmentation`], one engine per region).
pub(crate) struct Engine<'g> {
    graph: &'g ShapeGraph,
    bands: usize,
    /// `neighbours[i]`: `(j, edge weight, pairs as (k on j, k on i), raw pair weights)`.
    neighbours: Vec<Vec<Neighbour>>,
    /// Histogram of the current region of each shape (`N × K` counts).
    hist: Vec<Vec<f64>>,
    /// Size of the current region of each shape.
    size: Vec<usize>,
    /// The current region of each shape (ascending).
    current: Vec<Vec<u32>>,
    /// The mixed per-(feature, band) scores of the shape being updated, in `f32`: the gather
    /// reads one entry per (vertex, feature), and the smaller table stays in L1.
    table: Vec<f32>,
    scratch: crate::stable::ThresholdScratch,
}

struct Neighbour {
    j: usize,
    weight: f64,
    pairs: Vec<(usize, usize)>,
    raw: Vec<f64>,
}

impl<'g> Engine<'g> {
    pub(crate) fn new(graph: &'g ShapeGraph) -> Self {
        let n = graph.node_count();
        let bands = graph.node(0).bands.bands;
        let neighbours = (0..n)
            .map(|i| {
                graph
                    .neighbours(i)
                    .into_iter()
                    .map(|(j, e)| {
                        let np = e.pairs.len() as f64;
                        let raw = match &e.pair_weights {
                            Some(w) => {
                                let s: f64 = w.iter().sum();
                                w.iter().map(|x| x / s * np).collect()
                            }
                            None => vec![1.0; e.pairs.len()],
                        };
                        let pairs = e
                            .pairs
                            .iter()
                            .map(|&(lo, hi)| {
                                if j < i {
                                    (lo as usize, hi as usize)
                                } else {
                                    (hi as usize, lo as usize)
                                }
                            })
                            .collect();
                        Neighbour {
                            j,
                            weight: e.weight,
                            pairs,
                            raw,
                        }
                    })
                    .collect()
            })
            .collect();
        let hist = (0..n)
            .map(|i| vec![0.0; graph.node(i).bands.features * bands])
            .collect();
        Self {
            graph,
            bands,
            neighbours,
            hist,
            size: vec![0; n],
            current: vec![Vec::new(); n],
            table: Vec::new(),
            scratch: Default::default(),
        }
    }

    /// Makes `region` (strictly ascending) shape `i`'s current region. The histogram is
    /// updated by the vertices that enter or leave (counts are exact integers, so this equals a
    /// rebuild), which in late sweeps are a few boundary vertices.
    pub(crate) fn set_region(&mut self, i: usize, region: &[u32]) {
        let t = &self.graph.node(i).bands;
        let k = self.bands;
        let h = &mut self.hist[i];
        let mut add = |p: u32, delta: f64| {
            for (f, &l) in t.row(p as usize).iter().enumerate() {
                h[f * k + l as usize] += delta;
            }
        };
        let old = &self.current[i];
        debug_assert!(old.is_empty() || region.windows(2).all(|w| w[0] < w[1]));
        let (mut a, mut b) = (0, 0);
        while a < old.len() || b < region.len() {
            match (old.get(a), region.get(b)) {
                (Some(&x), Some(&y)) if x == y => {
                    a += 1;
                    b += 1;
                }
                (Some(&x), Some(&y)) if x < y => {
                    add(x, -1.0);
                    a += 1;
                }
                (Some(&x), None) => {
                    add(x, -1.0);
                    a += 1;
                }
                (_, Some(&y)) => {
                    add(y, 1.0);
                    b += 1;
                }
                (None, None) => unreachable!("loop condition"),
            }
        }
        self.current[i].clear();
        self.current[i].extend_from_slice(region);
        self.size[i] = region.len();
    }

    /// Scores on the remaining vertices of `i` from the current regions of `sources` (all
    /// neighbours when `None`).
    pub(crate) fn scores(
        &mut self,
        i: usize,
        sources: Option<&[usize]>,
        rem: &[u32],
        out: &mut Vec<f64>,
    ) {
        self.mix(i, sources);
        self.gather(i, rem, out);
    }

    /// Builds `table` for shape `i`: the per-(feature, band) score contributions of the current
    /// regions of `sources` (all neighbours when `None`).
    fn mix(&mut self, i: usize, sources: Option<&[usize]>) {
        let t = &self.graph.node(i).bands;
        let k = self.bands;
        self.table.clear();
        self.table.resize(t.features * k, 0.0);
        for nb in &self.neighbours[i] {
            if sources.is_some_and(|s| !s.contains(&nb.j)) || self.size[nb.j] == 0 {
                continue;
            }
            let c = nb.weight / (nb.pairs.len() as f64 * self.size[nb.j] as f64);
            let h = &self.hist[nb.j];
            for (&(ka, kb), &r) in nb.pairs.iter().zip(&nb.raw) {
                let cr = c * r;
                for (dst, &src) in self.table[kb * k..(kb + 1) * k]
                    .iter_mut()
                    .zip(&h[ka * k..(ka + 1) * k])
                {
                    *dst += (cr * src) as f32;
                }
            }
        }
    }

    /// Scores of the vertices `list` of shape `i` from the current `table`.
    fn gather(&self, i: usize, list: &[u32], out: &mut Vec<f64>) {
        let t = &self.graph.node(i).bands;
        let k = self.bands;
        out.clear();
        out.resize(list.len(), 0.0);
        let table = &self.table;
        out.par_chunks_mut(512)
            .zip(list.par_chunks(512))
            .for_each(|(o, idx)| {
                for (s, &q) in o.iter_mut().zip(idx) {
                    *s = f64::from(row_sum(table, t.row(q as usize), k));
                }
            });
    }

    /// `Σ_{q ∈ f_i} score_i(q)` for shape `i`'s current region, from `table` and the region's
    /// histogram (scores are linear in the table): `Σ_{f, b} table[f, b] · hist_i[f, b]`.
    fn region_objective(&self, i: usize) -> f64 {
        self.table
            .iter()
            .zip(&self.hist[i])
            .map(|(&t, &h)| f64::from(t) * h)
            .sum()
    }

    /// `P_α(scores)` on `rem` of shape `i`.
    fn select(&mut self, i: usize, rem: &[u32], scores: &[f64], alpha: f64, out: &mut Vec<u32>) {
        threshold(
            Threshold::AreaFraction(alpha),
            rem,
            scores,
            &self.graph.node(i).areas,
            1.0,
            out,
            &mut self.scratch,
        );
    }
}

/// Exact pruning of the gather in late sweeps.
///
/// For each shape, a reference: the mixed table `T_ref`, the scores `s_ref` of every remaining
/// vertex under it, and the score `θ_ref` of the last vertex `P_α` selected. Scores are linear
/// in the table, so under the current table `T` every score is within
/// `B = Σ_f max_b |T[f, b] − T_ref[f, b]|` of its reference, and the new cut-off score of `P_α`
/// is within `B` of `θ_ref` (the sets above any level move by at most `B`). Hence a vertex with
/// `s_ref > θ_ref + 2B` is selected and one with `s_ref < θ_ref − 2B` is not, whatever their
/// exact new scores; only the vertices in between need a gather. `P_α` on those candidates
/// (with the sure ones ranked first) selects the same vertices as on all of them, since sure
/// vertices lie strictly above the new cut-off and ties at the cut-off are all candidates.
/// When the candidates are more than half of the remaining vertices, a full gather is cheaper:
/// it runs and becomes the new reference. A margin covers the `f32` rounding of the gather.
struct Pruning {
    refs: Vec<Option<Reference>>,
    list: Vec<u32>,
    keys: Vec<f64>,
    candidates: Vec<u32>,
    exact: Vec<f64>,
}

struct Reference {
    table: Vec<f32>,
    scores: Vec<f64>,
    cutoff: f64,
}

impl Pruning {
    fn new(n: usize) -> Self {
        Self {
            refs: (0..n).map(|_| None).collect(),
            list: Vec::new(),
            keys: Vec::new(),
            candidates: Vec::new(),
            exact: Vec::new(),
        }
    }

    /// Makes the engine's current table and the full `scores` on `rem` shape `i`'s reference,
    /// `selected` being `P_α` of them.
    fn reset(
        &mut self,
        eng: &Engine<'_>,
        i: usize,
        rem: &[u32],
        scores: &[f64],
        selected: &[u32],
        alpha: f64,
    ) {
        let areas = &eng.graph.node(i).areas;
        let area: f64 = selected.iter().map(|&v| areas[v as usize]).sum();
        // Without a cut-off (everything selected, or nothing), there is nothing to prune by.
        if selected.is_empty() || selected.len() == rem.len() || area < alpha {
            self.refs[i] = None;
            return;
        }
        let mut cutoff = f64::INFINITY;
        let mut j = 0;
        for (&v, &s) in rem.iter().zip(scores) {
            if j < selected.len() && selected[j] == v {
                cutoff = cutoff.min(s);
                j += 1;
            }
        }
        self.refs[i] = Some(Reference {
            table: eng.table.clone(),
            scores: scores.to_vec(),
            cutoff,
        });
    }

    /// `P_α` on `rem` of shape `i` under the engine's current table, into `out`, by the pruned
    /// gather; `false` (and `out` unspecified) when it does not apply and a full gather is due.
    fn select(
        &mut self,
        eng: &mut Engine<'_>,
        i: usize,
        rem: &[u32],
        alpha: f64,
        out: &mut Vec<u32>,
    ) -> bool {
        let Some(r) = &self.refs[i] else {
            return false;
        };
        let k = eng.bands;
        let bound: f64 = eng
            .table
            .chunks_exact(k)
            .zip(r.table.chunks_exact(k))
            .map(|(a, b)| {
                a.iter()
                    .zip(b)
                    .map(|(&x, &y)| (f64::from(x) - f64::from(y)).abs())
                    .fold(0.0, f64::max)
            })
            .sum();
        // Gathered scores are sums of ~N non-negative f32 terms: their rounding error is below
        // N · 2⁻²⁴ · score, far inside the relative 1e-3 added here.
        let margin = 2.0 * bound + 1e-3 * (r.cutoff.abs() + bound) + 1e-9;
        let (hi, lo) = (r.cutoff + margin, r.cutoff - margin);
        self.list.clear();
        self.keys.clear();
        self.candidates.clear();
        for (&v, &s) in rem.iter().zip(&r.scores) {
            if s >= lo && s <= hi {
                self.candidates.push(v);
            }
        }
        if 2 * self.candidates.len() > rem.len() {
            return false;
        }
        let mut exact = std::mem::take(&mut self.exact);
        eng.gather(i, &self.candidates, &mut exact);
        let r = self.refs[i].as_ref().expect("checked above");
        let mut c = 0;
        for (&v, &s) in rem.iter().zip(&r.scores) {
            if s > hi {
                self.list.push(v);
                self.keys.push(f64::INFINITY);
            } else if s >= lo {
                debug_assert_eq!(self.candidates[c], v);
                self.list.push(v);
                self.keys.push(exact[c]);
                c += 1;
            }
        }
        self.exact = exact;
        eng.select(i, &self.list, &self.keys, alpha, out);
        // Safety net: if the sure and candidate vertices do not reach the area, the bound did
        // not hold (it cannot, up to rounding); let the full gather decide.
        let areas = &eng.graph.node(i).areas;
        let area: f64 = out.iter().map(|&v| areas[v as usize]).sum();
        area >= alpha && out.len() < self.list.len()
    }
}

fn check(graph: &ShapeGraph, options: &CosegmentOptions) -> Result<(), GraphError> {
    check_extraction(graph, options.root, options.max_sweeps)?;
    if options.regions == 0 {
        return Err(GraphError::BadOption("regions must be at least 1".into()));
    }
    let a = options.alpha();
    if !(a.is_finite() && a > 0.0 && a <= 1.0) {
        return Err(GraphError::BadOption(format!(
            "area fraction {a} must be in (0, 1]"
        )));
    }
    Ok(())
}

/// What every extraction of tuples needs of its graph and options (this one's [`cosegment`]
/// and the adaptive one of `parts`): two shapes or more, a connected graph, a sweep, a root
/// among the shapes and no shape without vertices.
pub(crate) fn check_extraction(
    graph: &ShapeGraph,
    root: Option<usize>,
    max_sweeps: usize,
) -> Result<(), GraphError> {
    let n = graph.node_count();
    if n < 2 {
        return Err(GraphError::BadOption(format!(
            "co-segmentation needs at least 2 shapes, got {n}"
        )));
    }
    if !graph.is_connected() {
        return Err(GraphError::BadOption(
            "the shape graph is not connected".into(),
        ));
    }
    if max_sweeps == 0 {
        return Err(GraphError::BadOption(
            "max_sweeps must be at least 1".into(),
        ));
    }
    if root.is_some_and(|r| r >= n) {
        return Err(GraphError::BadOption(format!(
            "root {} out of range ({n} shapes)",
            root.unwrap_or(0)
        )));
    }
    for i in 0..n {
        if graph.node(i).bands.vertices == 0 {
            return Err(GraphError::Incompatible {
                name: graph.node(i).name.clone(),
                reason: "no vertices".into(),
            });
        }
    }
    Ok(())
}

/// The state one extraction of tuples carries from the first tuple to the leftovers (of
/// [`cosegment`] and of the adaptive extraction of `parts`): the spanning tree, the vertices of
/// each shape not yet in a tuple, and the sampled triangles with their operators (built once).
pub(crate) struct Extraction<'g> {
    /// Root of the spanning tree.
    pub(crate) root: usize,
    /// Breadth-first order (root first).
    pub(crate) order: Vec<usize>,
    /// Spanning-tree parent of each shape.
    pub(crate) parent: Vec<Option<usize>>,
    /// The vertices of each shape in no tuple yet, ascending.
    pub(crate) rem: Vec<Vec<u32>>,
    triangles: Vec<[usize; 3]>,
    tri_ops: TriangleOps<'g>,
}

impl<'g> Extraction<'g> {
    /// Every vertex remaining, the spanning tree from `root` (or the best-connected shape) and
    /// `triangles` sampled triangles.
    pub(crate) fn start(
        graph: &'g ShapeGraph,
        root: Option<usize>,
        triangles: usize,
    ) -> Result<Self, GraphError> {
        let (root, order, parent) = spanning_tree(graph, root);
        let rem = (0..graph.node_count())
            .map(|i| (0..graph.node(i).bands.vertices as u32).collect())
            .collect();
        let triangles = sample_triangles(graph, triangles);
        let tri_ops = triangle_ops(graph, &triangles)?;
        Ok(Self {
            root,
            order,
            parent,
            rem,
            triangles,
            tri_ops,
        })
    }

    /// Tree-edge agreement and triangle cycle consistency of `tuple` on what remains (the
    /// engine's histograms hold the tuple's regions); see [`confidence`].
    pub(crate) fn confidence(
        &self,
        graph: &ShapeGraph,
        eng: &mut Engine<'_>,
        tuple: &[Vec<u32>],
    ) -> (f64, Option<f64>) {
        confidence(
            graph,
            eng,
            &self.parent,
            &self.tri_ops,
            &self.triangles,
            &self.rem,
            tuple,
        )
    }

    /// Takes `tuple`'s regions out of what remains.
    pub(crate) fn take(&mut self, tuple: &[Vec<u32>]) {
        for (i, region) in tuple.iter().enumerate() {
            remove_sorted(&mut self.rem[i], region);
        }
    }

    /// Appends the leftover tuple (every shape's remaining vertices, loaded into `eng`, with
    /// its confidences) when a vertex remains or no tuple was extracted.
    pub(crate) fn push_leftovers(
        &self,
        graph: &ShapeGraph,
        eng: &mut Engine<'_>,
        tuples: &mut Vec<RegionTuple>,
    ) {
        if self.rem.iter().any(|r| !r.is_empty()) || tuples.is_empty() {
            let tuple = self.rem.clone();
            for (i, region) in tuple.iter().enumerate() {
                eng.set_region(i, region);
            }
            let (confidence, cyc) = self.confidence(graph, eng, &tuple);
            tuples.push(leftovers_tuple(graph, tuple, confidence, cyc));
        }
    }

    /// The co-segmentation of `tuples` extracted with area fraction `alpha`.
    pub(crate) fn finish(
        self,
        graph: &ShapeGraph,
        alpha: f64,
        tuples: Vec<RegionTuple>,
    ) -> Cosegmentation {
        let n = graph.node_count();
        Cosegmentation {
            names: (0..n).map(|i| graph.node(i).name.clone()).collect(),
            vertices: (0..n).map(|i| graph.node(i).bands.vertices).collect(),
            root: self.root,
            order: self.order,
            parent: self.parent,
            alpha,
            tuples,
        }
    }
}

/// Root and breadth-first spanning tree of the graph.
pub(crate) fn spanning_tree(
    graph: &ShapeGraph,
    root: Option<usize>,
) -> (usize, Vec<usize>, Vec<Option<usize>>) {
    let n = graph.node_count();
    let root = root.unwrap_or_else(|| {
        let mut best = (f64::NEG_INFINITY, 0);
        for i in 0..n {
            let w: f64 = graph.neighbours(i).iter().map(|(_, e)| e.weight).sum();
            if w > best.0 {
                best = (w, i);
            }
        }
        best.1
    });
    let mut parent = vec![None; n];
    let mut seen = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut queue = VecDeque::from([root]);
    seen[root] = true;
    while let Some(i) = queue.pop_front() {
        order.push(i);
        for (j, _) in graph.neighbours(i) {
            if !seen[j] {
                seen[j] = true;
                parent[j] = Some(i);
                queue.push_back(j);
            }
        }
    }
    (root, order, parent)
}

pub(crate) fn seed_region(
    graph: &ShapeGraph,
    root: usize,
    rem: &[u32],
    seed: Option<u64>,
    index: usize,
) -> Vec<u32> {
    match seed {
        None => most_extreme_vertex(&graph.node(root).bands, rem)
            .map(|p| vec![p])
            .unwrap_or_default(),
        Some(s) => random_half(rem, s, index),
    }
}

/// The last tuple: the leftover vertices of every shape, with their confidences.
fn leftovers_tuple(
    graph: &ShapeGraph,
    regions: Vec<Vec<u32>>,
    confidence: f64,
    cycle_consistency: Option<f64>,
) -> RegionTuple {
    RegionTuple {
        area_fractions: area_fractions(graph, &regions),
        regions,
        sweeps: 0,
        converged: true,
        cycled: false,
        objective: 0.0,
        confidence,
        cycle_consistency,
        leftover: true,
    }
}

/// The area fraction of each shape's region of `tuple` (shapes have unit area).
pub(crate) fn area_fractions(graph: &ShapeGraph, tuple: &[Vec<u32>]) -> Vec<f64> {
    tuple
        .iter()
        .enumerate()
        .map(|(i, t)| area(&graph.node(i).areas, t))
        .collect()
}

pub(crate) fn area(areas: &[f64], v: &[u32]) -> f64 {
    v.iter().map(|&p| areas[p as usize]).sum()
}

pub(crate) fn iou(areas: &[f64], a: &[u32], b: &[u32]) -> f64 {
    let mut inter = Vec::new();
    intersect_sorted(a, b, &mut inter);
    let i = area(areas, &inter);
    let u = area(areas, a) + area(areas, b) - i;
    if u > 0.0 { i / u } else { 1.0 }
}

pub(crate) fn tuple_hash(tuple: &[Vec<u32>]) -> [u8; 32] {
    let mut h = blake3::Hasher::new();
    for r in tuple {
        h.update(&(r.len() as u64).to_le_bytes());
        for v in r {
            h.update(&v.to_le_bytes());
        }
    }
    *h.finalize().as_bytes()
}

/// The triangles `(i < j < k)` of the graph, a deterministic evenly spaced sample of `count`.
pub(crate) fn sample_triangles(graph: &ShapeGraph, count: usize) -> Vec<[usize; 3]> {
    if count == 0 {
        return Vec::new();
    }
    let n = graph.node_count();
    let mut all = Vec::new();
    for i in 0..n {
        let ni: Vec<usize> = graph
            .neighbours(i)
            .iter()
            .map(|x| x.0)
            .filter(|&j| j > i)
            .collect();
        for (a, &j) in ni.iter().enumerate() {
            for &k in &ni[a + 1..] {
                if graph.edge(j, k).is_some() {
                    all.push([i, j, k]);
                }
            }
        }
    }
    if all.len() <= count {
        return all;
    }
    (0..count).map(|t| all[t * all.len() / count]).collect()
}

/// One simultaneous (Jacobi) application of the update to `tuple`:
/// `out_i = P_α(Σ_j w_ij W_ij f_j / (N_ij |f_j|))` on `remaining[i]` for every shape, with
/// `α = options.alpha()`. A converged tuple of [`cosegment`] (given the remaining sets it was
/// found on, [`Cosegmentation::remaining_before`]) is returned unchanged.
pub fn cosegment_update(
    graph: &ShapeGraph,
    remaining: &[Vec<u32>],
    tuple: &[Vec<u32>],
    options: &CosegmentOptions,
) -> Result<Vec<Vec<u32>>, GraphError> {
    check(graph, options)?;
    let n = graph.node_count();
    if remaining.len() != n || tuple.len() != n {
        return Err(GraphError::BadOption(format!(
            "{n} shapes but {} remaining sets and {} regions",
            remaining.len(),
            tuple.len()
        )));
    }
    let mut eng = Engine::new(graph);
    for (i, r) in tuple.iter().enumerate() {
        eng.set_region(i, r);
    }
    let mut scores = Vec::new();
    let mut out = Vec::with_capacity(n);
    for (i, rem) in remaining.iter().enumerate() {
        eng.scores(i, None, rem, &mut scores);
        let mut f = Vec::new();
        eng.select(i, rem, &scores, options.alpha(), &mut f);
        out.push(f);
    }
    Ok(out)
}

/// Co-segments every shape of `graph` into `options.regions` corresponding regions (see the
/// module docs for the algorithm). Deterministic: same graph and options, identical output.
///
/// ```
/// use coseg::bands::equal_count_bands;
/// use coseg::graph::{cosegment, CosegmentOptions, GraphOptions, ShapeGraph, ShapeNode};
/// let vals: Vec<f64> = (0..12).map(|v| v as f64).collect();
/// let t = equal_count_bands(&vals, 1, 12, 3).unwrap();
/// let nodes = (0..3).map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &[1.0; 12]).unwrap()).collect();
/// let g = ShapeGraph::build(nodes, &GraphOptions::default()).unwrap();
/// let mut options = CosegmentOptions::default();
/// options.regions = 3;
/// let c = cosegment(&g, &options).unwrap();
/// // Identical shapes: identical labels.
/// assert_eq!(c.labels(0), c.labels(1));
/// assert_eq!(c.labels(0), c.labels(2));
/// ```
pub fn cosegment(
    graph: &ShapeGraph,
    options: &CosegmentOptions,
) -> Result<Cosegmentation, GraphError> {
    check(graph, options)?;
    let alpha = options.alpha();
    let mut x = Extraction::start(graph, options.root, options.triangles)?;
    let mut eng = Engine::new(graph);
    let mut tuples = Vec::with_capacity(options.regions);
    let mut scratch = Scratch::default();
    for r in 0..options.regions.saturating_sub(1) {
        if x.rem.iter().any(Vec::is_empty) {
            break;
        }
        let seed = seed_region(graph, x.root, &x.rem[x.root], options.seed, r);
        let tree = Tree {
            root: x.root,
            order: &x.order,
            parent: &x.parent,
        };
        let mut tuple = grow_tuple(&mut eng, &tree, seed, &x.rem, alpha, &mut scratch);
        let SweepOutcome {
            sweeps,
            converged,
            cycled,
            objective,
        } = sweep_tuple(
            &mut eng,
            &x.order,
            &x.rem,
            &mut tuple,
            alpha,
            options.max_sweeps,
            &mut scratch,
        );
        let (confidence, cyc) = x.confidence(graph, &mut eng, &tuple);
        x.take(&tuple);
        tuples.push(RegionTuple {
            area_fractions: area_fractions(graph, &tuple),
            regions: tuple,
            sweeps,
            converged,
            cycled,
            objective,
            confidence,
            cycle_consistency: cyc,
            leftover: false,
        });
    }
    x.push_leftovers(graph, &mut eng, &mut tuples);
    Ok(x.finish(graph, alpha, tuples))
}

/// The spanning tree a tuple grows along: its root, the visiting order (root first) and each
/// shape's parent.
struct Tree<'a> {
    root: usize,
    order: &'a [usize],
    parent: &'a [Option<usize>],
}

/// Buffers reused across shapes and tuples: the scores of the candidate vertices and the
/// selected region.
#[derive(Default)]
struct Scratch {
    scores: Vec<f64>,
    f: Vec<u32>,
}

/// How the block-coordinate sweeps of one tuple ended.
struct SweepOutcome {
    sweeps: usize,
    converged: bool,
    cycled: bool,
    objective: f64,
}

/// The band-affinity operators of the three edges of each sampled triangle, per triangle.
pub(crate) type TriangleOps<'g> = Vec<Vec<(BandAffinity<'g>, crate::affinity::Direction)>>;

/// The band-affinity operators of the three edges of each sampled triangle.
pub(crate) fn triangle_ops<'g>(
    graph: &'g ShapeGraph,
    triangles: &[[usize; 3]],
) -> Result<TriangleOps<'g>, GraphError> {
    let mut tri_ops = Vec::with_capacity(triangles.len());
    for t in triangles {
        let mut ops = Vec::with_capacity(3);
        for s in 0..3 {
            let (a, b) = (t[s], t[(s + 1) % 3]);
            let op = graph
                .affinity(a, b)
                .ok_or_else(|| GraphError::BadOption("triangle edge missing".into()))??;
            ops.push(op);
        }
        tri_ops.push(ops);
    }
    Ok(tri_ops)
}

/// The initial tuple: the root's `seed` region, then each other shape's region selected from
/// its parent's alone, in tree order (the engine's histograms end holding the tuple).
fn grow_tuple(
    eng: &mut Engine<'_>,
    tree: &Tree<'_>,
    seed: Vec<u32>,
    rem: &[Vec<u32>],
    alpha: f64,
    scratch: &mut Scratch,
) -> Vec<Vec<u32>> {
    let mut tuple: Vec<Vec<u32>> = vec![Vec::new(); rem.len()];
    for i in 0..rem.len() {
        eng.set_region(i, &[]);
    }
    tuple[tree.root] = seed;
    eng.set_region(tree.root, &tuple[tree.root]);
    for &c in &tree.order[1..] {
        let p = tree.parent[c].expect("non-root has a parent");
        eng.scores(c, Some(&[p]), &rem[c], &mut scratch.scores);
        eng.select(c, &rem[c], &scratch.scores, alpha, &mut scratch.f);
        tuple[c].clone_from(&scratch.f);
        eng.set_region(c, &scratch.f);
    }
    tuple
}

/// Block-coordinate sweeps over all shapes in tree order until no region changes, a tuple
/// repeats or `max_sweeps` is reached; without convergence the best tuple seen is restored
/// (into `tuple` and the engine).
fn sweep_tuple(
    eng: &mut Engine<'_>,
    order: &[usize],
    rem: &[Vec<u32>],
    tuple: &mut Vec<Vec<u32>>,
    alpha: f64,
    max_sweeps: usize,
    scratch: &mut Scratch,
) -> SweepOutcome {
    let n = rem.len();
    let mut seen = vec![tuple_hash(tuple)];
    let mut best: Option<(f64, Vec<Vec<u32>>)> = None;
    let (mut sweeps, mut converged, mut cycled, mut objective) = (0, false, false, 0.0);
    // A shape whose neighbours' regions have not changed since its last update would get
    // the same scores and the same region again: skip it, reusing its objective term.
    // `changed_at[j]` / `updated_at[i]` are ticks of one clock that advances on every
    // update, so the skip is exact and the result identical to recomputing everything.
    let mut clock = 1usize;
    let mut changed_at = vec![clock; n];
    let mut updated_at = vec![0usize; n];
    let mut term = vec![0.0; n];
    let mut prune = Pruning::new(n);
    while sweeps < max_sweeps {
        sweeps += 1;
        let mut changed = false;
        objective = 0.0;
        for &i in order {
            let stale = eng.neighbours[i]
                .iter()
                .any(|nb| changed_at[nb.j] >= updated_at[i]);
            if stale {
                clock += 1;
                updated_at[i] = clock;
                eng.mix(i, None);
                if !prune.select(eng, i, &rem[i], alpha, &mut scratch.f) {
                    eng.gather(i, &rem[i], &mut scratch.scores);
                    eng.select(i, &rem[i], &scratch.scores, alpha, &mut scratch.f);
                    prune.reset(eng, i, &rem[i], &scratch.scores, &scratch.f, alpha);
                }
                if scratch.f != tuple[i] {
                    changed = true;
                    changed_at[i] = clock;
                    tuple[i].clone_from(&scratch.f);
                    eng.set_region(i, &scratch.f);
                }
                term[i] = eng.region_objective(i);
            }
            objective += term[i];
        }
        if !changed {
            converged = true;
            break;
        }
        if best.as_ref().is_none_or(|b| objective > b.0) {
            best = Some((objective, tuple.clone()));
        }
        let h = tuple_hash(tuple);
        if seen.contains(&h) {
            cycled = true;
            break;
        }
        seen.push(h);
    }
    if !converged && let Some((o, t)) = best {
        objective = o;
        *tuple = t;
        for (i, region) in tuple.iter().enumerate() {
            eng.set_region(i, region);
        }
    }
    SweepOutcome {
        sweeps,
        converged,
        cycled,
        objective,
    }
}

/// Tree-edge agreement and triangle cycle consistency of a tuple (the engine's histograms hold
/// the tuple's regions).
pub(crate) fn confidence(
    graph: &ShapeGraph,
    eng: &mut Engine<'_>,
    parent: &[Option<usize>],
    tri_ops: &[Vec<(BandAffinity<'_>, crate::affinity::Direction)>],
    triangles: &[[usize; 3]],
    rem: &[Vec<u32>],
    tuple: &[Vec<u32>],
) -> (f64, Option<f64>) {
    let mut scores = Vec::new();
    let mut carried = Vec::new();
    let (mut sum, mut count) = (0.0, 0usize);
    for (c, p) in parent.iter().enumerate() {
        let Some(p) = *p else { continue };
        for (dst, src) in [(c, p), (p, c)] {
            let areas = &graph.node(dst).areas;
            eng.scores(dst, Some(&[src]), &rem[dst], &mut scores);
            threshold(
                Threshold::Count(tuple[dst].len()),
                &rem[dst],
                &scores,
                areas,
                1.0,
                &mut carried,
                &mut eng.scratch,
            );
            sum += iou(areas, &tuple[dst], &carried);
            count += 1;
        }
    }
    let conf = if count > 0 { sum / count as f64 } else { 1.0 };
    if triangles.is_empty() {
        return (conf, None);
    }
    let mut total = 0.0;
    for (t, ops) in triangles.iter().zip(tri_ops) {
        let shapes: Vec<CycleShape<'_>> = t
            .iter()
            .map(|&i| {
                let areas = &graph.node(i).areas;
                CycleShape {
                    remaining: &rem[i],
                    areas,
                    reference_area: 1.0,
                    rule: Threshold::Count(tuple[i].len()),
                }
            })
            .collect();
        let steps: Vec<CycleStep<'_, '_>> = ops
            .iter()
            .map(|(w, d)| CycleStep {
                affinity: w,
                direction: *d,
            })
            .collect();
        total += cycle_consistency(&shapes, &steps, &tuple[t[0]])
            .map(|c| c.iou)
            .unwrap_or(0.0);
    }
    (conf, Some(total / triangles.len() as f64))
}
