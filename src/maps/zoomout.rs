//! [`zoomout`]: refine a vertex-to-vertex map between two shapes spectrally (Melzi et al.,
//! *ZoomOut: spectral upsampling for efficient shape correspondence*, 2019).

use super::nearest_rows::{
    OwnedBase, QueryRows, col_slice_mut, gather_rows, in_single, nearest_candidates_owned,
};
use super::{AuctionOptions, CandidateLists, auction_assignment};
use crate::option_range::non_negative;
use crate::spectral::{SpectralError, Spectrum};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Options of [`zoomout`] (and of the ZoomOut stage of
/// [`region_point_map`](crate::maps::region_point_map)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct ZoomOutOptions {
    /// Size `k₀` of the first functional map (default 10).
    pub initial_size: usize,
    /// Size of the last functional map (default 150, capped by the eigenpairs available).
    pub final_size: usize,
    /// Growth of the map's size per step (default 5).
    pub step: usize,
    /// Vertices per shape (farthest-point samples) on which the steps run; the last map is
    /// evaluated on every vertex (default 2000; at least twice the final size is used).
    pub samples: usize,
    /// Weight `λ` of the descriptors in the last nearest-neighbour search, when both shapes
    /// carry them: the rows compared are `[Φ_A Cᵀ | λ D_A]` and `[Φ_B | λ D_B]`, each
    /// descriptor column scaled to unit Euclidean norm over its shape's vertices (default 0:
    /// plain ZoomOut). About 500 makes the descriptors weigh as much as the spectral
    /// coordinates; on near-isometric pairs they pin the map where the spectral embedding
    /// drifts (see [`MapGuidedOptions::near_isometric`](crate::maps::MapGuidedOptions::near_isometric)).
    pub descriptor_weight: f64,
    /// How the last point map is read from the embeddings (default
    /// [`FinalMatch::default`]: a near-bijective assignment).
    pub final_match: FinalMatch,
    /// Relative weight of each descriptor column in the last search (`None`, default: equal).
    /// Column `j` counts `w_j / mean(w)` times in the squared distance, so the feature
    /// families' shares of the band affinity ([`crate::stable::SegmentPairOptions::feature_weights`])
    /// also hold here; `segment_pair` sets it from them. Not serialised (it is derived from the
    /// pipeline's options, which are).
    #[serde(skip)]
    pub descriptor_weights: Option<Vec<f64>>,
}

impl Default for ZoomOutOptions {
    fn default() -> Self {
        ZoomOutOptions {
            initial_size: 10,
            final_size: 150,
            step: 5,
            samples: 2000,
            descriptor_weight: 0.0,
            final_match: FinalMatch::default(),
            descriptor_weights: None,
        }
    }
}

/// How [`zoomout`] reads its last point map over all vertices.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum FinalMatch {
    /// Every vertex of B takes the nearest row of A (ZoomOut as published): many-to-one
    /// where the embedding is compressed.
    Nearest,
    /// Every vertex of B takes one of its `candidates` nearest rows of A by
    /// [`auction_assignment`]: one-to-one between shapes of equal vertex count, balanced
    /// otherwise.
    Bijective {
        /// Candidates per vertex (default 64).
        candidates: usize,
        /// The assignment's options.
        auction: AuctionOptions,
    },
}

impl Default for FinalMatch {
    /// `Bijective` with 64 candidates and [`AuctionOptions::default`]: on the TOSCA
    /// within-class pairs it places the map step's boundaries 0.4–1.05 points of correspondence
    /// ratio better than `Nearest` (README), for 0.3–0.5 s more on 10,000 vertices
    /// (`examples/bench_zoomout.rs`).
    fn default() -> Self {
        FinalMatch::Bijective {
            candidates: 64,
            auction: AuctionOptions::default(),
        }
    }
}

/// What a spectral map needs of a shape.
#[derive(Debug, Clone, Copy)]
pub struct ShapeGeometry<'a> {
    /// Unit-area spectrum (mass-orthonormal eigenvectors, lumped masses).
    pub spectrum: &'a Spectrum,
    /// Vertex positions (only used to spread the samples).
    pub positions: &'a [[f64; 3]],
    /// Optional per-vertex descriptors, feature-major `N × d` (feature `f` of vertex `v` at
    /// `f·d + v`, the layout of [`Descriptors::values`](crate::features::Descriptors)); used
    /// by the last nearest-neighbour search when both shapes have the same `N`.
    pub descriptors: Option<&'a [f64]>,
}

