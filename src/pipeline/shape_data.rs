//! What the per-shape pipeline computes ([`ShapeData`], [`ShapeBands`]), its options and how
//! it is computed from a mesh.

use crate::bands::{BandError, BandOptions, BandTable, band_table};
use crate::cache::{EntryKind, ShapeKey, decode_entry, encode_entry, entry_key};
use crate::features::{
    DescriptorOptions, Descriptors, FeatureColumns, FeatureError, FeatureFamilies, descriptors,
    parse_alignment, parse_families, parse_family_weights,
};
use crate::mesh::{MeshError, TriMesh};
use crate::spectral::{
    SpectralError, Spectrum, SpectrumOptions, available_eigenpairs, laplace_beltrami_spectrum,
};
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
    #[error(transparent)]
    Io(#[from] crate::FileError),
}

/// Every option of the per-shape stages; all of it goes into the cache key.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
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

/// The feature families in their text form, as `coseg`'s flags and the Python package's
/// keywords state them; `Default` is their default (the spectral family, `--up y`, the
/// extrinsic family's default directions, no normal columns, weights 1 each), the one place
/// the front ends take it from. Applied by [`ShapePipelineOptions::set_family_flags`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct FamilyFlags {
    /// `--features`: `spectral,extrinsic,sdf,user:DIR`.
    pub features: String,
    /// `--up`: `y`, `-z`, `pca`, ….
    pub up: String,
    /// `--directions`: the extrinsic family's height directions.
    pub directions: usize,
    /// `--normals`: the extrinsic family's normal columns.
    pub normals: usize,
    /// `--family-weights`: `extrinsic=2,sdf=0.5` (empty: 1 each).
    pub family_weights: String,
}

impl Default for FamilyFlags {
    fn default() -> Self {
        let extrinsic = crate::features::ExtrinsicOptions::default();
        Self {
            features: "spectral".into(),
            up: extrinsic.alignment.to_string(),
            directions: extrinsic.directions,
            normals: extrinsic.normal_directions,
            family_weights: String::new(),
        }
    }
}

impl ShapePipelineOptions {
    /// [`Self::set_families`] from [`FamilyFlags`].
    ///
    /// ```
    /// use coseg::pipeline::{FamilyFlags, ShapePipelineOptions};
    /// let mut o = ShapePipelineOptions::default();
    /// o.set_family_flags(&FamilyFlags::default()).unwrap();
    /// assert_eq!(o, ShapePipelineOptions::default());
    /// ```
    pub fn set_family_flags(&mut self, flags: &FamilyFlags) -> Result<(), FeatureError> {
        self.set_families(
            &flags.features,
            &flags.up,
            flags.directions,
            flags.normals,
            &flags.family_weights,
        )
    }

    /// Sets the feature families from their text form, as `coseg`'s flags state them:
    /// `features` = `--features` (`spectral,extrinsic,sdf,user:DIR`,
    /// [`parse_families`](crate::features::parse_families)), `up` = `--up` (`y`, `-z`, `pca`,
    /// [`parse_alignment`](crate::features::parse_alignment)), `directions` and `normals` = the
    /// extrinsic family's `--directions` and `--normals` (unused without it), `weights` =
    /// `--family-weights` (`extrinsic=2,sdf=0.5`; empty: 1 each,
    /// [`parse_family_weights`](crate::features::parse_family_weights)). Without the spectral
    /// family the spectral descriptor counts become 0; with it they are left as they are. The
    /// one translation of these flags (the CLI and the examples call it).
    ///
    /// ```
    /// use coseg::pipeline::ShapePipelineOptions;
    /// let mut o = ShapePipelineOptions::default();
    /// o.set_families("spectral", "y", 100, 0, "").unwrap();
    /// assert_eq!(o, ShapePipelineOptions::default());
    /// o.set_families("extrinsic", "pca", 10, 4, "extrinsic=2").unwrap();
    /// assert_eq!(o.descriptors.hks_count, 0);
    /// assert_eq!(o.families.extrinsic.as_ref().unwrap().normal_directions, 4);
    /// assert!(o.set_families("spectral,colour", "y", 100, 0, "").is_err());
    /// ```
    pub fn set_families(
        &mut self,
        features: &str,
        up: &str,
        directions: usize,
        normals: usize,
        weights: &str,
    ) -> Result<(), FeatureError> {
        let (spectral, mut families) = parse_families(features, parse_alignment(up)?)?;
        if let Some(e) = families.extrinsic.as_mut() {
            e.directions = directions;
            e.normal_directions = normals;
        }
        parse_family_weights(weights, &mut families.weights)?;
        self.families = families;
        if !spectral {
            self.descriptors.hks_count = 0;
            self.descriptors.wks_count = 0;
            self.descriptors.curvature_count = 0;
        }
        Ok(())
    }

