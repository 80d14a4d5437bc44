//! [`initial_indicator`]: the starting `f⁽⁰⁾` of Algorithm 1 on the remaining vertices of A.

use crate::affinity::BandAffinity;
use crate::bands::BandTable;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};

/// How Algorithms 2 and 3 pick the initial indicator of each pair; parsed from `random` or
/// `extreme` (`coseg pair --init`).
///
/// ```
/// use coseg::stable::Init;
/// assert_eq!("extreme".parse::<Init>().unwrap(), Init::Extreme);
/// assert!("centre".parse::<Init>().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Init {
    /// The paper's choice: each remaining vertex of A independently with probability ½, from a
    /// ChaCha8 generator seeded with `seed` and the pair index.
    Random,
    /// Deterministic: the single remaining vertex of A whose band labels are the most extreme,
    /// `argmax_p Σ_k |2 band_A[k][p] − (K − 1)|` (ties: lowest index): a distinctive point such
    /// as a limb tip, from which the stable pair grows.
    Extreme,
}

/// The initial indicator for pair number `index` (ascending vertex list ⊂ `remaining_a`).
///
/// ```
/// use coseg::affinity::BandAffinity;
/// use coseg::bands::equal_count_bands;
/// use coseg::stable::{initial_indicator, Init};
/// let a = equal_count_bands(&[0.0, 1.0, 2.0, 3.0, 4.0, 5.0], 1, 6, 3).unwrap();
/// let w = BandAffinity::new(&a, &a).unwrap();
/// // Vertices 0, 1 are in band 0 and 4, 5 in band 2: vertex 0 is the first extreme one.
/// assert_eq!(initial_indicator(&w, &[0, 1, 2, 3, 4, 5], Init::Extreme, 7, 0), vec![0]);
/// assert_eq!(initial_indicator(&w, &[2, 3, 5], Init::Extreme, 7, 0), vec![5]);
/// ```
pub fn initial_indicator(
    w: &BandAffinity<'_>,
    remaining_a: &[u32],
    init: Init,
    seed: u64,
    index: usize,
) -> Vec<u32> {
    match init {
        Init::Random => random_half(remaining_a, seed, index),
        Init::Extreme => most_extreme_vertex(w.table_a(), remaining_a)
            .map(|p| vec![p])
            .unwrap_or_default(),
    }
}

/// [`Init::Random`]: each vertex of `remaining` independently with probability ½, from a
/// ChaCha8 generator seeded with `seed` and the pair (or tuple) `index`. The co-segmentation
/// seeds its tuples with it too, so a seed means the same start in both.
pub(crate) fn random_half(remaining: &[u32], seed: u64, index: usize) -> Vec<u32> {
    let mut rng =
        ChaCha8Rng::seed_from_u64(seed ^ (index as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let mut out = Vec::with_capacity(remaining.len() / 2 + 1);
    let mut bits = 0u64;
    for (i, &v) in remaining.iter().enumerate() {
        if i % 64 == 0 {
            bits = rng.next_u64();
        }
        if bits >> (i % 64) & 1 == 1 {
            out.push(v);
        }
    }
    out
}

/// [`Init::Extreme`]: the vertex of `remaining` whose band labels in `table` are the most
/// extreme, `argmax_p Σ_k |2 band[k][p] − (K − 1)|` (ties: the first); `None` when `remaining`
/// is empty. The co-segmentation starts its tuples there too.
pub(crate) fn most_extreme_vertex(table: &BandTable, remaining: &[u32]) -> Option<u32> {
    let k1 = table.bands as i32 - 1;
    let mut best: Option<(i64, u32)> = None;
    for &p in remaining {
        let s: i64 = table
            .row(p as usize)
            .iter()
            .map(|&l| (2 * l as i32 - k1).unsigned_abs() as i64)
            .sum();
        if best.is_none_or(|(bs, _)| s > bs) {
            best = Some((s, p));
        }
    }
    best.map(|(_, p)| p)
}
