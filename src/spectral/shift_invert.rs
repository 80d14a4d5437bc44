//! Private building blocks of the sparse solver: the pencil `(L, M)` restricted to the vertices
//! of positive mass, its null space, the shift-invert operator and Sylvester inertia counts.

use super::SpectralError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::reborrow::*;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky, supernodal,
};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Conj, MatMut, Par, Side};

/// The pencil `(L, M)` on the `n` vertices of positive mass ("active" vertices).
///
/// Vertices of zero mass (unreferenced, or only in zero-area triangles) carry no surface: the
/// generalized problem has no finite eigenvalue there, so they are dropped and their
/// eigenvector entries are reported as 0.
pub(crate) struct Pencil {
    /// `active[i]` = mesh vertex of active index `i`.
    pub active: Vec<usize>,
    /// Lumped mass of the active vertices (unit-area mesh).
    pub mass: Vec<f64>,
    /// `L` restricted to the active vertices, both triangles stored, every diagonal present.
    pub l: SparseColMat<usize, f64>,
    /// Position in `l`'s value array of each diagonal entry.
    diag_pos: Vec<usize>,
}

impl Pencil {
    /// Restricts `l` (d × d) and `mass` (length d) to the vertices of positive mass.
    pub fn new(l: &SparseColMat<usize, f64>, mass: &[f64]) -> Result<Self, SpectralError> {
        let d = mass.len();
        let mut index = vec![usize::MAX; d];
        let mut active = Vec::new();
        for (v, &m) in mass.iter().enumerate() {
            if m > 0.0 {
                index[v] = active.len();
                active.push(v);
            }
        }
        let n = active.len();
        let lr = l.as_ref();
        let mut triplets = Vec::with_capacity(lr.compute_nnz() + n);
        for (jn, &j) in active.iter().enumerate() {
            triplets.push(Triplet::new(jn, jn, 0.0));
            for (&i, &v) in lr.row_idx_of_col_raw(j).iter().zip(lr.val_of_col(j)) {
                let iname = index[i];
                if iname != usize::MAX {
                    triplets.push(Triplet::new(iname, jn, v));
                }
            }
        }
        let l = SparseColMat::try_new_from_triplets(n, n, &triplets)
            .map_err(|e| SpectralError::Solver(format!("building L: {e:?}")))?;
        let mut diag_pos = vec![0; n];
        {
            let sym = l.symbolic();
            let col_ptr = sym.col_ptr();
            let row_idx = sym.row_idx();
            for (j, pos) in diag_pos.iter_mut().enumerate() {
                let start = col_ptr[j];
                let off = row_idx[start..col_ptr[j + 1]]
                    .iter()
                    .position(|&i| i == j)
                    .expect("diagonal entries were inserted");
                *pos = start + off;
            }
        }
        let mass = active.iter().map(|&v| mass[v]).collect();
        Ok(Pencil {
            active,
            mass,
            l,
            diag_pos,
        })
    }

    /// Number of active vertices.
    pub fn n(&self) -> usize {
        self.active.len()
    }

    /// `L − s M` (same sparsity pattern for every `s`).
    pub fn shifted(&self, s: f64) -> SparseColMat<usize, f64> {
        let mut a = self.l.clone();
        let vals = a.val_mut();
        for (j, &p) in self.diag_pos.iter().enumerate() {
            vals[p] -= s * self.mass[j];
        }
        a
    }

    /// Connected components of the graph of the non-zero off-diagonal entries of `L`; each one
    /// spans one null vector of `L` (the constant on the component). Returns one label per
    /// active vertex and the number of components.
    pub fn components(&self) -> (Vec<usize>, usize) {
        let n = self.n();
        let mut label = vec![usize::MAX; n];
        let lr = self.l.as_ref();
        let mut count = 0;
        let mut stack = Vec::new();
        for s in 0..n {
            if label[s] != usize::MAX {
                continue;
            }
            label[s] = count;
            stack.push(s);
            while let Some(j) = stack.pop() {
                for (&i, &v) in lr.row_idx_of_col_raw(j).iter().zip(lr.val_of_col(j)) {
                    if v != 0.0 && label[i] == usize::MAX {
                        label[i] = count;
                        stack.push(i);
                    }
                }
            }
            count += 1;
        }
        (label, count)
    }

