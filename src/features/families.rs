//! Feature families as one extension point of the per-shape stage: which families a shape's
//! feature table holds beyond the spectral one, how they are computed, and their weights.
//!
//! Columns are appended to the spectral table (HKS, WKS, curvature) in a fixed family order —
//! extrinsic, sdf, user — each family's columns in its own order, so under the same options
//! every shape of a collection has the same column names in the same positions and the
//! affinity pairs them by name. A family's weight is its **total** share of the affinity: each
//! of its `n` columns gets `weight / n` (see [`FeatureFamilies::feature_weights`]). The extrinsic
//! family's normal columns (orientation, `--normals`) are weighted as a family of their own, so
//! orientation and position (heights, distances) each get a share whatever their column counts.

use super::{
    ExtrinsicOptions, FeatureColumns, FeatureError, SdfOptions, extrinsic_features,
    read_user_features, shape_diameter, user_feature_path,
};
use crate::mesh::TriMesh;
use std::path::{Path, PathBuf};

/// Where a shape's user features come from.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum UserSource {
    /// A folder holding `<mesh stem>.npy` or `<mesh stem>.csv` per shape; resolved per shape by
    /// [`FeatureFamilies::for_shape`].
    Dir(PathBuf),
    /// One resolved file and the BLAKE3 hash of its bytes (which puts its content in the cache
    /// key).
    File {
        /// The feature file.
        path: PathBuf,
        /// BLAKE3 of the file's bytes.
        hash: [u8; 32],
    },
}

/// Per-family weights: a family's total share of the affinity (default 1 each).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FamilyWeights {
    /// HKS + WKS + curvature together.
    pub spectral: f64,
    /// Extrinsic position columns together (heights `ext_dir_*`, distances `ext_centroid`,
    /// `ext_axis`).
    pub extrinsic: f64,
    /// Extrinsic normal columns `ext_nrm_*` together (orientation, [`ExtrinsicOptions::normal_directions`]):
    /// a share of their own, not taken from the positions'. Measured in docs/PROPAGATION.md
    /// ("Normals as a family of their own").
    #[serde(default = "one")]
    pub normals: f64,
    /// SDF columns together.
    pub sdf: f64,
    /// User columns together.
    pub user: f64,
}

/// Serde default of a family weight missing from older files.
fn one() -> f64 {
    1.0
}

impl Default for FamilyWeights {
    fn default() -> Self {
        Self {
            spectral: 1.0,
            extrinsic: 1.0,
            normals: 1.0,
            sdf: 1.0,
            user: 1.0,
        }
    }
}

/// The families beyond the spectral one (which [`super::DescriptorOptions`] sets; zero counts
/// there turn it off). Default: none, so the default table is the spectral one alone.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct FeatureFamilies {
    /// Extrinsic columns (`ext_*`), if on.
    pub extrinsic: Option<ExtrinsicOptions>,
    /// Shape diameter columns (`sdf_*`), if on.
    pub sdf: Option<SdfOptions>,
    /// User columns (`user_*` or `user:<header>`), if on.
    pub user: Option<UserSource>,
    /// Weight of each family in the affinity.
    pub weights: FamilyWeights,
}

impl FeatureFamilies {
    /// These options with a [`UserSource::Dir`] resolved to the file of the shape read from
    /// `mesh_path` (and its content hash). Errors name the folder and the expected files.
    pub fn for_shape(&self, mesh_path: &Path) -> Result<Self, FeatureError> {
        let mut out = self.clone();
        if let Some(UserSource::Dir(dir)) = &self.user {
            let stem = mesh_path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            let path = user_feature_path(dir, &stem).ok_or_else(|| FeatureError::UserFile {
                path: dir.display().to_string(),
                message: format!("no {stem}.npy or {stem}.csv for {}", mesh_path.display()),
            })?;
            let bytes = std::fs::read(&path).map_err(|e| FeatureError::UserFile {
                path: path.display().to_string(),
                message: e.to_string(),
            })?;
            out.user = Some(UserSource::File {
                hash: *blake3::hash(&bytes).as_bytes(),
                path,
            });
        }
        Ok(out)
    }

    /// The extra columns of `mesh` (extrinsic, then sdf, then user), and each family's column
    /// count in that order (`[extrinsic, sdf, user]`).
    ///
    /// ```
    /// use coseg::{mesh::TriMesh, features::{FeatureFamilies, ExtrinsicOptions}};
    /// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[0.,1.,0.]], vec![[0,1,2]]).unwrap();
    /// let mut f = FeatureFamilies::default();
    /// f.extrinsic = Some(ExtrinsicOptions::default());
    /// let (cols, counts) = f.columns(&m).unwrap();
    /// assert_eq!(counts, [102, 0, 0]);
    /// assert_eq!(cols.len(), 102);
    /// ```
    pub fn columns(&self, mesh: &TriMesh) -> Result<(FeatureColumns, [usize; 3]), FeatureError> {
        let kept = self.kept_columns(mesh)?;
        self.columns_with(mesh, kept)
    }

