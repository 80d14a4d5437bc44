//! What the per-shape pipeline computes ([`ShapeData`], [`ShapeBands`]), its options and how
//! it is computed from a mesh.

use crate::bands::{BandError, BandOptions, BandTable, band_table};
use crate::cache::{EntryKind, ShapeKey, encode_entry, entry_key};
use crate::features::{DescriptorOptions, Descriptors, FeatureError, FeatureFamilies, descriptors};
use crate::mesh::{MeshError, TriMesh};
use crate::spectral::{SpectralError, Spectrum, SpectrumOptions, laplace_beltrami_spectrum};
use thiserror::Error;

/// Errors of the per-shape pipeline and its cache.
#[derive(Debug, Error)]
pub enum PipelineError {
    /// The mesh file could not be read (the message names the file).
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The spectrum could not be computed.
    #[error(transparent)]
    Spectral(#[from] SpectralError),
    /// The descriptors could not be computed.
    #[error(transparent)]
    Features(#[from] FeatureError),
    /// The band table could not be computed.
    #[error(transparent)]
    Bands(#[from] BandError),
    /// The cache directory could not be created.
    #[error("{path}: {source}")]
    Io {
        /// The directory or file concerned.
        path: String,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// Every option of the per-shape stages; all of it goes into the cache key.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShapePipelineOptions {
    /// Eigenpairs (default: 200).
    pub spectrum: SpectrumOptions,
    /// Features (default: 100 HKS + 100 WKS + 100 mean curvature).
    pub descriptors: DescriptorOptions,
    /// Bands (default: `K = 20`, equal counts).
    pub bands: BandOptions,
    /// Feature families beyond the spectral one, and their weights (default: none).
    pub families: FeatureFamilies,
}

impl ShapePipelineOptions {
    /// Per-column affinity weights for a feature table of `features` columns made under these
    /// options ([`FeatureFamilies::feature_weights`]; the user family's count is what remains
    /// after the others). `None`: one family, equal weights.
    pub fn feature_weights(&self, features: usize) -> Option<Vec<f64>> {
        let d = &self.descriptors;
        let spectral = d.hks_count + d.wks_count + d.curvature_count;
        let f = &self.families;
        let ext = f.extrinsic.as_ref().map_or(0, |e| {
            e.directions + usize::from(e.centroid_distance) + usize::from(e.axis_distance)
        });
        let sdf = f.sdf.as_ref().map_or(0, |s| s.smoothing_rounds.len());
        let user = features.saturating_sub(spectral + ext + sdf);
        f.feature_weights(spectral, [ext, sdf, user])
    }
}

/// Everything coseg computes once per shape.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShapeData {
    /// The key these data were computed for (see [`shape_key`]).
    pub key: ShapeKey,
    /// Number of vertices `d` of the mesh.
    pub vertices: usize,
    /// Unit-area Laplace–Beltrami spectrum.
    pub spectrum: Spectrum,
    /// `N × d` feature table.
    pub descriptors: Descriptors,
    /// `d × N` band labels.
    pub bands: BandTable,
}

/// What the collection stage needs of a shape: its band table and vertex areas (the compact
/// cache entry of [`super::load_or_compute_bands`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShapeBands {
    /// The key these data were computed for (see [`shape_key`]).
    pub key: ShapeKey,
    /// `d × N` band labels.
    pub bands: BandTable,
    /// Per-vertex areas (length `d`), as [`Descriptors::vertex_areas`].
    pub vertex_areas: Vec<f64>,
}

impl ShapeBands {
    /// The compact part of `data`.
    pub fn of(data: &ShapeData) -> Self {
        Self {
            key: data.key,
            bands: data.bands.clone(),
            vertex_areas: data.descriptors.vertex_areas.clone(),
        }
    }

    /// `Err(reason)` unless these data are keyed `key` and sized for a mesh of `vertices`
    /// vertices (the check of a compact cache entry before it is trusted).
    pub(crate) fn check(&self, key: &ShapeKey, vertices: usize) -> Result<(), String> {
        if self.key != *key {
            return Err("payload key does not match".into());
        }
        let t = &self.bands;
        let consistent = t.vertices == vertices
            && t.labels.len() == t.features * vertices
            && t.labels.iter().all(|&l| (l as usize) < t.bands)
            && self.vertex_areas.len() == vertices;
        if !consistent {
            return Err("payload sizes do not match the mesh".into());
        }
        Ok(())
    }
}

impl ShapeData {
    /// `Err(reason)` unless these data are keyed `key` and sized for a mesh of `vertices`
    /// vertices (the check of a full cache entry before it is trusted).
    pub(crate) fn check(&self, key: &ShapeKey, vertices: usize) -> Result<(), String> {
        if self.key != *key {
            return Err("payload key does not match".into());
        }
        let n = self.descriptors.feature_count();
        let consistent = self.vertices == vertices
            && self.spectrum.vertex_count() == vertices
            && self.spectrum.eigenvectors.len() == vertices * self.spectrum.len()
            && self.descriptors.vertices == vertices
            && self.descriptors.values.len() == n * vertices
            && self.bands.vertices == vertices
            && self.bands.features == n
            && self.bands.labels.len() == n * vertices;
        if !consistent {
            return Err("payload sizes do not match the mesh".into());
        }
        Ok(())
    }
}

/// The cache key of a mesh under the pipeline's options ([`crate::cache::entry_key`]).
///
/// ```
/// use coseg::{mesh::TriMesh, pipeline::{shape_key, ShapePipelineOptions}};
/// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let mut o = ShapePipelineOptions::default();
/// let k1 = shape_key(&m, &o);
/// o.bands.bands = 10;
/// assert_ne!(k1, shape_key(&m, &o));
/// ```
pub fn shape_key(mesh: &TriMesh, options: &ShapePipelineOptions) -> ShapeKey {
    entry_key(mesh, options)
}

/// The bytes of the full cache entry of `data`.
pub fn encode_shape_entry(data: &ShapeData) -> Vec<u8> {
    encode_entry(EntryKind::Full, &data.key, data)
}

/// The bytes of the compact bands entry of `data`.
pub fn encode_bands_entry(data: &ShapeBands) -> Vec<u8> {
    encode_entry(EntryKind::Bands, &data.key, data)
}

/// Spectrum, descriptors and band table of a mesh, without touching any cache.
///
/// ```
/// use coseg::{mesh::TriMesh, pipeline::{compute_shape_data, ShapePipelineOptions}};
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.]], vec![[0,1,2],[0,2,3]]).unwrap();
/// let mut o = ShapePipelineOptions::default();
/// o.spectrum.eigenpairs = 4;
/// o.bands.bands = 2;
/// let data = compute_shape_data(&m, &o).unwrap();
/// assert_eq!(data.bands.features, 300);
/// ```
pub fn compute_shape_data(
    mesh: &TriMesh,
    options: &ShapePipelineOptions,
) -> Result<ShapeData, PipelineError> {
    let spectrum = laplace_beltrami_spectrum(mesh, &options.spectrum)?;
    shape_data_from_spectrum(mesh, spectrum, options)
}

/// Descriptors and band table from an already computed spectrum (e.g. read elsewhere), keyed
/// as [`compute_shape_data`] would key them. The spectrum must be the one
/// `options.spectrum` gives for `mesh`, or the cache key would lie.
pub fn shape_data_from_spectrum(
    mesh: &TriMesh,
    spectrum: Spectrum,
    options: &ShapePipelineOptions,
) -> Result<ShapeData, PipelineError> {
    let mut descriptors = descriptors(mesh, &spectrum, &options.descriptors)?;
    if options.families != FeatureFamilies::default() {
        let (extra, counts) = options.families.columns(mesh)?;
        descriptors.append(extra, counts)?;
    }
    let bands = band_table(&descriptors, &options.bands)?;
    Ok(ShapeData {
        key: shape_key(mesh, options),
        vertices: mesh.vertex_count(),
        spectrum,
        descriptors,
        bands,
    })
}
