//! [`paired_advantage`]: whether one candidate beats another on the same shapes by more than
//! the shapes' own spread would give by chance (a one-sided paired t-test), as
//! [`super::choose_features`] asks of the spectral family against both families.

use serde::Serialize;

/// The paired comparison of two candidates' per-shape values (`a` against `b`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PairedAdvantage {
    /// The shapes (pairs) compared.
    pub shapes: usize,
    /// The mean of the per-shape differences `a_i − b_i`.
    pub mean: f64,
    /// The standard error of that mean: the differences' sample standard deviation over
    /// `√shapes` (0 with fewer than two shapes).
    pub standard_error: f64,
    /// Student's `t = mean / standard_error` (`±∞` when every difference is the same non-zero
    /// value, 0 when all are zero or fewer than two shapes are compared).
    pub t: f64,
    /// The one-sided p-value of `t` under Student's t distribution with `shapes − 1` degrees of
    /// freedom: the probability, were `a` and `b` alike on average, of an advantage of `a` this
    /// large or larger. 1 with fewer than two shapes (no spread, no evidence).
    pub p_value: f64,
}

/// The one-sided paired t-test of `a` over `b` (two values per shape, same order).
///
/// Inputs: `a`, `b` of the same length (pairs beyond the shorter are ignored), finite values.
///
/// Output: the mean difference, its standard error, `t` and the p-value of an advantage of `a`
/// at least this large were the two alike (the differences taken as independent draws of one
/// normal law; shapes of one collection are close to that when none dominates the graph).
/// Deterministic; cost `O(n)`.
///
/// ```
/// use coseg::parts::paired_advantage;
/// // Every shape prefers `a` by about 0.1: significant.
/// let a = [0.9, 0.8, 0.85, 0.95];
/// let b = [0.8, 0.71, 0.74, 0.86];
/// assert!(paired_advantage(&a, &b).p_value < 0.01);
/// // Half the shapes prefer each: no evidence.
/// assert!(paired_advantage(&[0.9, 0.7, 0.9, 0.7], &[0.7, 0.9, 0.7, 0.9]).p_value >= 0.5);
/// ```
pub fn paired_advantage(a: &[f64], b: &[f64]) -> PairedAdvantage {
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    let n = d.len();
    if n < 2 {
        return PairedAdvantage {
            shapes: n,
            mean: d.first().copied().unwrap_or(0.0),
            standard_error: 0.0,
            t: 0.0,
            p_value: 1.0,
        };
    }
    let mean = d.iter().sum::<f64>() / n as f64;
    let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
    let standard_error = (var / n as f64).sqrt();
    // Differences equal to the last rounding bit are one value: a spread below the mean's
    // own rounding carries no information.
    let t = if standard_error > f64::EPSILON * mean.abs().max(f64::MIN_POSITIVE) * 4.0 {
        mean / standard_error
    } else if mean > 0.0 {
        f64::INFINITY
    } else if mean < 0.0 {
        f64::NEG_INFINITY
    } else {
        0.0
    };
    PairedAdvantage {
        shapes: n,
        mean,
        standard_error,
        t,
        p_value: student_t_upper_tail(t, (n - 1) as f64),
    }
}

/// `P(T ≥ t)` for Student's t with `df` degrees of freedom: `½ I_x(df/2, ½)` with
/// `x = df / (df + t²)` for `t ≥ 0`, its complement below.
fn student_t_upper_tail(t: f64, df: f64) -> f64 {
    if t.is_infinite() {
        return if t > 0.0 { 0.0 } else { 1.0 };
    }
    let tail = 0.5 * incomplete_beta(df / (df + t * t), 0.5 * df, 0.5);
    if t >= 0.0 { tail } else { 1.0 - tail }
}

/// The regularised incomplete beta function `I_x(a, b)` by its continued fraction (modified
/// Lentz), on the side where it converges fast (Numerical Recipes, §6.4).
fn incomplete_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front =
        (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_fraction(x, a, b) / a
    } else {
        1.0 - front * beta_fraction(1.0 - x, b, a) / b
    }
}

/// The continued fraction of the incomplete beta function (converges for
/// `x < (a + 1) / (a + b + 2)`); 300 terms bound the loop (the fraction needs `O(√max(a, b))`).
fn beta_fraction(x: f64, a: f64, b: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < TINY {
        d = TINY;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..=300 {
        let m = m as f64;
        let m2 = 2.0 * m;
        for aa in [
            m * (b - m) * x / ((qam + m2) * (a + m2)),
            -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2)),
        ] {
            d = 1.0 + aa * d;
            if d.abs() < TINY {
                d = TINY;
            }
            c = 1.0 + aa / c;
            if c.abs() < TINY {
                c = TINY;
            }
            d = 1.0 / d;
            h *= d * c;
        }
        if (d * c - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

/// `ln Γ(x)` for `x > 0` (Lanczos, g = 7, nine terms: relative error below 1e-15).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x) Γ(1 − x) = π / sin(πx).
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut s = G[0];
    for (i, g) in G.iter().enumerate().skip(1) {
        s += g / (x + i as f64);
    }
    let t = x + 7.5;
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + s.ln()
}