/// Refines a point map `T₀` from B to A (`initial[q]` is a vertex of A for every vertex `q`
/// of B) and returns the refined one, same layout.
///
/// The functional map of `T₀` is fitted at size `k₀` (`C = argmin ‖Φ_B C − Φ_A[T₀]‖`, `k₀ × k₀`,
/// from A's spectral coefficients to B's), then ZoomOut alternates nearest-neighbour point
/// maps and least-squares functional maps of sizes `k₀ + step, …, final_size` on
/// farthest-point samples; the last point map is the nearest neighbour of `Φ_B(q)` among the
/// rows of `Φ_A Cᵀ` over all vertices (from 8,192 vertices of A on, among the rows of
/// its nearest clusters of rows: an inverted-file search, ~15× cheaper at 50k vertices and
/// the same TOSCA correspondence ratio). Only `T₀`'s low-frequency content matters: a map with
/// small local errors everywhere is as good a start as an exact one.
///
/// Intrinsic: a map that flips a symmetric shape stays flipped. Deterministic whatever the
/// thread count (fixed blocks; ties go to the lowest index).
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::spectral::{laplace_beltrami_spectrum, SpectrumOptions};
/// use coseg::maps::{ShapeGeometry, ZoomOutOptions, zoomout};
/// // A 9 × 3 grid of points.
/// let (nx, ny) = (9u32, 3u32);
/// let pos: Vec<[f64; 3]> = (0..nx * ny).map(|i| [(i % nx) as f64, (i / nx) as f64, 0.0]).collect();
/// let mut faces = Vec::new();
/// for y in 0..ny - 1 { for x in 0..nx - 1 {
///     let v = y * nx + x;
///     faces.push([v, v + 1, v + nx + 1]);
///     faces.push([v, v + nx + 1, v + nx]);
/// }}
/// let mesh = TriMesh::new(pos.clone(), faces).unwrap();
/// let mut spectrum_options = SpectrumOptions::default();
/// spectrum_options.eigenpairs = 12;
/// let spectrum = laplace_beltrami_spectrum(&mesh, &spectrum_options).unwrap();
/// let shape = ShapeGeometry { spectrum: &spectrum, positions: &pos, descriptors: None };
/// // Start from the identity with every vertex of the middle row sent one step to the right.
/// let start: Vec<u32> = (0..nx * ny).map(|i| if i / nx == 1 && i % nx < nx - 1 { i + 1 } else { i }).collect();
/// let mut options = ZoomOutOptions::default();
/// (options.initial_size, options.final_size, options.step) = (4, 12, 4);
/// let map = zoomout(shape, shape, &start, &options).unwrap();
/// assert_eq!(map.len(), start.len());
/// ```
pub fn zoomout(
    a: ShapeGeometry<'_>,
    b: ShapeGeometry<'_>,
    initial: &[u32],
    options: &ZoomOutOptions,
) -> Result<Vec<u32>, SpectralError> {
    let final_size = validate(a, b, options)?;
    let d_a = a.spectrum.vertex_count();
    if initial.len() != b.spectrum.vertex_count() {
        return Err(SpectralError::InvalidOption(format!(
            "initial map has {} entries for a shape B of {} vertices",
            initial.len(),
            b.spectrum.vertex_count()
        )));
    }
    if let Some(&p) = initial.iter().find(|&&p| p as usize >= d_a) {
        return Err(SpectralError::InvalidOption(format!(
            "initial map sends a vertex to {p}, but shape A has {d_a} vertices"
        )));
    }
    let k = options.initial_size;
    let c0 = spectral_fit(
        eigenvectors(b.spectrum, k),
        eigenvectors(a.spectrum, k),
        initial,
    )?;
    zoomout_from(a, b, c0, final_size, options)
}