    /// The up direction in file coordinates (unit) when the extrinsic family is on with an
    /// aligned collection (`--up y`, …); `None` without it or with `--up pca`. What the
    /// mirror-pair test of the collection stage uses
    /// ([`crate::parts::SegmentCollectionOptions::up`]).
    ///
    /// ```
    /// use coseg::pipeline::ShapePipelineOptions;
    /// let mut o = ShapePipelineOptions::default();
    /// assert_eq!(o.up_direction(), None);
    /// o.set_families("spectral,extrinsic", "-z", 100, 0, "").unwrap();
    /// assert_eq!(o.up_direction(), Some([0.0, 0.0, -1.0]));
    /// o.set_families("spectral,extrinsic", "pca", 100, 0, "").unwrap();
    /// assert_eq!(o.up_direction(), None);
    /// ```
    pub fn up_direction(&self) -> Option<[f64; 3]> {
        match self.families.extrinsic.as_ref()?.alignment {
            crate::features::Alignment::Up(a) => {
                let mut u = [0.0; 3];
                u[a.index] = if a.positive { 1.0 } else { -1.0 };
                Some(u)
            }
            crate::features::Alignment::Pca => None,
        }
    }

    /// The columns of a feature table of `features` columns (made under these options) that a
    /// mirror image leaves unchanged: the spectral descriptors and the shape diameter (`sdf`),
    /// not the extrinsic heights and normals nor the user's columns (unknown). What the
    /// mirror-pair test compares two parts on ([`crate::parts::Likeness`]).
    ///
    /// ```
    /// use coseg::pipeline::ShapePipelineOptions;
    /// let mut o = ShapePipelineOptions::default();
    /// o.set_families("spectral,extrinsic", "y", 10, 0, "").unwrap();
    /// // 300 spectral columns, then 10 heights + 2 distances.
    /// assert_eq!(o.mirror_invariant_columns(312), (0..300).collect::<Vec<_>>());
    /// o.set_families("extrinsic", "y", 10, 0, "").unwrap();
    /// assert!(o.mirror_invariant_columns(12).is_empty());
    /// ```
    pub fn mirror_invariant_columns(&self, features: usize) -> Vec<usize> {
        let [spectral, ext, sdf] = self.family_columns();
        (0..spectral.min(features))
            .chain((spectral + ext).min(features)..(spectral + ext + sdf).min(features))
            .collect()
    }

    /// Per-column affinity weights for a feature table of `features` columns made under these
    /// options ([`FeatureFamilies::feature_weights`]; the user family's count is what remains
    /// after the others). `None`: one family, equal weights.
    pub fn feature_weights(&self, features: usize) -> Option<Vec<f64>> {
        let [spectral, ext, sdf] = self.family_columns();
        let user = features.saturating_sub(spectral + ext + sdf);
        self.families.feature_weights(spectral, [ext, sdf, user])
    }

