use super::block_lanczos::{BlockLanczosParams, largest_eigenpairs};
use super::shift_invert::{Pencil, ShiftInvert, count_below};
use super::{LaplacianKind, SpectralError, Spectrum, SurfaceOperators, lumped_mass};
use crate::mesh::TriMesh;
use faer::reborrow::*;
use faer::{Mat, Par};

/// Options of [`laplace_beltrami_spectrum`]. Every field has a documented default
/// ([`SpectrumOptions::default`]); eigenvalues refer to the mesh scaled to unit total area.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct SpectrumOptions {
    /// Number of eigenpairs `k` (default 200).
    pub eigenpairs: usize,
    /// Shift `σ` of the shift-invert operator `(L − σM)⁻¹M`; must be negative so that
    /// `L − σM` is positive definite (default `-1e-2`). The null space of `L` (one constant
    /// per connected component) is deflated exactly, so `σ` only has to be small compared with
    /// the spectrum's scale (unit area: `λ₁` is typically 1–50).
    pub shift: f64,
    /// Relative residual tolerance of the Ritz pairs of the shift-invert operator,
    /// `‖Aψ − θψ‖ ≤ tol·θ` with `θ = 1/(λ − σ)` (default `1e-10`). Eigenvalue errors are of
    /// the order of its square.
    pub tolerance: f64,
    /// Block size of the block Lanczos iteration (default 8).
    pub block_size: usize,
    /// Maximum Krylov basis size; `None` (default) means about twice the number of computed
    /// eigenpairs (rounded up to a multiple of the block size).
    pub basis_size: Option<usize>,
    /// Extra eigenpairs computed beyond `k` to verify that none was skipped; `None` (default)
    /// means `max(block_size, k / 20)`.
    pub guard: Option<usize>,
    /// Maximum number of thick restarts per attempt (default 100).
    pub max_restarts: usize,
    /// Seed of the Lanczos start block (default 0). Results depend on it only at rounding
    /// level (and in the basis chosen inside a multiple eigenvalue's eigenspace).
    pub seed: u64,
    /// Threads for the dense products and factorisations: 0 (default) = all of rayon's
    /// current pool, 1 = sequential, n = n threads. The result is bit-identical whatever the
    /// value and the pool size (the products split their output, never a sum; tested), so it is
    /// left out of the serialised options and of cache keys. Inside a collection's parallel
    /// loop over shapes the nested work mostly runs on the thread that spawned it; for one
    /// shape (`coseg spectrum`, `coseg pair`) it uses every core: victoria0 (45,659 vertices,
    /// k = 200) 5.3 s on 2 threads against 8.0 s sequential (docs/RESULTS.md, "Spectrum").
    #[serde(skip)]
    pub threads: usize,
    /// Finish with one step of inverse iteration on the computed eigenvectors followed by a
    /// symmetric (Löwdin) M-orthonormalisation (default `true`). It makes the equation hold
    /// accurately at vertices of tiny mass (needle or cap triangles), where the Krylov
    /// residual, measured in the M-metric, says little; it costs one block solve.
    pub polish: bool,
    /// Meshes with at most this many vertices (of positive area) use the dense eigensolver
    /// (default 600). Smaller meshes than the Krylov basis always do.
    pub dense_below: usize,
    /// The triangulation of the Laplacian and mass (default [`LaplacianKind::Cotangent`], the
    /// mesh's own triangles; [`LaplacianKind::IntrinsicDelaunay`] for poor triangulations).
    /// Left out of the serialised options when default, so default cache keys are unchanged.
    #[serde(default, skip_serializing_if = "LaplacianKind::is_cotangent")]
    pub laplacian: LaplacianKind,
}

impl Default for SpectrumOptions {
    fn default() -> Self {
        SpectrumOptions {
            eigenpairs: 200,
            shift: -1e-2,
            tolerance: 1e-10,
            block_size: 8,
            basis_size: None,
            guard: None,
            max_restarts: 100,
            seed: 0,
            threads: 0,
            polish: true,
            dense_below: 600,
            laplacian: LaplacianKind::Cotangent,
        }
    }
}

impl SpectrumOptions {
    /// Default options with `k` eigenpairs.
    pub fn with_eigenpairs(k: usize) -> Self {
        SpectrumOptions {
            eigenpairs: k,
            ..Default::default()
        }
    }
}

