//! [`choose_part_count`]: how many parts to cut a part tree into, read from the tree's merge
//! costs (`coseg segment` without `--parts N`).

use super::adaptive_cosegment::PartTree;
use serde::Serialize;

/// The number of parts chosen from a part tree, and the evidence (`summary.json`'s
/// `part_count`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartCount {
    /// The number of parts.
    pub count: usize,
    /// The cost `−ln(similarity)` of each merge of the tree, in merge order.
    pub costs: Vec<f64>,
    /// How well the chosen cut separates the merges made from those refused: the share of
    /// the costs' variance between the two classes (Otsu's separability η, in `[0, 1]`).
    pub separation: f64,
    /// One sentence for the user: the count and the reason.
    pub reason: String,
}

/// The cut of `tree` that best separates its merges into cheap ones (inside a part) and
/// expensive ones (across a part boundary): the number of parts `N` (from 2 to
/// `min(max_parts, leaves − 1)`) whose split of the merge costs — the first `L − N` merges
/// made, the last `N − 1` refused — has the largest between-class variance (Otsu's rule on
/// the merge costs, as [`super::AdaptiveOptions`] reads a part's size from its scores).
///
/// Why: merges inside a part join regions of one thickness across convex surface and cost
/// little; merges across a part boundary pay for a thickness jump or a concave crease. The
/// costs are then two populations, and the cut is where they divide; no level or penalty is
/// set by hand. The rule compares whole classes rather than two neighbouring merges, so one
/// expensive last merge (the two halves of a collection) does not decide alone, as the
/// largest single jump in cost would.
///
/// Inputs: a part tree of `L` leaves and `L − 1` merges (similarities in `(0, 1]`),
/// `max_parts ≥ 1`. Output: a [`PartCount`]; with fewer than three leaves, every leaf is a
/// part. Ties: the fewer parts. Deterministic.
///
/// ```
/// use coseg::parts::{PartMerge, PartTree, choose_part_count};
/// let m = |a, b, cost: f64| PartMerge { a, b, similarity: (-cost).exp() };
/// // Three cheap merges inside parts, then two expensive ones: three parts.
/// let tree = PartTree {
///     leaves: 6,
///     merges: vec![m(0, 1, 0.1), m(2, 3, 0.15), m(4, 5, 0.1), m(6, 7, 1.2), m(8, 9, 1.5)],
/// };
/// assert_eq!(choose_part_count(&tree, 8).count, 3);
/// ```
pub fn choose_part_count(tree: &PartTree, max_parts: usize) -> PartCount {
    let costs: Vec<f64> = tree
        .merges
        .iter()
        .map(|m| -m.similarity.clamp(f64::MIN_POSITIVE, 1.0).ln())
        .collect();
    let l = tree.leaves;
    if l < 3 || costs.len() + 1 < l {
        return PartCount {
            count: l,
            costs,
            separation: 0.0,
            reason: format!("{l} parts: too few regions to group"),
        };
    }
    let costs_used = &costs[..l - 1];
    let total = costs_used.len() as f64;
    let mean = costs_used.iter().sum::<f64>() / total;
    let variance = costs_used.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / total;
    let hi = max_parts.max(2).min(l - 1);
    let (mut count, mut between) = (2, f64::NEG_INFINITY);
    for n in 2..=hi {
        // n parts: the first l − n merges are made, the last n − 1 refused.
        let (made, refused) = costs_used.split_at(l - n);
        let (wa, wb) = (made.len() as f64 / total, refused.len() as f64 / total);
        let ma = made.iter().sum::<f64>() / made.len() as f64;
        let mb = refused.iter().sum::<f64>() / refused.len() as f64;
        let b = wa * wb * (mb - ma).powi(2);
        if b > between {
            (count, between) = (n, b);
        }
    }
    let separation = if variance > 0.0 {
        (between / variance).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (made, refused) = costs_used.split_at(l - count);
    let max_made = made.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let min_refused = refused.iter().copied().fold(f64::INFINITY, f64::min);
    PartCount {
        count,
        reason: format!(
            "{count} parts: the part tree's merge costs divide there into {} merges inside parts (at most {max_made:.2}) and {} across parts (from {min_refused:.2}; separation η = {separation:.2})",
            made.len(),
            refused.len(),
        ),
        costs,
        separation,
    }
}