/// Checks both shapes and the options; returns the final size actually used (capped by the
/// eigenpairs of both spectra).
pub(crate) fn validate(
    a: ShapeGeometry<'_>,
    b: ShapeGeometry<'_>,
    options: &ZoomOutOptions,
) -> Result<usize, SpectralError> {
    let mut descriptor_columns = Vec::new();
    for (s, name) in [(a, "A"), (b, "B")] {
        let d = s.spectrum.vertex_count();
        if s.positions.len() != d {
            return Err(SpectralError::InvalidOption(format!(
                "shape {name}: {} positions for a spectrum of {d} vertices",
                s.positions.len()
            )));
        }
        if let Some(x) = s.descriptors {
            if d == 0 || !x.len().is_multiple_of(d) {
                return Err(SpectralError::InvalidOption(format!(
                    "shape {name}: {} descriptor values are not a whole number of columns of {d}",
                    x.len()
                )));
            }
            descriptor_columns.push(x.len() / d);
        }
    }
    if descriptor_columns.len() == 2 && descriptor_columns[0] != descriptor_columns[1] {
        return Err(SpectralError::InvalidOption(format!(
            "the shapes carry {} and {} descriptors",
            descriptor_columns[0], descriptor_columns[1]
        )));
    }
    if let Some(w) = &options.descriptor_weights {
        let sum: f64 = w.iter().sum();
        let bad = |x: &f64| !x.is_finite() || *x < 0.0;
        let columns_differ = descriptor_columns.first().is_some_and(|&n| n != w.len());
        if columns_differ || w.iter().any(bad) || sum.is_nan() || sum <= 0.0 {
            return Err(SpectralError::InvalidOption(format!(
                "{} descriptor weights for {:?} descriptor columns (they must be one per \
                 column, finite, non-negative and not all zero)",
                w.len(),
                descriptor_columns.first()
            )));
        }
    }
    non_negative("descriptor_weight", options.descriptor_weight)
        .map_err(SpectralError::InvalidOption)?;
    if matches!(
        options.final_match,
        FinalMatch::Bijective { candidates: 0, .. }
    ) {
        return Err(SpectralError::InvalidOption(
            "a bijective final match needs at least 1 candidate".into(),
        ));
    }
    let available = a.spectrum.len().min(b.spectrum.len());
    let final_size = options.final_size.min(available);
    if options.initial_size == 0 || options.step == 0 || options.initial_size > final_size {
        return Err(SpectralError::InvalidOption(format!(
            "map sizes: initial {} and step {} must be positive, and the initial size at \
             most the final size {final_size} (eigenpairs available: {available})",
            options.initial_size, options.step
        )));
    }
    Ok(final_size)
}

/// ZoomOut from a functional map `c0` (`k₀ × k₀`, A's coefficients to B's) up to
/// `final_size`, then the point map over all vertices.
pub(crate) fn zoomout_from(
    a: ShapeGeometry<'_>,
    b: ShapeGeometry<'_>,
    c0: DMatrix<f64>,
    final_size: usize,
    options: &ZoomOutOptions,
) -> Result<Vec<u32>, SpectralError> {
    let phi_a = eigenvectors(a.spectrum, final_size);
    let phi_b = eigenvectors(b.spectrum, final_size);
    let samples = options.samples.max(2 * final_size);
    let (samples_a, samples_b) = rayon::join(
        || sample_rows(phi_a, a.positions, samples),
        || sample_rows(phi_b, b.positions, samples),
    );
    let mut c = c0;
    let mut k = c.ncols();
    while k < final_size {
        let t = nearest_rows(
            &pulled_back(samples_a.as_ref(), &c),
            samples_b.subcols(0, k),
        );
        let next = (k + options.step).min(final_size);
        c = spectral_fit(samples_b.subcols(0, next), samples_a.subcols(0, next), &t)?;
        k = next;
    }
    let lambda = options.descriptor_weight;
    match (a.descriptors, b.descriptors) {
        (Some(da), Some(db)) if lambda > 0.0 => {
            let w = options.descriptor_weights.as_deref();
            let scales_a = descriptor_scales(da, phi_a.nrows(), lambda, w);
            let base = last_match_base(phi_a, &c, Some((da, &scales_a)));
            let query = WithDescriptors {
                x: phi_b.subcols(0, k),
                descriptors: db,
                scales: descriptor_scales(db, phi_b.nrows(), lambda, w),
            };
            final_point_map(base, &query, &options.final_match)
        }
        _ => final_point_map(
            last_match_base(phi_a, &c, None),
            &phi_b.subcols(0, k),
            &options.final_match,
        ),
    }
}

