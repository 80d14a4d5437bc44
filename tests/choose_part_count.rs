//! Tests of `parts::choose_part_count` (src/parts/choose_part_count.rs): the number of parts
//! read from a part tree's merge costs.

use coseg::parts::{PartMerge, PartTree, choose_part_count};

/// A chain tree of `costs.len() + 1` leaves whose merges cost `costs` (in merge order).
fn tree(costs: &[f64]) -> PartTree {
    let leaves = costs.len() + 1;
    let merges = costs
        .iter()
        .enumerate()
        .map(|(k, &c)| PartMerge {
            a: if k == 0 { 0 } else { leaves + k - 1 },
            b: k + 1,
            similarity: (-c).exp(),
        })
        .collect();
    PartTree { leaves, merges }
}

/// Two clear populations of merge costs: the count is the number of expensive merges plus
/// one, and the reason says so.
#[test]
fn the_cut_divides_cheap_merges_from_expensive_ones() {
    let c = choose_part_count(&tree(&[0.05, 0.1, 0.08, 0.12, 0.1, 0.9, 1.0, 1.1]), 8);
    assert_eq!(c.count, 4);
    assert!(c.separation > 0.9, "{c:?}");
    assert!(c.reason.starts_with("4 parts"), "{}", c.reason);
    assert_eq!(c.costs.len(), 8);
}

/// Regression: the largest single jump in cost chose 2 parts on the shipped quadrupeds
/// (costs as measured there, 14 leaves: the last merge joins the two halves of the animal),
/// where the collection has 4 (torso, head, legs, tail); the split of the costs into two
/// classes gives 4 ± 1.
#[test]
fn regression_one_expensive_last_merge_does_not_decide_alone() {
    let costs = [
        0.02, 0.06, 0.07, 0.19, 0.2, 0.21, 0.28, 0.33, 0.37, 0.71, 0.75, 1.1, 1.5,
    ];
    let c = choose_part_count(&tree(&costs), 8);
    assert!((3..=5).contains(&c.count), "{c:?}");
}

/// The count stays within `2..=min(max_parts, leaves − 1)`; tiny trees keep their leaves;
/// the same tree gives the same answer.
#[test]
fn the_count_respects_its_bounds_and_is_deterministic() {
    let costs = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9];
    for max in [1, 2, 3, 5, 20] {
        let c = choose_part_count(&tree(&costs), max);
        assert!(
            c.count >= 2 && c.count <= max.max(2).min(costs.len()),
            "{max}: {c:?}"
        );
        assert_eq!(c, choose_part_count(&tree(&costs), max));
    }
    assert_eq!(choose_part_count(&tree(&[0.3]), 8).count, 2);
    assert_eq!(
        choose_part_count(
            &PartTree {
                leaves: 1,
                merges: vec![]
            },
            8
        )
        .count,
        1
    );
    // Equal costs: nothing separates them; the fewest parts.
    let flat = choose_part_count(&tree(&[0.4; 6]), 8);
    assert_eq!((flat.count, flat.separation), (2, 0.0));
    // Similarities of zero (no likeness at all) are not infinite costs.
    let mut t = tree(&[0.1, 0.1, 0.1]);
    t.merges[2].similarity = 0.0;
    assert!(choose_part_count(&t, 8).costs.iter().all(|c| c.is_finite()));
}