/// The `k` smallest eigenpairs of `L φ = λ M φ` for the mesh **scaled to unit total area**
/// (cotangent Laplacian `L`, lumped mass `M`), ascending, M-orthonormal (see [`Spectrum`]).
///
/// Method (sparse path):
/// - vertices of zero mass (unreferenced, or only in zero-area triangles) are dropped; their
///   eigenvector entries are 0;
/// - the null space of `L` (the constant on each connected component of the graph of `L`) is
///   known: those eigenpairs are returned exactly (`λ = 0`, `φ = 1_C / √area(C)`) and deflated;
/// - `L − σM = C Cᵀ` (σ < 0) is factored once by faer's sparse Cholesky (AMD ordering,
///   supernodal when profitable); the symmetric operator `A = M^{1/2}(L − σM)⁻¹M^{1/2}`
///   (eigenvalues `θ = 1/(λ − σ)`, eigenvectors `ψ = M^{1/2}φ`) is handed to a thick-restart
///   block Lanczos with full reorthogonalisation, asking for `k + guard` pairs;
/// - verification: the number of eigenvalues below a point `τ` in a gap just above `λ_{k−1}` is
///   counted exactly by Sylvester's law of inertia on an `LDLᵀ` factorisation of `L − τM`; if
///   the Lanczos run skipped an eigenvalue the counts differ, and it is re-run with a larger
///   block, guard and another seed (up to 3 attempts, then an error).
///
/// Small meshes (see [`SpectrumOptions::dense_below`]) use a dense eigensolver instead.
/// Eigenvector signs are normalised: the entry of largest magnitude is positive.
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::{laplace_beltrami_spectrum, SpectrumOptions}};
/// // A regular tetrahedron: two components would give two zero eigenvalues, one gives one.
/// let mesh = TriMesh::new(
///     vec![[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]],
///     vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
/// ).unwrap();
/// let s = laplace_beltrami_spectrum(&mesh, &SpectrumOptions::with_eigenpairs(4)).unwrap();
/// assert_eq!(s.eigenvalues[0], 0.0);
/// assert!(s.eigenvalues[1] > 0.0);
/// ```
pub fn laplace_beltrami_spectrum(
    mesh: &TriMesh,
    options: &SpectrumOptions,
) -> Result<Spectrum, SpectralError> {
    laplace_beltrami_spectrum_with_stats(mesh, options).map(|(s, _)| s)
}

/// The most eigenpairs [`laplace_beltrami_spectrum`] can return for `mesh`: its vertices of
/// positive mass (vertices used by no triangle of positive area carry none). A mesh of 4
/// vertices has 4 eigenpairs, whatever was asked for.
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::available_eigenpairs};
/// // Two triangles and one vertex no face uses.
/// let m = TriMesh::new(
///     vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.], [5., 5., 5.]],
///     vec![[0, 1, 2], [0, 2, 3]],
/// ).unwrap();
/// assert_eq!(available_eigenpairs(&m), 4);
/// ```
pub fn available_eigenpairs(mesh: &TriMesh) -> usize {
    lumped_mass(mesh).iter().filter(|&&m| m > 0.0).count()
}

/// What [`laplace_beltrami_spectrum_with_stats`] did: path taken, sizes, iteration counts and
/// wall-clock seconds per phase (for benchmarks and diagnostics; timings vary run to run, the
/// spectrum does not).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct SpectrumStats {
    /// True when the dense eigensolver was used.
    pub dense: bool,
    /// Vertices of positive mass (the size of the eigenproblem).
    pub active_vertices: usize,
    /// Connected components of `L`'s graph (= number of zero eigenvalues).
    pub components: usize,
    /// Non-zeros of the Cholesky factor of `L − σM`.
    pub factor_nnz: usize,
    /// Lanczos runs (more than one when the inertia check caught a skipped eigenvalue).
    pub attempts: usize,
    /// Thick restarts of the last run.
    pub restarts: usize,
    /// Operator applications (vectors) of the last run.
    pub applications: usize,
    /// Seconds in building `L`, `M` and the symbolic + numeric Cholesky factorisation.
    pub seconds_setup: f64,
    /// Seconds in the Lanczos iteration(s).
    pub seconds_lanczos: f64,
    /// Seconds in the inertia verification.
    pub seconds_verify: f64,
    /// Seconds in the final polish step.
    pub seconds_polish: f64,
}

