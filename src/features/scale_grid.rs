use super::FeatureError;

/// The reference band of eigenvalues `[λ_lo, λ_hi]` (unit-area surface) from which every time
/// and energy grid is derived. It is fixed by the options, never read off a shape's spectrum,
/// so that feature `k` means the same scale on every shape of a collection.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum SpectralBand {
    /// Weyl's law for a unit-area surface, `λ_n ≈ 4π n`, evaluated at `n = 1` and `n = k`
    /// (the eigenpair count): `λ_lo = 4π ≈ 12.6`, `λ_hi = 4π k` (≈ 2513 for `k = 200`).
    /// Real unit-area shapes have `λ_1` of about 5–25 (the unit-area sphere: `8π`) and `λ_200`
    /// of about 2000–3000, so this band covers what `k` eigenpairs resolve. Default.
    Weyl,
    /// An explicit band `[lambda_min, lambda_max]`, `0 < lambda_min < lambda_max` (e.g. pooled
    /// over a collection by the caller).
    Fixed {
        /// `λ_lo`.
        lambda_min: f64,
        /// `λ_hi`.
        lambda_max: f64,
    },
}

impl SpectralBand {
    /// `(λ_lo, λ_hi)` for a spectrum of `k` eigenpairs.
    pub fn bounds(&self, k: usize) -> Result<(f64, f64), FeatureError> {
        let (lo, hi) = match *self {
            SpectralBand::Weyl => {
                let four_pi = 4.0 * std::f64::consts::PI;
                (four_pi, four_pi * k.max(2) as f64)
            }
            SpectralBand::Fixed {
                lambda_min,
                lambda_max,
            } => (lambda_min, lambda_max),
        };
        if !(lo > 0.0 && hi > lo && hi.is_finite()) {
            return Err(FeatureError::BadScale(format!(
                "eigenvalue band [{lo}, {hi}] must satisfy 0 < lo < hi < ∞"
            )));
        }
        Ok((lo, hi))
    }
}

/// The time and energy grids of one descriptor configuration (see [`scale_grid`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ScaleGrid {
    /// HKS diffusion times, ascending (dimensionless: unit-area surface).
    pub hks_times: Vec<f64>,
    /// WKS log-energies `e` (natural log of an eigenvalue), ascending.
    pub wks_energies: Vec<f64>,
    /// WKS Gaussian width `σ` in log-eigenvalue units.
    pub wks_sigma: f64,
    /// Diffusion times of the multiscale mean curvature, ascending.
    pub curvature_times: Vec<f64>,
}

/// The scale rule. From the band `[λ_lo, λ_hi] = band.bounds(k)`:
/// - HKS times: `hks_count` values log-spaced in `[4 ln 10 / λ_hi, 4 ln 10 / λ_lo]` (the
///   range of Sun et al. and pyFM's `auto_HKS`, with `λ_1, λ_k` replaced by the band);
/// - WKS: `σ = sigma_multiple · (ln λ_hi − ln λ_lo) / wks_count`, energies evenly spaced in
///   `[ln λ_lo + 2σ, ln λ_hi − 2σ]` (pyFM's `auto_WKS` with the band; the margin is capped at a
///   quarter of the range so that the interval is never empty);
/// - curvature times: `curvature_count` values log-spaced over the same range as HKS.
///
/// A count of 1 gives the (geometric) midpoint. The grids depend only on the arguments: two
/// shapes with the same options and eigenpair count get bit-identical grids.
///
/// ```
/// use coseg::features::{scale_grid, SpectralBand};
/// let g = scale_grid(&SpectralBand::Weyl, 200, 100, 100, 100, 7.0).unwrap();
/// assert_eq!(g.hks_times.len(), 100);
/// assert!(g.hks_times[0] < g.hks_times[99]);
/// ```
pub fn scale_grid(
    band: &SpectralBand,
    k: usize,
    hks_count: usize,
    wks_count: usize,
    curvature_count: usize,
    sigma_multiple: f64,
) -> Result<ScaleGrid, FeatureError> {
    let (lo, hi) = band.bounds(k)?;
    if !(sigma_multiple > 0.0 && sigma_multiple.is_finite()) {
        return Err(FeatureError::BadScale(format!(
            "WKS sigma multiple {sigma_multiple} must be positive and finite"
        )));
    }
    let c = 4.0 * std::f64::consts::LN_10;
    let (t_min, t_max) = (c / hi, c / lo);
    let (e_lo, e_hi) = (lo.ln(), hi.ln());
    let wks_sigma = sigma_multiple * (e_hi - e_lo) / wks_count.max(1) as f64;
    let margin = (2.0 * wks_sigma).min((e_hi - e_lo) / 4.0);
    Ok(ScaleGrid {
        hks_times: geomspace(t_min, t_max, hks_count),
        wks_energies: linspace(e_lo + margin, e_hi - margin, wks_count),
        wks_sigma,
        curvature_times: geomspace(t_min, t_max, curvature_count),
    })
}

fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    match n {
        0 => vec![],
        1 => vec![0.5 * (a + b)],
        _ => (0..n)
            .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
            .collect(),
    }
}

fn geomspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    linspace(a.ln(), b.ln(), n)
        .into_iter()
        .map(f64::exp)
        .collect()
}
