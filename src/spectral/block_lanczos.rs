//! Private: thick-restart block Lanczos for the largest eigenvalues of a symmetric positive
//! (semi-)definite operator, with full reorthogonalisation done as matrix–matrix products.
//!
//! Why not `faer::matrix_free::eigen::partial_self_adjoint_eigen`: its Lanczos applies the
//! operator one vector at a time and reorthogonalises with vector–vector operations, so for
//! `k = 200` on a 50k-vertex mesh its time is dominated by memory traffic (reading the basis
//! four times per step). Here the operator (two sparse triangular solves) is applied to blocks of
//! `b` vectors and every projection is a BLAS-3 product, which reads the basis once per block.
//!
//! Invariants: `V[:, 0..j]` orthonormal and orthogonal to the deflated space `N`;
//! `A V_j = V_j H_j + Q R E_lastᵀ` with `H_j = V_jᵀ A V_j` symmetric, where the last block of
//! `V_j` was the last one applied. A thick restart keeps Ritz vectors, which preserves this
//! relation (their residuals all lie along `Q`).

use super::SpectralError;
use crate::generate::SplitMix64;
use faer::linalg::matmul::matmul;
use faer::reborrow::*;
use faer::{Accum, Mat, MatMut, MatRef, Par};

/// Settings of [`largest_eigenpairs`].
pub(crate) struct BlockLanczosParams {
    /// Number of wanted eigenpairs (largest eigenvalues).
    pub nev: usize,
    /// Block size `b`.
    pub block: usize,
    /// Maximum basis size (a multiple of `b`, `> nev + b`).
    pub max_basis: usize,
    /// Relative residual tolerance: `‖A y − θ y‖ ≤ tol · θ`.
    pub tol: f64,
    /// Maximum number of restarts.
    pub max_restarts: usize,
    /// Seed of the start block.
    pub seed: u64,
    /// Parallelism of dense products.
    pub par: Par,
}

/// Result: eigenvalues descending and eigenvectors (n × nev), plus iteration counts.
pub(crate) struct BlockLanczosResult {
    pub values: Vec<f64>,
    pub vectors: Mat<f64>,
    pub restarts: usize,
    pub applications: usize,
}

/// Start vectors uniform in [-1, 1): [`SplitMix64`] from the seed mixed with a constant.
pub(crate) struct SplitMix(SplitMix64);