/// [`laplace_beltrami_spectrum`], also returning [`SpectrumStats`].
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::{laplace_beltrami_spectrum_with_stats, SpectrumOptions}};
/// let mesh = TriMesh::new(
///     vec![[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]],
///     vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
/// ).unwrap();
/// let (s, stats) =
///     laplace_beltrami_spectrum_with_stats(&mesh, &SpectrumOptions::with_eigenpairs(2)).unwrap();
/// assert_eq!(s.len(), 2);
/// assert!(stats.dense);
/// ```
pub fn laplace_beltrami_spectrum_with_stats(
    mesh: &TriMesh,
    options: &SpectrumOptions,
) -> Result<(Spectrum, SpectrumStats), SpectralError> {
    let start = std::time::Instant::now();
    let mut stats = SpectrumStats::default();
    let k = options.eigenpairs;
    if options.shift.is_nan() || options.shift >= 0.0 || !options.shift.is_finite() {
        return Err(SpectralError::InvalidOption(format!(
            "shift must be negative and finite, got {}",
            options.shift
        )));
    }
    if options.tolerance.is_nan() || options.tolerance <= 0.0 || !options.tolerance.is_finite() {
        return Err(SpectralError::InvalidOption(format!(
            "tolerance must be positive, got {}",
            options.tolerance
        )));
    }
    if options.block_size == 0 {
        return Err(SpectralError::InvalidOption(
            "block size must be at least 1".into(),
        ));
    }
    let d = mesh.vertex_count();
    if k > d {
        return Err(SpectralError::TooManyEigenpairs {
            requested: k,
            vertices: d,
        });
    }
    let ops = SurfaceOperators::with_laplacian(mesh, options.laplacian);
    let (original_area, mass) = (ops.total_area(), ops.unit_mass().to_vec());
    let pencil = Pencil::new(ops.laplacian(), &mass)?;
    let n = pencil.n();
    if k > n {
        return Err(SpectralError::TooManyEigenpairs {
            requested: k,
            vertices: n,
        });
    }
    let par = if options.threads == 1 {
        Par::Seq
    } else {
        Par::rayon(options.threads)
    };
    let (labels, c) = pencil.components();
    let null = null_basis(&pencil, &labels, c);
    stats.active_vertices = n;
    stats.components = c;
    stats.seconds_setup = start.elapsed().as_secs_f64();

    let b = options.block_size;
    let nev_wanted = k.saturating_sub(c);
    let guard = options.guard.unwrap_or((k / 20).max(b)).max(1);
    let basis_for = |nev: usize, b: usize| -> usize {
        let m = options.basis_size.unwrap_or(2 * nev).max(nev + 2 * b);
        m.div_ceil(b) * b
    };
    let use_dense = n <= options.dense_below || basis_for(nev_wanted + guard, b) + b + c >= n;
    let (values, psi) = if use_dense {
        stats.dense = true;
        dense_active(&pencil, &null, k, c)?
    } else if nev_wanted == 0 {
        (vec![0.0; k], null.subcols(0, k).to_owned())
    } else {
        sparse_active(&pencil, &null, nev_wanted, guard, options, par, &mut stats)?
    };

    // Back to the mesh's vertices: φ = M^{-1/2} ψ, zero on dropped vertices.
    let mut eigenvectors = vec![0.0; d * k];
    for i in 0..k {
        let out = &mut eigenvectors[i * d..(i + 1) * d];
        for (a, &v) in pencil.active.iter().enumerate() {
            out[v] = psi[(a, i)] / pencil.mass[a].sqrt();
        }
        normalise_sign(out);
    }
    Ok((
        Spectrum {
            eigenvalues: values,
            eigenvectors,
            vertex_areas: mass,
            original_area,
        },
        stats,
    ))
}

/// Makes the entry of largest magnitude positive (first such index on ties).
fn normalise_sign(v: &mut [f64]) {
    let mut best = 0.0f64;
    let mut sign = 1.0;
    for &x in v.iter() {
        if x.abs() > best {
            best = x.abs();
            sign = x.signum();
        }
    }
    if sign < 0.0 {
        for x in v.iter_mut() {
            *x = -*x;
        }
    }
}

/// Orthonormal (Euclidean, ψ-space) basis of the null space: column `C` is
/// `√m_i / √area(C)` on the vertices of component `C`.
fn null_basis(pencil: &Pencil, labels: &[usize], c: usize) -> Mat<f64> {
    let n = pencil.n();
    let mut area = vec![0.0; c];
    for (i, &lab) in labels.iter().enumerate() {
        area[lab] += pencil.mass[i];
    }
    let mut null = Mat::<f64>::zeros(n, c);
    for (i, &lab) in labels.iter().enumerate() {
        null[(i, lab)] = (pencil.mass[i] / area[lab]).sqrt();
    }
    null
}

