//! Correspondence maps between two shapes: functional maps refined by ZoomOut
//! ([`zoomout`]), the one-to-one last match ([`auction_assignment`]), the spectra
//! discrepancy ([`eigenvalue_discrepancy`]) and the map-step preset chosen from it
//! ([`map_preset`]), and the vertex map read from region pairs ([`region_point_map`]).
//!
//! This stage sits between [`crate::spectral`] (whose spectra it reads) and
//! [`crate::stable`] (whose map-guided refinement uses these maps).

mod auction_assignment;
mod eigenvalue_discrepancy;
mod map_preset;
mod nearest_rows;
mod region_point_map;
pub(crate) mod zoomout;

pub use auction_assignment::{Assignment, AuctionOptions, CandidateLists, auction_assignment};
pub use eigenvalue_discrepancy::eigenvalue_discrepancy;
pub use map_preset::{
    MapGuidedOptions, MapOverrides, MapPreset, MapStep, PresetChoice, ResolvedMapStep, map_preset,
};
pub use nearest_rows::nearest_candidates;
pub use region_point_map::{MapShape, PointMapOptions, region_point_map};
pub use zoomout::{FinalMatch, ShapeGeometry, ZoomOutOptions, zoomout};

use crate::spectral::SpectralError;
use thiserror::Error;

/// Errors of the correspondence-map stage.
#[derive(Debug, Error)]
pub enum MapError {
    /// An option or an input is out of range (e.g. labels of the wrong length).
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// The spectral stage rejected its input (e.g. a map larger than the spectra).
    #[error(transparent)]
    Spectral(#[from] SpectralError),
}
