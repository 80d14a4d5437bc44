//! The Laplace–Beltrami spectrum of a triangle mesh: cotangent Laplacian `L`, lumped mass `M`,
//! and the smallest eigenpairs of `L φ = λ M φ`.
//!
//! Entry points: [`SurfaceOperators`] (a mesh's Laplacian, unit-area mass and cotangent weights,
//! under one rule; on the mesh's triangles or, with [`LaplacianKind::IntrinsicDelaunay`], on its
//! [`IntrinsicDelaunay`] triangulation), [`laplace_beltrami_spectrum`], [`HeatSmoother`].
//!
//! Every spectrum coseg computes is that of the mesh **scaled to unit total area**, so that
//! eigenvalues, diffusion times and energies mean the same on every shape of a collection,
//! whatever the units of its file. Eigenvectors are M-orthonormal for the unit-area mass.

mod block_lanczos;
mod cotan_laplacian;
mod cotangent_weights;
mod heat_smoother;
mod intrinsic_delaunay;
mod laplace_beltrami_spectrum;
mod lumped_mass;
mod shift_invert;
mod surface_operators;

pub use cotan_laplacian::cotan_laplacian;
pub use heat_smoother::HeatSmoother;
pub use intrinsic_delaunay::IntrinsicDelaunay;
pub use laplace_beltrami_spectrum::{
    SpectrumOptions, SpectrumStats, available_eigenpairs, dense_spectrum,
    laplace_beltrami_spectrum, laplace_beltrami_spectrum_with_stats,
};
pub use lumped_mass::lumped_mass;
pub use surface_operators::{LaplacianKind, SurfaceOperators, unresolved_triangles};

use thiserror::Error;

/// Errors of the spectral stage.
#[derive(Debug, Error)]
pub enum SpectralError {
    /// More eigenpairs were asked for than the mesh has vertices.
    #[error("asked for {requested} eigenpairs but the mesh has only {vertices} vertices")]
    TooManyEigenpairs {
        /// Requested count.
        requested: usize,
        /// Number of vertices.
        vertices: usize,
    },
    /// An option is out of its valid range.
    #[error("invalid spectrum option: {0}")]
    InvalidOption(String),
    /// A factorisation or eigensolver failed.
    #[error("eigensolver failed: {0}")]
    Solver(String),
}

/// The `k` smallest eigenpairs of `L φ = λ M φ` for a mesh scaled to unit total area.
///
/// - `eigenvalues`: length `k`, ascending, `λ₀ ≈ 0` (one zero per connected component);
///   units of 1/area for a unit-area surface, i.e. dimensionless.
/// - `eigenvectors`: `d × k`, column-major (`eigenvectors[i * d + v]` is `φ_i(v)`),
///   M-orthonormal: `Φᵀ M Φ = I` with `M = diag(vertex_areas)`.
/// - `vertex_areas`: length `d`, barycentric areas of the unit-area mesh (they sum to 1).
/// - `original_area`: total area of the mesh as read, in squared file units.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Spectrum {
    /// Eigenvalues, ascending.
    pub eigenvalues: Vec<f64>,
    /// Eigenvectors, `d × k` column-major.
    pub eigenvectors: Vec<f64>,
    /// Lumped mass of the unit-area mesh.
    pub vertex_areas: Vec<f64>,
    /// Total area before normalisation.
    pub original_area: f64,
}

impl Spectrum {
    /// Number of vertices `d`.
    pub fn vertex_count(&self) -> usize {
        self.vertex_areas.len()
    }

    /// Number of eigenpairs `k`.
    pub fn len(&self) -> usize {
        self.eigenvalues.len()
    }

    /// True when there are no eigenpairs.
    pub fn is_empty(&self) -> bool {
        self.eigenvalues.is_empty()
    }

    /// Eigenvector `i` (length `d`).
    pub fn eigenvector(&self, i: usize) -> &[f64] {
        let d = self.vertex_count();
        &self.eigenvectors[i * d..(i + 1) * d]
    }

    /// The eigenvectors as a `d × k` faer matrix view.
    pub fn eigenvector_matrix(&self) -> faer::MatRef<'_, f64> {
        faer::MatRef::from_column_major_slice(&self.eigenvectors, self.vertex_count(), self.len())
    }
}
