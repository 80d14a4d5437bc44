//! [`adaptive_cosegment`]: co-segmentation into parts of their own size — the paper's
//! Algorithm 3 (automatic thresholds) across a whole shape graph, the number of parts from the
//! data, and a coarse-to-fine tree of the parts found.
//!
//! # Tuples of their own size
//! [`cosegment`](crate::graph::cosegment) cuts every region at the same area `α` (Algorithm 2's fixed
//! cutoff). Here each tuple is found as Algorithm 3 finds a pair, with the graph update of
//! [`cosegment`](crate::graph::cosegment) (`f_i = P_i(Σ_j w_ij W_ij f_j / (N_ij |f_j|))`, Gauss–Seidel
//! sweeps in the spanning tree's breadth-first order until a sweep changes nothing):
//! 1. **Threshold search.** With `P_i = P[τ_t]` on every shape (vertices scoring at least
//!    `μ + t σ` of the remaining vertices' scores), find the largest `t ∈ {0, δt, 2δt, …, t_max}`
//!    for which the settled tuple is non-empty on *every* shape: galloping up from `t = 0`
//!    (1, 2, 4, … steps), then bisection, each probe warm-started from the last surviving tuple
//!    (this assumes, as [`TSearch::Bisect`](crate::stable::TSearch) does for pairs, that
//!    survival is monotone in `t`). If even `t = 0` leaves a shape empty, no stable tuple
//!    remains and the extraction stops.
//! 2. **Area-matched tuple.** Each shape's share of the last surviving tuple, `α_i`
//!    (fraction of the shape's total area), is its own size. Sizes may differ between shapes
//!    by the documented tolerance `τ` ([`AdaptiveOptions::size_tolerance`], default 0.5): each
//!    `α_i` is clamped into `[ᾱ / (1 + τ), ᾱ (1 + τ)]` around the median `ᾱ`, so one shape at
//!    the edge of vanishing (the last `t` is where *some* shape nearly empties) cannot shrink
//!    its part to a point, while genuinely different proportions (a long or a short leg) keep
//!    their own area. Then the sweeps run with `P_i = P_{α_i}` from that tuple, and their
//!    fixed point is the tuple ([`adaptive_update`] checks it).
//!
//! # How many parts
//! Tuples are extracted one after another on what remains, as in
//! [`cosegment`](crate::graph::cosegment). The extraction stops ([`StopReason`]) before a tuple that
//! is not stable (step 1 fails at `t = 0`, or step 2 empties a shape), not consistent (its
//! [`confidence`](crate::graph::RegionTuple::confidence) below [`AdaptiveOptions::min_confidence`],
//! default 0.5, or its triangle cycle consistency below
//! [`AdaptiveOptions::min_cycle_consistency`], default 0.5 — an IoU of one half means the
//! region carried by a neighbour, or around a triangle, overlaps itself more than it misses),
//! not separated (the median over shapes of `η`, the share of the score variance on the
//! remaining vertices explained by in/out of the tuple — Otsu's separability — below
//! [`AdaptiveOptions::min_separation`], default 0.8: a remainder that is one part has
//! single-peaked scores, and any cut of a single-peaked distribution explains at most 0.75 of
//! its variance for a uniform one, 0.64 for a Gaussian, so a part must separate better than
//! that), or too small (median area below [`AdaptiveOptions::min_area`], default 2 % of a shape),
//! or when `max_parts − 1` tuples are found; the remaining vertices form the last part (the
//! leftovers). With [`AdaptiveOptions::parts`] `= Some(N)` the confidence, consistency and size
//! levels are not applied until `N − 1` tuples are found (the user asked for `N` parts).
//!
//! # Hierarchy
//! The parts found (leftovers included) are the leaves of a merge tree ([`PartTree`]): the two
//! parts that are most alike are merged, then again, to one part. Alike is measured by the
//! transport the method already uses: with every shape's region of part `u` transported from its
//! neighbours, `ρ_i(u → x)` = the area-weighted mean score on part `x`'s region over the mean
//! score on `u`'s own region (1 when `x` looks to the features exactly like `u`); the
//! similarity of `u` and `x` is the mean over shapes of `½ (ρ_i(u → x) + ρ_i(x → u))`. A merged
//! part is the union of its leaves (its transport is computed afresh; a score mean over a
//! union of leaves follows from per-leaf sums). [`AdaptiveCosegmentation::cut`] returns the co-segmentation
//! with any number of parts from one run. Ties are broken by the lowest part indices, so the
//! tree is deterministic.

use crate::graph::{
    Cosegmentation, Engine, Extraction, GraphError, RegionTuple, ShapeGraph, area, area_fractions,
    check_extraction, seed_region, tuple_hash,
};
use crate::option_range::non_negative;
use crate::stable::{Threshold, ThresholdScratch, threshold};
use serde::{Deserialize, Serialize};

