use super::{SpectralError, SurfaceOperators};
use crate::mesh::TriMesh;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Llt;
use faer::sparse::{SparseColMat, Triplet};
use faer::{MatMut, Side};
use rayon::prelude::*;

/// One backward-Euler step of the heat equation on a mesh scaled to unit total area:
/// `u = (M + t L)⁻¹ M x`, with `L` the cotangent Laplacian and `M` the lumped mass of the
/// unit-area mesh.
///
/// It is a low-pass filter of vertex functions: it keeps constants (`u = x` when `x` is
/// constant), preserves the integral `Σ M x`, and damps an eigenfunction of eigenvalue `λ`
/// by `1 / (1 + t λ)`. The time `t` is dimensionless (unit area), so a given `t` smooths
/// the same share of every shape whatever its resolution or file units: `√t` is roughly the
/// smoothing radius as a fraction of the shape's size (`t = 10⁻³` ≈ 3 % of it).
///
/// The factorisation (sparse Cholesky of `M + t L`) is done once by [`HeatSmoother::new`];
/// every [`HeatSmoother::smooth`] is then two triangular solves. Vertices of zero mass (in no
/// triangle of positive area) get a tiny mass so the system stays positive definite.
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::HeatSmoother};
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.]], vec![[0,1,2],[0,2,3]]).unwrap();
/// let s = HeatSmoother::new(&m, 1e-2).unwrap();
/// let mut x = vec![2.0; 4];
/// s.smooth(&mut x, 1).unwrap();
/// assert!(x.iter().all(|v| (v - 2.0).abs() < 1e-12)); // constants are kept
/// ```
#[derive(Debug)]
pub struct HeatSmoother {
    llt: Llt<usize, f64>,
    mass: Vec<f64>,
    time: f64,
}

impl HeatSmoother {
    /// Factorises `M + t L` for `mesh` (scaled to unit area) and time `time > 0`.
    pub fn new(mesh: &TriMesh, time: f64) -> Result<Self, SpectralError> {
        Self::from_operators(&SurfaceOperators::new(mesh), time)
    }

    /// Same as [`HeatSmoother::new`], from operators already computed for the mesh.
    pub fn from_operators(ops: &SurfaceOperators, time: f64) -> Result<Self, SpectralError> {
        if !(time.is_finite() && time > 0.0) {
            return Err(SpectralError::InvalidOption(format!(
                "heat smoothing time must be positive and finite, got {time}"
            )));
        }
        let d = ops.vertex_count();
        // Normalised by the sum of the lumped masses (not the sum of the face areas the
        // spectrum divides by; the two differ in the last bits): `Σ M = 1` on this matrix, and
        // every smoothed output is unchanged from before the operators were shared.
        let areas = ops.vertex_areas();
        let total: f64 = areas.iter().sum();
        if !(total.is_finite() && total > 0.0) {
            return Err(SpectralError::InvalidOption(
                "the mesh has no area to smooth over".into(),
            ));
        }
        let floor = 1e-9 / d as f64;
        let mass: Vec<f64> = areas.iter().map(|a| (a / total).max(floor)).collect();
        let lr = ops.laplacian().as_ref();
        let mut triplets = Vec::with_capacity(lr.compute_nnz() + d);
        for (v, &m) in mass.iter().enumerate() {
            triplets.push(Triplet::new(v, v, m));
        }
        for j in 0..d {
            for (&i, &w) in lr.row_idx_of_col_raw(j).iter().zip(lr.val_of_col(j)) {
                if i >= j {
                    triplets.push(Triplet::new(i, j, time * w));
                }
            }
        }
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(d, d, &triplets)
            .map_err(|e| SpectralError::Solver(format!("building M + tL: {e:?}")))?;
        let llt = a
            .sp_cholesky(Side::Lower)
            .map_err(|e| SpectralError::Solver(format!("Cholesky of M + tL: {e:?}")))?;
        Ok(HeatSmoother { llt, mass, time })
    }

    /// The time `t` (unit area).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Number of vertices `d`.
    pub fn vertex_count(&self) -> usize {
        self.mass.len()
    }

    /// Smooths `columns` functions stored column-major in `x` (`x.len() = d · columns`) in
    /// place: each column `x_c ← (M + t L)⁻¹ M x_c`.
    pub fn smooth(&self, x: &mut [f64], columns: usize) -> Result<(), SpectralError> {
        let d = self.mass.len();
        if x.len() != d * columns {
            return Err(SpectralError::InvalidOption(format!(
                "smoothing {columns} functions of {d} vertices needs {} values, got {}",
                d * columns,
                x.len()
            )));
        }
        if columns == 0 {
            return Ok(());
        }
        for col in x.chunks_exact_mut(d) {
            for (v, m) in col.iter_mut().zip(&self.mass) {
                *v *= m;
            }
        }
        // Columns are independent: solve them in groups on rayon's threads (the result does not
        // depend on the grouping).
        let per_task = columns.div_ceil(rayon::current_num_threads()).max(1);
        x.par_chunks_mut(d * per_task).for_each(|group| {
            let rhs = MatMut::from_column_major_slice_mut(group, d, group.len() / d);
            self.llt.solve_in_place(rhs);
        });
        Ok(())
    }
}
