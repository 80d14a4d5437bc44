use super::{BandError, BandTable, ranked_labels};

/// Area-weighted band labels: for each feature, sort the vertices by value (ties by vertex
/// index) and cut the order into `bands` consecutive blocks of (nearly) equal total weight.
///
/// Vertex `v`, whose weight occupies the interval `[c, c + ω_v)` of the cumulative weight in
/// sorted order, goes to band `⌊K (c + ω_v/2) / Σω⌋` (the band holding the midpoint of its
/// interval). So every band's weight differs from `Σω / K` by at most the largest single
/// weight, and with equal weights this is exactly [`equal_count_bands`](super::equal_count_bands)
/// whenever `K` divides `d`.
///
/// `values` is feature-major (`values[k * vertices + v]`); `weights` has length `vertices`
/// (typically the vertex areas), finite, non-negative, with a positive sum.
///
/// ```
/// use coseg::bands::area_weighted_bands;
/// // Vertex 3 carries half of the area: it alone fills the top band.
/// let t = area_weighted_bands(&[0.0, 1.0, 2.0, 3.0], &[1.0, 1.0, 1.0, 3.0], 1, 4, 2).unwrap();
/// assert_eq!(t.labels, vec![0, 0, 0, 1]);
/// ```
pub fn area_weighted_bands(
    values: &[f64],
    weights: &[f64],
    features: usize,
    vertices: usize,
    bands: usize,
) -> Result<BandTable, BandError> {
    super::check_table_input(values, features, vertices, bands)?;
    if weights.len() != vertices {
        return Err(BandError::BadWeights(format!(
            "{} weights for {vertices} vertices",
            weights.len()
        )));
    }
    if let Some(v) = weights.iter().position(|w| !(w.is_finite() && *w >= 0.0)) {
        return Err(BandError::BadWeights(format!(
            "weight of vertex {v} is {}",
            weights[v]
        )));
    }
    let total: f64 = weights.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return Err(BandError::BadWeights(format!("total weight is {total}")));
    }
    ranked_labels(values, features, vertices, bands, Some(weights))
}