/// Dense solve on the active vertices; the `c` zero eigenpairs are replaced by the exact null
/// basis. Returns eigenvalues ascending and ψ = M^{1/2}φ (n × k).
fn dense_active(
    pencil: &Pencil,
    null: &Mat<f64>,
    k: usize,
    c: usize,
) -> Result<(Vec<f64>, Mat<f64>), SpectralError> {
    let n = pencil.n();
    let inv_sqrt: Vec<f64> = pencil.mass.iter().map(|m| 1.0 / m.sqrt()).collect();
    let mut a = Mat::<f64>::zeros(n, n);
    let lr = pencil.l.as_ref();
    for j in 0..n {
        for (&i, &v) in lr.row_idx_of_col_raw(j).iter().zip(lr.val_of_col(j)) {
            a[(i, j)] = v * inv_sqrt[i] * inv_sqrt[j];
        }
    }
    let evd = a
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|e| SpectralError::Solver(format!("dense eigensolver: {e:?}")))?;
    let (s, u) = (evd.S(), evd.U());
    let mut values = Vec::with_capacity(k);
    let mut psi = Mat::<f64>::zeros(n, k);
    for i in 0..k {
        if i < c {
            values.push(0.0);
            psi.col_mut(i).copy_from(null.col(i));
        } else {
            values.push(s[i].max(0.0));
            psi.col_mut(i).copy_from(u.col(i));
        }
    }
    Ok((values, psi))
}

/// Sparse shift-invert block Lanczos with inertia verification (see
/// [`laplace_beltrami_spectrum`]). Returns `c + nev_wanted` eigenvalues ascending and ψ.
fn sparse_active(
    pencil: &Pencil,
    null: &Mat<f64>,
    nev_wanted: usize,
    guard: usize,
    options: &SpectrumOptions,
    par: Par,
    stats: &mut SpectrumStats,
) -> Result<(Vec<f64>, Mat<f64>), SpectralError> {
    let t0 = std::time::Instant::now();
    let n = pencil.n();
    let c = null.ncols();
    let symbolic = pencil.symbolic()?;
    let mut sigma = options.shift;
    let op = {
        let mut attempt = 0;
        loop {
            match ShiftInvert::new(pencil, &symbolic, sigma, par) {
                Ok(op) => break op,
                Err(e) if attempt >= 3 => return Err(e),
                Err(_) => {
                    attempt += 1;
                    sigma *= 10.0;
                }
            }
        }
    };
    stats.factor_nnz = op.factor_nnz();
    stats.seconds_setup += t0.elapsed().as_secs_f64();
    let apply = |x: faer::MatMut<'_, f64>| op.apply_in_place(x);
    let mut b = options.block_size;
    let mut guard = guard;
    let mut last_err = None;
    for attempt in 0..3u64 {
        let nev = nev_wanted + guard;
        let max_basis = {
            let m = options.basis_size.unwrap_or(2 * nev).max(nev + 2 * b);
            m.div_ceil(b) * b
        };
        if max_basis + b + c >= n {
            // Not enough room for the Krylov basis: the dense solver is exact and cheap here.
            return dense_active(pencil, null, c + nev_wanted, c);
        }
        let params = BlockLanczosParams {
            nev,
            block: b,
            max_basis,
            tol: options.tolerance,
            max_restarts: options.max_restarts,
            seed: options.seed.wrapping_add(attempt),
            par,
        };
        let t1 = std::time::Instant::now();
        let res = largest_eigenpairs(n, &apply, null.as_ref(), &params)?;
        stats.seconds_lanczos += t1.elapsed().as_secs_f64();
        stats.attempts += 1;
        stats.restarts = res.restarts;
        stats.applications = res.applications;
        let t2 = std::time::Instant::now();
        // λ = σ + 1/θ, ascending because θ is descending.
        let lambda: Vec<f64> = res.values.iter().map(|&t| sigma + 1.0 / t).collect();
        let verdict = verify(pencil, &symbolic, &lambda, nev_wanted, c, par);
        stats.seconds_verify += t2.elapsed().as_secs_f64();
        match verdict {
            Ok(()) => {
                let mut values = vec![0.0; c];
                values.extend(lambda[..nev_wanted].iter().map(|&x| x.max(0.0)));
                let mut psi = Mat::<f64>::zeros(n, c + nev_wanted);
                psi.as_mut().subcols_mut(0, c).copy_from(null);
                let mut body = res.vectors.as_ref().subcols(0, nev_wanted).to_owned();
                if options.polish {
                    let t3 = std::time::Instant::now();
                    polish(&op, body.as_mut(), &res.values[..nev_wanted], null, par)?;
                    stats.seconds_polish = t3.elapsed().as_secs_f64();
                }
                psi.as_mut().subcols_mut(c, nev_wanted).copy_from(&body);
                return Ok((values, psi));
            }
            Err(e) => {
                last_err = Some(e);
                b *= 2;
                guard *= 2;
            }
        }
    }
    Err(last_err.expect("at least one attempt"))
}