impl SplitMix {
    pub fn new(seed: u64) -> Self {
        SplitMix(SplitMix64(seed ^ 0x853c_49e6_748f_ea9b))
    }
    pub fn next_f64(&mut self) -> f64 {
        self.0.next_f64() * 2.0 - 1.0
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    // Fixed-order chunked sum: deterministic and reasonably accurate.
    let mut acc = [0.0f64; 4];
    let chunks = a.len() / 4;
    for c in 0..chunks {
        for l in 0..4 {
            acc[l] += a[4 * c + l] * b[4 * c + l];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for i in 4 * chunks..a.len() {
        s += a[i] * b[i];
    }
    s
}

fn col(m: MatRef<'_, f64>, j: usize) -> &[f64] {
    m.col(j).try_as_col_major().unwrap().as_slice()
}

fn col_mut(m: MatMut<'_, f64>, j: usize) -> &mut [f64] {
    m.col_mut(j).try_as_col_major_mut().unwrap().as_slice_mut()
}

/// `W ← W − B (Bᵀ W)`, returning `Bᵀ W` (classical Gram–Schmidt step as two products).
fn project_out(basis: MatRef<'_, f64>, mut w: MatMut<'_, f64>, par: Par) -> Mat<f64> {
    let mut c = Mat::<f64>::zeros(basis.ncols(), w.ncols());
    if basis.ncols() == 0 {
        return c;
    }
    matmul(
        c.as_mut(),
        Accum::Replace,
        basis.transpose(),
        w.as_ref(),
        1.0,
        par,
    );
    matmul(w.as_mut(), Accum::Add, basis, c.as_ref(), -1.0, par);
    c
}

/// The Euclidean norm of column `i` of `w`.
fn column_norm(w: MatRef<'_, f64>, i: usize) -> f64 {
    let c = col(w, i);
    dot(c, c).sqrt()
}

/// Removes from column `i` of `w` its component along column `l` (not normalised: the
/// caller's columns before `i` are); returns that component's coefficient.
fn remove_component(mut w: MatMut<'_, f64>, l: usize, i: usize) -> f64 {
    let ql = col(w.as_ref(), l).to_vec();
    let wi = col_mut(w.rb_mut(), i);
    let c = dot(&ql, wi);
    for (x, q) in wi.iter_mut().zip(&ql) {
        *x -= c * q;
    }
    c
}

/// Projects column `i` of `w` off the columns of `first`, then of `second`, then off `w`'s
/// columns before `i` one by one (the order is part of the result at rounding level).
fn project_column(
    first: MatRef<'_, f64>,
    second: MatRef<'_, f64>,
    mut w: MatMut<'_, f64>,
    i: usize,
    par: Par,
) {
    let mut wi = w.rb_mut().subcols_mut(i, 1);
    project_out(first, wi.rb_mut(), par);
    project_out(second, wi.rb_mut(), par);
    for l in 0..i {
        remove_component(w.rb_mut(), l, i);
    }
}

/// Orthonormalises the columns of `w` in place (two Gram–Schmidt passes inside the block),
/// keeping them orthogonal to `v` and `null`; returns the upper-triangular `R` with
/// `W_in = Q R` (after the caller's projection). Columns whose norm collapses (the Krylov space
/// became invariant) are replaced by fresh random directions with a zero diagonal in `R`.
fn orthonormalise_block(
    v: MatRef<'_, f64>,
    null: MatRef<'_, f64>,
    mut w: MatMut<'_, f64>,
    norms_in: &[f64],
    rng: &mut SplitMix,
    par: Par,
) -> Mat<f64> {
    let b = w.ncols();
    let mut r = Mat::<f64>::zeros(b, b);
    for i in 0..b {
        let before = column_norm(w.as_ref(), i);
        for _pass in 0..2 {
            for l in 0..i {
                r[(l, i)] += remove_component(w.rb_mut(), l, i);
            }
        }
        let mut norm = column_norm(w.as_ref(), i);
        if norm < 1e-3 * before {
            // Heavy cancellation: orthogonality to the basis may be lost, so redo it.
            project_column(v, null, w.rb_mut(), i, par);
            norm = column_norm(w.as_ref(), i);
        }
        let scale = norms_in[i].max(before);
        if norm.is_nan() || norm <= 1e-13 * scale || !norm.is_finite() {
            // Deflation: the direction is (numerically) already in the basis.
            r[(i, i)] = 0.0;
            for attempt in 0..4 {
                {
                    let wi = col_mut(w.rb_mut(), i);
                    for x in wi.iter_mut() {
                        *x = rng.next_f64();
                    }
                }
                for _pass in 0..2 {
                    project_column(null, v, w.rb_mut(), i, par);
                }
                norm = column_norm(w.as_ref(), i);
                if norm > 1e-8 || attempt == 3 {
                    break;
                }
            }
        } else {
            r[(i, i)] = norm;
        }
        let inv = if norm > 0.0 { 1.0 / norm } else { 0.0 };
        for x in col_mut(w.rb_mut(), i).iter_mut() {
            *x *= inv;
        }
    }
    r
}

/// Largest `nev` eigenpairs of the symmetric operator `apply` (which maps an n × b block in
/// place) on the orthogonal complement of the orthonormal columns of `null`.
pub(crate) fn largest_eigenpairs(
    n: usize,
    apply: &dyn Fn(MatMut<'_, f64>),
    null: MatRef<'_, f64>,
    p: &BlockLanczosParams,
) -> Result<BlockLanczosResult, SpectralError> {
    let b = p.block.max(1);
    let m_max = p.max_basis;
    let nev = p.nev;
    if nev == 0 {
        return Ok(BlockLanczosResult {
            values: vec![],
            vectors: Mat::zeros(n, 0),
            restarts: 0,
            applications: 0,
        });
    }
    assert!(m_max.is_multiple_of(b) && m_max >= nev + 2 * b && m_max + null.ncols() < n);
    let par = p.par;
    let mut rng = SplitMix::new(p.seed);
    let mut v = Mat::<f64>::zeros(n, m_max);
    let mut h = Mat::<f64>::zeros(m_max, m_max);

    start_block(v.as_mut().subcols_mut(0, b), null, &mut rng, par);
    let mut j = b;
    let mut restarts = 0usize;
    let mut applications = 0usize;
    let check_every = (m_max / 6).max(2 * b);
    let mut last_check = 0usize;
    let mut w = Mat::<f64>::zeros(n, b);
    loop {
        let r = lanczos_step(
            apply,
            null,
            v.as_ref().subcols(0, j),
            &mut h,
            &mut w,
            &mut rng,
            par,
        );
        applications += b;

        let full = j + b > m_max;
        let want_check = full || (j >= nev + 2 * b && j - last_check >= check_every);
        if want_check {
            last_check = j;
            let hj = h.as_ref().submatrix(0, 0, j, j);
            let evd = hj
                .self_adjoint_eigen(faer::Side::Lower)
                .map_err(|e| SpectralError::Solver(format!("Rayleigh-Ritz: {e:?}")))?;
            let s = evd.S();
            let u = evd.U();
            // Descending order.
            let order: Vec<usize> = (0..j).rev().collect();
            let theta: Vec<f64> = order.iter().map(|&i| s[i]).collect();
            let converged = count_converged(r.as_ref(), u, &order, &theta, nev, p.tol);
            if converged >= nev {
                let y = ritz_coefficients(u, &order, nev);
                let vectors = ritz_vectors(v.as_ref().subcols(0, j), y.as_ref(), par);
                return Ok(BlockLanczosResult {
                    values: theta[..nev].to_vec(),
                    vectors,
                    restarts,
                    applications,
                });
            }
            if full {
                if restarts >= p.max_restarts {
                    return Err(SpectralError::Solver(format!(
                        "block Lanczos did not converge after {restarts} restarts \
                         ({converged} of {nev} eigenpairs converged)"
                    )));
                }
                restarts += 1;
                // Thick restart: keep the `keep` best Ritz vectors.
                let keep = {
                    let k = nev + (m_max - nev) / 2;
                    let k = k.min(m_max - b);
                    k.max(nev)
                };
                let y = ritz_coefficients(u, &order, keep);
                j = thick_restart(&mut v, &mut h, &w, r.as_ref(), y.as_ref(), &theta, par);
                last_check = j;
                continue;
            }
        }
        append_block(&mut v, &mut h, &w, r.as_ref(), j);
        j += b;
    }
}

/// Fills `w` (the first block of the basis) with random directions orthonormal to each other
/// and to `null`; kept apart so the main loop reads as the Lanczos recurrence alone.
fn start_block(mut w: MatMut<'_, f64>, null: MatRef<'_, f64>, rng: &mut SplitMix, par: Par) {
    let n = w.nrows();
    let b = w.ncols();
    for jj in 0..b {
        for x in col_mut(w.rb_mut(), jj).iter_mut() {
            *x = rng.next_f64();
        }
    }
    project_out(null, w.rb_mut(), par);
    project_out(null, w.rb_mut(), par);
    let norms = vec![1.0; b];
    orthonormalise_block(Mat::<f64>::zeros(n, 0).as_ref(), null, w, &norms, rng, par);
}

/// One block Lanczos step on the basis `vj` (whose last block was the last one added): applies
/// the operator to that block into `w`, records the projections in the matching columns of `h`
/// and orthonormalises `w`, returning its `R`. Kept apart so that the restart logic around it
/// fits on a screen.
fn lanczos_step(
    apply: &dyn Fn(MatMut<'_, f64>),
    null: MatRef<'_, f64>,
    vj: MatRef<'_, f64>,
    h: &mut Mat<f64>,
    w: &mut Mat<f64>,
    rng: &mut SplitMix,
    par: Par,
) -> Mat<f64> {
    let j = vj.ncols();
    let b = w.ncols();
    w.copy_from(vj.subcols(j - b, b));
    apply(w.as_mut());
    let norms_in: Vec<f64> = (0..b)
        .map(|i| {
            let c = col(w.as_ref(), i);
            dot(c, c).sqrt()
        })
        .collect();
    project_out(null, w.as_mut(), par);
    let mut c = project_out(vj, w.as_mut(), par);
    project_out(null, w.as_mut(), par);
    let c2 = project_out(vj, w.as_mut(), par);
    c += &c2;
    store_projection(h, &c, j, b);
    orthonormalise_block(vj, null, w.as_mut(), &norms_in, rng, par)
}

/// `H[:, block] = C`, mirrored, with the diagonal block symmetrised: `H` must stay exactly
/// symmetric for the Rayleigh–Ritz step although `C` is only symmetric up to rounding.
fn store_projection(h: &mut Mat<f64>, c: &Mat<f64>, j: usize, b: usize) {
    for col_i in 0..b {
        let hc = j - b + col_i;
        for row in 0..j {
            h[(row, hc)] = c[(row, col_i)];
        }
    }
    for col_i in 0..b {
        let hc = j - b + col_i;
        for row in 0..j - b {
            h[(hc, row)] = h[(row, hc)];
        }
    }
    for a in j - b..j {
        for bb in a + 1..j {
            let s = 0.5 * (h[(a, bb)] + h[(bb, a)]);
            h[(a, bb)] = s;
            h[(bb, a)] = s;
        }
    }
}

/// How many of the leading (largest) Ritz pairs have converged, counted in order and stopping
/// at the first that has not: the residual of a Ritz pair is `‖R · Y_last‖`, which needs only
/// the last block's rows of the eigenvectors `u` of `H_j`, not a product with the basis.
fn count_converged(
    r: MatRef<'_, f64>,
    u: MatRef<'_, f64>,
    order: &[usize],
    theta: &[f64],
    nev: usize,
    tol: f64,
) -> usize {
    let j = u.nrows();
    let b = r.nrows();
    let mut converged = 0usize;
    for (rank, &idx) in order.iter().enumerate().take(nev) {
        let mut res2 = 0.0;
        for row in 0..b {
            let mut acc = 0.0;
            for l in row..b {
                acc += r[(row, l)] * u[(j - b + l, idx)];
            }
            res2 += acc * acc;
        }
        if res2.sqrt() <= tol * theta[rank].abs() {
            converged += 1;
        } else {
            break;
        }
    }
    converged
}

/// The first `count` eigenvectors of `H_j` in `order`, as columns (`j × count`); shared by the
/// final answer and the thick restart, which both lift them into the basis.
fn ritz_coefficients(u: MatRef<'_, f64>, order: &[usize], count: usize) -> Mat<f64> {
    let j = u.nrows();
    let mut y = Mat::<f64>::zeros(j, count);
    for (rank, &idx) in order.iter().enumerate().take(count) {
        for row in 0..j {
            y[(row, rank)] = u[(row, idx)];
        }
    }
    y
}

/// Ritz vectors `V_j Y` (n × count) as one BLAS-3 product.
fn ritz_vectors(vj: MatRef<'_, f64>, y: MatRef<'_, f64>, par: Par) -> Mat<f64> {
    let mut vectors = Mat::<f64>::zeros(vj.nrows(), y.ncols());
    matmul(vectors.as_mut(), Accum::Replace, vj, y, 1.0, par);
    vectors
}

/// Thick restart: replaces the basis by the kept Ritz vectors (coefficients `y`, `j × keep`)
/// followed by the pending block `w`, and rebuilds `H` as their Ritz values plus the coupling
/// `R · Y_last` to the new block, which keeps the Lanczos relation of the module doc. Returns the
/// new basis size.
fn thick_restart(
    v: &mut Mat<f64>,
    h: &mut Mat<f64>,
    w: &Mat<f64>,
    r: MatRef<'_, f64>,
    y: MatRef<'_, f64>,
    theta: &[f64],
    par: Par,
) -> usize {
    let j = y.nrows();
    let keep = y.ncols();
    let b = w.ncols();
    let kept = ritz_vectors(v.as_ref().subcols(0, j), y, par);
    v.as_mut().subcols_mut(0, keep).copy_from(&kept);
    drop(kept);
    v.as_mut().subcols_mut(keep, b).copy_from(w);
    h.fill(0.0);
    for (rank, &t) in theta.iter().enumerate().take(keep) {
        h[(rank, rank)] = t;
    }
    // H[new, kept] = R · Y_last.
    for row in 0..b {
        for kc in 0..keep {
            let mut acc = 0.0;
            for l in row..b {
                acc += r[(row, l)] * y[(j - b + l, kc)];
            }
            h[(keep + row, kc)] = acc;
            h[(kc, keep + row)] = acc;
        }
    }
    keep + b
}

/// Appends the orthonormalised block `w` after the basis `V_j` and its `R` as the sub- and
/// super-diagonal blocks of `H`, the plain (non-restart) continuation of the recurrence.
fn append_block(v: &mut Mat<f64>, h: &mut Mat<f64>, w: &Mat<f64>, r: MatRef<'_, f64>, j: usize) {
    let b = w.ncols();
    v.as_mut().subcols_mut(j, b).copy_from(w);
    for row in 0..b {
        for cc in 0..b {
            h[(j + row, j - b + cc)] = r[(row, cc)];
            h[(j - b + cc, j + row)] = r[(row, cc)];
        }
    }
}
