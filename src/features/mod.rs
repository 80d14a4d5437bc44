//! Per-vertex feature functions computed from the Laplace–Beltrami spectrum: heat kernel
//! signatures (HKS), wave kernel signatures (WKS) and multiscale mean curvature.
//!
//! # Conventions
//! - Every spectrum is that of the mesh scaled to **unit total area** (see
//!   [`Spectrum`](crate::spectral::Spectrum)), so eigenvalues, diffusion times `t` and energies
//!   `e` are dimensionless and mean the same on every shape.
//! - Features are compared across shapes **by index**: feature `k` of shape A pairs with feature
//!   `k` of shape B. The time and energy grids are therefore chosen by a rule that depends only
//!   on the options (and the eigenpair count `k`, itself an option), never on the shape's own
//!   eigenvalues: see [`scale_grid`] and [`SpectralBand`].
//! - A feature table is feature-major: `values[f * d + v]` is feature `f` at vertex `v`, in the
//!   order HKS (ascending `t`), WKS (ascending `e`), mean curvature (ascending `t`).
//! - Only ranks matter downstream; any monotone transform of a feature gives the same bands.
//!
//! The common call is [`descriptors`] with [`DescriptorOptions::default`] (100 HKS + 100 WKS +
//! 100 mean-curvature scales, as in the paper).

mod columns;
mod descriptors;
mod extrinsic;
mod families;
mod heat_kernel_signature;
mod mean_curvature;
mod multiscale_mean_curvature;
mod scale_grid;
mod sdf;
mod spectral_product;
mod user;
mod wave_kernel_signature;

pub use columns::FeatureColumns;
pub use descriptors::{DescriptorOptions, Descriptors, FeatureKind, descriptors};
pub(crate) use extrinsic::surface_moments;
pub use extrinsic::{
    Alignment, Axis, ExtrinsicOptions, Frame, extrinsic_features, fixed_value_range,
    height_directions, shape_frame,
};
pub use families::{
    FamilyWeights, FeatureFamilies, UserSource, parse_alignment, parse_families,
    parse_family_weights,
};
pub use heat_kernel_signature::heat_kernel_signature;
pub use mean_curvature::{mean_curvature, mean_curvature_resolution};
pub use multiscale_mean_curvature::multiscale_mean_curvature;
pub use scale_grid::{ScaleGrid, SpectralBand, scale_grid};
pub(crate) use sdf::inward_wound;
pub use sdf::{SdfOptions, shape_diameter};
pub use user::{read_user_features, user_feature_path};
pub use wave_kernel_signature::wave_kernel_signature;

use thiserror::Error;

/// Errors of the feature stage.
#[derive(Debug, Error)]
pub enum FeatureError {
    /// The mesh and the spectrum do not have the same number of vertices.
    #[error("mesh has {mesh} vertices but the spectrum has {spectrum}")]
    VertexMismatch {
        /// Vertices of the mesh.
        mesh: usize,
        /// Vertices of the spectrum.
        spectrum: usize,
    },
    /// The spectrum has no eigenpairs (or none with a positive eigenvalue where one is needed).
    #[error("the spectrum has no usable eigenpairs ({0})")]
    EmptySpectrum(String),
    /// A scale option is out of range (non-positive or non-finite bound, empty range…).
    #[error("invalid scale option: {0}")]
    BadScale(String),
    /// An option of a feature family is invalid.
    #[error("invalid feature option: {0}")]
    BadOption(String),
    /// A user feature file is missing, unreadable or malformed.
    #[error("{path}: {message}")]
    UserFile {
        /// The file concerned.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A file could not be written.
    #[error(transparent)]
    Io(#[from] crate::FileError),
    /// Descriptor and band tables do not describe the same vertices/features.
    #[error("inconsistent tables: {0}")]
    Inconsistent(String),
}