/// One inverse-iteration step `Ψ ← AΨ diag(1/θ)`, projected off the null space, then the
/// symmetric orthonormalisation `Ψ ← Ψ (ΨᵀΨ)^{-1/2}` (which moves each vector least).
fn polish(
    op: &ShiftInvert<'_>,
    mut psi: faer::MatMut<'_, f64>,
    theta: &[f64],
    null: &Mat<f64>,
    par: Par,
) -> Result<(), SpectralError> {
    use faer::Accum;
    use faer::linalg::matmul::matmul;
    op.apply_in_place(psi.rb_mut());
    for (j, &t) in theta.iter().enumerate() {
        let inv = 1.0 / t;
        for x in psi.rb_mut().col_mut(j).iter_mut() {
            *x *= inv;
        }
    }
    if null.ncols() > 0 {
        let mut c = Mat::<f64>::zeros(null.ncols(), psi.ncols());
        matmul(
            c.as_mut(),
            Accum::Replace,
            null.transpose(),
            psi.rb(),
            1.0,
            par,
        );
        matmul(
            psi.rb_mut(),
            Accum::Add,
            null.as_ref(),
            c.as_ref(),
            -1.0,
            par,
        );
    }
    let k = psi.ncols();
    let mut g = Mat::<f64>::zeros(k, k);
    matmul(
        g.as_mut(),
        Accum::Replace,
        psi.rb().transpose(),
        psi.rb(),
        1.0,
        par,
    );
    let evd = g
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|e| SpectralError::Solver(format!("polish: {e:?}")))?;
    let (s, u) = (evd.S(), evd.U());
    let mut scaled = u.to_owned();
    for j in 0..k {
        if s[j].is_nan() || s[j] <= 0.0 {
            return Err(SpectralError::Solver(
                "polish: lost linear independence".into(),
            ));
        }
        let f = 1.0 / s[j].sqrt();
        for x in scaled.col_mut(j).iter_mut() {
            *x *= f;
        }
    }
    let mut inv_sqrt = Mat::<f64>::zeros(k, k);
    matmul(
        inv_sqrt.as_mut(),
        Accum::Replace,
        scaled.as_ref(),
        u.transpose(),
        1.0,
        par,
    );
    let copy = psi.to_owned();
    matmul(
        psi.rb_mut(),
        Accum::Replace,
        copy.as_ref(),
        inv_sqrt.as_ref(),
        1.0,
        par,
    );
    Ok(())
}

/// Checks by an inertia count that no eigenvalue below the computed ones was skipped.
/// `lambda` (ascending, length ≥ `nev_wanted + 1`) excludes the `c` zero eigenvalues.
fn verify(
    pencil: &Pencil,
    symbolic: &faer::sparse::linalg::cholesky::SymbolicCholesky<usize>,
    lambda: &[f64],
    nev_wanted: usize,
    c: usize,
    par: Par,
) -> Result<(), SpectralError> {
    // Cut in the widest relative gap among the guard eigenvalues.
    let mut best = (nev_wanted - 1, -1.0);
    for jx in nev_wanted - 1..lambda.len() - 1 {
        let gap = (lambda[jx + 1] - lambda[jx]) / lambda[jx + 1].abs().max(f64::MIN_POSITIVE);
        if gap > best.1 {
            best = (jx, gap);
        }
    }
    let jx = best.0;
    let expected = c + jx + 1;
    for frac in [0.5, 0.3, 0.7] {
        let tau = lambda[jx] + frac * (lambda[jx + 1] - lambda[jx]);
        if let Some(count) = count_below(pencil, symbolic, tau, par) {
            if count == expected {
                return Ok(());
            }
            return Err(SpectralError::Solver(format!(
                "eigenvalue count check failed: {count} eigenvalues below {tau:.6e}, \
                 the Lanczos iteration found {expected}"
            )));
        }
    }
    Err(SpectralError::Solver(
        "inertia count: LDLt factorisation broke down".into(),
    ))
}