/// Options of [`adaptive_cosegment`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct AdaptiveOptions {
    /// Upper bound on the number of parts, leftovers included (default 8).
    pub max_parts: usize,
    /// `None` (default): the finest consistent parts. `Some(N)`: `N` parts (at least `N` are
    /// extracted when the data has stable tuples for them, the tree is then cut at `N`).
    pub parts: Option<usize>,
    /// Step of the threshold search, in standard deviations (default 0.1, as Algorithm 3).
    pub delta_t: f64,
    /// Largest threshold tried, in standard deviations (default 20, as Algorithm 3).
    pub t_max: f64,
    /// How each shape's part size is read from the surviving tuple (default [`Sizing::Otsu`]).
    pub sizing: Sizing,
    /// How much a shape's part may differ from the median size (default 0.5: within a factor
    /// 1.5); see the module docs.
    pub size_tolerance: f64,
    /// Lowest tuple confidence (tree-edge IoU) accepted as a part (default 0.5).
    pub min_confidence: f64,
    /// Lowest triangle cycle consistency (IoU) accepted as a part (default 0.5).
    pub min_cycle_consistency: f64,
    /// Lowest median separation `η` of a part from the rest of what remains (default 0.8; see
    /// the module docs).
    pub min_separation: f64,
    /// Smallest median area of a part, as a fraction of its shape (default 0.02).
    pub min_area: f64,
    /// Root of the spanning tree (default `None`: as [`crate::graph::CosegmentOptions::root`]).
    pub root: Option<usize>,
    /// Start of each tuple (default `None`: as [`crate::graph::CosegmentOptions::seed`]).
    pub seed: Option<u64>,
    /// Sweep cap of each settling run (default 100).
    pub max_sweeps: usize,
    /// Triangles sampled for the cycle consistency (default 8).
    pub triangles: usize,
}

impl Default for AdaptiveOptions {
    fn default() -> Self {
        Self {
            max_parts: 8,
            parts: None,
            delta_t: 0.1,
            t_max: 20.0,
            sizing: Sizing::Otsu,
            size_tolerance: 0.5,
            min_confidence: 0.5,
            min_cycle_consistency: 0.5,
            min_separation: 0.8,
            min_area: 0.02,
            root: None,
            seed: None,
            max_sweeps: 100,
            triangles: 8,
        }
    }
}

/// How step 2 reads each shape's part size `α_i` (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sizing {
    /// Algorithm 3 as in the paper: the area of the last surviving tuple `Ω^t`. On a
    /// collection this is small — the last `t` is where the most peaked shape nearly empties.
    LastThreshold,
    /// The natural break of the scores that the tuple's neighbours give each shape: the cut of
    /// the score distribution (area-weighted) maximising Otsu's between-class variance
    /// `w_in w_out (μ_in − μ_out)²`, taken first from the transport of `Ω^t` and then from
    /// the area-matched tuple again until the sizes move by less than 1 % of a shape (at most
    /// 4 rounds). Parameter-free; a part whose scores separate cleanly from the rest gets its
    /// own area whatever the threshold search's `t`.
    Otsu,
}

/// Why the extraction stopped.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "reason")]
pub enum StopReason {
    /// `max_parts − 1` tuples were found.
    MaxParts,
    /// A shape has no vertex left, or less than `min_area` of its area.
    Exhausted,
    /// No threshold leaves a non-empty tuple on every shape.
    NoStableTuple,
    /// The next tuple's confidence was below the level.
    LowConfidence {
        /// The rejected tuple's confidence.
        confidence: f64,
    },
    /// The next tuple's cycle consistency was below the level.
    LowCycleConsistency {
        /// The rejected tuple's cycle consistency.
        cycle_consistency: f64,
    },
    /// The next tuple's scores did not separate it from the rest (median `η` below the level).
    NotSeparated {
        /// The rejected tuple's median separation.
        separation: f64,
    },
    /// The next tuple's median area was below `min_area`.
    TooSmall {
        /// The rejected tuple's median area fraction.
        area: f64,
    },
    /// Nothing was extracted: the leaves are equal-area regions grouped by geometry
    /// ([`super::PartsFrom::Geometry`]).
    EqualAreaLeaves,
}

impl std::fmt::Display for StopReason {
    /// What stopped the extraction, with the rejected tuple's value (the levels are
    /// [`AdaptiveOptions`]'s).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::MaxParts => write!(f, "the upper bound on the number of parts was reached"),
            Self::Exhausted => write!(f, "a shape had no area left to split"),
            Self::NoStableTuple => write!(f, "no threshold left a stable tuple on every shape"),
            Self::LowConfidence { confidence } => {
                write!(
                    f,
                    "the next tuple's confidence, {confidence:.3}, was below the level"
                )
            }
            Self::LowCycleConsistency { cycle_consistency } => write!(
                f,
                "the next tuple's cycle consistency, {cycle_consistency:.3}, was below the level"
            ),
            Self::NotSeparated { separation } => write!(
                f,
                "the next tuple's scores separated it from the rest by η = {separation:.3}, below the level"
            ),
            Self::EqualAreaLeaves => write!(
                f,
                "the finest parts are equal-area regions, grouped by thickness and concavity"
            ),
            Self::TooSmall { area } => write!(
                f,
                "the next tuple covered a median {:.1} % of its shapes, below the smallest part",
                100.0 * area
            ),
        }
    }
}

/// The automatic threshold of one extracted tuple.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AutoTuple {
    /// The last threshold `t` (standard deviations) at which the tuple survived.
    pub t: f64,
    /// `α_i` per shape: the area fraction each shape's region was cut at (after the clamp).
    pub alphas: Vec<f64>,
    /// Settling runs of the threshold search.
    pub probes: usize,
    /// Median over shapes of the separation `η` of the tuple's scores (module docs).
    pub separation: f64,
}

