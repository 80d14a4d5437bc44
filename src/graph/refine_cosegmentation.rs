//! [`refine_cosegmentation`]: the smoothed best-response refinement of
//! [`refine_partition`](crate::stable::refine_partition), over every edge of a shape graph.

use super::cosegment::Engine;
use super::shape_graph::ShapeGraph;
use super::{Cosegmentation, GraphError};
use crate::spectral::HeatSmoother;
use crate::stable::{RefineOptions, StableError, assign_regions};

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
/// let seg = cosegment(&g, &CosegmentOptions { regions: 3, ..Default::default() }).unwrap();
/// let refined = refine_cosegmentation(&g, &seg, None, &RefineOptions::default()).unwrap();
/// assert_eq!(refined.labels(0), refined.labels(1)); // identical shapes, identical ids
/// ```
pub fn refine_cosegmentation(
    graph: &ShapeGraph,
    coseg: &Cosegmentation,
    smoothers: Option<&[HeatSmoother]>,
    options: &RefineOptions,
) -> Result<Cosegmentation, GraphError> {
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
    let regions = coseg.tuples.len();
    let mut labels: Vec<Vec<i32>> = (0..n).map(|i| coseg.labels(i)).collect();
    let mut margins: Vec<Vec<f64>> = coseg.vertices.iter().map(|&d| vec![0.0; d]).collect();
    if regions == 0 {
        return Ok(coseg.clone());
    }
    let stable = |e: StableError| GraphError::BadOption(e.to_string());
    // One engine per region: engine `r` holds the band histogram of region `r` on every shape,
    // so a shape's scores for region `r` are one mix of its neighbours' histograms and one
    // gather over its vertices.
    let mut engines: Vec<Engine<'_>> = (0..regions).map(|_| Engine::new(graph)).collect();
    let members = |l: &[i32], r: usize| -> Vec<u32> {
        (0..l.len() as u32)
            .filter(|&v| l[v as usize] == r as i32)
            .collect()
    };
    for (r, eng) in engines.iter_mut().enumerate() {
        for (i, l) in labels.iter().enumerate() {
            eng.set_region(i, &members(l, r));
        }
    }
    let all: Vec<Vec<u32>> = coseg
        .vertices
        .iter()
        .map(|&d| (0..d as u32).collect())
        .collect();
    let mut column = Vec::new();
    let (mut rounds, mut converged) = (0, false);
    while rounds < options.max_rounds {
        rounds += 1;
        let mut changed = false;
        for &i in &coseg.order {
            let d = coseg.vertices[i];
            let mut total = vec![0.0; d * regions];
            for (r, eng) in engines.iter_mut().enumerate() {
                eng.scores(i, None, &all[i], &mut column);
                total[r * d..(r + 1) * d].copy_from_slice(&column);
            }
            let smoother = smoothers
                .filter(|_| options.smoothing_time > 0.0)
                .map(|s| &s[i]);
            let (new, margin) = assign_regions(&mut total, regions, smoother).map_err(stable)?;
            if new != labels[i] {
                changed = true;
                for (r, eng) in engines.iter_mut().enumerate() {
                    eng.set_region(i, &members(&new, r));
                }
                labels[i] = new;
            }
            margins[i] = margin;
        }
        if !changed {
            converged = true;
            break;
        }
    }
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
    Ok(out)
}