    /// Column counts of the spectral, extrinsic and sdf families (in table order; the user's
    /// columns come last and are what remains).
    fn family_columns(&self) -> [usize; 3] {
        let d = &self.descriptors;
        let spectral = d.hks_count + d.wks_count + d.curvature_count;
        let f = &self.families;
        let ext = f.extrinsic.as_ref().map_or(0, |e| {
            e.directions
                + usize::from(e.centroid_distance)
                + usize::from(e.axis_distance)
                + e.normal_directions
        });
        let sdf = f.sdf.as_ref().map_or(0, |s| s.smoothing_rounds.len());
        [spectral, ext, sdf]
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
        let consistent = table_fits(&self.bands, vertices) && self.vertex_areas.len() == vertices;
        if !consistent {
            return Err("payload sizes do not match the mesh".into());
        }
        if !self.vertex_areas.iter().all(|a| a.is_finite()) {
            return Err("payload holds non-finite vertex areas".into());
        }
        Ok(())
    }
}

/// True when a band table read from a cache entry is sized for `vertices` vertices and every
/// label is below its band count (the invariant the affinity kernel's unchecked reads rely on).
fn table_fits(t: &BandTable, vertices: usize) -> bool {
    t.vertices == vertices
        && Some(t.labels.len()) == vertices.checked_mul(t.features)
        && t.labels.iter().all(|&l| (l as usize) < t.bands)
}

/// What the full cache entry holds (format version 5): the spectrum with its eigenvectors
/// in `f32`, the columns of the families that are not cheap to recompute (sdf, user), and the
/// band table (deflated). The rest of [`ShapeData`] (the spectral and extrinsic descriptors)
/// is recomputed from it on a warm load by [`StoredShape::into_shape_data`], with the same
/// code and the same inputs as on a cold run, hence the same bits: about 8.6 MB for 10k
/// vertices and 200 eigenpairs instead of 43 MB (see [`crate::cache`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StoredShape {
    /// The key these data were computed for (see [`shape_key`]).
    pub key: ShapeKey,
    /// Number of vertices `d` of the mesh.
    pub vertices: usize,
    /// [`Spectrum::eigenvalues`], exactly.
    pub eigenvalues: Vec<f64>,
    /// [`Spectrum::eigenvectors`] (`d × k`, column-major), which the pipeline rounds to `f32`
    /// as soon as they are computed, so that narrowing here loses nothing.
    pub eigenvectors: Vec<f32>,
    /// [`Spectrum::vertex_areas`], exactly.
    pub vertex_areas: Vec<f64>,
    /// [`Spectrum::original_area`], exactly.
    pub original_area: f64,
    /// The kept families' columns ([`FeatureFamilies::kept_columns`]: sdf, then user) and
    /// their counts `[sdf, user]`; no column when those families are off.
    pub kept_columns: FeatureColumns,
    /// How many of `kept_columns` each kept family gave: `[sdf, user]`.
    pub kept_counts: [usize; 2],
    /// [`ShapeData::bands`], exactly; its labels are deflated in the entry (about 6:1 on real
    /// shapes). Recomputing it would be bit-identical too, but costs about as much as the
    /// descriptors on a warm load (0.06 s for 10k vertices, 0.26 s for 52k), for 6 % of the
    /// entry's size.
    #[serde(with = "deflated_bands")]
    pub bands: BandTable,
}

/// Serialises a [`BandTable`] with its labels deflated ([`crate::cache`]'s format, so a lying
/// length is refused before anything is allocated).
mod deflated_bands {
    use crate::bands::BandTable;
    use serde::{Deserialize, Deserializer, Serialize, Serializer, de::Error};

    #[derive(Serialize, Deserialize)]
    struct Packed {
        features: usize,
        vertices: usize,
        bands: usize,
        labels: Vec<u8>,
    }

