//! Band-label tables: each feature's sorted order on a shape cut into `K` equal blocks, one
//! `u8` label per (vertex, feature).
//!
//! Only ranks matter: any monotone transform of a feature gives the same table.

use thiserror::Error;

/// Errors of the band stage.
#[derive(Debug, Error)]
pub enum BandError {
    /// `K` must be in `1..=256` to fit a `u8` label.
    #[error("band count K = {0} must be in 1..=256")]
    BadBandCount(usize),
    /// The feature array does not have `features × vertices` entries.
    #[error("expected {expected} feature values ({features} features × {vertices} vertices), got {got}")]
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
    let mut labels = vec![0u8; features * vertices];
    let mut order: Vec<u32> = Vec::with_capacity(vertices);
    for k in 0..features {
        let f = &values[k * vertices..(k + 1) * vertices];
        if let Some(v) = f.iter().position(|x| x.is_nan()) {
            return Err(BandError::NaN { feature: k, vertex: v });
        }
        order.clear();
        order.extend(0..vertices as u32);
        order.sort_unstable_by(|&a, &b| f[a as usize].total_cmp(&f[b as usize]).then(a.cmp(&b)));
        let (base, extra) = (vertices / bands, vertices % bands);
        let mut pos = 0usize;
        for band in 0..bands {
            let size = base + usize::from(band < extra);
            for &v in &order[pos..pos + size] {
                labels[v as usize * features + k] = band as u8;
            }
            pos += size;
        }
    }
    Ok(BandTable {
        features,
        vertices,
        bands,
        labels,
    })
}