/// One merge of the part tree: node `a` and node `b` become node `leaves + index`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartMerge {
    /// First merged node (a leaf `< leaves`, or an earlier merge `leaves + m`).
    pub a: usize,
    /// Second merged node.
    pub b: usize,
    /// Similarity of the two (see the module docs; about 1 for parts that look alike).
    pub similarity: f64,
}

/// Coarse-to-fine tree of the parts: leaves `0..leaves` are the extracted tuples (the last one
/// the leftovers), each merge creates node `leaves + m`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartTree {
    /// Number of leaves.
    pub leaves: usize,
    /// Merges, most alike first.
    pub merges: Vec<PartMerge>,
}

impl PartTree {
    /// The leaves of each part when the tree is cut at `parts` parts (clamped to
    /// `1..=leaves`): groups of leaf indices, each ascending, ordered by their first leaf.
    ///
    /// ```
    /// use coseg::parts::{PartMerge, PartTree};
    /// let t = PartTree { leaves: 3, merges: vec![
    ///     PartMerge { a: 0, b: 2, similarity: 0.9 },
    ///     PartMerge { a: 3, b: 1, similarity: 0.5 },
    /// ] };
    /// assert_eq!(t.cut(2), vec![vec![0, 2], vec![1]]);
    /// assert_eq!(t.cut(1), vec![vec![0, 1, 2]]);
    /// assert_eq!(t.cut(3), vec![vec![0], vec![1], vec![2]]);
    /// ```
    pub fn cut(&self, parts: usize) -> Vec<Vec<usize>> {
        let l = self.leaves;
        let parts = parts.clamp(1.min(l), l);
        let mut members: Vec<Vec<usize>> = (0..l).map(|x| vec![x]).collect();
        let mut alive: Vec<bool> = vec![true; l];
        for m in self.merges.iter().take(l - parts) {
            let mut u = std::mem::take(&mut members[m.a]);
            u.append(&mut std::mem::take(&mut members[m.b]));
            u.sort_unstable();
            alive[m.a] = false;
            alive[m.b] = false;
            members.push(u);
            alive.push(true);
        }
        let mut out: Vec<Vec<usize>> = members
            .into_iter()
            .zip(alive)
            .filter(|(m, a)| *a && !m.is_empty())
            .map(|(m, _)| m)
            .collect();
        out.sort();
        out
    }
}

/// The result of [`adaptive_cosegment`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AdaptiveCosegmentation {
    /// The finest parts: one tuple per extracted part, then the leftovers. `alpha` is the mean
    /// area fraction of the extracted tuples.
    pub leaves: Cosegmentation,
    /// The automatic threshold of each extracted tuple (not of the leftovers).
    pub auto: Vec<AutoTuple>,
    /// Why the extraction stopped.
    pub stop: StopReason,
    /// The merge tree over `leaves.tuples`.
    pub tree: PartTree,
    /// With parts from geometry, when some region was split into its pieces
    /// ([`super::split_disconnected_leaves`]): the equal-area region each leaf comes from (a
    /// split region gives several leaves, the first keeping its id). Empty otherwise: every
    /// leaf is its own.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub leaf_origin: Vec<usize>,
    /// Of those leaves, the pairs split from one region whose pieces face the same way
    /// ([`super::SplitLeaves::alike`]: copies of one part, linked in the tree like mirror
    /// pairs); `(a, b)` with `a < b`, in order. Empty when nothing was split or none face
    /// alike.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub leaf_copies: Vec<(usize, usize)>,
}

impl AdaptiveCosegmentation {
    /// The co-segmentation with `parts` parts (clamped to `1..=leaves`), by cutting the tree: a
    /// part's regions are the union of its leaves' regions, its confidence the area-weighted
    /// mean of theirs, its cycle consistency the mean of theirs (where known), `converged`
    /// whether all of theirs are; it is the leftover part when it holds the leftover leaf, and
    /// is then last.
    ///
    /// ```
    /// use coseg::bands::equal_count_bands;
    /// use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
    /// use coseg::parts::{adaptive_cosegment, AdaptiveOptions};
    /// let vals: Vec<f64> = (0..40).map(|v| ((v * 7) % 40) as f64).collect();
    /// let t = equal_count_bands(&vals, 1, 40, 4).unwrap();
    /// let nodes = (0..3).map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &[1.0; 40]).unwrap()).collect();
    /// let g = ShapeGraph::build(nodes, &GraphOptions::default()).unwrap();
    /// let a = adaptive_cosegment(&g, &AdaptiveOptions::default()).unwrap();
    /// assert_eq!(a.cut(1).tuples.len(), 1);
    /// assert_eq!(a.cut(usize::MAX), a.leaves);
    /// ```
    pub fn cut(&self, parts: usize) -> Cosegmentation {
        let groups = self.tree.cut(parts);
        if groups.len() == self.leaves.tuples.len() {
            return self.leaves.clone();
        }
        let n = self.leaves.names.len();
        let mut tuples: Vec<RegionTuple> = groups
            .iter()
            .map(|g| merge_tuples(g.iter().map(|&l| &self.leaves.tuples[l]), n))
            .collect();
        // The leftovers, wherever they were merged, stay the last id.
        if let Some(p) = tuples.iter().position(|t| t.leftover) {
            let t = tuples.remove(p);
            tuples.push(t);
        }
        Cosegmentation {
            tuples,
            ..self.leaves.clone()
        }
    }
}

