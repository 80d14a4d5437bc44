//! [`Similarity`]: a rotation, a uniform scale and a translation, `x ↦ s R x + t`.

use rand_chacha::rand_core::Rng;
use serde::{Deserialize, Serialize};

/// A similarity transform `x ↦ scale · rotation · x + translation` of 3D points.
///
/// - `rotation`: a proper rotation (orthonormal, determinant +1), row-major: `rotation[i][j]` is
///   row `i`, column `j`;
/// - `scale`: a uniform factor, > 0;
/// - `translation`: added after rotating and scaling, in the units of the output.
///
/// See also: [`register_pair`](super::register_pair) (which returns one),
/// the collection stage (one per shape).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Similarity {
    /// Proper rotation, row-major.
    pub rotation: [[f64; 3]; 3],
    /// Uniform scale (> 0).
    pub scale: f64,
    /// Translation, applied last.
    pub translation: [f64; 3],
}

impl Default for Similarity {
    fn default() -> Self {
        Self::identity()
    }
}

impl Similarity {
    /// The identity transform.
    pub fn identity() -> Self {
        Self {
            rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            scale: 1.0,
            translation: [0.0; 3],
        }
    }

    /// A random similarity: a uniformly distributed rotation (a unit quaternion from four
    /// normal draws, Box–Muller), a scale in 0.5–2 (log-uniform) and a translation within ±10
    /// on each axis; seeded `rng`, same draws, same similarity. For moving a collection at
    /// random to test or benchmark the alignment.
    pub fn random<R: Rng + ?Sized>(rng: &mut R) -> Self {
        // A uniform draw in [0, 1) from the top 53 bits: every value a double holds exactly.
        let mut unit = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let mut q = [0.0f64; 4];
        for k in 0..2 {
            let (u1, u2) = (unit().max(1e-12), unit());
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
        let scale = 0.5 * 4f64.powf(unit());
        let translation = [0, 1, 2].map(|_| 20.0 * unit() - 10.0);
        Self {
            rotation,
            scale,
            translation,
        }
    }

    /// Whether this is exactly the identity (bit for bit): applying it would change nothing.
    pub fn is_identity(&self) -> bool {
        *self == Self::identity()
    }

    /// The image of one point.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let r = &self.rotation;
        let mut out = [0.0; 3];
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.scale * (r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2])
                + self.translation[i];
        }
        out
    }

    /// The image of a direction (rotation only: no scale, no translation).
    pub fn rotate(&self, v: [f64; 3]) -> [f64; 3] {
        let r = &self.rotation;
        [
            r[0][0] * v[0] + r[0][1] * v[1] + r[0][2] * v[2],
            r[1][0] * v[0] + r[1][1] * v[1] + r[1][2] * v[2],
            r[2][0] * v[0] + r[2][1] * v[1] + r[2][2] * v[2],
        ]
    }

    /// The images of many points.
    pub fn apply_all(&self, points: &[[f64; 3]]) -> Vec<[f64; 3]> {
        points.iter().map(|&p| self.apply(p)).collect()
    }

    /// `self ∘ other`: first `other`, then `self`.
    pub fn compose(&self, other: &Similarity) -> Similarity {
        let a = &self.rotation;
        let b = &other.rotation;
        let mut rotation = [[0.0; 3]; 3];
        for (i, row) in rotation.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
            }
        }
        Similarity {
            rotation,
            scale: self.scale * other.scale,
            translation: self.apply(other.translation),
        }
    }

    /// The inverse transform: `inverse().apply(apply(x)) == x` up to rounding.
    pub fn inverse(&self) -> Similarity {
        let r = &self.rotation;
        let rotation = [
            [r[0][0], r[1][0], r[2][0]],
            [r[0][1], r[1][1], r[2][1]],
            [r[0][2], r[1][2], r[2][2]],
        ];
        let s = 1.0 / self.scale;
        let t = self.translation;
        let mut translation = [0.0; 3];
        for (i, o) in translation.iter_mut().enumerate() {
            *o = -s * (rotation[i][0] * t[0] + rotation[i][1] * t[1] + rotation[i][2] * t[2]);
        }
        Similarity {
            rotation,
            scale: s,
            translation,
        }
    }

    /// The angle of `self`'s rotation relative to `other`'s, in degrees (0 to 180): the
    /// geodesic distance between the two rotations.
    pub fn rotation_angle_to(&self, other: &Similarity) -> f64 {
        rotation_angle(&self.rotation, &other.rotation)
    }
}

/// Angle in degrees of `a · bᵀ` (the geodesic distance between two rotations).
pub(crate) fn rotation_angle(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> f64 {
    // trace(a bᵀ) = Σ_ij a_ij b_ij.
    let mut tr = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            tr += a[i][j] * b[i][j];
        }
    }
    ((tr - 1.0) / 2.0).clamp(-1.0, 1.0).acos().to_degrees()
}