/// The last point map: rows of `query` (B) to rows of `base` (A).
fn final_point_map<Q: QueryRows + ?Sized>(
    base: OwnedBase,
    query: &Q,
    final_match: &FinalMatch,
) -> Result<Vec<u32>, SpectralError> {
    match final_match {
        FinalMatch::Nearest => Ok(nearest_candidates_owned(base, query, 1).targets),
        FinalMatch::Bijective {
            candidates,
            auction,
        } => {
            let n = base.nrows();
            let lists = nearest_candidates_owned(base, query, *candidates);
            Ok(auction_assignment(&lists, n, auction)?.map)
        }
    }
}

/// B's last-match embedding `[x | λ D̂]` ([`with_descriptors`]), assembled a block of rows at
/// a time by the search instead of held whole.
struct WithDescriptors<'a> {
    /// `d × k` spectral coordinates.
    x: MatRef<'a, f64>,
    /// `d × n`, column-major.
    descriptors: &'a [f64],
    /// [`descriptor_scales`] (`n`).
    scales: Vec<f64>,
}

impl QueryRows for WithDescriptors<'_> {
    fn nrows(&self) -> usize {
        self.x.nrows()
    }

    fn rows(&self, rows: &[usize]) -> Mat<f64> {
        self.rows_as(rows, |x| x)
    }

    /// The same rows rounded, written directly: the clustered search reads every row of B
    /// this way, twice (probing, then its group), and the double-precision block in between
    /// was a fortieth of `coseg pair`'s CPU on victoria0 × david0 (`perf`).
    fn single_rows(&self, rows: &[usize]) -> Mat<f32> {
        self.rows_as(rows, |x| x as f32)
    }
}

impl WithDescriptors<'_> {
    /// The rows `rows` of `[x | λ D̂]`, each entry computed in double precision and converted
    /// by `narrow`.
    fn rows_as<T: faer::traits::ComplexField + Copy>(
        &self,
        rows: &[usize],
        narrow: impl Fn(f64) -> T,
    ) -> Mat<T> {
        let (d, k) = (self.x.nrows(), self.x.ncols());
        let mut out = Mat::<T>::zeros(rows.len(), k + self.scales.len());
        for j in 0..out.ncols() {
            let dst = col_slice_mut(out.as_mut(), j);
            if j < k {
                let src = self.x.col(j);
                for (o, &r) in dst.iter_mut().zip(rows) {
                    *o = narrow(src[r]);
                }
            } else {
                let (col, scale) = (&self.descriptors[(j - k) * d..][..d], self.scales[j - k]);
                for (o, &r) in dst.iter_mut().zip(rows) {
                    *o = narrow(scale * col[r]);
                }
            }
        }
        out
    }
}

/// The factor of every descriptor column in a last-match embedding: `λ` over the column's
/// Euclidean norm (0 for a zero column), times `√(w_j / mean w)` with per-column weights.
fn descriptor_scales(
    descriptors: &[f64],
    d: usize,
    lambda: f64,
    weights: Option<&[f64]>,
) -> Vec<f64> {
    // Checked by `validate`: one finite, non-negative weight per column, not all zero.
    let relative: Option<Vec<f64>> = weights.map(|w| {
        let mean = w.iter().sum::<f64>() / w.len() as f64;
        w.iter().map(|x| (x / mean).sqrt()).collect()
    });
    descriptors
        .chunks_exact(d)
        .enumerate()
        .map(|(j, col)| {
            let norm = col.iter().map(|v| v * v).sum::<f64>().sqrt();
            let s = if norm > 0.0 { lambda / norm } else { 0.0 };
            relative.as_ref().map_or(s, |r| s * r[j])
        })
        .collect()
}

/// A's last-match embedding `[Φ Cᵀ | λ D̂]`: the pulled-back spectral coordinates
/// ([`pulled_back`], `d × k`) with the descriptors (`d × n`, column-major) appended as columns,
/// each scaled by its factor ([`descriptor_scales`]), or `Φ Cᵀ` alone. Written in place,
/// one `d × (k + n)` matrix: in double precision for a base the brute force searches, built
/// directly in single precision (products in double, then rounded, a block of rows at a
/// time) for one the clustered search will compare in single precision
/// ([`nearest_rows::in_single`](super::nearest_rows::in_single)), so that the double matrix
/// is never held whole.
fn last_match_base(
    phi: MatRef<'_, f64>,
    c: &DMatrix<f64>,
    descriptors: Option<(&[f64], &[f64])>,
) -> OwnedBase {
    let (d, k) = (phi.nrows(), c.nrows());
    let n = descriptors.map_or(0, |(_, scales)| scales.len());
    if !in_single(d) {
        let mut out = Mat::<f64>::zeros(d, k + n);
        pull_back_into(out.subcols_mut(0, k), phi, c);
        append_descriptors(&mut out, k, descriptors, |x| x);
        return OwnedBase::Double(out);
    }
    let mut out = Mat::<f32>::zeros(d, k + n);
    pull_back_blocks(out.subcols_mut(0, k), phi, c, |mut out, phi, ct| {
        let mut wide = Mat::<f64>::zeros(phi.nrows(), k);
        matmul(wide.as_mut(), Accum::Replace, phi, ct, 1.0, Par::Seq);
        for j in 0..k {
            for (o, &x) in out.as_mut().col_mut(j).iter_mut().zip(wide.col(j).iter()) {
                *o = x as f32;
            }
        }
    });
    append_descriptors(&mut out, k, descriptors, |x| x as f32);
    OwnedBase::Single(out)
}