/// Reference solver: the `k` smallest eigenpairs by a dense symmetric eigendecomposition of
/// `M^{-1/2} L M^{-1/2}`. O(d³): for small meshes and as a test oracle.
pub fn dense_spectrum(mesh: &TriMesh, k: usize) -> Result<Spectrum, SpectralError> {
    let d = mesh.vertex_count();
    if k > d {
        return Err(SpectralError::TooManyEigenpairs {
            requested: k,
            vertices: d,
        });
    }
    let ops = SurfaceOperators::new(mesh);
    let (original_area, mass, l) = (ops.total_area(), ops.unit_mass().to_vec(), ops.laplacian());
    let inv_sqrt: Vec<f64> = mass
        .iter()
        .map(|&m| if m > 0.0 { 1.0 / m.sqrt() } else { 0.0 })
        .collect();
    let mut a = faer::Mat::<f64>::zeros(d, d);
    for j in 0..d {
        let rows = l.as_ref().row_idx_of_col_raw(j);
        let vals = l.as_ref().val_of_col(j);
        for (&i, &v) in rows.iter().zip(vals) {
            a[(i, j)] = v * inv_sqrt[i] * inv_sqrt[j];
        }
    }
    let evd = a
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|e| SpectralError::Solver(format!("{e:?}")))?;
    let u = evd.U();
    let s = evd.S();
    let mut eigenvalues = Vec::with_capacity(k);
    let mut eigenvectors = Vec::with_capacity(k * d);
    for i in 0..k {
        eigenvalues.push(s[i]);
        for v in 0..d {
            eigenvectors.push(u[(v, i)] * inv_sqrt[v]);
        }
    }
    Ok(Spectrum {
        eigenvalues,
        eigenvectors,
        vertex_areas: mass,
        original_area,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small irregular mesh: a jittered, twice-subdivided octahedron-like grid sphere.
    fn bumpy_mesh() -> TriMesh {
        // A 12 × 12 grid wrapped as a torus gives a closed surface with a non-trivial spectrum.
        let (nu, nv) = (12usize, 10usize);
        let mut pos = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                let (u, v) = (
                    2.0 * std::f64::consts::PI * i as f64 / nu as f64,
                    2.0 * std::f64::consts::PI * j as f64 / nv as f64,
                );
                let r = 1.0 + 0.4 * v.cos() + 0.01 * ((i * 7 + j * 3) % 5) as f64;
                pos.push([r * u.cos(), r * u.sin(), 0.4 * v.sin()]);
            }
        }
        let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
        let mut faces = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                faces.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        TriMesh::new(pos, faces).unwrap()
    }

    #[test]
    fn inertia_check_accepts_the_true_spectrum_and_catches_a_skipped_eigenvalue() {
        let mesh = bumpy_mesh();
        let exact = dense_spectrum(&mesh, 30).unwrap();
        let ops = SurfaceOperators::new(&mesh);
        let pencil = Pencil::new(ops.laplacian(), ops.unit_mass()).unwrap();
        let symbolic = pencil.symbolic().unwrap();
        let (_, c) = pencil.components();
        assert_eq!(c, 1);
        // Nonzero eigenvalues 1..30: 20 wanted, 9 guard.
        let lambda: Vec<f64> = exact.eigenvalues[1..30].to_vec();
        assert!(verify(&pencil, &symbolic, &lambda, 20, c, Par::Seq).is_ok());
        // Drop one eigenvalue below the cut: the count must disagree.
        for skipped in [0usize, 10, 19] {
            let mut l = lambda.clone();
            l.remove(skipped);
            assert!(
                verify(&pencil, &symbolic, &l, 20, c, Par::Seq).is_err(),
                "skip of eigenvalue {skipped} not detected"
            );
        }
        // Counting directly: exactly i + 1 eigenvalues (with the zero) lie below a point
        // between λ_i and λ_{i+1} when they are distinct.
        for i in 1..29 {
            let (a, b) = (exact.eigenvalues[i], exact.eigenvalues[i + 1]);
            if b - a > 1e-6 * b {
                let n = count_below(&pencil, &symbolic, 0.5 * (a + b), Par::Seq).unwrap();
                assert_eq!(n, i + 1);
            }
        }
    }
}
