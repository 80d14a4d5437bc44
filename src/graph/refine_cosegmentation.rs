//! [`refine_cosegmentation`]: the smoothed best-response refinement of
//! [`refine_partition`](crate::stable::refine_partition), over every edge of a shape graph.

use super::shape_graph::ShapeGraph;
use super::{Cosegmentation, GraphError};
use crate::affinity::kernel::{Block, LANES, row_sum};
use crate::option_range::non_negative;
use crate::spectral::HeatSmoother;
use crate::stable::{RefineOptions, StableError, assign_regions, best_two};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Refines a co-segmentation's region ids on every shape, as
/// [`refine_partition`](crate::stable::refine_partition) does for two shapes: in
/// Gauss–Seidel sweeps over the shapes (in `coseg.order`), shape `i`'s vertices each take the
/// region `r` maximising
///
/// `Σ_{j ~ i} w_ij · (R_ij 1_{F_j,r})_q / (N_ij |F_j,r|)`
///
/// (the edge-weighted mean fraction of features whose bands agree with region `r` of the
/// neighbour `j`, as in [`cosegment`](super::cosegment)'s scores), heat-smoothed over shape `i`
/// when `smoothers` is given (one per shape, in graph order). A shape update that would leave
/// a region below `MIN_KEPT_SHARE` of its area before refinement is redone with that floor
/// (see there). Stops when a whole sweep changes nothing, or after `options.max_rounds` sweeps.
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
    refine_cosegmentation_sized(graph, coseg, smoothers, options, RefineSizes::Free)
}

/// How [`refine_cosegmentation_sized`] treats the regions' sizes.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "rule")]
pub enum RefineSizes {
    /// The free best response of [`refine_cosegmentation`] (default). Its scores are mean
    /// affinities (normalised by the region's size), so inside a region a vertex's score is
    /// about inversely proportional to the region's spread in band space: a small region's
    /// score peaks higher, wins the vertices on a shared boundary, and the regions drift
    /// towards equal areas (measured on the shipped families, docs/PARTS.md). One limit: no
    /// region falls below `MIN_KEPT_SHARE` of its area before refinement on any shape (a
    /// region spread thin would otherwise empty).
    #[default]
    Free,
    /// Size-aware best response: each vertex of shape `i` takes the region maximising
    /// `s_r(q) · exp(θ_ir)`, with one factor per shape and region chosen so that region `r`'s
    /// area on shape `i` stays within a factor `1 + tolerance` of its area before refinement
    /// (the sizes [`adaptive_cosegment`](crate::parts::adaptive_cosegment) read from the data).
    /// The factors are the dual variables of that size-constrained assignment, found by exact
    /// coordinate steps (a region outside its band gets the `θ_ir` that puts its area on the
    /// nearest bound, the others held; at most 20 passes over the regions per shape update,
    /// kept between sweeps), so boundaries move to where the scores cross while the sizes
    /// stay the data's. A region empty on a shape before refinement stays empty there.
    Keep {
        /// Allowed relative change of each region's area (`0.25`: within a factor 1.25).
        tolerance: f64,
    },
}