impl AdaptiveCosegmentation {
    /// Rebuilds [`Self::tree`] with the leaf pairs in `first` merged before anything else, in
    /// their order (pairs that repeat a leaf or name no leaf are skipped); the other merges
    /// follow the similarity of the module docs. `graph` must be the one the leaves were
    /// found on. Used to keep mirror pairs ([`super::mirror_pairs`]) together in every cut.
    ///
    /// ```
    /// use coseg::bands::equal_count_bands;
    /// use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
    /// use coseg::parts::{adaptive_cosegment, AdaptiveOptions};
    /// let vals: Vec<f64> = (0..40).map(|v| ((v * 7) % 40) as f64).collect();
    /// let t = equal_count_bands(&vals, 1, 40, 4).unwrap();
    /// let nodes = (0..3).map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &[1.0; 40]).unwrap()).collect();
    /// let g = ShapeGraph::build(nodes, &GraphOptions::default()).unwrap();
    /// let mut o = AdaptiveOptions::default();
    /// o.min_separation = 0.0;
    /// let mut a = adaptive_cosegment(&g, &o).unwrap();
    /// let l = a.leaves.tuples.len();
    /// assert!(l >= 3);
    /// a.regroup(&g, &[(0, l - 1)]);
    /// assert_eq!((a.tree.merges[0].a, a.tree.merges[0].b), (0, l - 1));
    /// assert_eq!(a.tree.merges.len(), l - 1);
    /// ```
    pub fn regroup(&mut self, graph: &ShapeGraph, first: &[(usize, usize)]) {
        let mut sw = Sweeper::new(graph, self.leaves.order.clone(), 1);
        self.tree = part_tree(&mut sw, &self.leaves, first);
    }
}

fn merge_tuples<'a>(group: impl Iterator<Item = &'a RegionTuple>, n: usize) -> RegionTuple {
    let group: Vec<&RegionTuple> = group.collect();
    let mut regions = vec![Vec::new(); n];
    let mut fractions = vec![0.0; n];
    for t in &group {
        for i in 0..n {
            regions[i].extend_from_slice(&t.regions[i]);
            fractions[i] += t.area_fractions[i];
        }
    }
    for r in &mut regions {
        r.sort_unstable();
    }
    let weight: Vec<f64> = group
        .iter()
        .map(|t| t.area_fractions.iter().sum::<f64>())
        .collect();
    let wsum: f64 = weight.iter().sum();
    let confidence = if wsum > 0.0 {
        group
            .iter()
            .zip(&weight)
            .map(|(t, w)| t.confidence * w)
            .sum::<f64>()
            / wsum
    } else {
        group.iter().map(|t| t.confidence).sum::<f64>() / group.len() as f64
    };
    let cycles: Vec<f64> = group.iter().filter_map(|t| t.cycle_consistency).collect();
    RegionTuple {
        regions,
        area_fractions: fractions,
        sweeps: group.iter().map(|t| t.sweeps).max().unwrap_or(0),
        converged: group.iter().all(|t| t.converged),
        cycled: group.iter().any(|t| t.cycled),
        objective: group.iter().map(|t| t.objective).sum(),
        confidence,
        cycle_consistency: (!cycles.is_empty())
            .then(|| cycles.iter().sum::<f64>() / cycles.len() as f64),
        leftover: group.iter().any(|t| t.leftover),
    }
}

/// The sweeps of the graph update with a per-shape thresholding rule.
struct Sweeper<'g> {
    graph: &'g ShapeGraph,
    eng: Engine<'g>,
    order: Vec<usize>,
    neighbours: Vec<Vec<usize>>,
    scores: Vec<f64>,
    f: Vec<u32>,
    scratch: ThresholdScratch,
    max_sweeps: usize,
}

struct Settled {
    sweeps: usize,
    converged: bool,
    cycled: bool,
}

impl<'g> Sweeper<'g> {
    fn new(graph: &'g ShapeGraph, order: Vec<usize>, max_sweeps: usize) -> Self {
        let neighbours = (0..graph.node_count())
            .map(|i| graph.neighbours(i).into_iter().map(|(j, _)| j).collect())
            .collect();
        Self {
            graph,
            eng: Engine::new(graph),
            order,
            neighbours,
            scores: Vec::new(),
            f: Vec::new(),
            scratch: ThresholdScratch::default(),
            max_sweeps,
        }
    }

    fn load(&mut self, tuple: &[Vec<u32>]) {
        for (i, r) in tuple.iter().enumerate() {
            self.eng.set_region(i, r);
        }
    }

    /// `P_i` of shape `i`'s scores from its current neighbours, into `self.f`.
    fn respond(&mut self, i: usize, rem: &[u32], rule: Threshold, sources: Option<&[usize]>) {
        self.eng.scores(i, sources, rem, &mut self.scores);
        let areas = &self.graph.node(i).areas;
        threshold(
            rule,
            rem,
            &self.scores,
            areas,
            1.0,
            &mut self.f,
            &mut self.scratch,
        );
    }

    /// Carries `root_region` down the spanning tree with `rule` (each child hears its parent).
    fn spread(
        &mut self,
        rem: &[Vec<u32>],
        root_region: Vec<u32>,
        parent: &[Option<usize>],
        rule: Threshold,
    ) -> Vec<Vec<u32>> {
        let n = rem.len();
        let mut tuple = vec![Vec::new(); n];
        self.load(&tuple);
        let root = self.order[0];
        self.eng.set_region(root, &root_region);
        tuple[root] = root_region;
        for k in 1..self.order.len() {
            let c = self.order[k];
            let p = parent[c].expect("non-root has a parent");
            self.respond(c, &rem[c], rule, Some(&[p]));
            tuple[c].clone_from(&self.f);
            self.eng.set_region(c, &tuple[c]);
        }
        tuple
    }