/// Writes column `j` of the descriptors (`d × n`, column-major), times `scales[j]` and
/// converted by `narrow`, into column `k + j` of `out` (`d` rows).
fn append_descriptors<T: Copy>(
    out: &mut Mat<T>,
    k: usize,
    descriptors: Option<(&[f64], &[f64])>,
    narrow: impl Fn(f64) -> T,
) {
    let Some((descriptors, scales)) = descriptors else {
        return;
    };
    for (j, col) in descriptors.chunks_exact(out.nrows()).enumerate() {
        let dst = col_slice_mut(out.as_mut(), k + j);
        for (o, &v) in dst.iter_mut().zip(col) {
            *o = narrow(scales[j] * v);
        }
    }
}

/// The first `k` eigenvectors as a `d × k` view.
pub(crate) fn eigenvectors(s: &Spectrum, k: usize) -> MatRef<'_, f64> {
    let d = s.vertex_count();
    MatRef::from_column_major_slice(&s.eigenvectors[..d * k], d, k)
}

/// `Φ Cᵀ` over the first `C.ncols()` columns of `Φ`: A's spectral embedding expressed in B's
/// basis, whose rows are compared with B's rows `Φ_B(q)`.
fn pulled_back(phi: MatRef<'_, f64>, c: &DMatrix<f64>) -> Mat<f64> {
    let mut out = Mat::zeros(phi.nrows(), c.nrows());
    pull_back_into(out.as_mut(), phi, c);
    out
}

/// Rows per task of [`pull_back_into`]: fixed, so every row is computed by the same
/// sequential product whatever the thread count.
const PULL_BACK_ROWS: usize = 4096;

/// `out = Φ Cᵀ` (`out` is `Φ.nrows() × C.nrows()`), in parallel over fixed blocks of rows.
fn pull_back_into(out: MatMut<'_, f64>, phi: MatRef<'_, f64>, c: &DMatrix<f64>) {
    pull_back_blocks(out, phi, c, |out, phi, ct| {
        matmul(out, Accum::Replace, phi, ct, 1.0, Par::Seq)
    });
}

