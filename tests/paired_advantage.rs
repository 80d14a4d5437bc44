//! Tests of `coseg::parts::paired_advantage`: the one-sided paired t-test by which the feature
//! choice asks whether the spectral family's advantage exceeds the probe's sampling error.

use coseg::parts::paired_advantage;

/// Differences `d` as two series (`a = b + d`).
fn with_differences(d: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let b: Vec<f64> = (0..d.len()).map(|i| 0.5 + 0.01 * i as f64).collect();
    (b.iter().zip(d).map(|(x, y)| x + y).collect(), b)
}

/// The mean, standard error and t of the differences 1…5 (mean 3, sample deviation √2.5).
#[test]
fn the_statistic_is_the_mean_difference_over_its_standard_error() {
    let (a, b) = with_differences(&[1.0, 2.0, 3.0, 4.0, 5.0]);
    let p = paired_advantage(&a, &b);
    assert_eq!(p.shapes, 5);
    assert!((p.mean - 3.0).abs() < 1e-12);
    assert!((p.standard_error - (2.5f64 / 5.0).sqrt()).abs() < 1e-12);
    assert!((p.t - 3.0 / (0.5f64).sqrt()).abs() < 1e-9);
    // Swapping the candidates flips the sign of t and takes the other tail.
    let q = paired_advantage(&b, &a);
    assert!((q.t + p.t).abs() < 1e-9);
    assert!((p.p_value + q.p_value - 1.0).abs() < 1e-12);
}

/// The p-value is Student's upper tail: exact forms for 1 and 2 degrees of freedom (Cauchy,
/// `½ − t / (2√(t² + 2))`) and the tabled quantiles 0.95 (5), 0.975 (11), 0.99 (21).
#[test]
fn the_p_value_is_the_upper_tail_of_students_t() {
    // The p-value of `n` (even) differences with mean `t` and standard error 1: half at
    // `t − √(n − 1)`, half at `t + √(n − 1)` (sample deviation √n).
    fn p_of(t: f64, n: usize) -> f64 {
        assert!(n.is_multiple_of(2));
        let half = ((n - 1) as f64).sqrt();
        let d: Vec<f64> = (0..n)
            .map(|i| if i % 2 == 0 { t - half } else { t + half })
            .collect();
        let (a, b) = with_differences(&d);
        let p = paired_advantage(&a, &b);
        assert!((p.t - t).abs() < 1e-9, "t {} against {t}", p.t);
        p.p_value
    }
    for t in [-3.0, -0.5, 0.0, 0.3, 1.0, 2.5, 10.0] {
        let cauchy = 0.5 - f64::atan(t) / std::f64::consts::PI;
        assert!((p_of(t, 2) - cauchy).abs() < 1e-10, "df 1, t {t}");
        // Two degrees of freedom: mean t, sample deviation 1, standard error 1/√3.
        let d = [t - 1.0, t, t + 1.0];
        let (a, b) = with_differences(&d);
        let p = paired_advantage(&a, &b);
        let tt = t * 3f64.sqrt();
        let exact = 0.5 - tt / (2.0 * (tt * tt + 2.0).sqrt());
        assert!((p.p_value - exact).abs() < 1e-10, "df 2, t {tt}");
    }
    assert!((p_of(2.015_048_4, 6) - 0.05).abs() < 1e-6);
    assert!((p_of(2.200_985_2, 12) - 0.025).abs() < 1e-6);
    assert!((p_of(2.517_648_0, 22) - 0.01).abs() < 1e-6);
}

/// Degenerate series: fewer than two shapes give no evidence (p = 1); identical non-zero
/// differences are certain (p = 0 or 1 by their sign); no difference gives p = ½.
#[test]
fn degenerate_series_have_a_defined_p_value() {
    assert_eq!(paired_advantage(&[], &[]).p_value, 1.0);
    assert_eq!(paired_advantage(&[0.9], &[0.1]).p_value, 1.0);
    assert_eq!(paired_advantage(&[0.9, 0.8], &[0.8, 0.7]).p_value, 0.0);
    assert_eq!(paired_advantage(&[0.7, 0.6], &[0.8, 0.7]).p_value, 1.0);
    assert_eq!(paired_advantage(&[0.5, 0.6], &[0.5, 0.6]).p_value, 0.5);
}

/// The case the feature choice is about: a small mean advantage with shapes favouring each
/// candidate is not significant, a large one shared by every shape is.
#[test]
fn a_small_advantage_inside_the_spread_is_not_significant() {
    let (a, b) = with_differences(&[0.06, -0.03, 0.05, -0.02, 0.04, 0.0]);
    assert!(paired_advantage(&a, &b).p_value > 0.05);
    let (a, b) = with_differences(&[0.09, 0.11, 0.1, 0.12, 0.08, 0.1]);
    assert!(paired_advantage(&a, &b).p_value < 1e-4);
}
