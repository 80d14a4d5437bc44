//! Seeded random similarities: the motions shapes are given to test that results do not
//! depend on how files are oriented, sized and placed.
// examples/bench_align includes this file for `random_similarity` and `net_motions` alone.
#![allow(dead_code)]

use coseg::align::{CollectionAlignment, Similarity};
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::Rng;

/// A uniform number in [0, 1) from 53 random bits.
pub fn unit(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// A uniformly random rotation, a scale in 0.5–2 (log-uniform) and a translation within ±10 on
/// each axis ([`Similarity::random`]).
pub fn random_similarity(rng: &mut ChaCha8Rng) -> Similarity {
    Similarity::random(rng)
}

/// Per shape, the recovered transform after the true motion (`recovered ∘ true`): the same
/// rotation for every shape when the collection frame is right.
pub fn net_motions(alignment: &CollectionAlignment, truth: &[Similarity]) -> Vec<Similarity> {
    alignment
        .shapes
        .iter()
        .zip(truth)
        .map(|(s, t)| s.transform.compose(t))
        .collect()
}
