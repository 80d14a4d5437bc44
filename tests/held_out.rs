//! Each route's accuracy on the sources, every source carried to from the others
//! (`coseg::propagate::held_out_accuracy`).

use coseg::bands::equal_count_bands;
use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
use coseg::propagate::{PropagateOptions, Route, held_out_accuracy};

/// Three shapes with the same 40-vertex band table.
fn three_copies() -> ShapeGraph {
    let vals: Vec<f64> = (0..40).map(|v| v as f64).collect();
    let t = equal_count_bands(&vals, 1, 40, 4).unwrap();
    let nodes: Vec<ShapeNode> = (0..3)
        .map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &[1.0; 40]).unwrap())
        .collect();
    ShapeGraph::build(nodes, &GraphOptions::default()).unwrap()
}

#[test]
fn identical_sources_score_each_other_fully_and_one_source_gives_nothing() {
    let g = three_copies();
    let half: Vec<i32> = (0..40).map(|v| if v < 20 { 0 } else { 1 }).collect();
    let o = PropagateOptions::default();
    let two = [Some(half.clone()), Some(half.clone()), None];
    let acc = held_out_accuracy(&g, &[], &two, None, &o, &[Route::Affinity], None, true)
        .unwrap()
        .expect("two sources: a held-out score");
    assert_eq!(acc.len(), 1);
    assert!(acc[0] > 0.99, "held-out accuracy {acc:?}");
    let one = [Some(half), None, None];
    let none = held_out_accuracy(&g, &[], &one, None, &o, &[Route::Affinity], None, true);
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
    let acc = held_out_accuracy(&g, &[], &ann, None, &o, &[Route::Affinity], None, true)
        .unwrap()
        .unwrap();
    assert!(acc[0] < 0.9, "held-out accuracy {acc:?}");
}
