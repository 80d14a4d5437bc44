//! [`map_preset`]: which map-step options suit a pair, from how near-isometric it is.

use super::eigenvalue_discrepancy;
use crate::spectral::Spectrum;
use crate::stable::{MapGuidedOptions, StableError};
use serde::{Deserialize, Serialize};

/// Eigenvalues compared by [`map_preset`] (`λ_1 … λ_19`).
pub const PRESET_EIGENVALUES: usize = 20;

/// The [`eigenvalue_discrepancy`] below which [`map_preset`] treats a pair as near-isometric.
/// Measured over [`PRESET_EIGENVALUES`]: 0.009–0.023 on the 24 TOSCA within-class pairs,
/// 0.036 and more on the generated quadrupeds (different bodies), 0.05 and more between
/// TOSCA classes (README).
pub const NEAR_ISOMETRIC_DISCREPANCY: f64 = 0.03;

/// A named set of map-step options.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum MapPreset {
    /// [`MapGuidedOptions::default`]: for shapes that are not two poses of one body.
    General,
    /// [`MapGuidedOptions::near_isometric`]: for two poses of one body.
    NearIsometric,
}

impl MapPreset {
    /// The preset's options.
    pub fn options(self) -> MapGuidedOptions {
        match self {
            MapPreset::General => MapGuidedOptions::default(),
            MapPreset::NearIsometric => MapGuidedOptions::near_isometric(),
        }
    }
}

/// What [`map_preset`] chose and why.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PresetChoice {
    /// The chosen preset.
    pub preset: MapPreset,
    /// The pair's [`eigenvalue_discrepancy`] over [`PRESET_EIGENVALUES`] (or fewer, when a
    /// spectrum is shorter).
    pub discrepancy: f64,
}

/// Chooses the map step's preset for shapes A and B from their unit-area spectra:
/// [`MapPreset::NearIsometric`] when their [`eigenvalue_discrepancy`] is below
/// [`NEAR_ISOMETRIC_DISCREPANCY`], else [`MapPreset::General`].
///
/// Why: the near-isometric preset trusts the point map more and matches descriptors
/// pointwise, which is what two poses of one body reward (TOSCA within-class: 95.7 % against
/// 94.3 %) and what different bodies punish (the shipped quadruped pair loses 4 points of
/// part purity). Isometric shapes have equal spectra, so the spectra tell the two apart
/// without any correspondence.
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::spectral::{laplace_beltrami_spectrum, SpectrumOptions};
/// use coseg::maps::{map_preset, MapPreset};
/// let n = 9u32;
/// let pos = (0..n * n).map(|i| [(i % n) as f64, (i / n) as f64, 0.0]).collect();
/// let mut faces = Vec::new();
/// for y in 0..n - 1 { for x in 0..n - 1 {
///     let v = y * n + x;
///     faces.push([v, v + 1, v + n + 1]);
///     faces.push([v, v + n + 1, v + n]);
/// }}
/// let mesh = TriMesh::new(pos, faces).unwrap();
/// let s = laplace_beltrami_spectrum(&mesh, &SpectrumOptions::with_eigenpairs(20)).unwrap();
/// assert_eq!(map_preset(&s, &s).unwrap().preset, MapPreset::NearIsometric);
/// ```
pub fn map_preset(a: &Spectrum, b: &Spectrum) -> Result<PresetChoice, StableError> {
    let count = PRESET_EIGENVALUES.min(a.len()).min(b.len());
    let discrepancy = eigenvalue_discrepancy(a, b, count)?;
    let preset = if discrepancy < NEAR_ISOMETRIC_DISCREPANCY {
        MapPreset::NearIsometric
    } else {
        MapPreset::General
    };
    Ok(PresetChoice {
        preset,
        discrepancy,
    })
}
