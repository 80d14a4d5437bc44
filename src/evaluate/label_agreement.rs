//! [`label_agreement`]: area-weighted accuracy, per-part IoU and confusion matrix of predicted
//! part labels against ground-truth labels (per vertex or per face).

use super::EvaluateError;
use crate::labels::vertices_to_faces;
use crate::mesh::TriMesh;
use serde::{Deserialize, Serialize};

/// One ground-truth or predicted part's scores.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartAgreement {
    /// The label.
    pub label: i32,
    /// Share of the scored area labelled so by the ground truth.
    pub truth_area: f64,
    /// Share of the scored area labelled so by the prediction.
    pub predicted_area: f64,
    /// Intersection over union of the two (`0` when the label is in neither).
    pub iou: f64,
}

/// Agreement of a prediction with the ground truth on one shape. Areas are shares of the
/// *scored* area: elements whose ground truth is `< 0` (unlabelled) are left out entirely.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LabelAgreement {
    /// Share of the scored area where prediction = truth (a prediction `< 0` is wrong).
    pub accuracy: f64,
    /// Every label present in the truth or the prediction, ascending.
    pub parts: Vec<PartAgreement>,
    /// Mean IoU over the labels present in the ground truth.
    pub mean_iou: f64,
    /// `confusion[t][p]`: share of the scored area of truth label `labels[t]` predicted as
    /// `labels[p]`; a last column holds the area predicted `< 0`. Rows sum to the truth shares.
    pub confusion: Vec<Vec<f64>>,
    /// Row and column labels of `confusion` (= `parts[i].label`).
    pub labels: Vec<i32>,
}

/// Scores `predicted` against `truth` (same length, one entry per element) with non-negative
/// element `weights` (vertex or face areas; any unit, they are normalised).
///
/// ```
/// use coseg::evaluate::label_agreement;
/// let a = label_agreement(&[1.0, 1.0, 2.0], &[0, 0, 1], &[0, 1, 1]).unwrap();
/// assert!((a.accuracy - 0.75).abs() < 1e-12);
/// assert!((a.parts[1].iou - 2.0 / 3.0).abs() < 1e-12);
/// assert!((a.confusion[0][1] - 0.25).abs() < 1e-12);
/// ```
pub fn label_agreement(
    weights: &[f64],
    truth: &[i32],
    predicted: &[i32],
) -> Result<LabelAgreement, EvaluateError> {
    if weights.len() != truth.len() || predicted.len() != truth.len() {
        return Err(EvaluateError::Shape {
            shape: "0".into(),
            message: format!(
                "{} weights, {} ground-truth labels and {} predicted labels",
                weights.len(),
                truth.len(),
                predicted.len()
            ),
        });
    }
    if let Some(w) = weights.iter().find(|w| !(w.is_finite() && **w >= 0.0)) {
        return Err(EvaluateError::Shape {
            shape: "0".into(),
            message: format!("weight {w} is not finite and non-negative"),
        });
    }
    let total: f64 = weights
        .iter()
        .zip(truth)
        .filter(|(_, t)| **t >= 0)
        .map(|(w, _)| w)
        .sum();
    if total <= 0.0 {
        return Err(EvaluateError::Empty(
            "no ground-truth-labelled area to score".into(),
        ));
    }
    let mut labels: Vec<i32> = truth
        .iter()
        .chain(predicted)
        .copied()
        .filter(|&l| l >= 0)
        .collect();
    labels.sort_unstable();
    labels.dedup();
    let n = labels.len();
    let pos = |l: i32| labels.binary_search(&l).ok();
    let mut confusion = vec![vec![0.0; n + 1]; n];
    for ((&w, &t), &p) in weights.iter().zip(truth).zip(predicted) {
        if t < 0 {
            continue;
        }
        let ti = pos(t).expect("truth labels are in the list");
        let pi = if p >= 0 { pos(p).unwrap_or(n) } else { n };
        confusion[ti][pi] += w / total;
    }
    let accuracy = (0..n).map(|i| confusion[i][i]).sum();
    let parts: Vec<PartAgreement> = (0..n)
        .map(|i| {
            let truth_area: f64 = confusion[i].iter().sum();
            let predicted_area: f64 = (0..n).map(|t| confusion[t][i]).sum();
            let inter = confusion[i][i];
            let union = truth_area + predicted_area - inter;
            PartAgreement {
                label: labels[i],
                truth_area,
                predicted_area,
                iou: if union > 0.0 { inter / union } else { 0.0 },
            }
        })
        .collect();
    let in_truth: Vec<&PartAgreement> = parts.iter().filter(|p| p.truth_area > 0.0).collect();
    let mean_iou = in_truth.iter().map(|p| p.iou).sum::<f64>() / in_truth.len().max(1) as f64;
    Ok(LabelAgreement {
        accuracy,
        parts,
        mean_iou,
        confusion,
        labels,
    })
}

/// Per-face scores of per-vertex predictions against per-face truth (a `.seg` file): each
/// face takes the majority label of its corners ([`vertices_to_faces`]) and is weighted by its
/// area.
///
/// ```
/// use coseg::evaluate::face_label_agreement;
/// use coseg::mesh::TriMesh;
/// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
///     vec![[0, 1, 2], [0, 2, 3]]).unwrap();
/// let a = face_label_agreement(&m, &[1, 2], &[1, 1, 1, 2]).unwrap();
/// assert!((a.accuracy - 0.5).abs() < 1e-12); // face 1 has corners 1, 1, 2
/// ```
pub fn face_label_agreement(
    mesh: &TriMesh,
    truth_faces: &[i32],
    predicted_vertices: &[i32],
) -> Result<LabelAgreement, EvaluateError> {
    let faces = vertices_to_faces(mesh, predicted_vertices).map_err(|e| EvaluateError::Shape {
        shape: "0".into(),
        message: e.to_string(),
    })?;
    if truth_faces.len() != mesh.face_count() {
        return Err(EvaluateError::Shape {
            shape: "0".into(),
            message: format!(
                "{} ground-truth face labels for a mesh of {} faces",
                truth_faces.len(),
                mesh.face_count()
            ),
        });
    }
    label_agreement(&finite_face_areas(mesh), truth_faces, &faces)
}

/// The weights of per-face scores: each face's area, 0 for a face whose area is not finite (a
/// degenerate face counts for nothing rather than spoiling every score).
pub(super) fn finite_face_areas(mesh: &TriMesh) -> Vec<f64> {
    mesh.face_areas()
        .into_iter()
        .map(|a| if a.is_finite() { a } else { 0.0 })
        .collect()
}

/// Per-vertex scores of per-vertex predictions against per-vertex truth, weighted by the
/// barycentric vertex areas.
///
/// ```
/// use coseg::evaluate::vertex_label_agreement;
/// use coseg::mesh::TriMesh;
/// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let a = vertex_label_agreement(&m, &[0, 0, 1], &[0, 0, 1]).unwrap();
/// assert!((a.accuracy - 1.0).abs() < 1e-12);
/// ```
pub fn vertex_label_agreement(
    mesh: &TriMesh,
    truth: &[i32],
    predicted: &[i32],
) -> Result<LabelAgreement, EvaluateError> {
    label_agreement(&mesh.vertex_areas(), truth, predicted)
}
