//! [`dense_affinity`]: the dense `W` (test oracle for small shapes).

use super::{AffinityError, BandAffinity};

/// Largest number of entries [`dense_affinity`] builds (2²⁶ ≈ 67 M, 512 MiB of `f64`).
const DENSE_LIMIT: usize = 1 << 26;

/// The dense affinity, row-major `d_b × d_a`: `w[q * d_a + p] = W_qp`. Only for tests and
/// small shapes (errors past `DENSE_LIMIT` entries); the library never builds it.
///
/// ```
/// use coseg::affinity::{dense_affinity, BandAffinity};
/// use coseg::bands::equal_count_bands;
/// let a = equal_count_bands(&[0.0, 1.0], 1, 2, 2).unwrap();
/// let w = BandAffinity::new(&a, &a).unwrap();
/// assert_eq!(dense_affinity(&w).unwrap(), vec![0.5, 0.0, 0.0, 0.5]);
/// ```
pub fn dense_affinity(w: &BandAffinity<'_>) -> Result<Vec<f64>, AffinityError> {
    let (rows, cols) = (w.rows(), w.cols());
    if rows.saturating_mul(cols) > DENSE_LIMIT {
        return Err(AffinityError::TooLargeForDense {
            rows,
            cols,
            limit: DENSE_LIMIT,
        });
    }
    let (a, b) = (w.table_a(), w.table_b());
    let weights = w.weights();
    let scale = w.bands() as f64 / (cols as f64 * rows as f64);
    let mut out = vec![0.0; rows * cols];
    for q in 0..rows {
        for p in 0..cols {
            let mut s = 0.0;
            for (i, &(ka, kb)) in w.pairs().iter().enumerate() {
                if a.label(p, ka as usize) == b.label(q, kb as usize) {
                    s += weights[i];
                }
            }
            out[q * cols + p] = scale * s;
        }
    }
    Ok(out)
}