    pub(super) fn serialize<S: Serializer>(t: &BandTable, s: S) -> Result<S::Ok, S::Error> {
        Packed {
            features: t.features,
            vertices: t.vertices,
            bands: t.bands,
            labels: crate::cache::deflate(&t.labels),
        }
        .serialize(s)
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<BandTable, D::Error> {
        let p = Packed::deserialize(d)?;
        Ok(BandTable {
            features: p.features,
            vertices: p.vertices,
            bands: p.bands,
            labels: crate::cache::inflate(&p.labels).map_err(D::Error::custom)?,
        })
    }
}

impl StoredShape {
    /// The stored part of `data`, which must come from [`compute_shape_data`] (or
    /// [`shape_data_from_spectrum`]): its eigenvectors are then `f32` values and its last
    /// descriptor columns the kept families'.
    pub fn of(data: &ShapeData) -> Self {
        let s = &data.spectrum;
        debug_assert!(
            s.eigenvectors.iter().all(|&x| f64::from(x as f32) == x),
            "eigenvectors not rounded to f32: the entry would not reproduce the data"
        );
        let t = &data.descriptors;
        let [ext, sdf, user] = t.family_counts;
        let first = t.spectral_count() + ext;
        let d = data.vertices;
        Self {
            key: data.key,
            vertices: d,
            eigenvalues: s.eigenvalues.clone(),
            eigenvectors: s.eigenvectors.iter().map(|&x| x as f32).collect(),
            vertex_areas: s.vertex_areas.clone(),
            original_area: s.original_area,
            kept_columns: FeatureColumns {
                vertices: d,
                names: t.extra_names[ext..].to_vec(),
                values: t.values[first * d..].to_vec(),
            },
            kept_counts: [sdf, user],
            bands: data.bands.clone(),
        }
    }

    /// `Err(reason)` unless these data are keyed `key`, sized for a mesh of `vertices`
    /// vertices and finite (the check of a full cache entry before it is trusted).
    pub(crate) fn check(&self, key: &ShapeKey, vertices: usize) -> Result<(), String> {
        if self.key != *key {
            return Err("payload key does not match".into());
        }
        let k = self.eigenvalues.len();
        let c = &self.kept_columns;
        let consistent = self.vertices == vertices
            && self.vertex_areas.len() == vertices
            && Some(self.eigenvectors.len()) == vertices.checked_mul(k)
            && c.vertices == vertices
            && Some(c.values.len()) == vertices.checked_mul(c.names.len())
            && self.kept_counts[0].checked_add(self.kept_counts[1]) == Some(c.names.len())
            && table_fits(&self.bands, vertices);
        if !consistent {
            return Err("payload sizes do not match the mesh".into());
        }
        // A checksum only proves the bytes are the ones written; NaN must never come out of
        // the cache into a stage (or an output file), whoever wrote the entry.
        let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
        if !(finite(&self.eigenvalues)
            && self.eigenvectors.iter().all(|v| v.is_finite())
            && finite(&self.vertex_areas)
            && self.original_area.is_finite()
            && finite(&c.values))
        {
            return Err("payload holds non-finite numbers".into());
        }
        Ok(())
    }