/// [`refine_cosegmentation`] with a size rule ([`RefineSizes`]); `RefineSizes::Free` is
/// [`refine_cosegmentation`] bit for bit.
pub fn refine_cosegmentation_sized(
    graph: &ShapeGraph,
    coseg: &Cosegmentation,
    smoothers: Option<&[HeatSmoother]>,
    options: &RefineOptions,
    sizes: RefineSizes,
) -> Result<Cosegmentation, GraphError> {
    check_inputs(graph, coseg, smoothers, options)?;
    if let RefineSizes::Keep { tolerance } = sizes {
        non_negative("size tolerance", tolerance).map_err(GraphError::BadOption)?;
    }
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
    // Per-shape area fractions before refinement (the size-aware rule's targets and the free
    // rule's floors), and the log factors of the size-constrained assignment.
    let start: Vec<Vec<f64>> = (0..n)
        .map(|i| coseg.tuples.iter().map(|t| t.area_fractions[i]).collect())
        .collect();
    let mut theta: Vec<Vec<f64>> = vec![vec![0.0; regions]; n];
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
            let areas = &graph.node(i).areas;
            let (new, margin) = match sizes {
                RefineSizes::Free => {
                    let (l, m) = assign_regions(&mut total, regions, smoother).map_err(stable)?;
                    let shares = region_shares(&l, areas, regions);
                    if (0..regions).any(|r| shares[r] < MIN_KEPT_SHARE * start[i][r]) {
                        assign_sized(
                            &total,
                            areas,
                            &start[i],
                            Band::Floor(MIN_KEPT_SHARE),
                            &mut theta[i],
                        )
                    } else {
                        (l, m)
                    }
                }
                RefineSizes::Keep { tolerance } => {
                    if let Some(s) = smoother {
                        s.smooth(&mut total, regions)
                            .map_err(|e| GraphError::BadOption(e.to_string()))?;
                    }
                    assign_sized(
                        &total,
                        areas,
                        &start[i],
                        Band::Tolerance(tolerance),
                        &mut theta[i],
                    )
                }
            };
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

/// The size-aware assignment of one shape ([`RefineSizes::Keep`], and the free rule's floor
/// `MIN_KEPT_SHARE`): `scores` column-major `d × R` (already smoothed), `areas` per vertex,
/// `target[r]` = region `r`'s area fraction before refinement, `band` the allowed areas
/// around it, `theta[r]` the log factors (updated in place, warm start). Each vertex takes
/// `argmax_r ln s_r(q) + θ_r`; passes over the regions set, for each region whose area is
/// outside its band, its `θ_r` exactly to the value that puts the area on the nearest bound
/// with the others held (a coordinate step of the dual of the size-constrained assignment),
/// until every area is inside or after
/// [`SIZE_PASSES`] passes. Returns the labels and the margins `(best − second) / best` of the
/// scaled scores.
fn assign_sized(
    scores: &[f64],
    areas: &[f64],
    target: &[f64],
    band: Band,
    theta: &mut [f64],
) -> (Vec<i32>, Vec<f64>) {
    let regions = target.len();
    let d = areas.len();
    let total: f64 = areas.iter().sum();
    let log = |r: usize, q: usize| -> f64 {
        let s = scores[r * d + q];
        if target[r] > 0.0 && s > 0.0 {
            s.ln()
        } else {
            f64::NEG_INFINITY
        }
    };
    let mut t: Vec<(f64, usize)> = Vec::with_capacity(d);
    for _ in 0..SIZE_PASSES {
        let mut moved = false;
        for r in 0..regions {
            if target[r] <= 0.0 || total <= 0.0 {
                continue;
            }
            // t_q: the factor above which region r wins vertex q, the others held.
            t.clear();
            let mut got = 0.0;
            for (q, &area) in areas.iter().enumerate() {
                let lr = log(r, q);
                let other = (0..regions)
                    .filter(|&x| x != r)
                    .map(|x| log(x, q) + theta[x])
                    .fold(f64::NEG_INFINITY, f64::max);
                let tq = other - lr;
                if !tq.is_nan() {
                    if theta[r] > tq {
                        got += area;
                    }
                    t.push((tq, q));
                }
            }
            let a = got / total;
            let (lower, upper) = match band {
                Band::Tolerance(tolerance) => {
                    (target[r] / (1.0 + tolerance), target[r] * (1.0 + tolerance))
                }
                Band::Floor(share) => (target[r] * share, f64::INFINITY),
            };
            let bound = if a > upper {
                upper
            } else if a < lower {
                lower
            } else {
                continue;
            };
            t.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            // The shortest prefix of the sorted t whose area reaches the bound.
            let mut acc = 0.0;
            let mut k = t.len();
            for (idx, &(_, q)) in t.iter().enumerate() {
                acc += areas[q] / total;
                if acc >= bound {
                    k = idx;
                    break;
                }
            }
            let next = |k: usize| t.get(k + 1).map_or(f64::INFINITY, |x| x.0);
            let value = if k >= t.len() {
                t.last().map_or(0.0, |x| x.0) + 1.0
            } else {
                let (lo, hi) = (t[k].0, next(k));
                if hi.is_finite() && lo.is_finite() {
                    0.5 * (lo + hi)
                } else if lo.is_finite() {
                    lo + 1.0
                } else {
                    continue;
                }
            };
            if value.is_finite() && value != theta[r] {
                theta[r] = value;
                moved = true;
            }
        }
        if !moved {
            break;
        }
    }
    // Only differences of the factors matter: centre them (they stay bounded across sweeps).
    let live: Vec<usize> = (0..regions).filter(|&r| target[r] > 0.0).collect();
    if !live.is_empty() {
        let mean = live.iter().map(|&r| theta[r]).sum::<f64>() / live.len() as f64;
        for &r in &live {
            theta[r] -= mean;
        }
    }
    let mut labels = vec![0i32; d];
    let mut margins = vec![0.0; d];
    for q in 0..d {
        let (best, second, arg) = best_two(theta.iter().enumerate().map(|(r, &th)| log(r, q) + th));
        labels[q] = arg as i32;
        // (best − second) / best of the scaled scores exp(s): 1 − exp(second − best).
        margins[q] = if best.is_finite() {
            (1.0 - (second - best).exp()).clamp(0.0, 1.0)
        } else {
            0.0
        };
    }
    (labels, margins)
}

/// The area band of [`assign_sized`], relative to each region's target area.
#[derive(Clone, Copy)]
enum Band {
    /// `[target / (1 + τ), target (1 + τ)]` ([`RefineSizes::Keep`]).
    Tolerance(f64),
    /// `[share · target, ∞)` (the free rule's floor, `MIN_KEPT_SHARE`).
    Floor(f64),
}

/// Passes over the regions of the factor search of [`assign_sized`] per shape update.
const SIZE_PASSES: usize = 20;

/// The free rule's floor: on every shape, a region keeps at least this share of its area
/// before refinement. Why: the free best response scores a region by its *mean* affinity, so
/// a region spread thin in band space (typically the leftovers, a mixture) scores low
/// everywhere; once it shrinks on every shape at once nothing pulls vertices back, and it
/// empties — a degenerate fixed point with one region fewer than asked (measured on COSEG
/// chairs, spectral + extrinsic with 16 normals, `--regions 3`: the third region empties in 7
/// sweeps; docs/PARTS.md). A shape update whose free labels leave a region below the floor is
/// redone by the size-aware assignment of [`RefineSizes::Keep`] with the band `[floor, ∞)`:
/// the boundaries still move where the scores cross, and updates that keep every region above
/// its floor are the free rule bit for bit. Measured at 0.25 and 0.1: 0.25 lowered 20 FAUST
/// from 94.1 to 93.5 %, 0.1 raised it to 94.5 % (TOSCA cats and michael unchanged).
const MIN_KEPT_SHARE: f64 = 0.1;

/// Area share of each of `regions` regions under `labels` (`areas` sum to 1).
fn region_shares(labels: &[i32], areas: &[f64], regions: usize) -> Vec<f64> {
    let mut shares = vec![0.0; regions];
    for (&l, &a) in labels.iter().zip(areas) {
        if l >= 0 && (l as usize) < regions {
            shares[l as usize] += a;
        }
    }
    shares
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
    non_negative("smoothing_time", options.smoothing_time).map_err(GraphError::BadOption)?;
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
