use super::spectral_product::spectral_product;
use crate::spectral::Spectrum;
use faer::Mat;

/// Wave kernel signature
/// `WKS(v, e) = Σ_i φ_i(v)² w_i(e) / Σ_i w_i(e)`, `w_i(e) = exp(−(e − ln λ_i)² / 2σ²)`,
/// for each log-energy `e` in `energies` (natural log of a unit-area eigenvalue).
///
/// Eigenpairs with `λ_i ≤ zero_eigenvalue` (the constant mode(s), whose log is undefined) are
/// left out, as in pyFM. The weights are normalised in a numerically safe way (the largest
/// exponent is subtracted first), so energies far outside the spectrum still give finite values;
/// if no eigenvalue exceeds `zero_eigenvalue` every value is 0.
///
/// Returns `energies.len() × d` values, feature-major (`out[j * d + v]`).
///
/// ```
/// use coseg::spectral::Spectrum;
/// use coseg::features::wave_kernel_signature;
/// let s = Spectrum { eigenvalues: vec![0.0, 2.0], eigenvectors: vec![1.0, 1.0, 1.0, -1.0],
///                    vertex_areas: vec![0.5, 0.5], original_area: 1.0 };
/// let w = wave_kernel_signature(&s, &[2f64.ln()], 0.5, 1e-5);
/// assert_eq!(w, vec![1.0, 1.0]);
/// ```
pub fn wave_kernel_signature(
    spectrum: &Spectrum,
    energies: &[f64],
    sigma: f64,
    zero_eigenvalue: f64,
) -> Vec<f64> {
    let lambda = &spectrum.eigenvalues;
    let log_lambda: Vec<Option<f64>> = lambda
        .iter()
        .map(|&l| (l > zero_eigenvalue).then(|| l.ln()))
        .collect();
    let two_sigma2 = 2.0 * sigma * sigma;
    let mut coeffs = Mat::<f64>::zeros(energies.len(), lambda.len());
    for (j, &e) in energies.iter().enumerate() {
        let expo: Vec<Option<f64>> = log_lambda
            .iter()
            .map(|ll| ll.map(|ll| -(e - ll) * (e - ll) / two_sigma2))
            .collect();
        let max = expo
            .iter()
            .flatten()
            .fold(f64::NEG_INFINITY, |a, &b| a.max(b));
        if !max.is_finite() {
            continue;
        }
        let w: Vec<f64> = expo
            .iter()
            .map(|x| x.map_or(0.0, |x| (x - max).exp()))
            .collect();
        let total: f64 = w.iter().sum();
        for (i, wi) in w.into_iter().enumerate() {
            coeffs[(j, i)] = wi / total;
        }
    }
    spectral_product(spectrum.eigenvector_matrix(), coeffs.as_ref(), true)
}
