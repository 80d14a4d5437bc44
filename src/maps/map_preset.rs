//! [`map_preset`]: which map-step options suit a pair, from how near-isometric it is.

use super::eigenvalue_discrepancy;
use super::{MapError, PointMapOptions};
use crate::spectral::Spectrum;
use serde::{Deserialize, Serialize};

/// Options of the map step, [`crate::stable::map_guided_refinement`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapGuidedOptions {
    /// The point map's options.
    pub point_map: PointMapOptions,
    /// Weight `β` of the point map's vote against the band affinity, which is scaled to a
    /// best score of 1 at every vertex (default 0.5; `0` ignores the map).
    pub map_weight: f64,
    /// Heat-smoothing time of the blended scores (unit-area surface; default `1e-3`, shorter
    /// than the refinement's: the map already places boundaries smoothly). The smoother given
    /// to [`crate::stable::map_guided_refinement`] should have this time ([`crate::stable::segment_pair`]
    /// builds it); `0` disables smoothing.
    pub smoothing_time: f64,
}

impl MapGuidedOptions {
    /// The map step for near-isometric pairs (two poses of one body): a vote of weight 2 and
    /// a point map whose last match also compares the descriptors (weight 500, see
    /// [`ZoomOutOptions::descriptor_weight`](super::ZoomOutOptions)). On the TOSCA
    /// within-class pairs it scores best (94.6 % against 94.0 % for the default, README); on
    /// shapes that are not near-isometric it trusts the map too much (the shipped quadruped
    /// pair loses 4 points of part purity), hence not the default.
    pub fn near_isometric() -> Self {
        let mut options = Self {
            map_weight: 2.0,
            ..Self::default()
        };
        options.point_map.zoomout.descriptor_weight = 500.0;
        options
    }
}

impl Default for MapGuidedOptions {
    fn default() -> Self {
        MapGuidedOptions {
            point_map: PointMapOptions::default(),
            map_weight: 0.5,
            smoothing_time: 1e-3,
        }
    }
}

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
pub fn map_preset(a: &Spectrum, b: &Spectrum) -> Result<PresetChoice, MapError> {
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
