//! [`region_point_map`]: a vertex-to-vertex map between two shapes built from their
//! corresponding regions, through a functional map fitted to the region indicators and refined
//! spectrally (ZoomOut).

use super::StableError;
use crate::spectral::Spectrum;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef, Par};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Options of [`region_point_map`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointMapOptions {
    /// Size `k₀` of the first functional map, the one fitted to the region indicators
    /// (default 10: about as many unknowns per row as there are region pairs).
    pub initial_size: usize,
    /// Size of the last functional map (default 150, capped by the eigenpairs available).
    pub final_size: usize,
    /// Growth of the map's size per ZoomOut step (default 5).
    pub step: usize,
    /// Weight of the Laplacian-commutativity term `‖CΛ_A − Λ_B C‖²` of the first fit, with
    /// eigenvalues divided by the largest one used (default 1).
    pub commutativity: f64,
    /// Vertices per shape (farthest-point samples) on which the ZoomOut steps run; the last
    /// map is evaluated on every vertex (default 2000).
    pub samples: usize,
}

impl Default for PointMapOptions {
    fn default() -> Self {
        PointMapOptions {
            initial_size: 10,
            final_size: 150,
            step: 5,
            commutativity: 1.0,
            samples: 2000,
        }
    }
}

/// One shape as [`region_point_map`] sees it.
#[derive(Debug, Clone, Copy)]
pub struct MapShape<'a> {
    /// Unit-area Laplace–Beltrami spectrum (mass-orthonormal eigenvectors).
    pub spectrum: &'a Spectrum,
    /// Vertex positions (only used to spread the samples).
    pub positions: &'a [[f64; 3]],
    /// Region id of every vertex (`-1`: none); region `r` of A corresponds to region `r` of B.
    pub labels: &'a [i32],
}

/// For every vertex `q` of B, a vertex `T(q)` of A, from corresponding regions.
///
/// The paper (§7.3) turns stable region pairs into functional constraints; this does the
/// same and then reads a point map back. A functional map `C` (`k₀ × k₀`, from A's spectral
/// coefficients to B's) is fitted to the region indicators, `C Φ_Aᵀ M_A 1_{Ω_A,r} ≈
/// Φ_Bᵀ M_B 1_{Ω_B,r}`, with the Laplacian-commutativity regulariser; ZoomOut (Melzi et al.
/// 2019) then alternates nearest-neighbour point maps and least-squares maps of growing size
/// `k₀, k₀ + step, …, final_size` on farthest-point samples. The returned map is the nearest
/// neighbour of `Φ_B(q)` among the rows of `Φ_A Cᵀ` over all vertices.
///
/// Region indicators, like the descriptors they come from, are blind to intrinsic symmetries,
/// so the map may flip a symmetric shape; a transfer of symmetric regions is unaffected.
/// Deterministic (fixed blocks, ties to the lowest index).
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::spectral::{laplace_beltrami_spectrum, SpectrumOptions};
/// use coseg::stable::{region_point_map, MapShape, PointMapOptions};
/// // A strip of 8 × 2 squares, cut into left and right halves.
/// let (nx, ny) = (9u32, 3u32);
/// let pos: Vec<[f64; 3]> = (0..nx * ny).map(|i| [(i % nx) as f64, (i / nx) as f64, 0.0]).collect();
/// let mut faces = Vec::new();
/// for y in 0..ny - 1 { for x in 0..nx - 1 {
///     let v = y * nx + x;
///     faces.push([v, v + 1, v + nx + 1]);
///     faces.push([v, v + nx + 1, v + nx]);
/// }}
/// let mesh = TriMesh::new(pos.clone(), faces).unwrap();
/// let spectrum = laplace_beltrami_spectrum(&mesh, &SpectrumOptions { eigenpairs: 12, ..Default::default() }).unwrap();
/// let labels: Vec<i32> = (0..nx * ny).map(|i| i32::from(i % nx >= 4)).collect();
/// let shape = MapShape { spectrum: &spectrum, positions: &pos, labels: &labels };
/// let options = PointMapOptions { initial_size: 4, final_size: 12, step: 4, ..Default::default() };
/// let map = region_point_map(&shape, &shape, &options).unwrap();
/// // Every vertex lands on the same side of the cut.
/// assert!(map.iter().enumerate().all(|(q, &p)| labels[q] == labels[p as usize]));
/// ```
pub fn region_point_map(
    a: &MapShape<'_>,
    b: &MapShape<'_>,
    options: &PointMapOptions,
) -> Result<Vec<u32>, StableError> {
    for (s, name) in [(a, "A"), (b, "B")] {
        let d = s.spectrum.vertex_count();
        if s.labels.len() != d || s.positions.len() != d {
            return Err(StableError::BadOption(format!(
                "shape {name}: {} labels and {} positions for a spectrum of {d} vertices",
                s.labels.len(),
                s.positions.len()
            )));
        }
    }
    let available = a
        .spectrum
        .eigenvalues
        .len()
        .min(b.spectrum.eigenvalues.len());
    let final_size = options.final_size.min(available);
    if options.initial_size == 0 || options.step == 0 || options.initial_size > final_size {
        return Err(StableError::BadOption(format!(
            "point map sizes: initial {} and step {} must be positive, and the initial size at \
             most the final size {final_size} (eigenpairs available: {available})",
            options.initial_size, options.step
        )));
    }
    if !(options.commutativity.is_finite() && options.commutativity >= 0.0) {
        return Err(StableError::BadOption(format!(
            "commutativity = {} must be finite and non-negative",
            options.commutativity
        )));
    }
    let phi_a = eigenvectors(a.spectrum, final_size);
    let phi_b = eigenvectors(b.spectrum, final_size);
    let mut c = initial_map(a, b, phi_a, phi_b, options)?;

    let samples_a = sample_rows(phi_a, a.positions, options.samples.max(2 * final_size));
    let samples_b = sample_rows(phi_b, b.positions, options.samples.max(2 * final_size));
    let mut k = options.initial_size;
    while k < final_size {
        let t = nearest_rows(
            &pulled_back(samples_a.as_ref(), &c),
            samples_b.subcols(0, k),
        );
        let next = (k + options.step).min(final_size);
        c = spectral_fit(samples_b.subcols(0, next), samples_a.subcols(0, next), &t)?;
        k = next;
    }
    Ok(nearest_rows(&pulled_back(phi_a, &c), phi_b.subcols(0, k)))
}

