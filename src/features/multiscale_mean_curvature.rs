use super::FeatureError;
use super::mean_curvature::mean_curvature;
use super::spectral_product::spectral_product;
use crate::mesh::TriMesh;
use crate::spectral::Spectrum;
use faer::Mat;
use rayon::prelude::*;

/// Multiscale mean curvature: the unit-area mean curvature `H` (see [`mean_curvature`],
/// multiplied by `sqrt(total area)`) diffused by the heat equation in the spectral basis,
/// `H_t = Σ_i exp(−λ_i t) φ_i ⟨φ_i, H⟩_M`, for each time in `times` (unit-area times).
///
/// `⟨f, g⟩_M = Σ_v ω_v f(v) g(v)` with the unit-area vertex areas of `spectrum`. Returns
/// `times.len() × d` values, feature-major (`out[j * d + v]`). Invariant to rigid motions and
/// uniform scaling of the mesh. On a sphere `H_t = sqrt(4π)` for every `t`.
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::dense_spectrum, features::multiscale_mean_curvature};
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.]], vec![[0,1,2],[0,2,3]]).unwrap();
/// let s = dense_spectrum(&m, 4).unwrap();
/// let h = multiscale_mean_curvature(&m, &s, &[0.01]).unwrap();
/// assert!(h.iter().all(|x| x.abs() < 1e-9));
/// ```
pub fn multiscale_mean_curvature(
    mesh: &TriMesh,
    spectrum: &Spectrum,
    times: &[f64],
) -> Result<Vec<f64>, FeatureError> {
    let d = mesh.vertex_count();
    if spectrum.vertex_count() != d {
        return Err(FeatureError::VertexMismatch {
            mesh: d,
            spectrum: spectrum.vertex_count(),
        });
    }
    let scale = mesh.total_area().sqrt();
    let weighted: Vec<f64> = mean_curvature(mesh)
        .iter()
        .zip(&spectrum.vertex_areas)
        .map(|(h, w)| h * scale * w)
        .collect();
    // ⟨φ_i, H⟩_M: one sequential dot product per eigenvector (deterministic).
    let proj: Vec<f64> = (0..spectrum.len())
        .into_par_iter()
        .map(|i| {
            spectrum
                .eigenvector(i)
                .iter()
                .zip(&weighted)
                .map(|(p, w)| p * w)
                .sum()
        })
        .collect();
    let lambda = &spectrum.eigenvalues;
    let coeffs = Mat::from_fn(times.len(), lambda.len(), |j, i| {
        (-lambda[i] * times[j]).exp() * proj[i]
    });
    Ok(spectral_product(
        spectrum.eigenvector_matrix(),
        coeffs.as_ref(),
        false,
    ))
}
