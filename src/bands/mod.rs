//! Band-label tables: each feature's sorted order on a shape cut into `K` equal blocks, one
//! `u8` label per (vertex, feature).
//!
//! Only ranks matter: any monotone transform of a feature gives the same table — except for
//! the columns whose values mean the same on every shape (normal orientations), which
//! [`band_table`] cuts by value over their fixed range ([`fixed_range_bands`]).

use thiserror::Error;

mod area_weighted_bands;
mod band_table;
mod fixed_range_bands;
mod synthetic_band_table;

pub use area_weighted_bands::area_weighted_bands;
pub use band_table::{BandOptions, BandWeighting, band_table};
pub use fixed_range_bands::fixed_range_bands;
pub use synthetic_band_table::synthetic_band_table;

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
    /// More vertices than a `u32` index can address.
    #[error("{0} vertices exceed the u32 index range")]
    TooManyVertices(usize),
    /// The fixed value range of a feature is not finite with `lo < hi`.
    #[error("bad fixed band range [{0}, {1}]: must be finite with lo < hi")]
    BadRange(f64, f64),
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
    check_table_input(values, features, vertices, bands)?;
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
    if vertices > u32::MAX as usize {
        return Err(BandError::TooManyVertices(vertices));
    }
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
            // Unique keys: (value in total order, vertex index).
            keys.clear();
            keys.extend(f.iter().enumerate().map(|(v, &x)| key(x, v)));
            let mut col = vec![0u8; vertices];
            match weights {
                None if vertices >= 2 * bands => {
                    bucket_count_bands(f, bands, keys, &mut col);
                }
                None => {
                    keys.sort_unstable();
                    let (base, extra) = (vertices / bands, vertices % bands);
                    let mut pos = 0usize;
                    for band in 0..bands {
                        let size = base + usize::from(band < extra);
                        for &kv in &keys[pos..pos + size] {
                            col[(kv as u32) as usize] = band as u8;
                        }
                        pos += size;
                    }
                }
                Some(w) => {
                    keys.sort_unstable();
                    let mut before = 0.0f64;
                    for &kv in keys.iter() {
                        let v = (kv as u32) as usize;
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
    // Transpose to vertex-major, in parallel over fixed blocks of vertices (pure copies).
    const VERTEX_BLOCK: usize = 1024;
    let mut labels = vec![0u8; features * vertices];
    if features > 0 {
        labels
            .par_chunks_mut(features * VERTEX_BLOCK)
            .enumerate()
            .for_each(|(block, out)| {
                let v0 = block * VERTEX_BLOCK;
                let n = out.len() / features;
                for (k, col) in columns.iter().enumerate() {
                    for (i, &b) in col[v0..v0 + n].iter().enumerate() {
                        out[i * features + k] = b;
                    }
                }
            });
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

/// The sort key of value `x` at vertex `v`: `total_cmp` order, then vertex index. Unique.
#[inline]
fn key(x: f64, v: usize) -> u128 {
    ((order_bits(x) as u128) << 32) | v as u128
}

/// Buckets of [`bucket_count_bands`]: `2^BUCKET_BITS`.
const BUCKET_BITS: u32 = 14;

/// Equal-count labels of one feature without a full sort, identical to sorting by
/// `(value, index)` and cutting: a counting pass over `2^14` buckets of the order-preserving
/// key; a bucket whose ranks fall in one band labels all its vertices at once; the few buckets
/// that straddle a cut are sorted exactly (by key, then index). `vertices ≥ 2 · bands`.
fn bucket_count_bands(f: &[f64], bands: usize, scratch: &mut Vec<u128>, col: &mut [u8]) {
    let d = f.len();
    let (base, extra) = (d / bands, d % bands);
    // Band of rank r: blocks of size base + 1 first, then base.
    let big = extra * (base + 1);
    let band_of_rank = |r: usize| -> u8 {
        if r < big {
            (r / (base + 1)) as u8
        } else {
            (extra + (r - big) / base) as u8
        }
    };
    let (mut lo, mut hi) = (u64::MAX, 0u64);
    for &x in f {
        let k = order_bits(x);
        lo = lo.min(k);
        hi = hi.max(k);
    }
    let range = hi - lo;
    let shift = (64 - range.leading_zeros()).saturating_sub(BUCKET_BITS);
    let bucket = |x: f64| ((order_bits(x) - lo) >> shift) as usize;
    let nb = ((range >> shift) as usize) + 1;
    let mut start = vec![0usize; nb + 1];
    for &x in f {
        start[bucket(x) + 1] += 1;
    }
    for b in 0..nb {
        start[b + 1] += start[b];
    }
    // The label of a bucket whose ranks all fall in one band; None if it straddles a cut.
    let uniform: Vec<Option<u8>> = (0..nb)
        .map(|b| {
            let (s, e) = (start[b], start[b + 1]);
            if s == e {
                return Some(0);
            }
            let (first, last) = (band_of_rank(s), band_of_rank(e - 1));
            (first == last).then_some(first)
        })
        .collect();
    scratch.clear();
    for (v, (&x, c)) in f.iter().zip(col.iter_mut()).enumerate() {
        let b = bucket(x);
        match uniform[b] {
            Some(label) => *c = label,
            // Straddling: sort key (bucket, value order, index), all fit in 128 bits
            // because the bucket is a function of the value order.
            None => scratch.push(((order_bits(x) as u128) << 32) | v as u128),
        }
    }
    scratch.sort_unstable();
    // Walk the straddling elements bucket by bucket (sorted by value, so by bucket too).
    let mut i = 0;
    while i < scratch.len() {
        let x_bits = (scratch[i] >> 32) as u64;
        let b = ((x_bits - lo) >> shift) as usize;
        let s = start[b];
        let mut j = i;
        while j < scratch.len() && ((((scratch[j] >> 32) as u64) - lo) >> shift) as usize == b {
            let v = (scratch[j] as u32) as usize;
            col[v] = band_of_rank(s + (j - i));
            j += 1;
        }
        i = j;
    }
}

/// Checks what every band builder needs: `K` fits a `u8` label and `values` holds
/// `features × vertices` entries.
pub(crate) fn check_table_input(
    values: &[f64],
    features: usize,
    vertices: usize,
    bands: usize,
) -> Result<(), BandError> {
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
    Ok(())
}