fn eigenvectors(s: &Spectrum, k: usize) -> MatRef<'_, f64> {
    let d = s.vertex_count();
    MatRef::from_column_major_slice(&s.eigenvectors[..d * k], d, k)
}

/// The first functional map, row by row: `(a aᵀ + μ D_i) c_i = a b_i` with
/// `D_i = diag(((λ_A,l − λ_B,i) / λ_max)²)`.
fn initial_map(
    a: &MapShape<'_>,
    b: &MapShape<'_>,
    phi_a: MatRef<'_, f64>,
    phi_b: MatRef<'_, f64>,
    options: &PointMapOptions,
) -> Result<DMatrix<f64>, StableError> {
    let k = options.initial_size;
    let regions = a
        .labels
        .iter()
        .chain(b.labels)
        .copied()
        .max()
        .map_or(0, |m| (m + 1).max(0) as usize);
    let coefficients = |s: &MapShape<'_>, phi: MatRef<'_, f64>| {
        let mut x = DMatrix::<f64>::zeros(k, regions);
        for (v, &l) in s.labels.iter().enumerate() {
            if l >= 0 {
                let m = s.spectrum.vertex_areas[v];
                for i in 0..k {
                    x[(i, l as usize)] += m * phi[(v, i)];
                }
            }
        }
        x
    };
    let (ca, cb) = (coefficients(a, phi_a), coefficients(b, phi_b));
    // Only regions present on both shapes constrain the map.
    let shared: Vec<usize> = (0..regions)
        .filter(|&r| {
            ca.column(r).iter().any(|&x| x != 0.0) && cb.column(r).iter().any(|&x| x != 0.0)
        })
        .collect();
    if shared.is_empty() {
        return Err(StableError::BadOption(
            "no region is present on both shapes".into(),
        ));
    }
    let ca = ca.select_columns(&shared);
    let cb = cb.select_columns(&shared);
    let (la, lb) = (&a.spectrum.eigenvalues, &b.spectrum.eigenvalues);
    let scale = la[k - 1].abs().max(lb[k - 1].abs()).max(f64::MIN_POSITIVE);
    let gram = &ca * ca.transpose();
    let mut c = DMatrix::zeros(k, k);
    for (i, &lambda_b) in lb.iter().enumerate().take(k) {
        let mut m = gram.clone();
        for (l, &lambda_a) in la.iter().enumerate().take(k) {
            m[(l, l)] += options.commutativity * ((lambda_a - lambda_b) / scale).powi(2);
        }
        let rhs: DVector<f64> = &ca * cb.row(i).transpose();
        let row = m
            .svd(true, true)
            .solve(&rhs, 1e-12)
            .map_err(|e| StableError::BadOption(format!("functional map fit: {e}")))?;
        c.set_row(i, &row.transpose());
    }
    Ok(c)
}

