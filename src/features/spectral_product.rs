//! The one dense kernel every spectral feature uses:
//! `out = [Φ∘Φ · Sᵀ | Φ · Pᵀ]` (entrywise square times the "squared" coefficients, then Φ
//! times the "plain" coefficients), computed in fixed row blocks so that the result is
//! bit-identical whatever the number of threads.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef, Par};
use rayon::prelude::*;

/// Rows per block. Fixed (never derived from the thread count) so that the floating-point
/// operations, hence the result bits, do not depend on the machine.
const BLOCK_ROWS: usize = 512;

/// `out[f * d + v]`, for `f < S`: `Σ_i squared[(f, i)] φ_i(v)²`; for `f = S + g`:
/// `Σ_i plain[(g, i)] φ_i(v)`.
///
/// `phi` is `d × k` column-major, `squared` is `S × k`, `plain` is `P × k`. Returns
/// `(S + P) × d` values, feature-major. Each row block is one sequential GEMM per
/// coefficient matrix; blocks run in parallel (rayon) and are scattered in block order.
pub(crate) fn spectral_product(
    phi: MatRef<'_, f64>,
    squared: MatRef<'_, f64>,
    plain: MatRef<'_, f64>,
) -> Vec<f64> {
    let (d, k) = (phi.nrows(), phi.ncols());
    let (ns, np) = (squared.nrows(), plain.nrows());
    debug_assert!(squared.ncols() == k && plain.ncols() == k);
    let t = ns + np;
    let mut out = vec![0.0; d * t];
    if d == 0 || t == 0 {
        return out;
    }
    let blocks: Vec<(usize, Mat<f64>)> = (0..d.div_ceil(BLOCK_ROWS))
        .into_par_iter()
        .map(|b| {
            let r0 = b * BLOCK_ROWS;
            let n = BLOCK_ROWS.min(d - r0);
            let rows = phi.subrows(r0, n);
            let mut dst = Mat::<f64>::zeros(n, t);
            if ns > 0 {
                let sq = Mat::from_fn(n, k, |i, j| {
                    let x = rows[(i, j)];
                    x * x
                });
                matmul(
                    dst.as_mut().subcols_mut(0, ns),
                    Accum::Replace,
                    sq.as_ref(),
                    squared.transpose(),
                    1.0,
                    Par::Seq,
                );
            }
            if np > 0 {
                matmul(
                    dst.as_mut().subcols_mut(ns, np),
                    Accum::Replace,
                    rows,
                    plain.transpose(),
                    1.0,
                    Par::Seq,
                );
            }
            (r0, dst)
        })
        .collect();
    // Scatter in parallel over features (disjoint output columns; pure copies).
    out.par_chunks_mut(d).enumerate().for_each(|(f, col)| {
        for (r0, dst) in &blocks {
            let src = dst.col(f);
            for (i, o) in col[*r0..*r0 + dst.nrows()].iter_mut().enumerate() {
                *o = src[i];
            }
        }
    });
    out
}