    /// The columns of the families the per-shape cache keeps rather than recomputes (sdf, then
    /// user) and each one's count (`[sdf, user]`): the sdf casts rays (about 0.7 s per 10k
    /// vertices) and the user file may have changed or gone by the next run, while the
    /// extrinsic columns cost milliseconds. See [`crate::pipeline`] and [`crate::cache`].
    ///
    /// ```
    /// use coseg::{mesh::TriMesh, features::{FeatureFamilies, ExtrinsicOptions}};
    /// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[0.,1.,0.]], vec![[0,1,2]]).unwrap();
    /// let mut f = FeatureFamilies::default();
    /// f.extrinsic = Some(ExtrinsicOptions::default());
    /// let (kept, counts) = f.kept_columns(&m).unwrap();
    /// assert_eq!((kept.len(), counts), (0, [0, 0]));
    /// assert_eq!(f.columns_with(&m, (kept, counts)).unwrap(), f.columns(&m).unwrap());
    /// ```
    pub fn kept_columns(
        &self,
        mesh: &TriMesh,
    ) -> Result<(FeatureColumns, [usize; 2]), FeatureError> {
        let d = mesh.vertex_count();
        let mut names = Vec::new();
        let mut values = Vec::new();
        let mut counts = [0usize; 2];
        let mut push = |c: FeatureColumns, slot: usize| {
            counts[slot] = c.len();
            names.extend(c.names);
            values.extend(c.values);
        };
        if let Some(o) = &self.sdf {
            push(shape_diameter(mesh, o)?, 0);
        }
        match &self.user {
            None => {}
            Some(UserSource::Dir(dir)) => {
                return Err(FeatureError::UserFile {
                    path: dir.display().to_string(),
                    message: "user features from a folder need the shape's file name \
                              (resolve with FeatureFamilies::for_shape)"
                        .into(),
                });
            }
            Some(UserSource::File { path, .. }) => {
                push(sorted_by_name(read_user_features(path, d)?), 1)
            }
        }
        FeatureColumns::new(d, names, values).map(|c| (c, counts))
    }

    /// All the extra columns (extrinsic, then sdf, then user) and their counts, as
    /// [`columns`](Self::columns) gives them, with the kept families' columns taken from
    /// `kept` ([`kept_columns`](Self::kept_columns)'s result, computed now or read from a cache
    /// entry) and the extrinsic ones computed.
    pub fn columns_with(
        &self,
        mesh: &TriMesh,
        kept: (FeatureColumns, [usize; 2]),
    ) -> Result<(FeatureColumns, [usize; 3]), FeatureError> {
        let d = mesh.vertex_count();
        let (kept, [sdf, user]) = kept;
        if kept.vertices != d || sdf + user != kept.len() {
            return Err(FeatureError::Inconsistent(format!(
                "{} kept columns on {} vertices ({sdf} sdf + {user} user) for a mesh of {d} \
                 vertices",
                kept.len(),
                kept.vertices
            )));
        }
        let (mut names, mut values, ext) = match &self.extrinsic {
            Some(o) => {
                let c = extrinsic_features(mesh, o)?;
                let n = c.len();
                (c.names, c.values, n)
            }
            None => (Vec::new(), Vec::new(), 0),
        };
        names.extend(kept.names);
        values.extend(kept.values);
        FeatureColumns::new(d, names, values).map(|c| (c, [ext, sdf, user]))
    }

    /// Per-column weights for a table of `spectral` spectral columns followed by
    /// `counts = [extrinsic, sdf, user]` columns: each column gets its family's weight over the
    /// family's column count. The last [`ExtrinsicOptions::normal_directions`] extrinsic
    /// columns (the normals, which [`extrinsic_features`] puts last) count as the `normals`
    /// family. `None` when only one family has columns (equal weights: the affinity's exact
    /// integer path, bit-identical to a single-family table).
    ///
    /// ```
    /// use coseg::features::{ExtrinsicOptions, FeatureFamilies};
    /// let mut f = FeatureFamilies::default();
    /// assert_eq!(f.feature_weights(300, [0, 0, 0]), None);
    /// let w = f.feature_weights(2, [4, 0, 0]).unwrap();
    /// assert_eq!(w, vec![0.5, 0.5, 0.25, 0.25, 0.25, 0.25]);
    /// // Two of the four extrinsic columns are normals: a family of their own.
    /// let mut e = ExtrinsicOptions::default();
    /// e.normal_directions = 2;
    /// f.extrinsic = Some(e);
    /// let w = f.feature_weights(2, [4, 0, 0]).unwrap();
    /// assert_eq!(w, vec![0.5, 0.5, 0.5, 0.5, 0.5, 0.5]);
    /// ```
    pub fn feature_weights(&self, spectral: usize, counts: [usize; 3]) -> Option<Vec<f64>> {
        let normals = self
            .extrinsic
            .as_ref()
            .map_or(0, |e| e.normal_directions)
            .min(counts[0]);
        let fams = [
            (spectral, self.weights.spectral),
            (counts[0] - normals, self.weights.extrinsic),
            (normals, self.weights.normals),
            (counts[1], self.weights.sdf),
            (counts[2], self.weights.user),
        ];
        if fams.iter().filter(|(n, _)| *n > 0).count() <= 1 {
            return None;
        }
        Some(
            fams.iter()
                .flat_map(|&(n, w)| std::iter::repeat_n(w / n.max(1) as f64, n))
                .collect(),
        )
    }
}

