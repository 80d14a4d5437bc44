use super::{BandError, check_table_input};

/// Fixed-range band labels of one feature column: the range `[lo, hi]` cut into `bands` equal
/// intervals, vertex `v` in band `⌊K (x_v − lo) / (hi − lo)⌋` (values at or beyond an end in
/// the end band).
///
/// For a feature whose values mean the same on every shape (the orientation of a normal,
/// `|n·u| ∈ [0, 1]`), rank bands would throw that meaning away: a stool whose top is all
/// horizontal and a chair with a small horizontal seat would put their horizontal vertices
/// in different rank bands. With fixed-range bands a horizontal patch is in the top band on
/// every shape, whatever share of the surface it is. Bands may then hold any number of
/// vertices, including none. See also [`equal_count_bands`](super::equal_count_bands) (the
/// paper's rank bands, used for every other feature) and
/// [`Descriptors::value_ranges`](crate::features::Descriptors::value_ranges) (which columns
/// get these bands).
///
/// Inputs: `column` (length `d`), `range = [lo, hi]` finite with `lo < hi`, `bands` = `K` in
/// `1..=256`. Output: `d` labels in `0..K`.
///
/// ```
/// use coseg::bands::fixed_range_bands;
/// let b = fixed_range_bands(&[0.0, 0.24, 0.25, 0.99, 1.0, 1.5], [0.0, 1.0], 4).unwrap();
/// assert_eq!(b, vec![0, 0, 1, 3, 3, 3]);
/// ```
pub fn fixed_range_bands(
    column: &[f64],
    range: [f64; 2],
    bands: usize,
) -> Result<Vec<u8>, BandError> {
    check_table_input(column, 1, column.len(), bands)?;
    let [lo, hi] = range;
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(BandError::BadRange(lo, hi));
    }
    if let Some(v) = column.iter().position(|x| x.is_nan()) {
        return Err(BandError::NaN {
            feature: 0,
            vertex: v,
        });
    }
    let top = (bands - 1) as f64;
    let scale = bands as f64 / (hi - lo);
    // The clamp in f64 before the cast keeps infinities and far values in the end bands.
    Ok(column
        .iter()
        .map(|&x| ((x - lo) * scale).floor().clamp(0.0, top) as u8)
        .collect())
}
