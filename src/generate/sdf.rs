//! Signed distance functions of the primitives shapes are built from, smooth union, and the
//! deterministic trigonometry and random numbers the families use.
//!
//! Everything here uses only `+ − × ÷ sqrt` and comparisons (IEEE-754 correctly rounded), never
//! the platform's `sin`/`cos`/`exp`, so a given seed produces bit-identical shapes on every
//! platform.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{Rng, SeedableRng};

// The mesh's vector helpers (only `+ − ×` and `sqrt`, like the rest of this module).
pub(crate) use crate::mesh::{dot, norm as len, sub};

/// A point or vector in 3D.
pub(crate) type V3 = [f64; 3];

#[inline]
pub(crate) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline]
pub(crate) fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// sin(x) from a Taylor series after reduction to [−π, π]; accurate to ~1e-15, deterministic.
pub(crate) fn det_sin(x: f64) -> f64 {
    const PI: f64 = std::f64::consts::PI;
    const TAU: f64 = 2.0 * PI;
    let mut x = x - TAU * (x / TAU).round();
    // Reduce further to [−π/2, π/2] with sin(π − x) = sin(x).
    if x > PI / 2.0 {
        x = PI - x;
    } else if x < -PI / 2.0 {
        x = -PI - x;
    }
    let x2 = x * x;
    let mut term = x;
    let mut sum = x;
    let mut n = 1.0;
    for _ in 0..12 {
        term = -term * x2 / ((n + 1.0) * (n + 2.0));
        sum += term;
        n += 2.0;
    }
    sum
}

/// cos(x) = sin(x + π/2), deterministic.
pub(crate) fn det_cos(x: f64) -> f64 {
    det_sin(x + std::f64::consts::FRAC_PI_2)
}

/// Rotation matrix (rows) about the x, y or z axis by `angle` radians (right-hand rule).
pub(crate) fn rotation(axis: usize, angle: f64) -> [V3; 3] {
    let (s, c) = (det_sin(angle), det_cos(angle));
    match axis {
        0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
    }
}

/// `m · v`.
pub(crate) fn mat_vec(m: &[V3; 3], v: V3) -> V3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// `mᵀ · v` (the inverse rotation).
pub(crate) fn mat_t_vec(m: &[V3; 3], v: V3) -> V3 {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}

/// `a · b`.
pub(crate) fn mat_mul(a: &[V3; 3], b: &[V3; 3]) -> [V3; 3] {
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    r
}

/// Polynomial smooth minimum with blend radius `k` (exact `min` when the two values differ by
/// more than `k`).
#[inline]
pub(crate) fn smin(a: f64, b: f64, k: f64) -> f64 {
    if k <= 0.0 {
        return a.min(b);
    }
    let h = (0.5 + 0.5 * (b - a) / k).clamp(0.0, 1.0);
    b + (a - b) * h - k * h * (1.0 - h)
}

/// One solid primitive, as a signed distance function (negative inside).
#[derive(Debug, Clone)]
pub(crate) enum Primitive {
    /// Segment `a`–`b` swept by a radius varying linearly from `ra` to `rb`.
    Capsule { a: V3, b: V3, ra: f64, rb: f64 },
    /// Axis-aligned (in its own frame) ellipsoid with semi-axes `r`, rotated by `rot`.
    Ellipsoid { c: V3, r: V3, rot: [V3; 3] },
    /// Box with half extents `half` (rounding included) and corner radius `round`, rotated.
    RoundBox {
        c: V3,
        half: V3,
        round: f64,
        rot: [V3; 3],
    },
    /// Vertical cylinder of radius `r` and half height `h` around `c`, edges rounded by `round`.
    RoundCylinder { c: V3, r: f64, h: f64, round: f64 },
    /// Spherical shell of mid radius `r`, half thickness `t`, cut by the plane `y = c.y + h`
    /// (the part below it kept, rim rounded), vertically stretched by `sy`.
    Bowl {
        c: V3,
        r: f64,
        h: f64,
        t: f64,
        sy: f64,
    },
    /// Torus of major radius `big` and tube radius `small` in the plane z = c.z, around `c`,
    /// with everything inside the sphere (`cut_c`, `cut_r`) removed.
    CutTorus {
        c: V3,
        big: f64,
        small: f64,
        cut_c: V3,
        cut_r: f64,
    },
}

