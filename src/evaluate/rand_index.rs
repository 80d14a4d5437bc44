//! [`rand_index`]: agreement of two partitions of the same vertices, label-permutation free.

use super::EvaluateError;
use std::collections::HashMap;

/// The Rand index of two labellings of the same `n` vertices: the fraction of the
/// `n (n − 1) / 2` vertex pairs on which they agree (both put the pair in one class, or both
/// split it). 1 for identical partitions whatever the label values; counted exactly from the
/// contingency table in `O(n)` (vertices are unweighted; every label value, `-1` included, is
/// one class). `n < 2` gives 1.
///
/// ```
/// use coseg::evaluate::rand_index;
/// assert_eq!(rand_index(&[0, 0, 1, 1], &[7, 7, 3, 3]).unwrap(), 1.0);
/// // Pairs: (0,1) agree, (2,3) split in b, the four cross pairs agree: 5 of 6.
/// assert!((rand_index(&[0, 0, 1, 1], &[0, 0, 1, 2]).unwrap() - 5.0 / 6.0).abs() < 1e-15);
/// ```
pub fn rand_index(a: &[i32], b: &[i32]) -> Result<f64, EvaluateError> {
    if a.len() != b.len() {
        return Err(EvaluateError::Shape {
            shape: "rand index".into(),
            message: format!("{} labels against {}", a.len(), b.len()),
        });
    }
    let n = a.len() as u128;
    if n < 2 {
        return Ok(1.0);
    }
    let pairs = |c: u128| c * c.saturating_sub(1) / 2;
    let mut joint: HashMap<(i32, i32), u128> = HashMap::new();
    let mut ca: HashMap<i32, u128> = HashMap::new();
    let mut cb: HashMap<i32, u128> = HashMap::new();
    for (&x, &y) in a.iter().zip(b) {
        *joint.entry((x, y)).or_default() += 1;
        *ca.entry(x).or_default() += 1;
        *cb.entry(y).or_default() += 1;
    }
    let same_both: u128 = joint.values().map(|&c| pairs(c)).sum();
    let same_a: u128 = ca.values().map(|&c| pairs(c)).sum();
    let same_b: u128 = cb.values().map(|&c| pairs(c)).sum();
    let total = pairs(n);
    // Agreements = pairs together in both + pairs apart in both.
    let agree = total + 2 * same_both - same_a - same_b;
    Ok(agree as f64 / total as f64)
}
