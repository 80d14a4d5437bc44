//! [`spectral_agreement`]: whether a collection is near-isometric, read from its shapes'
//! Laplace–Beltrami spectra alone (no correspondence, no alignment), as
//! [`super::choose_features`] asks before it may drop the extrinsic family.
//!
//! Why the spectra: the spectral family describes a point the same way on two shapes only as
//! far as the shapes are isometric, and isometric shapes have equal unit-area spectra, so the
//! spectra say whether a consistent spectral co-segmentation can be a correspondence at all.
//! Why each shape's *nearest* partner rather than all pairs: the co-segmentation carries
//! regions along the shape graph's edges, between similar shapes, so what matters is whether
//! a shape has a near-isometric neighbour to carry them from (ten people of FAUST in one pose
//! each: every shape has one, although the median pair of different people does not). Why the
//! map step's criterion ([`crate::maps::map_preset`]): it is the product's one answer to "are
//! these two shapes near-isometric" (poses of one body against different bodies), set on
//! TOSCA pairs, not on the collections the feature choice is measured on.

use crate::maps::{MapPreset, map_preset};
use crate::mesh::TriMesh;
use crate::spectral::{
    SpectralError, Spectrum, SpectrumOptions, available_eigenpairs, laplace_beltrami_spectrum,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Eigenpairs computed per shape: the count [`map_preset`] compares (`λ_0 … λ_19`), so that
/// its criterion is applied as it was set. The low modes are the ones a coarse change of
/// proportions moves; their cost is a small fraction of the per-shape spectrum.
const AGREEMENT_EIGENPAIRS: usize = 20;

/// How far a collection's spectra agree ([`spectral_agreement`]; `summary.json`'s
/// `features.spectral_agreement`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpectralAgreement {
    /// The shapes compared.
    pub shapes: usize,
    /// Shapes whose spectrally nearest other shape is near-isometric to them by the map step's
    /// criterion ([`crate::maps::map_preset`]: [`MapPreset::NearIsometric`]).
    pub with_partner: usize,
    /// Each shape's [`crate::maps::eigenvalue_discrepancy`] to its spectrally nearest other shape (input
    /// order; `None` for a shape whose spectrum could not be computed, or alone).
    pub nearest: Vec<Option<f64>>,
    /// The verdict: more than half the shapes have a near-isometric partner.
    pub near_isometric: bool,
}

/// Whether the collection of `meshes` is near-isometric (module docs).
///
/// Inputs: the meshes (any count; each scaled to unit area by the spectrum). Output: each
/// shape's nearest spectral partner, how many are near-isometric to theirs, and the verdict
/// (a strict majority: a collection that is half poses of one body and half other bodies is not
/// near-isometric as a whole). A mesh whose spectrum cannot be computed (too few vertices, a
/// failed solve) has no partner and counts against the majority. Deterministic; cost one
/// 20-eigenpair spectrum per shape (in parallel) and `shapes²` comparisons of 20 numbers.
///
/// See also [`crate::maps::eigenvalue_discrepancy`], [`crate::maps::map_preset`].
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::parts::spectral_agreement;
/// // A grid, the same grid folded along a line (each triangle moved rigidly: isometric), and
/// // the grid stretched 2 : 1 (not isometric).
/// let grid = |sx: f64, fold: f64| {
///     let n = 9u32;
///     let pos = (0..n * n)
///         .map(|i| {
///             let (x, y) = (sx * (i % n) as f64, (i / n) as f64);
///             let over = (x - 4.0 * sx).max(0.0);
///             [x - over + over * fold.cos(), y, over * fold.sin()]
///         })
///         .collect();
///     let mut faces = Vec::new();
///     for y in 0..n - 1 { for x in 0..n - 1 {
///         let v = y * n + x;
///         faces.push([v, v + 1, v + n + 1]);
///         faces.push([v, v + n + 1, v + n]);
///     }}
///     TriMesh::new(pos, faces).unwrap()
/// };
/// let a = spectral_agreement(&[grid(1.0, 0.0), grid(1.0, 1.0), grid(1.0, 2.0)]);
/// assert!(a.near_isometric && a.with_partner == 3);
/// let b = spectral_agreement(&[grid(1.0, 0.0), grid(2.0, 0.0), grid(3.0, 0.0)]);
/// assert!(!b.near_isometric);
/// ```
pub fn spectral_agreement(meshes: &[TriMesh]) -> SpectralAgreement {
    let spectra: Vec<Option<Spectrum>> =
        meshes.par_iter().map(|m| shape_spectrum(m).ok()).collect();
    agreement_of(&spectra)
}

/// One shape's low unit-area spectrum, sequential inside (the shapes run in parallel).
fn shape_spectrum(mesh: &TriMesh) -> Result<Spectrum, SpectralError> {
    let k = AGREEMENT_EIGENPAIRS.min(available_eigenpairs(mesh));
    let mut options = SpectrumOptions::with_eigenpairs(k);
    options.threads = 1;
    laplace_beltrami_spectrum(mesh, &options)
}

/// [`spectral_agreement`] from the spectra (`None`: not computed).
fn agreement_of(spectra: &[Option<Spectrum>]) -> SpectralAgreement {
    let n = spectra.len();
    let mut nearest: Vec<Option<(f64, bool)>> = vec![None; n];
    for (i, a) in spectra.iter().enumerate() {
        let Some(a) = a else { continue };
        for (j, b) in spectra.iter().enumerate() {
            let Some(b) = b else { continue };
            if i == j {
                continue;
            }
            // Too short a spectrum to compare (fewer than two eigenvalues) is no partner.
            let Ok(choice) = map_preset(a, b) else {
                continue;
            };
            // The first of equally near partners (input order): deterministic.
            if nearest[i].is_none_or(|(d, _)| choice.discrepancy < d) {
                nearest[i] = Some((
                    choice.discrepancy,
                    choice.preset == MapPreset::NearIsometric,
                ));
            }
        }
    }
    let with_partner = nearest.iter().filter(|p| p.is_some_and(|(_, y)| y)).count();
    SpectralAgreement {
        shapes: n,
        with_partner,
        nearest: nearest.iter().map(|p| p.map(|(d, _)| d)).collect(),
        near_isometric: 2 * with_partner > n,
    }
}