    /// Gauss–Seidel sweeps from `tuple` until a sweep changes nothing, a tuple repeats, or the
    /// cap; shapes whose neighbours did not change since their last update are skipped (exact:
    /// they would get the same region).
    fn settle(
        &mut self,
        rem: &[Vec<u32>],
        tuple: &mut [Vec<u32>],
        rule: &dyn Fn(usize) -> Threshold,
    ) -> Settled {
        let n = rem.len();
        self.load(tuple);
        let mut clock = 1usize;
        let mut changed_at = vec![clock; n];
        let mut updated_at = vec![0usize; n];
        let mut seen = vec![tuple_hash(tuple)];
        let mut out = Settled {
            sweeps: 0,
            converged: false,
            cycled: false,
        };
        while out.sweeps < self.max_sweeps {
            out.sweeps += 1;
            let mut changed = false;
            for k in 0..self.order.len() {
                let i = self.order[k];
                if !self.neighbours[i]
                    .iter()
                    .any(|&j| changed_at[j] >= updated_at[i])
                {
                    continue;
                }
                clock += 1;
                updated_at[i] = clock;
                self.respond(i, &rem[i], rule(i), None);
                if self.f != tuple[i] {
                    changed = true;
                    changed_at[i] = clock;
                    tuple[i].clone_from(&self.f);
                    self.eng.set_region(i, &tuple[i]);
                }
            }
            if !changed {
                out.converged = true;
                break;
            }
            let h = tuple_hash(tuple);
            if seen.contains(&h) {
                out.cycled = true;
                break;
            }
            seen.push(h);
        }
        out
    }
}

/// One simultaneous (Jacobi) application of the area-matched update with per-shape sizes:
/// `out_i = P_{alphas[i]}(Σ_j w_ij W_ij f_j / (N_ij |f_j|))` on `remaining[i]` (`alphas[i]` a
/// fraction of shape `i`'s total area). A converged extracted tuple `r` of
/// [`adaptive_cosegment`] (with `remaining` = [`Cosegmentation::remaining_before`]`(r, ·)` of
/// its leaves and `alphas` = its [`AutoTuple::alphas`]) is returned unchanged.
///
/// ```
/// use coseg::bands::equal_count_bands;
/// use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
/// use coseg::parts::{adaptive_cosegment, adaptive_update, AdaptiveOptions};
/// let vals: Vec<f64> = (0..40).map(|v| ((v * 7) % 40) as f64).collect();
/// let t = equal_count_bands(&vals, 1, 40, 4).unwrap();
/// let nodes = (0..3).map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &[1.0; 40]).unwrap()).collect();
/// let g = ShapeGraph::build(nodes, &GraphOptions::default()).unwrap();
/// let a = adaptive_cosegment(&g, &AdaptiveOptions::default()).unwrap();
/// let rem: Vec<Vec<u32>> = (0..3).map(|i| a.leaves.remaining_before(0, i)).collect();
/// let next = adaptive_update(&g, &rem, &a.leaves.tuples[0].regions, &a.auto[0].alphas).unwrap();
/// assert_eq!(next, a.leaves.tuples[0].regions);
/// ```
pub fn adaptive_update(
    graph: &ShapeGraph,
    remaining: &[Vec<u32>],
    tuple: &[Vec<u32>],
    alphas: &[f64],
) -> Result<Vec<Vec<u32>>, GraphError> {
    let n = graph.node_count();
    if remaining.len() != n || tuple.len() != n || alphas.len() != n {
        return Err(GraphError::BadOption(format!(
            "{n} shapes but {} remaining sets, {} regions and {} sizes",
            remaining.len(),
            tuple.len(),
            alphas.len()
        )));
    }
    let mut sw = Sweeper::new(graph, (0..n).collect(), 1);
    sw.load(tuple);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        sw.respond(i, &remaining[i], Threshold::AreaFraction(alphas[i]), None);
        out.push(sw.f.clone());
    }
    Ok(out)
}

fn check(graph: &ShapeGraph, o: &AdaptiveOptions) -> Result<(), GraphError> {
    check_extraction(graph, o.root, o.max_sweeps)?;
    if o.max_parts == 0 || o.parts == Some(0) {
        return Err(GraphError::BadOption("parts must be at least 1".into()));
    }
    if !(o.delta_t.is_finite() && o.delta_t > 0.0 && o.t_max.is_finite() && o.t_max >= 0.0) {
        return Err(GraphError::BadOption(format!(
            "delta_t = {} must be positive and t_max = {} finite and non-negative",
            o.delta_t, o.t_max
        )));
    }
    non_negative("size_tolerance", o.size_tolerance).map_err(GraphError::BadOption)?;
    Ok(())
}

/// The median of `v` (the mean of the middle two for an even length).
pub(crate) fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let m = s.len() / 2;
    if s.len() % 2 == 1 {
        s[m]
    } else {
        0.5 * (s[m - 1] + s[m])
    }
}

