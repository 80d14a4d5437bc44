//! Stable region pairs between two shapes: thresholding functions and Algorithms 1–3 of the
//! paper (docs/METHOD.md §4), on the never-dense affinity operator of [`crate::affinity`].
//!
//! - [`threshold`]: `P_p`, `P_α`, `P[τ_t]` on a remaining subset.
//! - [`stable_pair`]: Algorithm 1 (stable pair from an initial indicator).
//! - [`stable_pairs_fixed`]: Algorithm 2 (fixed thresholds).
//! - [`stable_pairs_auto`]: Algorithm 3 (automatic thresholds).
//! - [`stable_regions`]: one call from two band tables ([`stable_regions_with`]: on an affinity
//!   already built, e.g. [`pair_affinity`] with per-feature weights).
//! - [`refine_partition`]: smoothed best-response refinement of two corresponding partitions.
//! - [`refine_regions`]: the same on the output of Algorithms 2 and 3.
//! - [`region_point_map`](crate::maps::region_point_map): a vertex map from corresponding regions (functional map + ZoomOut), in [`crate::maps`].
//! - [`map_guided_refinement`]: B's regions re-assigned by band affinity and that map
//!   ([`point_map_refinement`]: the same with a map of your own).
//! - [`segment_pair`]: the whole pair stage in one call (algorithm → refinement → map step).
//! - [`correspondence_ratio`]: quality against a ground-truth map (paper §7.2).

mod correspondence_ratio;
mod extraction;
mod initial_indicator;
mod map_guided_refinement;
mod refine_partition;
mod refine_regions;
mod region_types;
mod segment_pair;
mod stable_pair;
mod stable_pairs_auto;
mod stable_pairs_fixed;
mod stable_regions;
mod threshold;

pub use correspondence_ratio::{
    CorrespondenceStats, VertexMap, correspondence_ratio, correspondence_stats,
};
pub use initial_indicator::{Init, initial_indicator};
pub(crate) use initial_indicator::{most_extreme_vertex, random_half};
pub use map_guided_refinement::{map_guided_refinement, point_map_refinement};
pub(crate) use refine_partition::best_two;
pub use refine_partition::{
    RefineOptions, RefinedPartition, assign_regions, refine_partition, region_scores,
};
pub use refine_regions::refine_regions;
pub use region_types::{
    Algorithm, AreaReference, AutoThreshold, RegionPair, StableRegions, StableRegionsOptions,
    TSearch,
};
pub use segment_pair::{
    PairShape, PairStage, PairTimes, SegmentPairOptions, SegmentedPair, StageFallback, segment_pair,
};
pub use stable_pair::{
    Remaining, StablePair, StablePairOptions, StableWorkspace, stable_pair, stable_pair_with,
};
pub use stable_pairs_auto::stable_pairs_auto;
pub use stable_pairs_fixed::stable_pairs_fixed;
pub use stable_regions::{pair_affinity, stable_regions, stable_regions_with};
pub use threshold::{Threshold, ThresholdScratch, threshold};

use crate::affinity::AffinityError;
use thiserror::Error;

/// Errors of the stable-region stage.
#[derive(Debug, Error)]
pub enum StableError {
    /// The affinity operator rejected its input.
    #[error(transparent)]
    Affinity(#[from] AffinityError),
    /// Area vectors do not match the vertex counts.
    #[error(
        "area vectors have lengths {got_a} and {got_b}, expected {expected_a} and {expected_b}"
    )]
    AreaLength {
        /// `d_a`.
        expected_a: usize,
        /// `d_b`.
        expected_b: usize,
        /// Length given for A.
        got_a: usize,
        /// Length given for B.
        got_b: usize,
    },
    /// A vertex list that must be strictly ascending is not.
    #[error("{0} must be strictly ascending")]
    NotAscending(&'static str),
    /// An option is out of range.
    #[error("invalid option: {0}")]
    BadOption(String),
    /// The spectral stage (a smoother or a spectral map) rejected its input.
    #[error(transparent)]
    Spectral(#[from] crate::spectral::SpectralError),
    /// The correspondence-map stage rejected its input.
    #[error(transparent)]
    Map(#[from] crate::maps::MapError),
    /// A ground-truth map is malformed or unreadable (names the file when there is one).
    #[error("ground-truth map: {0}")]
    BadMap(String),
}

/// `FromStr` for an option enum by the names `coseg pair`'s flags and Python's keywords give
/// its values: the names and the error naming the option kept in one place.
macro_rules! from_names {
    ($ty:ty, $option:literal, $($name:literal => $value:expr),+) => {
        impl std::str::FromStr for $ty {
            type Err = StableError;

            fn from_str(s: &str) -> Result<Self, StableError> {
                match s {
                    $($name => Ok($value),)+
                    _ => Err(StableError::BadOption(format!(
                        concat!($option, " {:?}: expected one of", $(" `", $name, "`"),+),
                        s
                    ))),
                }
            }
        }
    };
}

from_names!(Algorithm, "algorithm", "fixed" => Algorithm::Fixed, "auto" => Algorithm::Auto);
from_names!(Init, "init", "random" => Init::Random, "extreme" => Init::Extreme);
