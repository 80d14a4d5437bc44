//! [`refine_cosegmentation`]: the smoothed best-response refinement of
//! [`refine_partition`](crate::stable::refine_partition), over every edge of a shape graph.

use super::shape_graph::ShapeGraph;
use super::{Cosegmentation, GraphError};
use crate::affinity::kernel::{Block, LANES, row_sum};
use crate::spectral::HeatSmoother;
use crate::stable::{RefineOptions, StableError, assign_regions};
use rayon::prelude::*;

/// Refines a co-segmentation's region ids on every shape, as
/// [`refine_partition`](crate::stable::refine_partition) does for two shapes: in
/// Gauss–Seidel sweeps over the shapes (in `coseg.order`), shape `i`'s vertices each take the
/// region `r` maximising
///
/// `Σ_{j ~ i} w_ij · (R_ij 1_{F_j,r})_q / (N_ij |F_j,r|)`
///
/// (the edge-weighted mean fraction of features whose bands agree with region `r` of the
/// neighbour `j`, as in [`cosegment`](super::cosegment)'s scores), heat-smoothed over shape `i`
/// when `smoothers` is given (one per shape, in graph order). Stops when a whole sweep changes
/// nothing, or after `options.max_rounds` sweeps.
///
/// The result is `coseg` with every tuple's regions replaced by the refined ones (region id
/// `r` keeps its meaning), area fractions recomputed, `sweeps` = refinement sweeps and
/// `converged` = whether the last sweep changed nothing; `confidence` becomes the area-weighted
/// mean, over the region's vertices on every shape, of the assignment margin
/// `(best − second best) / best` of the scores (`0` = a coin toss between two regions, `1` =
/// no other region receives the vertex at all); `objective` and `cycle_consistency` are kept
/// from `coseg` (they describe the tuples before refinement).
///
/// ```
/// use coseg::bands::equal_count_bands;
/// use coseg::graph::{cosegment, refine_cosegmentation, CosegmentOptions, GraphOptions, ShapeGraph, ShapeNode};
/// use coseg::stable::RefineOptions;
/// let vals: Vec<f64> = (0..60).map(|v| ((v * 7) % 60) as f64).collect();
/// let t = equal_count_bands(&vals, 1, 60, 6).unwrap();
/// let nodes: Vec<ShapeNode> = (0..3)
///     .map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &vec![1.0; 60]).unwrap())
///     .collect();
/// let g = ShapeGraph::build(nodes, &GraphOptions::default()).unwrap();
/// let mut options = CosegmentOptions::default();
/// options.regions = 3;
/// let seg = cosegment(&g, &options).unwrap();
/// let refined = refine_cosegmentation(&g, &seg, None, &RefineOptions::default()).unwrap();
/// assert_eq!(refined.labels(0), refined.labels(1)); // identical shapes, identical ids
/// ```
pub fn refine_cosegmentation(
    graph: &ShapeGraph,
    coseg: &Cosegmentation,
    smoothers: Option<&[HeatSmoother]>,
    options: &RefineOptions,
) -> Result<Cosegmentation, GraphError> {
    check_inputs(graph, coseg, smoothers, options)?;
    let n = graph.node_count();
    let regions = coseg.tuples.len();
    let mut labels: Vec<Vec<i32>> = (0..n).map(|i| coseg.labels(i)).collect();
    let mut margins: Vec<Vec<f64>> = coseg.vertices.iter().map(|&d| vec![0.0; d]).collect();
    if regions == 0 {
        return Ok(coseg.clone());
    }
    let stable = |e: StableError| GraphError::BadOption(e.to_string());
    let mut counts = RegionCounts::new(graph, regions, &labels);
    let mut table: Vec<Block> = Vec::new();
    let (mut rounds, mut converged) = (0, false);
    // A shape's scores depend only on its neighbours' labels: when none changed since its last
    // update, it would get the same labels again, so it is skipped (ticks of one clock, as in
    // `cosegment`; the result is identical to updating every shape).
    let neighbours: Vec<Vec<usize>> = (0..n)
        .map(|i| graph.neighbours(i).into_iter().map(|(j, _)| j).collect())
        .collect();
    let mut clock = 1usize;
    let mut changed_at = vec![clock; n];
    let mut updated_at = vec![0usize; n];
    while rounds < options.max_rounds {
        rounds += 1;
        let mut changed = false;
        for &i in &coseg.order {
            if neighbours[i].iter().all(|&j| changed_at[j] < updated_at[i]) {
                continue;
            }
            clock += 1;
            updated_at[i] = clock;
            let mut total = counts.scores(graph, i, &mut table);
            let smoother = smoothers
                .filter(|_| options.smoothing_time > 0.0)
                .map(|s| &s[i]);
            let (new, margin) = assign_regions(&mut total, regions, smoother).map_err(stable)?;
            if new != labels[i] {
                changed = true;
                changed_at[i] = clock;
                counts.relabel(graph, i, &labels[i], &new);
                labels[i] = new;
            }
            margins[i] = margin;
        }
        if !changed {
            converged = true;
            break;
        }
    }
    Ok(refined(graph, coseg, &labels, &margins, rounds, converged))
}