pub(crate) const IDENTITY: [V3; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

impl Primitive {
    /// Signed distance (exact or a close bound) at `p`.
    pub(crate) fn eval(&self, p: V3) -> f64 {
        match self {
            Primitive::Capsule { a, b, ra, rb } => {
                let pa = sub(p, *a);
                let ba = sub(*b, *a);
                let h = (dot(pa, ba) / dot(ba, ba)).clamp(0.0, 1.0);
                len(sub(pa, scale(ba, h))) - (ra + (rb - ra) * h)
            }
            Primitive::Ellipsoid { c, r, rot } => {
                let q = mat_t_vec(rot, sub(p, *c));
                let k0 = len([q[0] / r[0], q[1] / r[1], q[2] / r[2]]);
                let k1 = len([
                    q[0] / (r[0] * r[0]),
                    q[1] / (r[1] * r[1]),
                    q[2] / (r[2] * r[2]),
                ]);
                if k1 == 0.0 {
                    -r[0].min(r[1]).min(r[2])
                } else {
                    k0 * (k0 - 1.0) / k1
                }
            }
            Primitive::RoundBox {
                c,
                half,
                round,
                rot,
            } => {
                let q = mat_t_vec(rot, sub(p, *c));
                let d = [
                    q[0].abs() - half[0] + round,
                    q[1].abs() - half[1] + round,
                    q[2].abs() - half[2] + round,
                ];
                let outside = len([d[0].max(0.0), d[1].max(0.0), d[2].max(0.0)]);
                outside + d[0].max(d[1]).max(d[2]).min(0.0) - round
            }
            Primitive::RoundCylinder { c, r, h, round } => {
                let q = sub(p, *c);
                let dx = (q[0] * q[0] + q[2] * q[2]).sqrt() - r + round;
                let dy = q[1].abs() - h + round;
                dx.max(dy).min(0.0) + (dx.max(0.0) * dx.max(0.0) + dy.max(0.0) * dy.max(0.0)).sqrt()
                    - round
            }
            Primitive::Bowl { c, r, h, t, sy } => {
                let q = sub(p, *c);
                let q = [q[0], q[1] / sy, q[2]];
                let w = (r * r - h * h).sqrt();
                let qx = (q[0] * q[0] + q[2] * q[2]).sqrt();
                let qy = q[1];
                let d = if h * qx < w * qy {
                    ((qx - w) * (qx - w) + (qy - h) * (qy - h)).sqrt()
                } else {
                    ((qx * qx + qy * qy).sqrt() - r).abs()
                };
                (d - t) * sy.min(1.0)
            }
            Primitive::CutTorus {
                c,
                big,
                small,
                cut_c,
                cut_r,
            } => {
                let q = sub(p, *c);
                let ring = (q[0] * q[0] + q[1] * q[1]).sqrt() - big;
                let torus = (ring * ring + q[2] * q[2]).sqrt() - small;
                torus.max(cut_r - len(sub(p, *cut_c)))
            }
        }
    }

    /// Smallest feature radius, for checking that the grid resolves the primitive.
    pub(crate) fn thickness(&self) -> f64 {
        match self {
            Primitive::Capsule { ra, rb, .. } => ra.min(*rb),
            Primitive::Ellipsoid { r, .. } => r[0].min(r[1]).min(r[2]),
            Primitive::RoundBox { half, .. } => half[0].min(half[1]).min(half[2]),
            Primitive::RoundCylinder { h, .. } => *h,
            Primitive::Bowl { t, sy, .. } => t * sy.min(1.0),
            Primitive::CutTorus { small, .. } => *small,
        }
    }

    /// A box (min, max) containing the primitive.
    pub(crate) fn bounds(&self) -> (V3, V3) {
        match self {
            Primitive::Capsule { a, b, ra, rb } => {
                let r = ra.max(*rb);
                let mut lo = [0.0; 3];
                let mut hi = [0.0; 3];
                for i in 0..3 {
                    lo[i] = a[i].min(b[i]) - r;
                    hi[i] = a[i].max(b[i]) + r;
                }
                (lo, hi)
            }
            Primitive::Ellipsoid { c, r, .. } => {
                let m = r[0].max(r[1]).max(r[2]);
                (sub(*c, [m; 3]), add(*c, [m; 3]))
            }
            Primitive::RoundBox { c, half, .. } => {
                let m = len(*half);
                (sub(*c, [m; 3]), add(*c, [m; 3]))
            }
            Primitive::RoundCylinder { c, r, h, .. } => {
                (sub(*c, [*r, *h, *r]), add(*c, [*r, *h, *r]))
            }
            Primitive::Bowl { c, r, t, sy, .. } => {
                let m = (r + t) * sy.max(1.0);
                (sub(*c, [m; 3]), add(*c, [m; 3]))
            }
            Primitive::CutTorus { c, big, small, .. } => {
                let m = big + small;
                (sub(*c, [m, m, *small]), add(*c, [m, m, *small]))
            }
        }
    }
}

/// A part: primitives united with a smooth minimum of radius `blend`.
#[derive(Debug, Clone)]
pub(crate) struct Part {
    pub(crate) primitives: Vec<Primitive>,
    pub(crate) blend: f64,
}

impl Part {
    pub(crate) fn eval(&self, p: V3) -> f64 {
        let mut d = f64::INFINITY;
        for (i, prim) in self.primitives.iter().enumerate() {
            let e = prim.eval(p);
            d = if i == 0 { e } else { smin(d, e, self.blend) };
        }
        d
    }
}

/// A whole shape: parts (index = label) joined by a smooth minimum of radius `blend`.
#[derive(Debug, Clone)]
pub(crate) struct Model {
    /// `None` for an optional part that this shape does not have.
    pub(crate) parts: Vec<Option<Part>>,
    pub(crate) blend: f64,
}

impl Model {
    /// The shape's signed distance at `p` (negative inside).
    pub(crate) fn eval(&self, p: V3) -> f64 {
        let mut d = f64::INFINITY;
        let mut first = true;
        for part in self.parts.iter().flatten() {
            let e = part.eval(p);
            d = if first { e } else { smin(d, e, self.blend) };
            first = false;
        }
        d
    }

    /// The part whose signed distance is smallest at `p` (lowest index on ties).
    pub(crate) fn label(&self, p: V3) -> u32 {
        let mut best = f64::INFINITY;
        let mut label = 0u32;
        for (i, part) in self.parts.iter().enumerate() {
            if let Some(part) = part {
                let e = part.eval(p);
                if e < best {
                    best = e;
                    label = i as u32;
                }
            }
        }
        label
    }

    /// A box (min, max) containing the shape.
    pub(crate) fn bounds(&self) -> (V3, V3) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for part in self.parts.iter().flatten() {
            for prim in &part.primitives {
                let (l, h) = prim.bounds();
                for i in 0..3 {
                    lo[i] = lo[i].min(l[i]);
                    hi[i] = hi[i].max(h[i]);
                }
            }
        }
        (lo, hi)
    }

    /// Thinnest primitive radius of the shape.
    pub(crate) fn thickness(&self) -> f64 {
        self.parts
            .iter()
            .flatten()
            .flat_map(|p| p.primitives.iter())
            .map(Primitive::thickness)
            .fold(f64::INFINITY, f64::min)
    }
}

