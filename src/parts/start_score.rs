//! [`start_score`]: the mean confidence of a co-segmentation's tuples, by which the collection
//! stage chooses among starts and among feature families.

use crate::graph::Cosegmentation;

/// The score by which [`super::segment_collection`] chooses among starts: the mean confidence of the
/// segmentation's tuples (leftovers included), in `[0, 1]`; `0` for a segmentation of fewer
/// than two tuples. One tuple covering every shape splits nothing and agrees with itself
/// perfectly (confidence 1), so it would beat every real segmentation: with `--parts auto` a
/// start whose extraction finds no stable tuple returned the whole shape as one part and won.
pub fn start_score(segmentation: &Cosegmentation) -> f64 {
    let t = &segmentation.tuples;
    if t.len() < 2 {
        return 0.0;
    }
    t.iter().map(|x| x.confidence).sum::<f64>() / t.len() as f64
}
