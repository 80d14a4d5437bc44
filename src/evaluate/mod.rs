//! Agreement of found regions with ground-truth parts (the shipped `collections/` carry
//! per-vertex part labels; see [`crate::generate`]).
//!
//! Both scores pool every shape, so a region id means one region *tuple* across the collection
//! (as `coseg segment` and `coseg pair` write them), and both weigh vertices by area, with each
//! shape scaled to unit total area so that every shape counts the same whatever its units or
//! resolution:
//!
//! - [`part_purity`]: for each found region, the share of its area lying in its majority
//!   ground-truth part; area-weighted mean over regions. 1 when no region straddles two parts.
//! - [`part_coverage`]: for each ground-truth part, the largest share of its area that a single
//!   region id covers; plain mean over parts. 1 when every part lies inside one region.
//!
//! Purity alone rewards tiny regions and coverage alone one huge region; read them together.
//! Ground truth comes from a family folder's `manifest.json` through [`GroundTruth`], which
//! merges the parts of a group (left and right legs, …) with [`group_parts`]: an intrinsic method
//! cannot tell mirror-symmetric parts apart, so evaluations use the grouped parts.
//!
//! ```
//! use coseg::evaluate::{part_coverage, part_purity, ShapeParts};
//! // Four equal vertices: parts 0,0,1,1; found regions 5,5,5,7.
//! let shape = ShapeParts::new(vec![1.0; 4], vec![0, 0, 1, 1], vec![5, 5, 5, 7]).unwrap();
//! // Region 5 holds 2/3 of its area in part 0, region 7 is pure: (2 + 1) / 4.
//! assert!((part_purity(&[shape.clone()]).unwrap() - 0.75).abs() < 1e-12);
//! // Part 0 lies entirely in region 5, part 1 half in region 5 and half in 7: (1 + 1/2) / 2.
//! assert!((part_coverage(&[shape]).unwrap() - 0.75).abs() < 1e-12);
//! ```

mod evaluate_folder;
mod ground_truth;
mod group_parts;
mod label_agreement;
mod matched_scores;
mod part_coverage;
mod part_purity;
mod rand_index;
mod read_labels;

pub use evaluate_folder::{
    CorrespondenceMap, EvaluateFolderOptions, FolderScores, ResultKind, ShapeScores,
    evaluate_folder,
};
pub use ground_truth::GroundTruth;
pub use group_parts::{PartGroups, group_parts};
pub use label_agreement::{
    LabelAgreement, PartAgreement, face_label_agreement, label_agreement, vertex_label_agreement,
};
pub use matched_scores::{MatchedScores, matched_scores};
pub use part_coverage::part_coverage;
pub use part_purity::part_purity;
pub use rand_index::rand_index;
pub use read_labels::{parse_labels, read_labels};

use crate::labels::LabelError;
use crate::mesh::TriMesh;
use std::collections::BTreeMap;
use thiserror::Error;

/// Errors of the evaluation; each names the file or shape concerned.
#[derive(Debug, Error)]
pub enum EvaluateError {
    /// A file could not be read.
    #[error(transparent)]
    Io(#[from] crate::FileError),
    /// A line of a label file is not an integer ([`LabelError::BadLabel`]: the label files'
    /// one parser serves both modules).
    #[error(transparent)]
    Label(LabelError),
    /// A manifest could not be parsed or is inconsistent.
    #[error("{path}: {message}")]
    BadManifest {
        /// The manifest file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// Per-vertex vectors of one shape differ in length, or a label is out of range.
    #[error("shape {shape}: {message}")]
    Shape {
        /// Index of the shape in the slice given, or its name.
        shape: String,
        /// What does not match.
        message: String,
    },
    /// Part groups name an unknown part, put a part in two groups, or a label has no part.
    #[error("part groups: {0}")]
    BadGroups(String),
    /// No shape, or no area to score.
    #[error("nothing to evaluate: {0}")]
    Empty(String),
}

/// One shape's per-vertex data for scoring: area, ground-truth part and found region.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeParts {
    /// Area of every vertex (length `d`, any unit; non-negative). Scores rescale each shape to
    /// unit total area.
    pub areas: Vec<f64>,
    /// Ground-truth part of every vertex (length `d`; grouped parts, see [`GroundTruth`]).
    pub truth: Vec<usize>,
    /// Found region id of every vertex (length `d`; negative = in no region).
    pub found: Vec<i32>,
}

impl ShapeParts {
    /// Checks that the three vectors have the same length and the areas are finite and
    /// non-negative.
    pub fn new(areas: Vec<f64>, truth: Vec<usize>, found: Vec<i32>) -> Result<Self, EvaluateError> {
        let shape = ShapeParts {
            areas,
            truth,
            found,
        };
        shape.check("0")?;
        Ok(shape)
    }

    /// The shape's barycentric vertex areas ([`TriMesh::vertex_areas`]) with `truth` and
    /// `found` (each one entry per vertex of `mesh`).
    pub fn of_mesh(
        mesh: &TriMesh,
        truth: Vec<usize>,
        found: Vec<i32>,
    ) -> Result<Self, EvaluateError> {
        Self::new(mesh.vertex_areas(), truth, found)
    }

    fn check(&self, shape: &str) -> Result<(), EvaluateError> {
        let d = self.areas.len();
        if self.truth.len() != d || self.found.len() != d {
            return Err(EvaluateError::Shape {
                shape: shape.to_string(),
                message: format!(
                    "{d} areas, {} ground-truth labels and {} region ids",
                    self.truth.len(),
                    self.found.len()
                ),
            });
        }
        if let Some(a) = self.areas.iter().find(|a| !(a.is_finite() && **a >= 0.0)) {
            return Err(EvaluateError::Shape {
                shape: shape.to_string(),
                message: format!("vertex area {a} is not finite and non-negative"),
            });
        }
        Ok(())
    }
}

/// Pooled area of every (found region, ground-truth part) pair over all shapes, each shape
/// scaled to unit area, plus each part's total area (vertices in no region included).
struct Overlap {
    /// `(region, part) → area`; regions with negative ids are left out.
    cells: BTreeMap<(i32, usize), f64>,
    /// `part → area`, every vertex counted.
    parts: BTreeMap<usize, f64>,
}

impl Overlap {
    fn pool(shapes: &[ShapeParts]) -> Result<Self, EvaluateError> {
        if shapes.is_empty() {
            return Err(EvaluateError::Empty("no shapes".into()));
        }
        let mut cells = BTreeMap::new();
        let mut parts = BTreeMap::new();
        for (i, s) in shapes.iter().enumerate() {
            s.check(&i.to_string())?;
            let total: f64 = s.areas.iter().sum();
            if total <= 0.0 {
                return Err(EvaluateError::Shape {
                    shape: i.to_string(),
                    message: "zero total area".into(),
                });
            }
            for ((&a, &t), &f) in s.areas.iter().zip(&s.truth).zip(&s.found) {
                let a = a / total;
                *parts.entry(t).or_insert(0.0) += a;
                if f >= 0 {
                    *cells.entry((f, t)).or_insert(0.0) += a;
                }
            }
        }
        Ok(Overlap { cells, parts })
    }
}