/// `Φ Cᵀ` over the first `C.ncols()` columns of `Φ`: A's spectral embedding expressed in B's
/// basis, whose rows are compared with B's rows `Φ_B(q)`.
fn pulled_back(phi: MatRef<'_, f64>, c: &DMatrix<f64>) -> Mat<f64> {
    let k = c.ncols();
    let ct = Mat::from_fn(k, c.nrows(), |i, j| c[(j, i)]);
    let mut out = Mat::zeros(phi.nrows(), c.nrows());
    matmul(
        out.as_mut(),
        Accum::Replace,
        phi.subcols(0, k),
        ct.as_ref(),
        1.0,
        Par::Seq,
    );
    out
}

/// Least-squares functional map of a point map on samples: `C = argmin ‖Φ_B C − Φ_A[T]‖`.
fn spectral_fit(
    phi_b: MatRef<'_, f64>,
    phi_a: MatRef<'_, f64>,
    t: &[u32],
) -> Result<DMatrix<f64>, StableError> {
    let k = phi_b.ncols();
    let b = DMatrix::from_fn(phi_b.nrows(), k, |i, j| phi_b[(i, j)]);
    let a = DMatrix::from_fn(t.len(), k, |i, j| phi_a[(t[i] as usize, j)]);
    let btb = b.transpose() * &b;
    let bta = b.transpose() * a;
    btb.cholesky()
        .map(|ch| ch.solve(&bta))
        .ok_or_else(|| StableError::BadOption("ZoomOut: sampled eigenbasis is singular".into()))
}

/// Rows of `phi` at `count` farthest-point samples of `positions` (all rows when `count ≥ d`),
/// starting from vertex 0.
fn sample_rows(phi: MatRef<'_, f64>, positions: &[[f64; 3]], count: usize) -> Mat<f64> {
    let d = positions.len();
    let chosen: Vec<usize> = if count >= d {
        (0..d).collect()
    } else {
        let mut dist = vec![f64::INFINITY; d];
        let mut out = Vec::with_capacity(count);
        let mut current = 0usize;
        for _ in 0..count {
            out.push(current);
            let c = positions[current];
            let mut far = (-1.0, 0usize);
            for (i, p) in positions.iter().enumerate() {
                let d2 = (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2);
                if d2 < dist[i] {
                    dist[i] = d2;
                }
                if dist[i] > far.0 {
                    far = (dist[i], i);
                }
            }
            current = far.1;
        }
        out
    };
    Mat::from_fn(chosen.len(), phi.ncols(), |i, j| phi[(chosen[i], j)])
}

/// Rows of `query` per block: fixed, so the result does not depend on the thread count.
const QUERY_BLOCK: usize = 128;

/// For every row of `query`, the index of the nearest row of `base` (Euclidean; ties to the
/// lowest index). Both have the same number of columns.
fn nearest_rows(base: &Mat<f64>, query: MatRef<'_, f64>) -> Vec<u32> {
    let n = base.nrows();
    let norms: Vec<f64> = (0..n)
        .map(|i| (0..base.ncols()).map(|j| base[(i, j)] * base[(i, j)]).sum())
        .collect();
    let starts: Vec<usize> = (0..query.nrows()).step_by(QUERY_BLOCK).collect();
    starts
        .par_iter()
        .flat_map_iter(|&r0| {
            let m = QUERY_BLOCK.min(query.nrows() - r0);
            let mut dots = Mat::<f64>::zeros(n, m);
            matmul(
                dots.as_mut(),
                Accum::Replace,
                base.as_ref(),
                query.subrows(r0, m).transpose(),
                1.0,
                Par::Seq,
            );
            (0..m)
                .map(|j| {
                    let col = dots.col(j);
                    let mut best = (f64::INFINITY, 0usize);
                    for (i, &norm) in norms.iter().enumerate() {
                        let d = norm - 2.0 * col[i];
                        if d < best.0 {
                            best = (d, i);
                        }
                    }
                    best.1 as u32
                })
                .collect::<Vec<_>>()
        })
        .collect()
}
