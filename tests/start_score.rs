//! Tests for `coseg::parts::start_score`: the mean tuple confidence by which the collection
//! stage chooses among starts and feature families.

use coseg::graph::{Cosegmentation, RegionTuple};
use coseg::parts::start_score;

fn tuple(confidence: f64, leftover: bool) -> RegionTuple {
    RegionTuple {
        regions: vec![vec![0], vec![0]],
        area_fractions: vec![0.5, 0.5],
        sweeps: 1,
        converged: true,
        cycled: false,
        objective: 0.0,
        confidence,
        cycle_consistency: None,
        leftover,
    }
}

fn segmentation(tuples: Vec<RegionTuple>) -> Cosegmentation {
    Cosegmentation {
        names: vec!["a".into(), "b".into()],
        vertices: vec![2, 2],
        root: 0,
        order: vec![0, 1],
        parent: vec![None, Some(0)],
        alpha: 0.5,
        tuples,
    }
}

/// The mean over every tuple, the leftovers included.
#[test]
fn the_score_is_the_mean_tuple_confidence() {
    let s = segmentation(vec![tuple(0.9, false), tuple(0.7, false), tuple(0.2, true)]);
    assert!((start_score(&s) - 0.6).abs() < 1e-12);
}

/// Regression: one tuple covering every shape splits nothing and agrees with itself
/// (confidence 1), so it beat every real segmentation; it scores 0, as does no tuple.
#[test]
fn start_score_of_a_single_part_is_zero() {
    assert_eq!(start_score(&segmentation(vec![tuple(1.0, true)])), 0.0);
    assert_eq!(start_score(&segmentation(vec![])), 0.0);
}