/// Step 1 of the module docs: the largest surviving `t` step and its tuple, or `None`.
fn search_threshold(
    sw: &mut Sweeper<'_>,
    rem: &[Vec<u32>],
    start: Vec<Vec<u32>>,
    o: &AdaptiveOptions,
    probes: &mut usize,
) -> Option<(usize, Vec<Vec<u32>>)> {
    let steps = (o.t_max / o.delta_t + 1e-9).floor() as usize;
    let mut probe = |s: usize, from: &[Vec<u32>], sw: &mut Sweeper<'_>| {
        *probes += 1;
        let mut t = from.to_vec();
        let rule = Threshold::MeanStd(s as f64 * o.delta_t);
        sw.settle(rem, &mut t, &|_| rule);
        t.iter().all(|r| !r.is_empty()).then_some(t)
    };
    let mut last = (0, probe(0, &start, sw)?);
    let mut hi = None;
    let mut d = 1;
    while last.0 < steps {
        let s = d.min(steps);
        match probe(s, &last.1, sw) {
            Some(t) => last = (s, t),
            None => {
                hi = Some(s);
                break;
            }
        }
        d *= 2;
    }
    if let Some(mut hi) = hi {
        while hi - last.0 > 1 {
            let mid = last.0 + (hi - last.0) / 2;
            match probe(mid, &last.1, sw) {
                Some(t) => last = (mid, t),
                None => hi = mid,
            }
        }
    }
    Some(last)
}

/// Co-segments every shape of `graph` into parts of their own size, as many as the data
/// supports (see the module docs for the algorithm, the stop rule and the tree).
/// Deterministic: same graph and options, identical output, whatever the thread count.
///
/// Returns the finest parts (`leaves`), each extracted tuple's threshold and sizes, why the
/// extraction stopped, and the merge tree; [`AdaptiveCosegmentation::cut`] gives any coarser
/// number of parts.
///
/// (About 110 lines: the extraction loop is one sequence of named steps, each a helper —
/// `search_threshold`, `area_matched`, `confidence`, `acceptance`; splitting it further would
/// scatter the stop bookkeeping it shares.)
///
/// ```
/// use coseg::bands::equal_count_bands;
/// use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
/// use coseg::parts::{adaptive_cosegment, AdaptiveOptions};
/// let vals: Vec<f64> = (0..40).map(|v| ((v * 7) % 40) as f64).collect();
/// let t = equal_count_bands(&vals, 1, 40, 4).unwrap();
/// let nodes = (0..3).map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &[1.0; 40]).unwrap()).collect();
/// let g = ShapeGraph::build(nodes, &GraphOptions::default()).unwrap();
/// let a = adaptive_cosegment(&g, &AdaptiveOptions::default()).unwrap();
/// // Identical shapes: identical parts.
/// assert_eq!(a.leaves.labels(0), a.leaves.labels(1));
/// assert_eq!(a.tree.leaves, a.leaves.tuples.len());
/// ```
pub fn adaptive_cosegment(
    graph: &ShapeGraph,
    options: &AdaptiveOptions,
) -> Result<AdaptiveCosegmentation, GraphError> {
    check(graph, options)?;
    let o = options;
    let n = graph.node_count();
    let mut x = Extraction::start(graph, o.root, o.triangles)?;
    let mut sw = Sweeper::new(graph, x.order.clone(), o.max_sweeps);
    let forced = o.parts.unwrap_or(0).min(o.max_parts).saturating_sub(1);
    let mut tuples = Vec::new();
    let mut auto = Vec::new();
    let mut stop = StopReason::MaxParts;
    while tuples.len() + 1 < o.max_parts {
        let enforce = tuples.len() >= forced;
        let rem = &x.rem;
        let left = median(
            &(0..n)
                .map(|i| area(&graph.node(i).areas, &rem[i]))
                .collect::<Vec<_>>(),
        );
        if rem.iter().any(Vec::is_empty) || (enforce && left < 2.0 * o.min_area) {
            stop = StopReason::Exhausted;
            break;
        }
        let seed = seed_region(graph, x.root, &rem[x.root], o.seed, tuples.len());
        let start = sw.spread(rem, seed, &x.parent, Threshold::MeanStd(0.0));
        let mut probes = 0;
        let Some((step, omega)) = search_threshold(&mut sw, rem, start, o, &mut probes) else {
            stop = StopReason::NoStableTuple;
            break;
        };
        let (tuple, alphas, settled) = area_matched(&mut sw, rem, omega, o);
        if tuple.iter().any(Vec::is_empty) {
            stop = StopReason::NoStableTuple;
            break;
        }
        sw.load(&tuple);
        let (conf, cyc) = x.confidence(graph, &mut sw.eng, &tuple);
        let fractions = area_fractions(graph, &tuple);
        let separation = median(
            &(0..n)
                .map(|i| separation(&mut sw, i, &rem[i], &tuple[i]))
                .collect::<Vec<_>>(),
        );
        if enforce {
            stop = acceptance(o, conf, cyc, separation, &fractions);
            if stop != StopReason::MaxParts {
                break;
            }
        }
        x.take(&tuple);
        auto.push(AutoTuple {
            t: step as f64 * o.delta_t,
            alphas,
            probes,
            separation,
        });
        tuples.push(RegionTuple {
            area_fractions: fractions,
            regions: tuple,
            sweeps: settled.sweeps,
            converged: settled.converged,
            cycled: settled.cycled,
            objective: 0.0,
            confidence: conf,
            cycle_consistency: cyc,
            leftover: false,
        });
    }
    x.push_leftovers(graph, &mut sw.eng, &mut tuples);
    let alpha = mean_alpha(&tuples, auto.len(), n);
    let leaves = x.finish(graph, alpha, tuples);
    let tree = part_tree(&mut sw, &leaves, &[]);
    Ok(AdaptiveCosegmentation {
        leaves,
        auto,
        stop,
        tree,
        leaf_origin: Vec::new(),
        leaf_copies: Vec::new(),
    })
}

