//! Fixtures for the affinity and stable-region tests: random band tables.

use coseg::bands::BandTable;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{Rng, SeedableRng};

/// A random band table with `vertices × features` labels in `0..bands` (seeded).
pub fn random_table(vertices: usize, features: usize, bands: usize, seed: u64) -> BandTable {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let labels = (0..vertices * features)
        .map(|_| (rng.next_u64() % bands as u64) as u8)
        .collect();
    BandTable {
        features,
        vertices,
        bands,
        labels,
    }
}

/// A random table whose every feature has exactly `vertices / bands` vertices per band
/// (requires `bands` to divide `vertices`): a random permutation cut into equal blocks.
pub fn random_equal_table(vertices: usize, features: usize, bands: usize, seed: u64) -> BandTable {
    assert_eq!(vertices % bands, 0);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut labels = vec![0u8; vertices * features];
    let mut perm: Vec<usize> = (0..vertices).collect();
    for k in 0..features {
        for i in (1..vertices).rev() {
            let j = (rng.next_u64() % (i as u64 + 1)) as usize;
            perm.swap(i, j);
        }
        for (pos, &v) in perm.iter().enumerate() {
            labels[v * features + k] = (pos / (vertices / bands)) as u8;
        }
    }
    BandTable {
        features,
        vertices,
        bands,
        labels,
    }
}

/// A table correlated with `base`: each label kept with probability `keep`, else redrawn.
pub fn noisy_copy(base: &BandTable, keep: f64, seed: u64) -> BandTable {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let labels = base
        .labels
        .iter()
        .map(|&l| {
            let u = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
            if u < keep {
                l
            } else {
                (rng.next_u64() % base.bands as u64) as u8
            }
        })
        .collect();
    BandTable {
        labels,
        ..base.clone()
    }
}

/// Seeded uniform values in `[0, 1)`.
pub fn random_vec(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
        .collect()
}

/// Refinement of at most `rounds` sweeps with heat smoothing over `smoothing_time`.
pub fn refinement(rounds: usize, smoothing_time: f64) -> coseg::stable::RefineOptions {
    let mut opts = coseg::stable::RefineOptions::default();
    opts.max_rounds = rounds;
    opts.smoothing_time = smoothing_time;
    opts
}

/// Refinement of at most `rounds` sweeps without heat smoothing (the bare affinity votes).
pub fn unsmoothed_rounds(rounds: usize) -> coseg::stable::RefineOptions {
    refinement(rounds, 0.0)
}
