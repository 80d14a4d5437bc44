//! [`region_point_map`]: a vertex-to-vertex map between two shapes built from their
//! corresponding regions, through a functional map fitted to the region indicators and refined
//! spectrally (ZoomOut).

use super::MapError;
use super::zoomout::{eigenvectors, validate, zoomout_from};
use super::{ShapeGeometry, ZoomOutOptions};
use crate::option_range::non_negative;
use crate::spectral::Spectrum;
use faer::MatRef;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Options of [`region_point_map`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct PointMapOptions {
    /// The ZoomOut stage; its `initial_size` `k₀` is also the size of the functional map
    /// fitted to the region indicators (default 10: about as many unknowns per row as there
    /// are region pairs).
    pub zoomout: ZoomOutOptions,
    /// Weight of the Laplacian-commutativity term `‖CΛ_A − Λ_B C‖²` of the first fit, with
    /// eigenvalues divided by the largest one used (default 1).
    pub commutativity: f64,
}

impl Default for PointMapOptions {
    fn default() -> Self {
        PointMapOptions {
            zoomout: ZoomOutOptions::default(),
            commutativity: 1.0,
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
    /// Optional per-vertex descriptors (see [`ShapeGeometry::descriptors`]), used by the last
    /// nearest-neighbour search.
    pub descriptors: Option<&'a [f64]>,
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
/// use coseg::maps::ZoomOutOptions;
/// use coseg::maps::{region_point_map, MapShape, PointMapOptions};
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
/// let mut spectrum_options = SpectrumOptions::default();
/// spectrum_options.eigenpairs = 12;
/// let spectrum = laplace_beltrami_spectrum(&mesh, &spectrum_options).unwrap();
/// let labels: Vec<i32> = (0..nx * ny).map(|i| i32::from(i % nx >= 4)).collect();
/// let shape = MapShape { spectrum: &spectrum, positions: &pos, labels: &labels, descriptors: None };
/// let mut options = PointMapOptions::default();
/// (options.zoomout.initial_size, options.zoomout.final_size, options.zoomout.step) = (4, 12, 4);
/// let map = region_point_map(&shape, &shape, &options).unwrap();
/// // Every vertex lands on the same side of the cut.
/// assert!(map.iter().enumerate().all(|(q, &p)| labels[q] == labels[p as usize]));
/// ```
pub fn region_point_map(
    a: &MapShape<'_>,
    b: &MapShape<'_>,
    options: &PointMapOptions,
) -> Result<Vec<u32>, MapError> {
    let (ga, gb) = (a.geometry(), b.geometry());
    let final_size = validate(ga, gb, &options.zoomout)?;
    for (s, name) in [(a, "A"), (b, "B")] {
        let d = s.spectrum.vertex_count();
        if s.labels.len() != d {
            return Err(MapError::InvalidOption(format!(
                "shape {name}: {} labels for a spectrum of {d} vertices",
                s.labels.len()
            )));
        }
    }
    non_negative("commutativity", options.commutativity).map_err(MapError::InvalidOption)?;
    let k = options.zoomout.initial_size;
    let c = initial_map(
        a,
        b,
        eigenvectors(a.spectrum, k),
        eigenvectors(b.spectrum, k),
        options,
    )?;
    Ok(zoomout_from(ga, gb, c, final_size, &options.zoomout)?)
}

impl MapShape<'_> {
    fn geometry(&self) -> ShapeGeometry<'_> {
        ShapeGeometry {
            spectrum: self.spectrum,
            positions: self.positions,
            descriptors: self.descriptors,
        }
    }
}

/// The first functional map, row by row: `(a aᵀ + μ D_i) c_i = a b_i` with
/// `D_i = diag(((λ_A,l − λ_B,i) / λ_max)²)`.
fn initial_map(
    a: &MapShape<'_>,
    b: &MapShape<'_>,
    phi_a: MatRef<'_, f64>,
    phi_b: MatRef<'_, f64>,
    options: &PointMapOptions,
) -> Result<DMatrix<f64>, MapError> {
    let k = options.zoomout.initial_size;
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
        return Err(MapError::InvalidOption(
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
            .map_err(|e| MapError::InvalidOption(format!("functional map fit: {e}")))?;
        c.set_row(i, &row.transpose());
    }
    Ok(c)
}