/// The mean over the `parts` extracted (non-leftover) tuples of their mean area fraction over
/// the `n` shapes; 1 when none was extracted.
fn mean_alpha(tuples: &[RegionTuple], parts: usize, n: usize) -> f64 {
    if parts == 0 {
        1.0
    } else {
        tuples
            .iter()
            .filter(|t| !t.leftover)
            .map(|t| t.area_fractions.iter().sum::<f64>() / n as f64)
            .sum::<f64>()
            / parts as f64
    }
}

/// Why a tuple fails the acceptance tests (confidence, cycle consistency, separation, median
/// area, checked in this order), or [`StopReason::MaxParts`] when it passes them all.
fn acceptance(
    o: &AdaptiveOptions,
    conf: f64,
    cyc: Option<f64>,
    separation: f64,
    fractions: &[f64],
) -> StopReason {
    let a = median(fractions);
    if conf < o.min_confidence {
        StopReason::LowConfidence { confidence: conf }
    } else if let Some(c) = cyc.filter(|&c| c < o.min_cycle_consistency) {
        StopReason::LowCycleConsistency {
            cycle_consistency: c,
        }
    } else if separation < o.min_separation {
        StopReason::NotSeparated { separation }
    } else if a < o.min_area {
        StopReason::TooSmall { area: a }
    } else {
        StopReason::MaxParts
    }
}

/// Clamps sizes into `[ᾱ / (1 + τ), ᾱ (1 + τ)]` around their median `ᾱ`.
fn clamp_sizes(sizes: &[f64], tolerance: f64) -> Vec<f64> {
    let mid = median(sizes);
    let (lo, hi) = (mid / (1.0 + tolerance), mid * (1.0 + tolerance));
    sizes.iter().map(|a| a.clamp(lo, hi)).collect()
}

/// Step 2 of the module docs: per-shape sizes and the area-matched tuple settled from `omega`.
fn area_matched(
    sw: &mut Sweeper<'_>,
    rem: &[Vec<u32>],
    omega: Vec<Vec<u32>>,
    o: &AdaptiveOptions,
) -> (Vec<Vec<u32>>, Vec<f64>, Settled) {
    let graph = sw.graph;
    let n = rem.len();
    let own: Vec<f64> = (0..n)
        .map(|i| area(&graph.node(i).areas, &omega[i]))
        .collect();
    let mut alphas = clamp_sizes(&own, o.size_tolerance);
    let mut tuple = omega;
    if o.sizing == Sizing::Otsu {
        for _ in 0..4 {
            sw.load(&tuple);
            let sizes: Vec<f64> = (0..n).map(|i| otsu_size(sw, i, &rem[i])).collect();
            let next = clamp_sizes(&sizes, o.size_tolerance);
            let moved = next
                .iter()
                .zip(&alphas)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            alphas = next;
            let a = alphas.clone();
            sw.settle(rem, &mut tuple, &|i| Threshold::AreaFraction(a[i]));
            if moved < 0.01 {
                break;
            }
        }
    }
    let a = alphas.clone();
    let settled = sw.settle(rem, &mut tuple, &|i| Threshold::AreaFraction(a[i]));
    (tuple, alphas, settled)
}

/// `η` of shape `i`: between-class over total variance (area-weighted) of the scores on `rem`
/// under the sweeper's current regions, classes = `region` and the rest of `rem`; in `[0, 1]`,
/// 0 when the scores do not tell the region from the rest.
fn separation(sw: &mut Sweeper<'_>, i: usize, rem: &[u32], region: &[u32]) -> f64 {
    sw.eng.scores(i, None, rem, &mut sw.scores);
    let areas = &sw.graph.node(i).areas;
    let (mut w, mut m, mut q) = (0.0, 0.0, 0.0);
    let (mut w_in, mut m_in) = (0.0, 0.0);
    let mut k = 0;
    for (&v, &x) in rem.iter().zip(&sw.scores) {
        let a = areas[v as usize];
        w += a;
        m += a * x;
        q += a * x * x;
        while k < region.len() && region[k] < v {
            k += 1;
        }
        if k < region.len() && region[k] == v {
            w_in += a;
            m_in += a * x;
        }
    }
    let w_out = w - w_in;
    let var = q / w - (m / w) * (m / w);
    if w_in <= 0.0 || w_out <= 0.0 || var <= 0.0 {
        return 0.0;
    }
    let d = m_in / w_in - (m - m_in) / w_out;
    (w_in * w_out / (w * w) * d * d / var).min(1.0)
}