/// Calls `write(out rows, Φ rows, Cᵀ)` on every block of [`PULL_BACK_ROWS`] rows of `out`
/// (`Φ.nrows() × C.nrows()`) and the same rows of `Φ`'s first `C.ncols()` columns, in
/// parallel: the one blocking of `Φ Cᵀ`, whatever precision `out` is written in.
fn pull_back_blocks<T: faer::traits::ComplexField>(
    out: MatMut<'_, T>,
    phi: MatRef<'_, f64>,
    c: &DMatrix<f64>,
    write: impl Fn(MatMut<'_, T>, MatRef<'_, f64>, MatRef<'_, f64>) + Sync,
) {
    use rayon::prelude::*;
    let k = c.ncols();
    let ct = Mat::from_fn(k, c.nrows(), |i, j| c[(j, i)]);
    let phi = phi.subcols(0, k);
    out.par_row_chunks_mut(PULL_BACK_ROWS)
        .zip(phi.par_row_chunks(PULL_BACK_ROWS))
        .for_each(|(out, phi)| write(out, phi, ct.as_ref()));
}

/// Least-squares functional map of a point map: `C = argmin ‖Φ_B C − Φ_A[T]‖` (rows of `phi_b`
/// and entries of `t` correspond).
fn spectral_fit(
    phi_b: MatRef<'_, f64>,
    phi_a: MatRef<'_, f64>,
    t: &[u32],
) -> Result<DMatrix<f64>, SpectralError> {
    let k = phi_b.ncols();
    let b = DMatrix::from_fn(phi_b.nrows(), k, |i, j| phi_b[(i, j)]);
    let a = DMatrix::from_fn(t.len(), k, |i, j| phi_a[(t[i] as usize, j)]);
    let btb = b.transpose() * &b;
    let bta = b.transpose() * &a;
    // A shape with several components has basis functions that vanish on (nearly) every
    // sample, so `BᵀB` can be singular or close to it: then the minimum-norm least-squares
    // map (SVD, relative cutoff) leaves their coefficients at zero instead of failing.
    let diagonal = (0..k).map(|i| btb[(i, i)]);
    let largest = diagonal.clone().fold(0.0, f64::max);
    let smallest = diagonal.fold(f64::INFINITY, f64::min);
    if smallest > 1e-10 * largest
        && let Some(ch) = btb.clone().cholesky()
    {
        let ch_diag = ch.l_dirty().diagonal();
        let (lo, hi) = ch_diag
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| {
                (lo.min(x.abs()), hi.max(x.abs()))
            });
        if lo > 1e-6 * hi {
            let c = ch.solve(&bta);
            if c.iter().all(|x| x.is_finite()) {
                return Ok(c);
            }
        }
    }
    minimum_norm_fit(b, a)
}

/// `argmin ‖B C − A‖` of least norm, singular values of `B` below `1e-9 ×` the largest taken
/// as zero.
fn minimum_norm_fit(b: DMatrix<f64>, a: DMatrix<f64>) -> Result<DMatrix<f64>, SpectralError> {
    let svd = b.svd(true, true);
    let cutoff = 1e-9 * svd.singular_values.max();
    let c = svd
        .solve(&a, cutoff)
        .map_err(|e| SpectralError::Solver(format!("ZoomOut: least-squares map: {e}")))?;
    if c.iter().all(|x| x.is_finite()) {
        Ok(c)
    } else {
        Err(SpectralError::Solver(
            "ZoomOut: the sampled eigenbasis gives a non-finite map".into(),
        ))
    }
}

/// Rows of `phi` at `count` farthest-point samples of `positions` (all rows when `count ≥ d`),
/// starting from vertex 0.
fn sample_rows(phi: MatRef<'_, f64>, positions: &[[f64; 3]], count: usize) -> Mat<f64> {
    let d = positions.len();
    let chosen: Vec<usize> = if count >= d {
        (0..d).collect()
    } else {
        farthest_point_samples(positions, count)
    };
    let chosen = cover_basis(phi, chosen);
    gather_rows(phi, &chosen)
}

/// `count < positions.len()` farthest-point samples, starting from vertex 0: each next sample
/// is the vertex farthest (squared Euclidean) from those chosen, ties to the lowest index.
///
/// Coordinates are read as three separate arrays and each round is two passes (distances
/// and eight running maxima, then the first vertex at the maximum) because that vectorises;
/// the one-pass scan was a twentieth of `coseg pair`'s CPU on TOSCA's dog0 × cat0 (`perf`).
fn farthest_point_samples(positions: &[[f64; 3]], count: usize) -> Vec<usize> {
    const LANES: usize = 8;
    let d = positions.len();
    let coordinate = |k: usize| positions.iter().map(|p| p[k]).collect::<Vec<f64>>();
    let (xs, ys, zs) = (coordinate(0), coordinate(1), coordinate(2));
    let mut dist = vec![f64::INFINITY; d];
    let mut out = Vec::with_capacity(count);
    let mut current = 0usize;
    for _ in 0..count {
        out.push(current);
        let c = positions[current];
        let mut lanes = [-1.0f64; LANES];
        let step = |x: f64, y: f64, z: f64, dist: &mut f64, lane: &mut f64| {
            let d2 = (x - c[0]).powi(2) + (y - c[1]).powi(2) + (z - c[2]).powi(2);
            if d2 < *dist {
                *dist = d2;
            }
            *lane = if *dist > *lane { *dist } else { *lane };
        };
        let whole = d - d % LANES;
        for (((x, y), z), dist) in xs[..whole]
            .chunks_exact(LANES)
            .zip(ys[..whole].chunks_exact(LANES))
            .zip(zs[..whole].chunks_exact(LANES))
            .zip(dist[..whole].chunks_exact_mut(LANES))
        {
            for l in 0..LANES {
                step(x[l], y[l], z[l], &mut dist[l], &mut lanes[l]);
            }
        }
        for i in whole..d {
            step(xs[i], ys[i], zs[i], &mut dist[i], &mut lanes[0]);
        }
        let far = lanes.iter().fold(-1.0, |m, &x| if x > m { x } else { m });
        // Distances are never NaN (a NaN coordinate leaves +∞, which `<` never lowers), so
        // the first vertex at the maximum is the one a scan replacing only on `>` keeps.
        current = dist.iter().position(|&x| x == far).unwrap_or(0);
    }
    out
}