/// The inputs must belong together and the smoothing time be usable; checked before any work so
/// that a mismatch is the caller's error.
fn check_inputs(
    graph: &ShapeGraph,
    coseg: &Cosegmentation,
    smoothers: Option<&[HeatSmoother]>,
    options: &RefineOptions,
) -> Result<(), GraphError> {
    let n = graph.node_count();
    if coseg.vertices.len() != n
        || (0..n).any(|i| coseg.vertices[i] != graph.node(i).bands.vertices)
    {
        return Err(GraphError::BadOption(
            "the co-segmentation does not belong to this graph".into(),
        ));
    }
    if let Some(s) = smoothers
        && (s.len() != n || (0..n).any(|i| s[i].vertex_count() != coseg.vertices[i]))
    {
        return Err(GraphError::BadOption(
            "one heat smoother per shape, with the shape's vertex count, is needed".into(),
        ));
    }
    if !(options.smoothing_time.is_finite() && options.smoothing_time >= 0.0) {
        return Err(GraphError::BadOption(format!(
            "smoothing_time = {} must be finite and non-negative",
            options.smoothing_time
        )));
    }
    Ok(())
}

/// The refined co-segmentation: `coseg`'s tuples with the regions of the final `labels`, their
/// area fractions and their area-weighted mean `margins` as confidence. Apart from
/// [`refine_cosegmentation`] because it only summarises the finished sweeps.
fn refined(
    graph: &ShapeGraph,
    coseg: &Cosegmentation,
    labels: &[Vec<i32>],
    margins: &[Vec<f64>],
    rounds: usize,
    converged: bool,
) -> Cosegmentation {
    let n = graph.node_count();
    let mut out = coseg.clone();
    for (r, tuple) in out.tuples.iter_mut().enumerate() {
        let (mut weighted, mut area_sum) = (0.0, 0.0);
        for i in 0..n {
            let areas = &graph.node(i).areas;
            let total: f64 = areas.iter().sum();
            let region: Vec<u32> = (0..coseg.vertices[i] as u32)
                .filter(|&v| labels[i][v as usize] == r as i32)
                .collect();
            let a: f64 = region.iter().map(|&v| areas[v as usize]).sum();
            weighted += region
                .iter()
                .map(|&v| areas[v as usize] * margins[i][v as usize])
                .sum::<f64>();
            area_sum += a;
            tuple.area_fractions[i] = if total > 0.0 { a / total } else { 0.0 };
            tuple.regions[i] = region;
        }
        tuple.sweeps = rounds;
        tuple.converged = converged;
        tuple.confidence = if area_sum > 0.0 {
            weighted / area_sum
        } else {
            0.0
        };
    }
    out
}

/// Regions are processed in blocks of this many lanes, each block an `[f32; LANES]` that the
/// gather keeps in one vector register. The tables are `f32`, half the memory the gather reads
/// per (vertex, feature); scores are sums of 300-odd non-negative terms of similar size, far
/// from `f32`'s limits (the result matched the `f64` version on TOSCA cats and FAUST).
/// Per-shape band counts of every region at once, as region blocks laid out
/// `[(block · N + feature) · K + band]`, so that one pass over a shape's band table scores
/// `LANES` regions per table read.
struct RegionCounts {
    regions: usize,
    blocks: usize,
    bands: usize,
    /// `counts[i]`: `blocks · N_i · K` blocks of counts (exact integers in `f32`: below 2²⁴).
    counts: Vec<Vec<Block>>,
    /// `sizes[i][r]`: vertices of region `r` on shape `i`.
    sizes: Vec<Vec<usize>>,
}

