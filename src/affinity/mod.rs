//! The affinity `W` between two shapes as an operator on their band tables (never dense).
//!
//! For shapes `A` (`d_a` vertices) and `B` (`d_b` vertices) with `K` bands and feature pairs
//! `(k_a, k_b)` of weights `w` (summing to one; default: the identity pairing with equal
//! weights `1/N`), the `d_b × d_a` matrix is
//!
//! `W_qp = K / (d_a d_b) · Σ_i w_i [band_B[k_b,i][q] = band_A[k_a,i][p]]`,
//!
//! a transport plan between the uniform measures (rows sum to `1/d_b`, columns to `1/d_a` when
//! `K` divides both vertex counts). [`BandAffinity`] applies `W x` and `Wᵀ y` in
//! `O(N (d_a + d_b))` through per-feature band histograms (docs/METHOD.md §3); [`dense_affinity`] builds
//! the dense matrix for tests on small shapes.

mod band_affinity;
mod dense_affinity;
pub(crate) mod kernel;

pub use band_affinity::{
    AffinityWorkspace, BandAffinity, Direction, FeaturePairing, IndicatorHistogram,
};
pub use dense_affinity::dense_affinity;

use thiserror::Error;

/// Errors of the affinity stage.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum AffinityError {
    /// The two band tables use different band counts `K`.
    #[error("band tables use different band counts: {a} (shape A) vs {b} (shape B)")]
    BandCountMismatch {
        /// `K` of shape A.
        a: usize,
        /// `K` of shape B.
        b: usize,
    },
    /// A band table's label array does not have `vertices × features` entries.
    #[error("band table of shape {shape} has {got} labels, expected {expected}")]
    TableSize {
        /// `"A"` or `"B"`.
        shape: &'static str,
        /// Expected `vertices × features`.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// A label is `≥ K`.
    #[error(
        "band table of shape {shape}: label {label} at vertex {vertex} is not below K = {bands}"
    )]
    LabelOutOfRange {
        /// `"A"` or `"B"`.
        shape: &'static str,
        /// Vertex index.
        vertex: usize,
        /// The offending label.
        label: u8,
        /// `K`.
        bands: usize,
    },
    /// A feature pair refers to a feature a table does not have.
    #[error(
        "feature pair {index} = ({a}, {b}) is out of range ({features_a} features on A, {features_b} on B)"
    )]
    PairOutOfRange {
        /// Index of the pair.
        index: usize,
        /// Feature on A.
        a: usize,
        /// Feature on B.
        b: usize,
        /// Features of A.
        features_a: usize,
        /// Features of B.
        features_b: usize,
    },
    /// Weights are missing, negative, non-finite or all zero, or their count differs from the
    /// number of pairs.
    #[error("invalid feature weights: {0}")]
    BadWeights(String),
    /// No feature pairs, no vertices, or `K = 0`.
    #[error("empty affinity: {0}")]
    Empty(String),
    /// A vector passed to the operator has the wrong length.
    #[error("vector length {got}, expected {expected}")]
    LengthMismatch {
        /// Expected length.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// A vertex index is out of range.
    #[error("vertex index {index} out of range (shape has {vertices} vertices)")]
    IndexOutOfRange {
        /// The index.
        index: usize,
        /// Vertex count.
        vertices: usize,
    },
    /// The dense oracle would be too large.
    #[error("dense affinity of {rows} × {cols} exceeds the oracle limit of {limit} entries")]
    TooLargeForDense {
        /// `d_b`.
        rows: usize,
        /// `d_a`.
        cols: usize,
        /// Maximum entries.
        limit: usize,
    },
}