/// `chosen` plus, for every column of `phi` that (almost) vanishes on the chosen rows, the
/// row where it is largest. Farthest-point samples can miss a small component entirely, and
/// a basis function living there (its constant, at least) is then zero on every sample; one
/// sample on it keeps the fitted map from ignoring it. A no-op on a connected surface, where
/// no low-frequency eigenfunction vanishes on well-spread samples.
fn cover_basis(phi: MatRef<'_, f64>, mut chosen: Vec<usize>) -> Vec<usize> {
    let d = phi.nrows();
    if chosen.len() >= d {
        return chosen;
    }
    let mut taken = vec![false; d];
    chosen.iter().for_each(|&v| taken[v] = true);
    for j in 0..phi.ncols() {
        let col = phi.col(j);
        let total: f64 = col.iter().map(|x| x * x).sum();
        let sampled: f64 = chosen.iter().map(|&v| col[v] * col[v]).sum();
        // Mass-orthonormal columns spread over the samples carry about their share of the
        // squared norm; a millionth of it means the samples do not see the function.
        if sampled > 1e-6 * total * chosen.len() as f64 / d as f64 {
            continue;
        }
        let best = (0..d).fold(0, |b, v| if col[v].abs() > col[b].abs() { v } else { b });
        if !taken[best] {
            taken[best] = true;
            chosen.push(best);
        }
    }
    chosen
}

/// For every row of `query`, the index of the nearest row of `base` (Euclidean; ties to the
/// lowest index). Both have the same number of columns.
fn nearest_rows(base: &Mat<f64>, query: MatRef<'_, f64>) -> Vec<u32> {
    nearest_candidates(base, query, 1).targets
}

