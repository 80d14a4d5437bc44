//! Stable region pairs between two shapes: thresholding functions and Algorithms 1–3 of the
//! paper (DESIGN §4), on the never-dense affinity operator of [`crate::affinity`].

mod stable_pair;
mod threshold;

pub use stable_pair::{
    Remaining, StablePair, StablePairOptions, StableWorkspace, stable_pair, stable_pair_with,
};
pub use threshold::{Threshold, threshold};

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
    /// A ground-truth map is malformed.
    #[error("ground-truth map: {0}")]
    BadMap(String),
}