/// Header-named user columns in name order, so files that list the same headers in different
/// orders give the same table; positional columns keep their order.
fn sorted_by_name(c: FeatureColumns) -> FeatureColumns {
    if !c.names.iter().any(|n| n.starts_with("user:")) {
        return c;
    }
    let mut order: Vec<usize> = (0..c.len()).collect();
    order.sort_by(|&a, &b| c.names[a].cmp(&c.names[b]));
    FeatureColumns {
        vertices: c.vertices,
        names: order.iter().map(|&i| c.names[i].clone()).collect(),
        values: order.iter().flat_map(|&i| c.column(i).to_vec()).collect(),
    }
}

/// Parses a family list such as `spectral,extrinsic,sdf` or `sdf,user:feats/`: whether the
/// spectral family is on, and the other families with their default options (the extrinsic
/// frame is `alignment`). Errors name the unknown entry.
///
/// ```
/// use coseg::features::{parse_families, Alignment};
/// let (spectral, f) = parse_families("spectral,sdf", Alignment::Pca).unwrap();
/// assert!(spectral && f.sdf.is_some() && f.extrinsic.is_none());
/// assert!(parse_families("spectral,colour", Alignment::Pca).is_err());
/// ```
pub fn parse_families(
    list: &str,
    alignment: super::Alignment,
) -> Result<(bool, FeatureFamilies), FeatureError> {
    let mut spectral = false;
    let mut f = FeatureFamilies::default();
    for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        match item {
            "spectral" => spectral = true,
            "extrinsic" => {
                f.extrinsic = Some(ExtrinsicOptions {
                    alignment,
                    ..Default::default()
                });
            }
            "sdf" => f.sdf = Some(SdfOptions::default()),
            _ => match item.strip_prefix("user:") {
                Some(dir) if !dir.is_empty() => f.user = Some(UserSource::Dir(dir.into())),
                _ => {
                    return Err(FeatureError::BadOption(format!(
                        "unknown feature family {item:?} (expected spectral, extrinsic, sdf \
                         or user:DIR)"
                    )));
                }
            },
        }
    }
    if !spectral && f == FeatureFamilies::default() {
        return Err(FeatureError::BadOption(format!(
            "feature list {list:?} selects no family"
        )));
    }
    Ok((spectral, f))
}

/// Parses an alignment: `pca`, or an up axis `x`, `+y`, `-z`… (see [`super::Alignment`]).
///
/// ```
/// use coseg::features::{parse_alignment, Alignment};
/// assert_eq!(parse_alignment("PCA").unwrap(), Alignment::Pca);
/// assert!(matches!(parse_alignment("-z").unwrap(), Alignment::Up(_)));
/// ```
pub fn parse_alignment(s: &str) -> Result<super::Alignment, FeatureError> {
    if s.trim().eq_ignore_ascii_case("pca") {
        Ok(super::Alignment::Pca)
    } else {
        s.parse().map(super::Alignment::Up)
    }
}

/// Parses family weights `spectral=1,extrinsic=2,normals=1,sdf=0.5,user=1` (any subset; the
/// others keep their value in `weights`). Weights must be finite and non-negative.
///
/// ```
/// use coseg::features::{parse_family_weights, FamilyWeights};
/// let mut w = FamilyWeights::default();
/// parse_family_weights("extrinsic=2, sdf=0.5", &mut w).unwrap();
/// assert_eq!((w.spectral, w.extrinsic, w.sdf), (1.0, 2.0, 0.5));
/// assert!(parse_family_weights("sdf=-1", &mut w).is_err());
/// ```
pub fn parse_family_weights(s: &str, weights: &mut FamilyWeights) -> Result<(), FeatureError> {
    for item in s.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let bad =
            || FeatureError::BadOption(format!("family weight {item:?}: expected NAME=WEIGHT"));
        let (name, value) = item.split_once('=').ok_or_else(bad)?;
        let w: f64 = value.trim().parse().map_err(|_| bad())?;
        if !(w.is_finite() && w >= 0.0) {
            return Err(bad());
        }
        let slot = match name.trim() {
            "spectral" => &mut weights.spectral,
            "extrinsic" => &mut weights.extrinsic,
            "normals" => &mut weights.normals,
            "sdf" => &mut weights.sdf,
            "user" => &mut weights.user,
            _ => return Err(bad()),
        };
        *slot = w;
    }
    Ok(())
}
