//! [`map_preset`]: which map-step options suit a pair, from how near-isometric it is.

use super::eigenvalue_discrepancy;
use super::{MapError, PointMapOptions};
use crate::spectral::Spectrum;
use serde::{Deserialize, Serialize};

/// Options of the map step, [`crate::stable::map_guided_refinement`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
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
const PRESET_EIGENVALUES: usize = 20;

/// The [`eigenvalue_discrepancy`] below which [`map_preset`] treats a pair as near-isometric.
/// Measured over `PRESET_EIGENVALUES`: 0.009–0.023 on the 24 TOSCA within-class pairs,
/// 0.036 and more on the generated quadrupeds (different bodies), 0.05 and more between
/// TOSCA classes (README).
const NEAR_ISOMETRIC_DISCREPANCY: f64 = 0.03;

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
    /// The pair's [`eigenvalue_discrepancy`] over `PRESET_EIGENVALUES` (or fewer, when a
    /// spectrum is shorter).
    pub discrepancy: f64,
}

/// Chooses the map step's preset for shapes A and B from their unit-area spectra:
/// [`MapPreset::NearIsometric`] when their [`eigenvalue_discrepancy`] is below
/// `NEAR_ISOMETRIC_DISCREPANCY`, else [`MapPreset::General`].
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

/// Changes to a preset's options, each `None` keeping the preset's value (`coseg pair`'s
/// `--map-weight`, `--map-size`, `--map-smoothing-time`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct MapOverrides {
    /// [`MapGuidedOptions::map_weight`]; `0` turns the map step off.
    pub map_weight: Option<f64>,
    /// The last functional map's size ([`ZoomOutOptions::final_size`](super::ZoomOutOptions)).
    pub final_size: Option<usize>,
    /// [`MapGuidedOptions::smoothing_time`].
    pub smoothing_time: Option<f64>,
}

impl MapOverrides {
    /// The preset's options with these changes; `None` when the weight is not positive (the
    /// step is off).
    pub fn apply(&self, preset: MapPreset) -> Option<MapGuidedOptions> {
        let mut options = preset.options();
        if let Some(w) = self.map_weight {
            options.map_weight = w;
        }
        if let Some(n) = self.final_size {
            options.point_map.zoomout.final_size = n;
        }
        if let Some(t) = self.smoothing_time {
            options.smoothing_time = t;
        }
        (options.map_weight > 0.0).then_some(options)
    }
}

/// How the map step of [`segment_pair`](crate::stable::segment_pair) gets its options.
///
/// The default, [`MapStep::Auto`], is what `coseg pair` runs with no flags: the preset
/// [`map_preset`] picks from the two spectra.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum MapStep {
    /// The preset [`map_preset`] picks from the two spectra, with the overrides (default:
    /// none).
    Auto(MapOverrides),
    /// This preset whatever the spectra, with the overrides.
    Preset(MapPreset, MapOverrides),
    /// These options as they are (no preset).
    Options(MapGuidedOptions),
    /// No map step.
    Off,
}

impl Default for MapStep {
    fn default() -> Self {
        MapStep::Auto(MapOverrides::default())
    }
}

/// A [`MapStep`] resolved for one pair.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedMapStep {
    /// The map step's options; `None` when it does not run.
    pub options: Option<MapGuidedOptions>,
    /// The preset used and the pair's discrepancy, when the step runs with a preset
    /// ([`MapStep::Auto`] or [`MapStep::Preset`]); `None` otherwise.
    pub preset: Option<PresetChoice>,
}

impl MapStep {
    /// The map step with `preset` (`None`: [`MapStep::Auto`], the preset picked from the two
    /// spectra) and `overrides`, as `coseg pair --map-preset` and the overriding flags state it.
    ///
    /// ```
    /// use coseg::maps::{MapOverrides, MapStep};
    /// assert_eq!(MapStep::with_preset(None, MapOverrides::default()), MapStep::default());
    /// ```
    pub fn with_preset(preset: Option<MapPreset>, overrides: MapOverrides) -> Self {
        match preset {
            None => MapStep::Auto(overrides),
            Some(p) => MapStep::Preset(p, overrides),
        }
    }

    /// The options for shapes with spectra `a` and `b`. The discrepancy is computed for
    /// [`MapStep::Auto`] and [`MapStep::Preset`] (reported with the preset used), and errors
    /// only there.
    pub fn resolve(&self, a: &Spectrum, b: &Spectrum) -> Result<ResolvedMapStep, MapError> {
        let with_preset = |preset: Option<MapPreset>, overrides: &MapOverrides| {
            let choice = map_preset(a, b)?;
            let preset = preset.unwrap_or(choice.preset);
            let options = overrides.apply(preset);
            let preset = options.as_ref().map(|_| PresetChoice {
                preset,
                discrepancy: choice.discrepancy,
            });
            Ok(ResolvedMapStep { options, preset })
        };
        match self {
            MapStep::Auto(o) => with_preset(None, o),
            MapStep::Preset(p, o) => with_preset(Some(*p), o),
            MapStep::Options(o) => Ok(ResolvedMapStep {
                options: Some(o.clone()),
                preset: None,
            }),
            MapStep::Off => Ok(ResolvedMapStep {
                options: None,
                preset: None,
            }),
        }
    }
}