    /// The shape's full data: the spectrum widened back to `f64` (the very values the cold
    /// run used), then the descriptors computed from it exactly as
    /// [`shape_data_from_spectrum`] does, with the kept columns and the band table taken
    /// from the entry. `mesh` and `options` must be the ones the key was made from.
    pub fn into_shape_data(
        self,
        mesh: &TriMesh,
        options: &ShapePipelineOptions,
    ) -> Result<ShapeData, PipelineError> {
        let f = &options.families;
        let sdf = f.sdf.as_ref().map_or(0, |s| s.smoothing_rounds.len());
        let [kept_sdf, kept_user] = self.kept_counts;
        if kept_sdf != sdf || (f.user.is_none() && kept_user != 0) {
            return Err(FeatureError::Inconsistent(format!(
                "the entry keeps {kept_sdf} sdf and {kept_user} user columns, the options ask \
                 for {sdf} sdf columns{}",
                if f.user.is_none() {
                    " and no user ones"
                } else {
                    ""
                }
            ))
            .into());
        }
        let spectrum = Spectrum {
            eigenvalues: self.eigenvalues,
            eigenvectors: self.eigenvectors.into_iter().map(f64::from).collect(),
            vertex_areas: self.vertex_areas,
            original_area: self.original_area,
        };
        assemble(
            mesh,
            spectrum,
            (self.kept_columns, self.kept_counts),
            Some(self.bands),
            options,
        )
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

/// The bytes of the full cache entry of `data` ([`StoredShape::of`]).
pub fn encode_shape_entry(data: &ShapeData) -> Vec<u8> {
    encode_entry(EntryKind::Full, &data.key, &StoredShape::of(data))
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
    let mut spectrum_options = options.spectrum.clone();
    spectrum_options.eigenpairs = spectrum_options.eigenpairs.min(available_eigenpairs(mesh));
    let spectrum = laplace_beltrami_spectrum(mesh, &spectrum_options)?;
    shape_data_from_spectrum(mesh, spectrum, options)
}

/// The warning for a mesh with fewer usable vertices than the eigenpairs `options` ask for
/// (see [`crate::spectral::available_eigenpairs`]): [`compute_shape_data`] then computes as
/// many eigenpairs as the mesh has, and every later stage works with that many (the map step
/// fits a smaller first map). `None` when the mesh is large enough.
///
/// ```
/// use coseg::{mesh::TriMesh, pipeline::{small_mesh_warning, ShapePipelineOptions}};
/// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let w = small_mesh_warning(&m, &ShapePipelineOptions::default()).unwrap();
/// assert!(w.contains("3 of the 200 eigenpairs"), "{w}");
/// ```
pub fn small_mesh_warning(mesh: &TriMesh, options: &ShapePipelineOptions) -> Option<String> {
    let available = available_eigenpairs(mesh);
    let asked = options.spectrum.eigenpairs;
    (available < asked).then(|| {
        format!(
            "{available} vertices carry area: computing {available} of the {asked} eigenpairs asked for"
        )
    })
}

/// The warning for a mesh with triangles collinear up to rounding
/// ([`crate::spectral::unresolved_triangles`]): their computed cotangents are noise, so the
/// Laplacian treats them as zero-area (no weight, no mass) and the spectrum is that of the
/// rest of the surface. Before 0.1.0's fix (issue #42) such triangles could make `L − σM`
/// indefinite and the shape was dropped. `None` when there is none.
///
/// ```
/// use coseg::{mesh::TriMesh, pipeline::unresolved_triangles_warning};
/// let (a, b) = ([0.1, 0.7, 0.3], [0.9, 0.2, 0.6]);
/// let p = [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) / 3.0); // on the edge, up to rounding
/// let m = TriMesh::new(vec![a, b, [0.5, 1.5, 0.0], p], vec![[0, 1, 2], [0, 3, 1]]).unwrap();
/// let w = unresolved_triangles_warning(&m).unwrap();
/// assert!(w.starts_with("1 triangles are collinear up to rounding"), "{w}");
/// ```
pub fn unresolved_triangles_warning(mesh: &TriMesh) -> Option<String> {
    let count = crate::spectral::unresolved_triangles(mesh);
    (count > 0).then(|| {
        format!(
            "{count} triangles are collinear up to rounding (their cotangents are noise): \
             the Laplacian treats them as zero-area (no weight, no mass)"
        )
    })
}

/// Verifies and decodes the bytes of a full cache entry written for `key` on a mesh of
/// `vertices` vertices; `Err` says why it cannot be trusted (frame, decoding, sizes,
/// non-finite numbers: see [`crate::cache::read_entry`]). Never panics, whatever the bytes.
/// [`StoredShape::into_shape_data`] turns the result into the shape's full data.
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::pipeline::{compute_shape_data, decode_shape_entry, encode_shape_entry, ShapePipelineOptions};
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.]], vec![[0,1,2],[0,2,3]]).unwrap();
/// let mut o = ShapePipelineOptions::default();
/// o.spectrum.eigenpairs = 4;
/// o.bands.bands = 2;
/// let data = compute_shape_data(&m, &o).unwrap();
/// let mut bytes = encode_shape_entry(&data);
/// let stored = decode_shape_entry(&bytes, &data.key, 4).unwrap();
/// assert_eq!(stored.into_shape_data(&m, &o).unwrap(), data);
/// *bytes.last_mut().unwrap() ^= 1; // one flipped bit: the checksum no longer matches
/// assert!(decode_shape_entry(&bytes, &data.key, 4).unwrap_err().contains("checksum"));
/// ```
pub fn decode_shape_entry(
    bytes: &[u8],
    key: &ShapeKey,
    vertices: usize,
) -> Result<StoredShape, String> {
    decode_entry(bytes, EntryKind::Full, key, |d: &StoredShape| {
        d.check(key, vertices)
    })
}

