//! Tests of `coseg::graph::shape_confidences`: each shape's share of a co-segmentation's
//! confidence (the samples the feature choice pairs across candidates).

mod common;

use common::graph::curve_table;
use common::stable::{noisy_copy, random_vec};
use coseg::graph::{
    CosegmentOptions, Cosegmentation, GraphError, GraphOptions, ShapeGraph, ShapeNode, cosegment,
    shape_confidences,
};

/// Five noisy copies of one curve shape (200 vertices, 32 features, 8 bands), random areas,
/// co-segmented into 5 tuples.
fn collection() -> (ShapeGraph, Cosegmentation) {
    let base = curve_table(200, 32, 8, 0.2, 3);
    let nodes: Vec<ShapeNode> = (0..5u64)
        .map(|i| {
            let areas: Vec<f64> = random_vec(200, 3000 + i).iter().map(|x| 0.5 + x).collect();
            ShapeNode::new(format!("s{i}"), noisy_copy(&base, 0.8, 300 + i), &areas).unwrap()
        })
        .collect();
    let g = ShapeGraph::build(nodes, &GraphOptions::default()).unwrap();
    let mut o = CosegmentOptions::default();
    o.regions = 5;
    let c = cosegment(&g, &o).unwrap();
    (g, c)
}

/// The per-shape values weighted by each shape's spanning-tree degree average to the mean
/// tuple confidence: they split the same IoUs by the shape that receives the carried region.
#[test]
fn the_degree_weighted_mean_is_the_mean_tuple_confidence() {
    let (g, c) = collection();
    let per_shape = shape_confidences(&g, &c).unwrap();
    assert_eq!(per_shape.len(), 5);
    assert!(per_shape.iter().all(|x| (0.0..=1.0).contains(x)));
    let mut degree = vec![0.0; 5];
    for (child, p) in c.parent.iter().enumerate() {
        if let Some(p) = *p {
            degree[child] += 1.0;
            degree[p] += 1.0;
        }
    }
    let weighted: f64 = per_shape
        .iter()
        .zip(&degree)
        .map(|(x, d)| x * d)
        .sum::<f64>()
        / degree.iter().sum::<f64>();
    let tuples = c.tuples.iter().map(|t| t.confidence).sum::<f64>() / c.tuples.len() as f64;
    assert!(
        (weighted - tuples).abs() < 1e-9,
        "{weighted} against {tuples}"
    );
}

/// A shape whose regions are exchanged between two tuples loses its confidence; the values
/// tell which shape disagrees (the comparison can fail).
#[test]
fn a_shape_that_disagrees_has_the_lowest_confidence() {
    let (g, mut c) = collection();
    let before = shape_confidences(&g, &c).unwrap();
    let (first, rest) = c.tuples.split_at_mut(1);
    std::mem::swap(&mut first[0].regions[2], &mut rest[0].regions[2]);
    let after = shape_confidences(&g, &c).unwrap();
    assert!(after[2] < before[2] - 0.1, "{before:?} → {after:?}");
    let lowest = (0..5)
        .min_by(|&a, &b| after[a].total_cmp(&after[b]))
        .unwrap();
    assert_eq!(lowest, 2, "{after:?}");
}

/// A co-segmentation of other shapes is an error, not a panic.
#[test]
fn a_segmentation_of_another_graph_is_rejected() {
    let (g, mut c) = collection();
    c.vertices[1] += 1;
    assert!(matches!(
        shape_confidences(&g, &c),
        Err(GraphError::BadOption(_))
    ));
    let (_, mut c) = collection();
    c.tuples[0].regions[0].push(10_000);
    assert!(matches!(
        shape_confidences(&g, &c),
        Err(GraphError::BadOption(_))
    ));
}