    /// Fill-reducing (AMD) symbolic Cholesky structure, shared by every shift.
    pub fn symbolic(&self) -> Result<SymbolicCholesky<usize>, SpectralError> {
        factorize_symbolic_cholesky(
            self.l.symbolic(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| SpectralError::Solver(format!("symbolic Cholesky: {e:?}")))
    }
}

/// `K = L − σ M = C Cᵀ` factored; applies `A = M^{1/2} K^{-1} M^{1/2}`, symmetric positive
/// definite when `σ < 0`, whose eigenvalues are `θ = 1 / (λ − σ)` with eigenvectors
/// `ψ = M^{1/2} φ`.
pub(crate) struct ShiftInvert<'a> {
    symbolic: &'a SymbolicCholesky<usize>,
    values: Vec<f64>,
    sqrt_mass: Vec<f64>,
    par: Par,
}

impl<'a> ShiftInvert<'a> {
    /// Factors `L − σ M`. Fails when it is not numerically positive definite.
    pub fn new(
        pencil: &Pencil,
        symbolic: &'a SymbolicCholesky<usize>,
        sigma: f64,
        par: Par,
    ) -> Result<Self, SpectralError> {
        let k = pencil.shifted(sigma);
        let mut values = vec![0.0; symbolic.len_val()];
        let mut mem =
            MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()));
        symbolic
            .factorize_numeric_llt::<f64>(
                &mut values,
                k.as_ref(),
                Side::Lower,
                LltRegularization::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| {
                SpectralError::Solver(format!("Cholesky of L - sigma M (sigma = {sigma}): {e:?}"))
            })?;
        Ok(ShiftInvert {
            symbolic,
            values,
            sqrt_mass: pencil.mass.iter().map(|m| m.sqrt()).collect(),
            par,
        })
    }

    /// Number of non-zeros of the Cholesky factor.
    pub fn factor_nnz(&self) -> usize {
        self.values.len()
    }

    /// `x ← A x` for every column of `x` (n × b).
    pub fn apply_in_place(&self, mut x: MatMut<'_, f64>) {
        let n = x.nrows();
        let b = x.ncols();
        for j in 0..b {
            let mut c = x.rb_mut().col_mut(j);
            for i in 0..n {
                c[i] *= self.sqrt_mass[i];
            }
        }
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(b, self.par));
        LltRef::new(self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            x.rb_mut(),
            self.par,
            MemStack::new(&mut mem),
        );
        for j in 0..b {
            let mut c = x.rb_mut().col_mut(j);
            for i in 0..n {
                c[i] *= self.sqrt_mass[i];
            }
        }
    }
}

/// Number of eigenvalues of `L φ = λ M φ` (active vertices) strictly below `tau`, by Sylvester's
/// law of inertia on an `LDLᵀ` factorisation of `L − τ M`. `None` when the factorisation breaks
/// down (a zero pivot), in which case the caller should move `tau` a little.
pub(crate) fn count_below(
    pencil: &Pencil,
    symbolic: &SymbolicCholesky<usize>,
    tau: f64,
    par: Par,
) -> Option<usize> {
    let k = pencil.shifted(tau);
    let mut values = vec![0.0; symbolic.len_val()];
    let mut mem =
        MemBuffer::new(symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()));
    symbolic
        .factorize_numeric_ldlt::<f64>(
            &mut values,
            k.as_ref(),
            Side::Lower,
            LdltRegularization::default(),
            par,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .ok()?;
    let mut negative = 0usize;
    let mut check = |dv: f64| -> bool {
        if !dv.is_finite() || dv == 0.0 {
            return false;
        }
        if dv < 0.0 {
            negative += 1;
        }
        true
    };
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            let f = s.factor();
            let col_ptr = f.col_ptr();
            let row_idx = f.row_idx();
            for j in 0..s.nrows() {
                let range = col_ptr[j]..col_ptr[j + 1];
                let p = row_idx[range.clone()].iter().position(|&i| i == j)?;
                if !check(values[range.start + p]) {
                    return None;
                }
            }
        }
        SymbolicCholeskyRaw::Supernodal(s) => {
            let f = supernodal::SupernodalLdltRef::new(s, &values);
            for sn in 0..s.n_supernodes() {
                let val = f.supernode(sn).val();
                for j in 0..val.ncols() {
                    if !check(val[(j, j)]) {
                        return None;
                    }
                }
            }
        }
    }
    Some(negative)
}