/// [`decode_shape_entry`] for a compact bands entry.
///
/// ```
/// use coseg::bands::equal_count_bands;
/// use coseg::cache::ShapeKey;
/// use coseg::pipeline::{decode_bands_entry, encode_bands_entry, ShapeBands};
/// let bands = equal_count_bands(&[0.0, 1.0, 2.0], 1, 3, 2).unwrap();
/// let data = ShapeBands { key: ShapeKey([7; 32]), bands, vertex_areas: vec![1.0 / 3.0; 3] };
/// let bytes = encode_bands_entry(&data);
/// assert_eq!(decode_bands_entry(&bytes, &data.key, 3).unwrap(), data);
/// assert!(decode_bands_entry(&bytes[..bytes.len() - 1], &data.key, 3).is_err());
/// ```
pub fn decode_bands_entry(
    bytes: &[u8],
    key: &ShapeKey,
    vertices: usize,
) -> Result<ShapeBands, String> {
    decode_entry(bytes, EntryKind::Bands, key, |d: &ShapeBands| {
        d.check(key, vertices)
    })
}

/// Descriptors and band table from an already computed spectrum (e.g. read elsewhere), keyed
/// as [`compute_shape_data`] would key them. The spectrum must be the one
/// `options.spectrum` gives for `mesh`, or the cache key would lie.
///
/// The eigenvectors are rounded to `f32` first (widened back to `f64`): the full cache entry
/// stores them in `f32` ([`StoredShape`]), and rounding here, before anything uses them, makes
/// every result of a cold run bit-identical to the same result recomputed from the entry on a
/// warm run. The rounding (relative 6·10⁻⁸) is far below the solver's own accuracy on
/// eigenvectors; its effect on quality is measured in `docs/PERFORMANCE.md` (Compact cache).
pub fn shape_data_from_spectrum(
    mesh: &TriMesh,
    mut spectrum: Spectrum,
    options: &ShapePipelineOptions,
) -> Result<ShapeData, PipelineError> {
    round_to_f32(&mut spectrum.eigenvectors);
    let kept = options.families.kept_columns(mesh)?;
    assemble(mesh, spectrum, kept, None, options)
}

/// Rounds every value to the nearest `f32` (kept as `f64`).
fn round_to_f32(values: &mut [f64]) {
    for x in values {
        *x = f64::from(*x as f32);
    }
}

/// The one place both a cold run ([`shape_data_from_spectrum`]) and a warm load
/// ([`StoredShape::into_shape_data`]) build a shape's data from its spectrum and its kept
/// columns, so that both give the same bits. `bands`: the stored band table (warm), or `None`
/// to compute it (cold).
fn assemble(
    mesh: &TriMesh,
    spectrum: Spectrum,
    kept: (FeatureColumns, [usize; 2]),
    bands: Option<BandTable>,
    options: &ShapePipelineOptions,
) -> Result<ShapeData, PipelineError> {
    let mut descriptors = descriptors(mesh, &spectrum, &options.descriptors)?;
    if options.families != FeatureFamilies::default() {
        let (extra, counts) = options.families.columns_with(mesh, kept)?;
        descriptors.append(extra, counts)?;
    }
    let bands = match bands {
        None => band_table(&descriptors, &options.bands)?,
        Some(t) if t.features == descriptors.feature_count() && t.bands == options.bands.bands => t,
        Some(t) => {
            return Err(FeatureError::Inconsistent(format!(
                "a stored band table of {} features and {} bands for {} features and {} bands",
                t.features,
                t.bands,
                descriptors.feature_count(),
                options.bands.bands
            ))
            .into());
        }
    };
    Ok(ShapeData {
        key: shape_key(mesh, options),
        vertices: mesh.vertex_count(),
        spectrum,
        descriptors,
        bands,
    })
}
