use super::{SpectralError, Spectrum, cotan_laplacian, lumped_mass};
use crate::mesh::TriMesh;

/// Options of [`laplace_beltrami_spectrum`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpectrumOptions {
    /// Number of eigenpairs `k` (default 200).
    pub eigenpairs: usize,
}

impl Default for SpectrumOptions {
    fn default() -> Self {
        SpectrumOptions { eigenpairs: 200 }
    }
}

/// The `k` smallest eigenpairs of the unit-area-normalised mesh (see [`Spectrum`]).
pub fn laplace_beltrami_spectrum(
    mesh: &TriMesh,
    options: &SpectrumOptions,
) -> Result<Spectrum, SpectralError> {
    // Replaced by the sparse shift-invert Lanczos solver (issue 3).
    dense_spectrum(mesh, options.eigenpairs)
}

/// Reference solver: the `k` smallest eigenpairs by a dense symmetric eigendecomposition of
/// `M^{-1/2} L M^{-1/2}`. O(d³): for small meshes and as a test oracle.
pub fn dense_spectrum(mesh: &TriMesh, k: usize) -> Result<Spectrum, SpectralError> {
    let d = mesh.vertex_count();
    if k > d {
        return Err(SpectralError::TooManyEigenpairs {
            requested: k,
            vertices: d,
        });
    }
    let original_area = mesh.total_area();
    // L is scale invariant; M scales with area, so unit area means M / A.
    let mass: Vec<f64> = lumped_mass(mesh)
        .iter()
        .map(|m| m / original_area)
        .collect();
    let l = cotan_laplacian(mesh);
    let inv_sqrt: Vec<f64> = mass
        .iter()
        .map(|&m| if m > 0.0 { 1.0 / m.sqrt() } else { 0.0 })
        .collect();
    let mut a = faer::Mat::<f64>::zeros(d, d);
    for j in 0..d {
        let rows = l.as_ref().row_idx_of_col_raw(j);
        let vals = l.as_ref().val_of_col(j);
        for (&i, &v) in rows.iter().zip(vals) {
            a[(i, j)] = v * inv_sqrt[i] * inv_sqrt[j];
        }
    }
    let evd = a
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|e| SpectralError::Solver(format!("{e:?}")))?;
    let u = evd.U();
    let s = evd.S();
    let mut eigenvalues = Vec::with_capacity(k);
    let mut eigenvectors = Vec::with_capacity(k * d);
    for i in 0..k {
        eigenvalues.push(s[i]);
        for v in 0..d {
            eigenvectors.push(u[(v, i)] * inv_sqrt[v]);
        }
    }
    Ok(Spectrum {
        eigenvalues,
        eigenvectors,
        vertex_areas: mass,
        original_area,
    })
}
