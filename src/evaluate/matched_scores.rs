//! [`matched_scores`]: accuracy and per-part IoU of found region ids against ground-truth
//! labels, after mapping each region id to a part.

use super::{EvaluateError, rand_index};
use serde::Serialize;
use std::collections::BTreeMap;

/// Scores of one folder of results (see [`matched_scores`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MatchedScores {
    /// Region id → ground-truth part it was mapped to (its majority part, pooled over shapes).
    pub mapping: BTreeMap<i32, i32>,
    /// Fraction of all vertices whose mapped part is their true part.
    pub accuracy: f64,
    /// Ground-truth part → IoU of the vertices mapped to it with the vertices in it (pooled).
    pub part_iou: BTreeMap<i32, f64>,
    /// Mean of `part_iou`.
    pub mean_iou: f64,
    /// Per shape: (accuracy, Rand index), in the order given.
    pub per_shape: Vec<(f64, f64)>,
}

/// Scores found region ids against ground-truth part labels over a collection.
///
/// `shapes[s] = (found, truth)`, both one label per vertex of shape `s`. A region id means
/// the same region on every shape (as `coseg segment` writes them), so each id is mapped to
/// the part holding most of its vertices over all shapes (ties: the smallest part label;
/// `-1`, "no region", is scored like any id). Accuracy and IoU count vertices; the Rand
/// index ([`rand_index`]) needs no mapping. Errors when lengths differ or nothing is given.
///
/// ```
/// use coseg::evaluate::matched_scores;
/// let s = matched_scores(&[(vec![5, 5, 7, 7], vec![0, 0, 1, 0])]).unwrap();
/// assert_eq!(s.mapping[&5], 0);
/// assert_eq!(s.accuracy, 0.75);
/// // Region 7 is split 1–1 between parts 0 and 1: the tie goes to part 0, so every vertex
/// // maps to part 0: IoU 3/4 for part 0, 0 for part 1.
/// assert_eq!(s.mapping[&7], 0);
/// assert_eq!((s.part_iou[&0], s.part_iou[&1]), (0.75, 0.0));
/// ```
pub fn matched_scores(shapes: &[(Vec<i32>, Vec<i32>)]) -> Result<MatchedScores, EvaluateError> {
    if shapes.is_empty() || shapes.iter().all(|s| s.0.is_empty()) {
        return Err(EvaluateError::Empty("no labelled vertices".into()));
    }
    let mut counts: BTreeMap<i32, BTreeMap<i32, usize>> = BTreeMap::new();
    for (i, (found, truth)) in shapes.iter().enumerate() {
        if found.len() != truth.len() {
            return Err(EvaluateError::Shape {
                shape: i.to_string(),
                message: format!(
                    "{} found labels against {} true labels",
                    found.len(),
                    truth.len()
                ),
            });
        }
        for (&f, &t) in found.iter().zip(truth) {
            *counts.entry(f).or_default().entry(t).or_default() += 1;
        }
    }
    let mapping: BTreeMap<i32, i32> = counts
        .iter()
        .map(|(&f, parts)| {
            // max_by_key keeps the last maximum: iterate in reverse to keep the smallest label.
            let best = parts
                .iter()
                .rev()
                .max_by_key(|(_, c)| **c)
                .map_or(-1, |(t, _)| *t);
            (f, best)
        })
        .collect();
    let (mut hit, mut total) = (0usize, 0usize);
    let mut inter: BTreeMap<i32, usize> = BTreeMap::new();
    let mut truth_n: BTreeMap<i32, usize> = BTreeMap::new();
    let mut pred_n: BTreeMap<i32, usize> = BTreeMap::new();
    let mut per_shape = Vec::new();
    for (found, truth) in shapes {
        let mut h = 0usize;
        for (&f, &t) in found.iter().zip(truth) {
            let p = mapping[&f];
            *truth_n.entry(t).or_default() += 1;
            *pred_n.entry(p).or_default() += 1;
            if p == t {
                h += 1;
                *inter.entry(t).or_default() += 1;
            }
        }
        hit += h;
        total += found.len();
        let acc = if found.is_empty() {
            1.0
        } else {
            h as f64 / found.len() as f64
        };
        per_shape.push((acc, rand_index(found, truth)?));
    }
    let part_iou: BTreeMap<i32, f64> = truth_n
        .iter()
        .map(|(&t, &n)| {
            let i = inter.get(&t).copied().unwrap_or(0);
            let union = n + pred_n.get(&t).copied().unwrap_or(0) - i;
            (t, i as f64 / union as f64)
        })
        .collect();
    let mean_iou = part_iou.values().sum::<f64>() / part_iou.len() as f64;
    Ok(MatchedScores {
        mapping,
        accuracy: hit as f64 / total as f64,
        part_iou,
        mean_iou,
        per_shape,
    })
}