/// Seeded parameter source: ChaCha8 seeded from the user seed and a stream tag, with its own
/// u64 → f64 conversion so the numbers do not depend on `rand`'s distribution code.
pub(crate) struct Params {
    rng: ChaCha8Rng,
    /// Every parameter drawn, in draw order, for the manifest.
    pub(crate) drawn: Vec<(String, f64)>,
}

impl Params {
    pub(crate) fn new(seed: u64, stream: u64) -> Self {
        let mut bytes = [0u8; 32];
        bytes[..8].copy_from_slice(&seed.to_le_bytes());
        bytes[8..16].copy_from_slice(&stream.to_le_bytes());
        bytes[16..24].copy_from_slice(b"cosegGEN");
        Params {
            rng: ChaCha8Rng::from_seed(bytes),
            drawn: Vec::new(),
        }
    }

    /// Uniform in [0, 1) with 53 random bits.
    fn unit(&mut self) -> f64 {
        (self.rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A named parameter uniform in [lo, hi], rounded to 1e-4 (the value recorded is the value
    /// used).
    pub(crate) fn uniform(&mut self, name: &str, lo: f64, hi: f64) -> f64 {
        let x = lo + (hi - lo) * self.unit();
        let x = round_to(x, 1e4);
        self.drawn.push((name.to_string(), x));
        x
    }

    /// A named proportion spread over a family: log-uniform in `[lo, hi]`, restricted to the
    /// window of `level` (0: lowest 15% of the log range, 1: middle 30%, 2: top 15%; taken
    /// mod 3), rounded to 1e-4. Shapes at levels 0 and 2 differ by at least `(hi/lo)^0.7`.
    pub(crate) fn spread(&mut self, name: &str, lo: f64, hi: f64, level: usize) -> f64 {
        let (a, b) = [(0.0, 0.15), (0.35, 0.65), (0.85, 1.0)][level % 3];
        let t = a + (b - a) * self.unit();
        // lo · (hi/lo)^t, with a deterministic power: exp2/log2 are not used, so compute
        // (hi/lo)^t by repeated square roots (binary expansion of t, 30 bits).
        let ratio = hi / lo;
        let mut factor = 1.0;
        let mut root = ratio;
        let mut frac = t;
        for _ in 0..30 {
            root = root.sqrt();
            frac *= 2.0;
            if frac >= 1.0 {
                factor *= root;
                frac -= 1.0;
            }
        }
        let x = round_to(lo * factor, 1e4);
        self.drawn.push((name.to_string(), x));
        x
    }

    /// Records a derived or fixed parameter.
    pub(crate) fn record(&mut self, name: &str, value: f64) {
        self.drawn.push((name.to_string(), value));
    }
}

/// `x` rounded to a multiple of `1/per_unit` (nearest integer multiple, exact division).
pub(crate) fn round_to(x: f64, per_unit: f64) -> f64 {
    let k = (x * per_unit).round() as i64;
    k as f64 / per_unit
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn det_trig_matches_std() {
        let mut x = -7.0;
        while x < 7.0 {
            assert!((det_sin(x) - x.sin()).abs() < 1e-13, "sin {x}");
            assert!((det_cos(x) - x.cos()).abs() < 1e-13, "cos {x}");
            x += 0.0137;
        }
    }

    #[test]
    fn primitives_have_correct_sign_and_distance() {
        let cap = Primitive::Capsule {
            a: [0.0; 3],
            b: [1.0, 0.0, 0.0],
            ra: 0.2,
            rb: 0.2,
        };
        assert!((cap.eval([0.5, 0.5, 0.0]) - 0.3).abs() < 1e-12);
        assert!((cap.eval([0.5, 0.0, 0.0]) + 0.2).abs() < 1e-12);
        let bx = Primitive::RoundBox {
            c: [0.0; 3],
            half: [1.0, 0.5, 0.25],
            round: 0.1,
            rot: IDENTITY,
        };
        assert!((bx.eval([2.0, 0.0, 0.0]) - 1.0).abs() < 1e-12);
        assert!((bx.eval([0.0, 0.0, 0.0]) + 0.25).abs() < 1e-12);
        let el = Primitive::Ellipsoid {
            c: [0.0; 3],
            r: [0.5, 0.5, 0.5],
            rot: IDENTITY,
        };
        assert!((el.eval([1.0, 0.0, 0.0]) - 0.5).abs() < 1e-12);
        let bowl = Primitive::Bowl {
            c: [0.0; 3],
            r: 1.0,
            h: 0.0,
            t: 0.1,
            sy: 1.0,
        };
        // On the shell, below the rim: inside; at the centre (cavity): outside.
        assert!(bowl.eval([0.0, -1.0, 0.0]) < 0.0);
        assert!((bowl.eval([0.0, 0.0, 0.0]) - 0.9).abs() < 1e-12);
        assert!(bowl.eval([0.0, 1.0, 0.0]) > 0.0);
    }

    #[test]
    fn spread_stays_in_its_window_and_separates_levels() {
        let mut p = Params::new(3, 0);
        let (lo, hi) = (0.3, 0.9);
        for level in 0..3 {
            let (a, b) = [(0.0, 0.15), (0.35, 0.65), (0.85, 1.0)][level];
            for _ in 0..200 {
                let x = p.spread("x", lo, hi, level);
                let (wlo, whi) = (lo * (hi / lo).powf(a), lo * (hi / lo).powf(b));
                assert!(x >= wlo - 1e-4 && x <= whi + 1e-4, "level {level}: {x}");
            }
        }
        // Level 2 over level 0 is at least (hi/lo)^0.7.
        assert!(f64::powf(hi / lo, 0.7) > 2.0);
    }

    #[test]
    fn params_are_deterministic_per_seed_and_stream() {
        let draw = |seed, stream| {
            let mut p = Params::new(seed, stream);
            (0..5).map(|_| p.uniform("u", 0.0, 1.0)).collect::<Vec<_>>()
        };
        assert_eq!(draw(1, 2), draw(1, 2));
        assert_ne!(draw(1, 2), draw(1, 3));
        assert_ne!(draw(1, 2), draw(2, 2));
    }

    #[test]
    fn smin_is_min_far_apart_and_below_min_near() {
        assert_eq!(smin(1.0, 3.0, 0.5), 1.0);
        assert!(smin(1.0, 1.1, 0.5) < 1.0);
    }
}
