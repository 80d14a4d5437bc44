use super::heat_kernel_signature::hks_coefficients;
use super::multiscale_mean_curvature::curvature_coefficients;
use super::spectral_product::spectral_product;
use super::wave_kernel_signature::wks_coefficients;
use super::{FeatureError, SpectralBand, scale_grid};
use crate::mesh::TriMesh;
use crate::spectral::Spectrum;
use faer::Mat;

/// Options of [`descriptors`]. Every field changes the result (and so belongs in a cache key).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct DescriptorOptions {
    /// Number of HKS features (default 100).
    pub hks_count: usize,
    /// Number of WKS features (default 100).
    pub wks_count: usize,
    /// Number of multiscale mean-curvature features (default 100).
    pub curvature_count: usize,
    /// The eigenvalue band the time/energy grids are derived from (default
    /// [`SpectralBand::Weyl`]); see [`scale_grid`](super::scale_grid) for the rule.
    pub band: SpectralBand,
    /// WKS `σ` as a multiple of `(ln λ_hi − ln λ_lo) / wks_count` (default 7, as pyFM).
    pub wks_sigma_multiple: f64,
    /// Eigenvalues `≤` this (unit area) are treated as zero and left out of the WKS
    /// (default 1e-5, as pyFM).
    pub zero_eigenvalue: f64,
}

impl Default for DescriptorOptions {
    fn default() -> Self {
        DescriptorOptions {
            hks_count: 100,
            wks_count: 100,
            curvature_count: 100,
            band: SpectralBand::Weyl,
            wks_sigma_multiple: 7.0,
            zero_eigenvalue: 1e-5,
        }
    }
}

/// Which family a feature belongs to, with its scale.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum FeatureKind {
    /// Heat kernel signature at diffusion time `t` (unit area).
    Hks(f64),
    /// Wave kernel signature at log-energy `e`.
    Wks(f64),
    /// Mean curvature diffused for time `t` (unit area).
    MeanCurvature(f64),
}

impl FeatureKind {
    /// The family name: `hks`, `wks` or `curv` (as in the column names).
    pub fn family(&self) -> &'static str {
        match self {
            FeatureKind::Hks(_) => "hks",
            FeatureKind::Wks(_) => "wks",
            FeatureKind::MeanCurvature(_) => "curv",
        }
    }

    /// The scale: `t` for HKS and curvature, `e` for WKS.
    pub fn scale(&self) -> f64 {
        match *self {
            FeatureKind::Hks(t) | FeatureKind::Wks(t) | FeatureKind::MeanCurvature(t) => t,
        }
    }
}

/// The feature table of one shape: `N = hks + wks + curvature` features on `d` vertices.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Descriptors {
    /// Number of vertices `d`.
    pub vertices: usize,
    /// HKS times (unit area), ascending; features `0..hks`.
    pub hks_times: Vec<f64>,
    /// WKS log-energies, ascending; the next `wks` features.
    pub wks_energies: Vec<f64>,
    /// WKS Gaussian width (log-eigenvalue units).
    pub wks_sigma: f64,
    /// Mean-curvature diffusion times (unit area), ascending; the last features.
    pub curvature_times: Vec<f64>,
    /// Unit-area vertex areas (length `d`, sum 1), for area-weighted bands.
    pub vertex_areas: Vec<f64>,
    /// `N × d` values, feature-major: `values[f * d + v]`.
    pub values: Vec<f64>,
    /// Names of the columns of the other families, appended after the spectral ones (see
    /// [`FeatureFamilies`](super::FeatureFamilies)); empty for a spectral-only table.
    #[serde(default)]
    pub extra_names: Vec<String>,
    /// How many of the extra columns each family gave: `[extrinsic, sdf, user]`.
    #[serde(default)]
    pub family_counts: [usize; 3],
}

impl Descriptors {
    /// Number of features `N`.
    pub fn feature_count(&self) -> usize {
        self.spectral_count() + self.extra_names.len()
    }

    /// Number of spectral features (HKS + WKS + curvature), the first columns.
    pub fn spectral_count(&self) -> usize {
        self.hks_times.len() + self.wks_energies.len() + self.curvature_times.len()
    }

    /// Appends the columns of other families (`counts` = `[extrinsic, sdf, user]` column
    /// counts, as [`FeatureFamilies::columns`](super::FeatureFamilies::columns) gives them).
    pub fn append(
        &mut self,
        extra: super::FeatureColumns,
        counts: [usize; 3],
    ) -> Result<(), FeatureError> {
        if extra.vertices != self.vertices || counts.iter().sum::<usize>() != extra.len() {
            return Err(FeatureError::Inconsistent(format!(
                "{} extra columns on {} vertices for a table of {} vertices",
                extra.len(),
                extra.vertices,
                self.vertices
            )));
        }
        self.values.extend(extra.values);
        self.extra_names.extend(extra.names);
        for (c, n) in self.family_counts.iter_mut().zip(counts) {
            *c += n;
        }
        Ok(())
    }

