//! [`GroundTruth`]: a family folder's manifest and per-vertex part labels, grouped.

use super::{EvaluateError, PartGroups, group_parts, read_labels};
use crate::generate::{Manifest, ManifestShape};
use std::path::{Path, PathBuf};

/// The ground truth of a generated family folder (`collections/<family>/`): its
/// `manifest.json` and the part grouping of its `part_groups`.
#[derive(Debug, Clone)]
pub struct GroundTruth {
    /// The folder holding the manifest.
    pub dir: PathBuf,
    /// The parsed manifest.
    pub manifest: Manifest,
    /// The manifest's parts merged by its `part_groups` ([`group_parts`]).
    pub groups: PartGroups,
}

impl GroundTruth {
    /// Reads `dir/manifest.json` and groups its parts.
    ///
    /// ```
    /// use coseg::evaluate::GroundTruth;
    /// let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/collections/quadrupeds");
    /// let truth = GroundTruth::read(dir).unwrap();
    /// assert_eq!(truth.groups.names, ["torso", "head", "leg", "tail"]);
    /// let labels = truth.grouped_labels("quadrupeds_00").unwrap();
    /// assert_eq!(labels.len(), truth.shape("quadrupeds_00").unwrap().vertices);
    /// ```
    pub fn read(dir: impl AsRef<Path>) -> Result<Self, EvaluateError> {
        let dir = dir.as_ref().to_path_buf();
        let path = dir.join("manifest.json");
        let bad = |message: String| EvaluateError::BadManifest {
            path: path.display().to_string(),
            message,
        };
        let text = std::fs::read_to_string(&path).map_err(|source| {
            EvaluateError::Io(crate::FileError {
                path: path.display().to_string(),
                source,
            })
        })?;
        let manifest: Manifest = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
        let groups = group_parts(&manifest.parts, &manifest.part_groups).map_err(|e| match e {
            EvaluateError::BadGroups(m) => bad(m),
            other => other,
        })?;
        Ok(GroundTruth {
            dir,
            manifest,
            groups,
        })
    }

    /// The manifest entry of the shape named `name` (file stem), if any.
    pub fn shape(&self, name: &str) -> Option<&ManifestShape> {
        self.manifest.shapes.iter().find(|s| s.name == name)
    }

    /// The grouped part label of every vertex of shape `name`: its labels file, checked to
    /// have one label per vertex, mapped through [`GroundTruth::groups`].
    pub fn grouped_labels(&self, name: &str) -> Result<Vec<usize>, EvaluateError> {
        let shape = self.shape(name).ok_or_else(|| EvaluateError::Shape {
            shape: name.to_string(),
            message: format!("not in {}", self.dir.join("manifest.json").display()),
        })?;
        let path = self.dir.join(&shape.labels);
        let labels = read_labels(&path)?;
        let located = |message: String| EvaluateError::Shape {
            shape: format!("{name} ({})", path.display()),
            message,
        };
        if labels.len() != shape.vertices {
            return Err(located(format!(
                "{} labels for {} vertices",
                labels.len(),
                shape.vertices
            )));
        }
        self.groups
            .apply(&labels)
            .map_err(|e| located(e.to_string()))
    }
}