/// Area (fraction of the shape) above the Otsu cut of shape `i`'s scores on `rem` under the
/// sweeper's current regions; 0 when the scores do not separate.
fn otsu_size(sw: &mut Sweeper<'_>, i: usize, rem: &[u32]) -> f64 {
    sw.eng.scores(i, None, rem, &mut sw.scores);
    let areas = &sw.graph.node(i).areas;
    let mut idx: Vec<usize> = (0..rem.len()).collect();
    let s = &sw.scores;
    idx.sort_by(|&a, &b| s[b].total_cmp(&s[a]).then(a.cmp(&b)));
    let w: f64 = rem.iter().map(|&v| areas[v as usize]).sum();
    let m: f64 = rem
        .iter()
        .zip(s)
        .map(|(&v, &x)| areas[v as usize] * x)
        .sum();
    let (mut w_in, mut m_in) = (0.0, 0.0);
    let (mut best, mut best_area) = (0.0, 0.0);
    for (k, &j) in idx.iter().enumerate() {
        let a = areas[rem[j] as usize];
        w_in += a;
        m_in += a * s[j];
        // Cut only between distinct scores.
        if k + 1 < idx.len() && s[idx[k + 1]] == s[j] {
            continue;
        }
        let w_out = w - w_in;
        if w_in <= 0.0 || w_out <= 0.0 {
            continue;
        }
        let d = m_in / w_in - (m - m_in) / w_out;
        let v = w_in * w_out * d * d;
        if v > best {
            best = v;
            best_area = w_in;
        }
    }
    best_area
}

/// For part `u` transported from the neighbours onto every shape: `sums[i][leaf]` = the
/// area-weighted score sum over that leaf's region on shape `i` (the score mean of any union
/// of leaves follows from these sums and the leaves' areas).
fn transport_sums(sw: &mut Sweeper<'_>, coseg: &Cosegmentation, u: &[usize]) -> Vec<Vec<f64>> {
    let n = coseg.names.len();
    let regions: Vec<Vec<u32>> = (0..n)
        .map(|i| {
            let mut r: Vec<u32> = u
                .iter()
                .flat_map(|&l| coseg.tuples[l].regions[i].iter().copied())
                .collect();
            r.sort_unstable();
            r
        })
        .collect();
    sw.load(&regions);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let labels = coseg.labels(i);
        let all: Vec<u32> = (0..coseg.vertices[i] as u32).collect();
        sw.eng.scores(i, None, &all, &mut sw.scores);
        let areas = &sw.graph.node(i).areas;
        let mut sums = vec![0.0; coseg.tuples.len()];
        for (v, &l) in labels.iter().enumerate() {
            if l >= 0 {
                sums[l as usize] += areas[v] * sw.scores[v];
            }
        }
        out.push(sums);
    }
    out
}

/// The merge tree of the module docs over the tuples of `coseg`; the leaf pairs in `first`
/// (disjoint) are merged before anything else, in their order.
fn part_tree(sw: &mut Sweeper<'_>, coseg: &Cosegmentation, first: &[(usize, usize)]) -> PartTree {
    let l = coseg.tuples.len();
    let n = coseg.names.len();
    let mut members: Vec<Vec<usize>> = (0..l).map(|x| vec![x]).collect();
    let mut sums: Vec<Vec<Vec<f64>>> = (0..l).map(|x| transport_sums(sw, coseg, &[x])).collect();
    let mut alive: Vec<bool> = vec![true; l];
    let leaf_area = |i: usize, m: &[usize]| -> f64 {
        m.iter().map(|&x| coseg.tuples[x].area_fractions[i]).sum()
    };
    // ρ_i(u → x): mean score on x over mean score on u, under u's transport.
    let rho = |sums: &[Vec<f64>], mu: &[usize], mx: &[usize], i: usize| -> f64 {
        let (au, ax) = (leaf_area(i, mu), leaf_area(i, mx));
        let su: f64 = mu.iter().map(|&x| sums[i][x]).sum();
        let sx: f64 = mx.iter().map(|&x| sums[i][x]).sum();
        if au <= 0.0 || ax <= 0.0 || su <= 0.0 {
            0.0
        } else {
            (sx / ax) / (su / au)
        }
    };
    let similarity = |sums: &[Vec<Vec<f64>>], members: &[Vec<usize>], a: usize, b: usize| {
        (0..n)
            .map(|i| {
                0.5 * (rho(&sums[a], &members[a], &members[b], i)
                    + rho(&sums[b], &members[b], &members[a], i))
            })
            .sum::<f64>()
            / n as f64
    };
    let mut merges = Vec::new();
    let mut seen = vec![false; l];
    let mut forced: Vec<(usize, usize)> = Vec::new();
    for &(a, b) in first {
        if a != b && a.max(b) < l && !seen[a] && !seen[b] {
            seen[a] = true;
            seen[b] = true;
            forced.push((a.min(b), a.max(b)));
        }
    }
    while alive.iter().filter(|&&a| a).count() > 1 {
        let mut best: Option<(f64, usize, usize)> = forced
            .get(merges.len())
            .map(|&(a, b)| (similarity(&sums, &members, a, b), a, b));
        for a in 0..members.len() {
            if merges.len() < forced.len() {
                break;
            }
            for b in a + 1..members.len() {
                if !(alive[a] && alive[b]) {
                    continue;
                }
                let s = similarity(&sums, &members, a, b);
                if best.is_none_or(|(bs, _, _)| s > bs) {
                    best = Some((s, a, b));
                }
            }
        }
        let Some((sim, a, b)) = best else {
            break;
        };
        alive[a] = false;
        alive[b] = false;
        let mut m = members[a].clone();
        m.extend_from_slice(&members[b]);
        m.sort_unstable();
        sums.push(transport_sums(sw, coseg, &m));
        members.push(m);
        alive.push(true);
        merges.push(PartMerge {
            a,
            b,
            similarity: sim,
        });
    }
    PartTree { leaves: l, merges }
}
