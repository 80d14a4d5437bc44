use super::spectral_product::spectral_product;
use crate::spectral::Spectrum;
use faer::Mat;

/// Heat kernel signature `HKS(v, t) = Σ_i exp(−λ_i t) φ_i(v)²` over all eigenpairs of the
/// (unit-area) spectrum, for each time in `times`.
///
/// Returns `times.len() × d` values, feature-major (`out[j * d + v]` is `HKS(v, times[j])`).
/// Unscaled (no division by `Σ_i exp(−λ_i t)`): scaling by a per-time constant does not change
/// ranks. Deterministic and bit-identical for any number of threads.
///
/// ```
/// use coseg::spectral::Spectrum;
/// use coseg::features::heat_kernel_signature;
/// // One vertex, one constant eigenvector of eigenvalue 0.
/// let s = Spectrum { eigenvalues: vec![0.0], eigenvectors: vec![1.0], vertex_areas: vec![1.0], original_area: 1.0 };
/// assert_eq!(heat_kernel_signature(&s, &[0.1]), vec![1.0]);
/// ```
pub fn heat_kernel_signature(spectrum: &Spectrum, times: &[f64]) -> Vec<f64> {
    let lambda = &spectrum.eigenvalues;
    let coeffs = Mat::from_fn(times.len(), lambda.len(), |j, i| {
        (-lambda[i] * times[j]).exp()
    });
    spectral_product(spectrum.eigenvector_matrix(), coeffs.as_ref(), true)
}