impl RegionCounts {
    fn new(graph: &ShapeGraph, regions: usize, labels: &[Vec<i32>]) -> Self {
        let bands = graph.node(0).bands.bands;
        let blocks = regions.div_ceil(LANES);
        let mut rc = RegionCounts {
            regions,
            blocks,
            bands,
            counts: Vec::with_capacity(labels.len()),
            sizes: Vec::with_capacity(labels.len()),
        };
        for (i, l) in labels.iter().enumerate() {
            let t = &graph.node(i).bands;
            rc.counts
                .push(vec![[0.0; LANES]; blocks * t.features * bands]);
            rc.sizes.push(vec![0; regions]);
            let none = vec![-1; l.len()];
            rc.relabel(graph, i, &none, l);
        }
        rc
    }

    /// Moves the vertices of shape `i` whose label changes from `old` to `new`.
    fn relabel(&mut self, graph: &ShapeGraph, i: usize, old: &[i32], new: &[i32]) {
        let t = &graph.node(i).bands;
        let (k, nf, r) = (self.bands, t.features, self.regions);
        let c = &mut self.counts[i];
        let mut update = |v: usize, label: i32, delta: f32| {
            if label < 0 || label as usize >= r {
                return false;
            }
            let (block, lane) = (label as usize / LANES, label as usize % LANES);
            let base = block * nf * k;
            for (f, &b) in t.row(v).iter().enumerate() {
                c[base + f * k + b as usize][lane] += delta;
            }
            true
        };
        for (v, (&lo, &ln)) in old.iter().zip(new).enumerate() {
            if lo == ln {
                continue;
            }
            if update(v, lo, -1.0) {
                self.sizes[i][lo as usize] -= 1;
            }
            if update(v, ln, 1.0) {
                self.sizes[i][ln as usize] += 1;
            }
        }
    }

    /// Scores of every vertex of shape `i` for every region, column-major `d_i × R`:
    /// `Σ_{j ~ i} w_ij · (R_ij 1_{F_j,r})_q / (N_ij |F_j,r|)` (edge pair weights normalised to
    /// mean 1, as in `cosegment`).
    fn scores(&self, graph: &ShapeGraph, i: usize, table: &mut Vec<Block>) -> Vec<f64> {
        let t = &graph.node(i).bands;
        let (k, r, blocks) = (self.bands, self.regions, self.blocks);
        let nf_i = t.features;
        table.clear();
        table.resize(blocks * nf_i * k, [0.0; LANES]);
        let mut scale = vec![0.0f64; blocks * LANES];
        for (j, edge) in graph.neighbours(i) {
            let nf_j = graph.node(j).bands.features;
            let np = edge.pairs.len().max(1) as f64;
            for (c, &n) in scale.iter_mut().zip(&self.sizes[j]) {
                *c = if n > 0 {
                    edge.weight / (np * n as f64)
                } else {
                    0.0
                };
            }
            let weight_sum: f64 = edge.pair_weights.as_ref().map_or(np, |w| w.iter().sum());
            let h = &self.counts[j];
            for (p, &(lo, hi)) in edge.pairs.iter().enumerate() {
                // Feature `ka` on `j`, `kb` on `i`.
                let (ka, kb) = if j < i {
                    (lo as usize, hi as usize)
                } else {
                    (hi as usize, lo as usize)
                };
                let raw = edge
                    .pair_weights
                    .as_ref()
                    .map_or(1.0, |w| w[p] / weight_sum * np);
                for block in 0..blocks {
                    let mut scaled: Block = [0.0; LANES];
                    for (l, x) in scaled.iter_mut().enumerate() {
                        *x = (raw * scale[block * LANES + l]) as f32;
                    }
                    let src = &h[(block * nf_j + ka) * k..][..k];
                    let dst = &mut table[(block * nf_i + kb) * k..][..k];
                    for (d, s) in dst.iter_mut().zip(src) {
                        for l in 0..LANES {
                            d[l] += scaled[l] * s[l];
                        }
                    }
                }
            }
        }
        let d = t.vertices;
        let mut rows: Vec<Block> = vec![[0.0; LANES]; d * blocks];
        let table = &*table;
        rows.par_chunks_mut(512 * blocks)
            .enumerate()
            .for_each(|(chunk, out)| {
                for (o, q) in out.chunks_exact_mut(blocks).zip(chunk * 512..) {
                    let row = t.row(q);
                    for (block, acc) in o.iter_mut().enumerate() {
                        *acc = row_sum(&table[block * nf_i * k..][..nf_i * k], row, k);
                    }
                }
            });
        // Vertex-major blocks to region columns.
        let mut cols = vec![0.0; d * r];
        for (q, row) in rows.chunks_exact(blocks).enumerate() {
            for (c, col) in cols.chunks_exact_mut(d).enumerate() {
                col[q] = f64::from(row[c / LANES][c % LANES]);
            }
        }
        cols
    }
}