    /// The fixed value range of every feature, in table order: `Some([lo, hi])` for the
    /// extrinsic family's normal columns ([`fixed_value_range`](super::fixed_value_range)),
    /// whose bands are cut by value, `None` (rank bands) for every other feature.
    ///
    /// ```
    /// use coseg::{mesh::TriMesh, spectral::dense_spectrum};
    /// use coseg::features::{descriptors, extrinsic_features, DescriptorOptions, ExtrinsicOptions};
    /// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.]], vec![[0,1,2],[0,2,3]]).unwrap();
    /// let mut opts = DescriptorOptions::default();
    /// (opts.hks_count, opts.wks_count, opts.curvature_count) = (2, 2, 2);
    /// let mut d = descriptors(&m, &dense_spectrum(&m, 4).unwrap(), &opts).unwrap();
    /// let mut o = ExtrinsicOptions::default();
    /// (o.directions, o.normal_directions) = (2, 3);
    /// let c = extrinsic_features(&m, &o).unwrap();
    /// let n = c.len(); // 2 heights, 2 distances, 3 normal columns
    /// d.append(c, [n, 0, 0]).unwrap();
    /// let r = d.value_ranges();
    /// assert_eq!(r[..6 + 4], [None; 10]);
    /// assert_eq!(r[10..], [Some([0.0, 1.0]); 3]);
    /// ```
    pub fn value_ranges(&self) -> Vec<Option<[f64; 2]>> {
        let extrinsic = self.family_counts[0];
        std::iter::repeat_n(None, self.spectral_count())
            .chain(self.extra_names.iter().enumerate().map(|(i, name)| {
                if i < extrinsic {
                    super::fixed_value_range(name)
                } else {
                    None
                }
            }))
            .collect()
    }

    /// Feature `f` (length `d`).
    pub fn feature(&self, f: usize) -> &[f64] {
        &self.values[f * self.vertices..(f + 1) * self.vertices]
    }

    /// Family and scale of every feature, in table order.
    pub fn kinds(&self) -> Vec<FeatureKind> {
        self.hks_times
            .iter()
            .map(|&t| FeatureKind::Hks(t))
            .chain(self.wks_energies.iter().map(|&e| FeatureKind::Wks(e)))
            .chain(
                self.curvature_times
                    .iter()
                    .map(|&t| FeatureKind::MeanCurvature(t)),
            )
            .collect()
    }

    /// Column names such as `hks_000`, `wks_099`, `curv_042`, in table order.
    pub fn names(&self) -> Vec<String> {
        let mut names = Vec::with_capacity(self.feature_count());
        for (fam, n) in [
            ("hks", self.hks_times.len()),
            ("wks", self.wks_energies.len()),
            ("curv", self.curvature_times.len()),
        ] {
            names.extend((0..n).map(|i| format!("{fam}_{i:03}")));
        }
        names.extend(self.extra_names.iter().cloned());
        names
    }
}

/// HKS, WKS and multiscale mean curvature of a mesh from its (unit-area) spectrum, on the
/// shape-independent scale grid of [`scale_grid`](super::scale_grid) (with `k` =
/// `spectrum.len()`).
///
/// Invariant to rigid motions and uniform scaling of the mesh; a vertex permutation permutes
/// the columns. Bit-identical on every run and any number of threads.
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::dense_spectrum};
/// use coseg::features::{descriptors, DescriptorOptions};
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.]], vec![[0,1,2],[0,2,3]]).unwrap();
/// let s = dense_spectrum(&m, 4).unwrap();
/// let mut opts = DescriptorOptions::default();
/// (opts.hks_count, opts.wks_count, opts.curvature_count) = (3, 2, 1);
/// let f = descriptors(&m, &s, &opts).unwrap();
/// assert_eq!(f.feature_count(), 6);
/// assert_eq!(f.values.len(), 6 * 4);
/// ```
pub fn descriptors(
    mesh: &TriMesh,
    spectrum: &Spectrum,
    options: &DescriptorOptions,
) -> Result<Descriptors, FeatureError> {
    let d = mesh.vertex_count();
    if spectrum.vertex_count() != d {
        return Err(FeatureError::VertexMismatch {
            mesh: d,
            spectrum: spectrum.vertex_count(),
        });
    }
    if spectrum.is_empty() || spectrum.eigenvectors.len() != d * spectrum.len() {
        return Err(FeatureError::EmptySpectrum(format!(
            "{} eigenvalues, {} eigenvector entries for {d} vertices",
            spectrum.len(),
            spectrum.eigenvectors.len()
        )));
    }
    if spectrum
        .eigenvalues
        .iter()
        .chain(&spectrum.eigenvectors)
        .any(|x| !x.is_finite())
    {
        return Err(FeatureError::EmptySpectrum(
            "the spectrum has non-finite entries".into(),
        ));
    }
    let grid = scale_grid(
        &options.band,
        spectrum.len(),
        options.hks_count,
        options.wks_count,
        options.curvature_count,
        options.wks_sigma_multiple,
    )?;
    // One pass over Φ: [HKS; WKS] use φ², curvature uses φ.
    let lambda = &spectrum.eigenvalues;
    let hks = hks_coefficients(lambda, &grid.hks_times);
    let wks = wks_coefficients(
        lambda,
        &grid.wks_energies,
        grid.wks_sigma,
        options.zero_eigenvalue,
    );
    let squared = Mat::from_fn(hks.nrows() + wks.nrows(), lambda.len(), |j, i| {
        if j < hks.nrows() {
            hks[(j, i)]
        } else {
            wks[(j - hks.nrows(), i)]
        }
    });
    let plain = curvature_coefficients(mesh, spectrum, &grid.curvature_times);
    let values = spectral_product(
        spectrum.eigenvector_matrix(),
        squared.as_ref(),
        plain.as_ref(),
    );
    Ok(Descriptors {
        vertices: d,
        hks_times: grid.hks_times,
        wks_energies: grid.wks_energies,
        wks_sigma: grid.wks_sigma,
        curvature_times: grid.curvature_times,
        vertex_areas: spectrum.vertex_areas.clone(),
        values,
        extra_names: Vec::new(),
        family_counts: [0; 3],
    })
}
