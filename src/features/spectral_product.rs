//! The one dense kernel every spectral feature uses: `out = g(Φ) · Cᵀ` with `g` either the
//! identity or the entrywise square, computed in fixed row blocks so that the result is
//! bit-identical whatever the number of threads.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef, Par};
use rayon::prelude::*;

/// Rows per block. Fixed (never derived from the thread count) so that the floating-point
/// operations, hence the result bits, do not depend on the machine.
const BLOCK_ROWS: usize = 1024;

/// `out[f * d + v] = Σ_i coeffs[(f, i)] · g(φ_i(v))` where `g(x) = x²` when `square`, else `x`.
///
/// `phi` is `d × k` column-major, `coeffs` is `T × k`. Returns a `d × T` column-major vector
/// (feature-major). Each row block is one sequential GEMM; blocks run in parallel (rayon).
pub(crate) fn spectral_product(
    phi: MatRef<'_, f64>,
    coeffs: MatRef<'_, f64>,
    square: bool,
) -> Vec<f64> {
    let (d, k) = (phi.nrows(), phi.ncols());
    let t = coeffs.nrows();
    debug_assert_eq!(coeffs.ncols(), k);
    let mut out = vec![0.0; d * t];
    if d == 0 || t == 0 {
        return out;
    }
    let coeffs_t = coeffs.transpose();
    let blocks: Vec<(usize, Mat<f64>)> = (0..d.div_ceil(BLOCK_ROWS))
        .into_par_iter()
        .map(|b| {
            let r0 = b * BLOCK_ROWS;
            let n = BLOCK_ROWS.min(d - r0);
            let rows = phi.subrows(r0, n);
            let lhs = if square {
                Mat::from_fn(n, k, |i, j| {
                    let x = rows[(i, j)];
                    x * x
                })
            } else {
                rows.to_owned()
            };
            let mut dst = Mat::<f64>::zeros(n, t);
            matmul(
                dst.as_mut(),
                Accum::Replace,
                lhs.as_ref(),
                coeffs_t,
                1.0,
                Par::Seq,
            );
            (r0, dst)
        })
        .collect();
    for (r0, dst) in blocks {
        for f in 0..t {
            let col = &mut out[f * d + r0..f * d + r0 + dst.nrows()];
            for (i, o) in col.iter_mut().enumerate() {
                *o = dst[(i, f)];
            }
        }
    }
    out
}
