//! Seeded random similarities: the motions shapes are given to test that results do not
//! depend on how files are oriented, sized and placed.

use coseg::align::Similarity;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::Rng;

/// A uniform number in [0, 1) from 53 random bits.
pub fn unit(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// A uniformly random rotation (unit quaternion from four normals by Box–Muller), a scale in
/// 0.5–2 (log-uniform) and a translation within ±10 on each axis.
pub fn random_similarity(rng: &mut ChaCha8Rng) -> Similarity {
    let mut q = [0.0f64; 4];
    for k in 0..2 {
        let (u1, u2) = (unit(rng).max(1e-12), unit(rng));
        let r = (-2.0 * u1.ln()).sqrt();
        q[2 * k] = r * (std::f64::consts::TAU * u2).cos();
        q[2 * k + 1] = r * (std::f64::consts::TAU * u2).sin();
    }
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    let [w, x, y, z] = q.map(|v| v / n);
    let rotation = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    Similarity {
        rotation,
        scale: 0.5 * 4f64.powf(unit(rng)),
        translation: [0, 1, 2].map(|_| 20.0 * unit(rng) - 10.0),
    }
}