/// For every row of `query`, the `count` nearest rows of `base` (capped by its rows) and
/// their squared distances, nearest first (ties to the lowest index).
fn nearest_candidates(base: &Mat<f64>, query: MatRef<'_, f64>, count: usize) -> CandidateLists {
    super::nearest_rows::nearest_candidates(base.as_ref(), query, count)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The vectorised farthest-point sampling chooses what the one-pass scan chose, ties
    /// (repeated points) and a NaN coordinate included.
    #[test]
    fn farthest_point_samples_are_those_of_a_scan() {
        let scan = |positions: &[[f64; 3]], count: usize| {
            let mut dist = vec![f64::INFINITY; positions.len()];
            let (mut out, mut current) = (Vec::new(), 0usize);
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
        for n in [1usize, 7, 8, 9, 31, 200] {
            // A coarse grid, so that many points tie; every 13th point repeated.
            let mut positions: Vec<[f64; 3]> = (0..n)
                .map(|i| {
                    let i = if i % 13 == 12 { i - 1 } else { i };
                    [
                        (i % 4) as f64,
                        ((i / 4) % 3) as f64,
                        (i * 7 % 5) as f64 * 0.5,
                    ]
                })
                .collect();
            for count in [1, n / 2, n.saturating_sub(1)]
                .into_iter()
                .filter(|&c| c >= 1)
            {
                assert_eq!(
                    farthest_point_samples(&positions, count),
                    scan(&positions, count),
                    "{n} points, {count} samples"
                );
            }
            if n > 3 {
                positions[3][1] = f64::NAN;
                assert_eq!(
                    farthest_point_samples(&positions, n - 1),
                    scan(&positions, n - 1)
                );
            }
        }
    }

    /// B's embedding read block by block has the entries the whole embedding had: the
    /// spectral columns as they are, each descriptor column scaled by `λ / ‖column‖`; in
    /// single precision, those entries rounded.
    #[test]
    fn descriptor_rows_are_the_scaled_columns() {
        let (d, k, n) = (37, 5, 3);
        let x = Mat::from_fn(d, k, |i, j| ((i * 3 + j * 11) % 17) as f64 - 8.0);
        let descriptors: Vec<f64> = (0..d * n).map(|i| ((i * 13) % 29) as f64 * 0.25).collect();
        let query = WithDescriptors {
            x: x.as_ref(),
            descriptors: &descriptors,
            scales: descriptor_scales(&descriptors, d, 500.0, None),
        };
        let rows = [36, 0, 17, 17];
        let got = query.rows(&rows);
        let narrow = query.single_rows(&rows);
        for g in 0..rows.len() {
            for j in 0..k + n {
                assert_eq!(narrow[(g, j)].to_bits(), (got[(g, j)] as f32).to_bits());
            }
        }
        for (g, &r) in rows.iter().enumerate() {
            for j in 0..k {
                assert_eq!(got[(g, j)].to_bits(), x[(r, j)].to_bits());
            }
            for f in 0..n {
                let col = &descriptors[f * d..(f + 1) * d];
                let norm = col.iter().map(|v| v * v).sum::<f64>().sqrt();
                assert_eq!(got[(g, k + f)].to_bits(), (500.0 / norm * col[r]).to_bits());
            }
        }
    }

    /// A base large enough for the clustered search is built in single precision, each entry
    /// the double-precision one rounded (products blocked as in [`pull_back_into`], then
    /// rounded), whatever the thread count; a smaller one stays in double precision.
    #[test]
    fn last_match_base_is_the_double_embedding_rounded() {
        let (d, k, n) = (2 * PULL_BACK_ROWS + 517, 9, 2);
        assert!(in_single(d) && !in_single(d / 4));
        let phi = Mat::from_fn(d, k + 3, |i, j| {
            ((i * 7 + j * 13) % 101) as f64 / 37.0 - 1.3
        });
        let c = DMatrix::from_fn(k, k, |i, j| ((i * 5 + j * 3) % 11) as f64 / 7.0 - 0.6);
        let descriptors: Vec<f64> = (0..d * n).map(|i| ((i * 13) % 29) as f64 * 0.25).collect();
        let scales = descriptor_scales(&descriptors, d, 500.0, None);
        let wide = pulled_back(phi.as_ref(), &c);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let base =
                pool.install(|| last_match_base(phi.as_ref(), &c, Some((&descriptors, &scales))));
            let OwnedBase::Single(base) = base else {
                panic!("single precision expected")
            };
            assert_eq!((base.nrows(), base.ncols()), (d, k + n));
            for i in (0..d).step_by(97) {
                for j in 0..k {
                    assert_eq!(base[(i, j)].to_bits(), (wide[(i, j)] as f32).to_bits());
                }
                for f in 0..n {
                    let v = (scales[f] * descriptors[f * d + i]) as f32;
                    assert_eq!(base[(i, k + f)].to_bits(), v.to_bits());
                }
            }
        }
        let small = last_match_base(phi.subrows(0, d / 4), &c, None);
        assert!(matches!(small, OwnedBase::Double(_)));
    }

    /// The blocked parallel `Φ Cᵀ` gives every row the bits of one sequential product of the
    /// whole matrix, whatever the thread count (the last match's embedding, and so the map,
    /// must not depend on it).
    #[test]
    fn pull_back_is_the_sequential_product_bit_for_bit() {
        let (d, k) = (2 * PULL_BACK_ROWS + 517, 23);
        let phi = Mat::from_fn(d, k + 4, |i, j| {
            ((i * 7 + j * 13) % 101) as f64 / 37.0 - 1.3
        });
        let c = DMatrix::from_fn(k, k, |i, j| ((i * 5 + j * 3) % 17) as f64 / 9.0 - 0.8);
        let ct = Mat::from_fn(k, k, |i, j| c[(j, i)]);
        let mut sequential = Mat::<f64>::zeros(d, k);
        matmul(
            sequential.as_mut(),
            Accum::Replace,
            phi.subcols(0, k),
            ct.as_ref(),
            1.0,
            Par::Seq,
        );
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let out = pool.install(|| pulled_back(phi.as_ref(), &c));
            for j in 0..k {
                for i in 0..d {
                    assert_eq!(
                        out[(i, j)].to_bits(),
                        sequential[(i, j)].to_bits(),
                        "row {i}, column {j}, {threads} threads"
                    );
                }
            }
        }
    }
}
