//! Tests of `coseg::evaluate::rand_index` and `matched_scores` against brute-force oracles.

use coseg::evaluate::{matched_scores, rand_index};
use proptest::prelude::*;

/// The definition: agreeing pairs over all pairs, by enumeration.
fn brute_rand(a: &[i32], b: &[i32]) -> f64 {
    let n = a.len();
    let (mut agree, mut total) = (0usize, 0usize);
    for i in 0..n {
        for j in i + 1..n {
            total += 1;
            if (a[i] == a[j]) == (b[i] == b[j]) {
                agree += 1;
            }
        }
    }
    if total == 0 {
        1.0
    } else {
        agree as f64 / total as f64
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(18), ..ProptestConfig::default() })]
    #[test]
    fn rand_index_equals_pair_enumeration(
        pairs in proptest::collection::vec((-1i32..4, -1i32..5), 0..60),
        relabel in 1i32..50,
    ) {
        let (a, b): (Vec<i32>, Vec<i32>) = pairs.into_iter().unzip();
        let ri = rand_index(&a, &b).unwrap();
        prop_assert!((ri - brute_rand(&a, &b)).abs() < 1e-12);
        prop_assert_eq!(ri, rand_index(&b, &a).unwrap());
        // Renaming the classes of one labelling changes nothing.
        let renamed: Vec<i32> = a.iter().map(|x| x * 7 + relabel).collect();
        prop_assert_eq!(ri, rand_index(&renamed, &b).unwrap());
    }
}

#[test]
fn rand_index_is_one_only_for_equal_partitions_and_rejects_length_mismatch() {
    assert_eq!(rand_index(&[1, 1, 2], &[5, 5, 9]).unwrap(), 1.0);
    assert!(rand_index(&[1, 1, 2], &[5, 9, 9]).unwrap() < 1.0);
    assert_eq!(rand_index(&[], &[]).unwrap(), 1.0);
    let e = rand_index(&[1], &[1, 2]).unwrap_err().to_string();
    assert!(e.contains("1 labels against 2"), "{e}");
}

#[test]
fn matched_scores_pool_the_mapping_over_shapes() {
    // Region 3 is mostly part 0 over the two shapes (3 of 4 vertices), region 8 part 1.
    let s = matched_scores(&[
        (vec![3, 3, 8, 8], vec![0, 0, 1, 1]),
        (vec![3, 3, 8, 8], vec![0, 1, 1, 1]),
    ])
    .unwrap();
    assert_eq!(s.mapping.get(&3), Some(&0));
    assert_eq!(s.mapping.get(&8), Some(&1));
    assert_eq!(s.accuracy, 7.0 / 8.0);
    assert_eq!(s.per_shape[0].0, 1.0);
    assert_eq!(s.per_shape[1].0, 0.75);
    // Part 0: truth {3 vertices}, predicted {4}, both 3 -> 3/4; part 1: 4 of 5 -> 4/5.
    assert_eq!(s.part_iou.get(&0), Some(&0.75));
    assert_eq!(s.part_iou.get(&1), Some(&0.8));
    assert!(matched_scores(&[]).is_err());
    assert!(matched_scores(&[(vec![1], vec![1, 2])]).is_err());
}
