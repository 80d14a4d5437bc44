//! Band-label tables: each feature's sorted order on a shape cut into `K` equal blocks, one
//! `u8` label per (vertex, feature).
//!
//! Only ranks matter: any monotone transform of a feature gives the same table.

use thiserror::Error;

mod area_weighted_bands;
mod band_table;

pub use area_weighted_bands::area_weighted_bands;
pub use band_table::{BandOptions, BandWeighting, band_table};

/// Errors of the band stage.
#[derive(Debug, Error)]
pub enum BandError {
    /// `K` must be in `1..=256` to fit a `u8` label.
    #[error("band count K = {0} must be in 1..=256")]
    BadBandCount(usize),
    /// The feature array does not have `features × vertices` entries.
    #[error(
        "expected {expected} feature values ({features} features × {vertices} vertices), got {got}"
    )]
    ShapeMismatch {
        /// Features.
        features: usize,
        /// Vertices.
        vertices: usize,
        /// Expected length.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// The vertex weights of area-weighted bands are not `d` finite non-negative numbers with a
    /// positive sum.
    #[error("bad vertex weights: {0}")]
    BadWeights(String),
    /// A feature value is NaN.
    #[error("feature {feature} is NaN at vertex {vertex}")]
    NaN {
        /// Feature index.
        feature: usize,
        /// Vertex index.
        vertex: usize,
    },
}

/// Per-shape band labels: `labels[v * features + k]` is the band (`0..bands`) of vertex `v`
/// in feature `k`.
///
/// Layout: vertex-major (each vertex's `N` labels contiguous). The affinity operator reads a
/// vertex's whole row at once both when it scatters `x_p` into per-feature histograms and when
/// it gathers `(W x)_q`, so this is the layout it streams fastest.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct BandTable {
    /// Number of features `N`.
    pub features: usize,
    /// Number of vertices `d`.
    pub vertices: usize,
    /// Number of bands `K` (labels are `0..K`).
    pub bands: usize,
    /// `d × N` labels, vertex-major.
    pub labels: Vec<u8>,
}

impl BandTable {
    /// The `N` labels of vertex `v`.
    #[inline]
    pub fn row(&self, v: usize) -> &[u8] {
        &self.labels[v * self.features..(v + 1) * self.features]
    }

    /// The label of vertex `v` in feature `k`.
    #[inline]
    pub fn label(&self, v: usize, k: usize) -> u8 {
        self.labels[v * self.features + k]
    }
}

/// Equal-count band labels: for each feature, sort the vertices by value (ties by vertex
/// index), cut the order into `bands` consecutive blocks whose sizes differ by at most one
/// (the larger blocks first), and label each vertex with its block.
///
/// `values` is feature-major: `values[k * vertices + v]`.
///
/// ```
/// use coseg::bands::equal_count_bands;
/// let t = equal_count_bands(&[3.0, 1.0, 2.0, 0.0], 1, 4, 2).unwrap();
/// assert_eq!(t.labels, vec![1, 0, 1, 0]);
/// ```
pub fn equal_count_bands(
    values: &[f64],
    features: usize,
    vertices: usize,
    bands: usize,
) -> Result<BandTable, BandError> {
    if bands == 0 || bands > 256 {
        return Err(BandError::BadBandCount(bands));
    }
    if values.len() != features * vertices {
        return Err(BandError::ShapeMismatch {
            features,
            vertices,
            expected: features * vertices,
            got: values.len(),
        });
    }
    ranked_labels(values, features, vertices, bands, None)
}

/// Shared engine of the band builders: per feature (in parallel, one feature per task so the
/// result does not depend on the thread count), sort by value with ties by index, then cut by
/// count (`weights = None`) or by cumulative weight (midpoint rule).
pub(crate) fn ranked_labels(
    values: &[f64],
    features: usize,
    vertices: usize,
    bands: usize,
    weights: Option<&[f64]>,
) -> Result<BandTable, BandError> {
    use rayon::prelude::*;
    if let Some(f) = (0..features).find(|&k| {
        values[k * vertices..(k + 1) * vertices]
            .iter()
            .any(|x| x.is_nan())
    }) {
        let v = values[f * vertices..(f + 1) * vertices]
            .iter()
            .position(|x| x.is_nan())
            .unwrap_or(0);
        return Err(BandError::NaN {
            feature: f,
            vertex: v,
        });
    }
    let total: f64 = weights.map_or(0.0, |w| w.iter().sum());
    let columns: Vec<Vec<u8>> = (0..features)
        .into_par_iter()
        .map_init(Vec::new, |keys: &mut Vec<u128>, k| {
            let f = &values[k * vertices..(k + 1) * vertices];
            keys.clear();
            keys.extend(
                f.iter()
                    .enumerate()
                    .map(|(v, &x)| ((order_bits(x) as u128) << 32) | v as u128),
            );
            keys.sort_unstable();
            let mut col = vec![0u8; vertices];
            match weights {
                None => {
                    let (base, extra) = (vertices / bands, vertices % bands);
                    let mut pos = 0usize;
                    for band in 0..bands {
                        let size = base + usize::from(band < extra);
                        for &key in &keys[pos..pos + size] {
                            col[(key as u32) as usize] = band as u8;
                        }
                        pos += size;
                    }
                }
                Some(w) => {
                    let mut before = 0.0f64;
                    for &key in keys.iter() {
                        let v = (key as u32) as usize;
                        let mid = before + 0.5 * w[v];
                        before += w[v];
                        let b = ((mid / total) * bands as f64).floor();
                        col[v] = (b.max(0.0) as usize).min(bands - 1) as u8;
                    }
                }
            }
            col
        })
        .collect();
    let mut labels = vec![0u8; features * vertices];
    for (k, col) in columns.iter().enumerate() {
        for (v, &b) in col.iter().enumerate() {
            labels[v * features + k] = b;
        }
    }
    Ok(BandTable {
        features,
        vertices,
        bands,
        labels,
    })
}

/// Maps an `f64` to a `u64` whose unsigned order is `f64::total_cmp`'s order.
#[inline]
fn order_bits(x: f64) -> u64 {
    let b = x.to_bits();
    if b >> 63 == 1 { !b } else { b | (1 << 63) }
}
