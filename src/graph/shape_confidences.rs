//! [`shape_confidences`]: each shape's share of a co-segmentation's confidence, the samples a
//! comparison of two co-segmentations of the same shapes pairs (`parts::choose_features`).

use super::GraphError;
use super::cosegment::{Cosegmentation, Engine, iou};
use super::shape_graph::ShapeGraph;
use crate::stable::{Threshold, ThresholdScratch, threshold};
use crate::vertex_sets::remove_sorted;

/// Each shape's confidence in `segmentation`: the mean, over its tuples (the leftovers
/// included), of the mean area IoU between the shape's region and the region each
/// spanning-tree neighbour carries onto it (keeping as many vertices as the shape's region),
/// in `[0, 1]`; the tuple confidence of [`super::cosegment`] split by the shape that receives
/// the carried region. The tuple confidences average the same IoUs over every tree edge in both
/// directions, so the mean of these values weighted by each shape's tree degree is the mean
/// tuple confidence (`parts::start_score`).
///
/// Inputs: `graph`, the graph `segmentation` was computed on (same shapes and vertex counts;
/// its spanning tree is the segmentation's `parent`).
///
/// Output: one value per shape, graph order; a shape without a tree neighbour (a single
/// shape) gets 1, as a tuple without an edge does.
///
/// Cost: one carried region per tree edge, direction and tuple (the cost of the confidences
/// [`super::cosegment`] computes, without its sweeps).
///
/// Errors: [`GraphError::BadOption`] when `segmentation` does not belong to `graph` (another
/// shape count or vertex count, or a parent out of range).
pub fn shape_confidences(
    graph: &ShapeGraph,
    segmentation: &Cosegmentation,
) -> Result<Vec<f64>, GraphError> {
    let n = graph.node_count();
    let belongs = segmentation.vertices.len() == n
        && segmentation.parent.len() == n
        && (0..n).all(|i| graph.node(i).bands.vertices == segmentation.vertices[i])
        && segmentation.parent.iter().flatten().all(|&p| p < n)
        && segmentation.tuples.iter().all(|t| {
            t.regions.len() == n
                && t.regions.iter().zip(&segmentation.vertices).all(|(r, &v)| {
                    r.windows(2).all(|w| w[0] < w[1]) && r.last().is_none_or(|&x| (x as usize) < v)
                })
        });
    if !belongs {
        return Err(GraphError::BadOption(
            "shape confidences: the co-segmentation is not of this graph".into(),
        ));
    }
    let mut eng = Engine::new(graph);
    let mut rem: Vec<Vec<u32>> = (0..n)
        .map(|i| (0..graph.node(i).bands.vertices as u32).collect())
        .collect();
    let (mut sum, mut count) = (vec![0.0; n], vec![0usize; n]);
    let (mut scores, mut carried) = (Vec::new(), Vec::new());
    let mut scratch = ThresholdScratch::default();
    for t in &segmentation.tuples {
        for (i, region) in t.regions.iter().enumerate() {
            eng.set_region(i, region);
        }
        let mut per_shape = vec![(0.0, 0usize); n];
        for (c, p) in segmentation.parent.iter().enumerate() {
            let Some(p) = *p else { continue };
            for (dst, src) in [(c, p), (p, c)] {
                let areas = &graph.node(dst).areas;
                eng.scores(dst, Some(&[src]), &rem[dst], &mut scores);
                threshold(
                    Threshold::Count(t.regions[dst].len()),
                    &rem[dst],
                    &scores,
                    areas,
                    1.0,
                    &mut carried,
                    &mut scratch,
                );
                per_shape[dst].0 += iou(areas, &t.regions[dst], &carried);
                per_shape[dst].1 += 1;
            }
        }
        for (i, &(s, k)) in per_shape.iter().enumerate() {
            sum[i] += if k > 0 { s / k as f64 } else { 1.0 };
            count[i] += 1;
        }
        for (i, region) in t.regions.iter().enumerate() {
            remove_sorted(&mut rem[i], region);
        }
    }
    Ok(sum
        .iter()
        .zip(&count)
        .map(|(&s, &k)| if k > 0 { s / k as f64 } else { 1.0 })
        .collect())
}
