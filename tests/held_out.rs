//! Each route's accuracy on the sources, every source carried to from the others
//! (`coseg::propagate::held_out_accuracy`).

use coseg::bands::equal_count_bands;
use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
use coseg::propagate::{
    HeldOutInputs, PropagateOptions, RigidSteps, Route, held_out_accuracy, held_out_routes,
};

/// Three shapes with the same 40-vertex band table.
fn three_copies() -> ShapeGraph {
    let vals: Vec<f64> = (0..40).map(|v| v as f64).collect();
    let t = equal_count_bands(&vals, 1, 40, 4).unwrap();
    let nodes: Vec<ShapeNode> = (0..3)
        .map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &[1.0; 40]).unwrap())
        .collect();
    ShapeGraph::build(nodes, &GraphOptions::default()).unwrap()
}

/// The affinity route alone, held out over `annotations` on `graph` (no meshes, no
/// segmentation).
fn affinity_only<'a>(
    graph: &'a ShapeGraph,
    annotations: &'a [Option<Vec<i32>>],
    propagate: &'a PropagateOptions,
) -> HeldOutInputs<'a> {
    HeldOutInputs {
        graph,
        meshes: &[],
        annotations,
        smoothers: None,
        propagate,
        routes: &[Route::Affinity],
        segmentation: None,
        steps: RigidSteps {
            affine: true,
            nonrigid: false,
        },
    }
}

#[test]
fn identical_sources_score_each_other_fully_and_one_source_gives_nothing() {
    let g = three_copies();
    let half: Vec<i32> = (0..40).map(|v| if v < 20 { 0 } else { 1 }).collect();
    let o = PropagateOptions::default();
    let two = [Some(half.clone()), Some(half.clone()), None];
    let acc = held_out_accuracy(&affinity_only(&g, &two, &o))
        .unwrap()
        .expect("two sources: a held-out score");
    assert_eq!(acc.len(), 1);
    assert!(acc[0] > 0.99, "held-out accuracy {acc:?}");
    let one = [Some(half), None, None];
    let none = held_out_accuracy(&affinity_only(&g, &one, &o));
    assert!(none.unwrap().is_none());
}

#[test]
fn a_source_labelled_against_the_others_lowers_the_score() {
    // The third source's labels are the others' exchanged: held out, it receives the other
    // two's labels (wrong everywhere); each of the others, held out, receives a mixture.
    let g = three_copies();
    let half: Vec<i32> = (0..40).map(|v| if v < 20 { 0 } else { 1 }).collect();
    let swapped: Vec<i32> = half.iter().map(|l| 1 - l).collect();
    let o = PropagateOptions::default();
    let ann = [Some(half.clone()), Some(half), Some(swapped)];
    let acc = held_out_accuracy(&affinity_only(&g, &ann, &o))
        .unwrap()
        .unwrap();
    assert!(acc[0] < 0.9, "held-out accuracy {acc:?}");
}

#[test]
fn held_out_runs_keep_each_sources_labels_and_their_scores() {
    let g = three_copies();
    let half: Vec<i32> = (0..40).map(|v| if v < 20 { 0 } else { 1 }).collect();
    let o = PropagateOptions::default();
    let two = [Some(half.clone()), None, Some(half.clone())];
    let h = held_out_routes(&affinity_only(&g, &two, &o))
        .unwrap()
        .expect("two sources: held-out runs");
    assert_eq!(h.sources, vec![0, 2]);
    for (k, labels) in h.labels.iter().enumerate() {
        assert_eq!(labels[0].len(), 40);
        let hit = labels[0].iter().zip(&half).filter(|(a, b)| a == b).count();
        assert!((h.scores[k][0] - hit as f64 / 40.0).abs() < 1e-12);
        assert!(h.residual[k][0].is_nan(), "the affinity has no residual");
    }
    let mean = (h.scores[0][0] + h.scores[1][0]) / 2.0;
    assert!((h.accuracy[0] - mean).abs() < 1e-12);
    let acc = held_out_accuracy(&affinity_only(&g, &two, &o))
        .unwrap()
        .unwrap();
    assert_eq!(acc, h.accuracy);
}
