//! [`evaluate_folder`]: scores a folder written by `coseg segment`, `pair` or `propagate`
//! against a ground-truth folder (what `coseg eval` prints).

use super::label_agreement::finite_face_areas;
use super::{EvaluateError, LabelAgreement, label_agreement, matched_scores, read_labels};
use crate::labels::{faces_to_vertices, vertices_to_faces};
use crate::mesh::{TriMesh, read_mesh};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What a result folder holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ResultKind {
    /// `<name>.regions.txt` of `segment` or `pair`: region ids, the same id the same part on
    /// every shape but with no meaning of its own, so each id is mapped to its majority true
    /// part pooled over the shapes before scoring.
    Regions,
    /// `<name>.labels.txt` of `propagate`: the annotation's own labels, compared as they are.
    Labels,
}

/// A point-to-point map for the correspondence ratio of a two-shape result.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CorrespondenceMap {
    /// Vertex `p` of the first shape corresponds to vertex `p` of the second (same
    /// triangulation, as in TOSCA and FAUST classes).
    Identity,
    /// A file with one integer per vertex of the first shape: its image on the second
    /// (negative = none).
    File(PathBuf),
}

/// Options of [`evaluate_folder`].
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct EvaluateFolderOptions {
    /// Also score the correspondence ratio (two-shape results only).
    pub map: Option<CorrespondenceMap>,
}

/// One shape's scores.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShapeScores {
    /// File stem.
    pub name: String,
    /// Whether `summary.json` lists the shape as an annotated source (propagation only);
    /// sources are left out of the means.
    pub source: bool,
    /// Accuracy as pooled in [`FolderScores::accuracy`] (regions: share of vertices; labels:
    /// share of area, of faces against `.seg` truth, of vertex areas otherwise).
    pub accuracy: f64,
    /// Rand index of the found partition against the truth's (needs no mapping).
    pub rand_index: f64,
    /// Labels only: mean IoU over the shape's true parts.
    pub mean_iou: Option<f64>,
}

/// Scores of one result folder.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FolderScores {
    /// What was scored.
    pub kind: ResultKind,
    /// Per shape, sorted by name.
    pub shapes: Vec<ShapeScores>,
    /// Regions: share of all vertices whose mapped part is their true part (pooled). Labels:
    /// mean over the non-source shapes of their area-weighted accuracy.
    pub accuracy: f64,
    /// Mean Rand index over the scored shapes.
    pub mean_rand_index: f64,
    /// True part → IoU (regions: pooled vertices; labels: mean over the non-source shapes
    /// whose truth has the part).
    pub part_iou: BTreeMap<i32, f64>,
    /// Mean of `part_iou`.
    pub mean_iou: f64,
    /// Regions only: region id → the true part it was mapped to.
    pub mapping: BTreeMap<i32, i32>,
    /// With [`EvaluateFolderOptions::map`]: fraction of the first shape's mapped vertices whose
    /// image carries the same region or label.
    pub correspondence_ratio: Option<f64>,
}

/// Scores every `<name>.regions.txt` (or, when there is none, every `<name>.labels.txt`) in
/// `result` against `truth/<name>.labels.txt` (one label per vertex) or `truth/<name>.seg`
/// (one per face; the mesh is `result/<name>.regions.ply` or `<name>.labels.ply`, which
/// coseg writes beside the labels). Label files hold one integer per line; true labels `< 0`
/// are not scored.
///
/// - Region results are scored with [`matched_scores`] (ids mapped to parts over the set).
/// - Label results are scored per shape with [`label_agreement`]: per face (face areas)
///   against `.seg` truth, the prediction's face label being the majority of its corners as
///   `coseg propagate` writes `<name>.seg`; per vertex (vertex areas) otherwise. The shapes
///   `result/summary.json` names as `sources` are reported but left out of the means.
///
/// Errors name the file: a missing truth, lengths that differ, an unreadable file.
///
/// ```no_run
/// use coseg::evaluate::{evaluate_folder, EvaluateFolderOptions};
/// use std::path::Path;
/// let s = evaluate_folder(Path::new("out"), Path::new("truth"),
///     &EvaluateFolderOptions::default()).unwrap();
/// println!("{:.1} % correct", 100.0 * s.accuracy);
/// ```
pub fn evaluate_folder(
    result: &Path,
    truth: &Path,
    options: &EvaluateFolderOptions,
) -> Result<FolderScores, EvaluateError> {
    let io = |path: &Path| {
        let path = path.display().to_string();
        move |source| EvaluateError::Io(crate::FileError { path, source })
    };
    let mut stems: BTreeMap<ResultKind, Vec<String>> = BTreeMap::new();
    for entry in std::fs::read_dir(result).map_err(io(result))? {
        let name = entry.map_err(io(result))?.file_name();
        let Some(name) = name.to_str() else { continue };
        for (kind, suffix) in [
            (ResultKind::Regions, ".regions.txt"),
            (ResultKind::Labels, ".labels.txt"),
        ] {
            if let Some(stem) = name.strip_suffix(suffix) {
                stems.entry(kind).or_default().push(stem.to_string());
            }
        }
    }
    let (kind, mut names) = stems.into_iter().next().ok_or_else(|| {
        EvaluateError::Empty(format!(
            "{}: no <name>.regions.txt or <name>.labels.txt files",
            result.display()
        ))
    })?;
    names.sort();
    let sources = read_sources(result)?;
    let suffix = match kind {
        ResultKind::Regions => "regions",
        ResultKind::Labels => "labels",
    };
    let mut shapes = Vec::with_capacity(names.len());
    for name in &names {
        let found = read_labels(result.join(format!("{name}.{suffix}.txt")))?;
        let mesh_path = result.join(format!("{name}.{suffix}.ply"));
        let truth = read_truth(truth, &mesh_path, name, found.len())?;
        shapes.push((name.clone(), found, truth));
    }
    let correspondence_ratio = match &options.map {
        None => None,
        Some(map) if shapes.len() == 2 => {
            Some(correspondence_ratio(&shapes[0].1, &shapes[1].1, map)?)
        }
        Some(_) => {
            return Err(EvaluateError::Shape {
                shape: result.display().to_string(),
                message: format!(
                    "a correspondence ratio needs a two-shape result, got {} shapes",
                    shapes.len()
                ),
            });
        }
    };
    match kind {
        ResultKind::Regions => score_regions(&names, &shapes, correspondence_ratio),
        ResultKind::Labels => score_labels(result, &sources, &shapes, correspondence_ratio),
    }
}

/// One shape's result and truth: its name, the found ids or labels per vertex, the truth.
type Scored = (String, Vec<i32>, Truth);

/// Region ids mapped to parts over the whole set ([`matched_scores`]).
fn score_regions(
    names: &[String],
    shapes: &[Scored],
    correspondence_ratio: Option<f64>,
) -> Result<FolderScores, EvaluateError> {
    let pairs: Vec<(Vec<i32>, Vec<i32>)> = shapes
        .iter()
        .map(|(_, found, t)| (found.clone(), t.vertices.clone()))
        .collect();
    let m = matched_scores(&pairs)?;
    let per_shape: Vec<ShapeScores> = names
        .iter()
        .zip(&m.per_shape)
        .map(|(name, &(accuracy, rand_index))| ShapeScores {
            name: name.clone(),
            source: false,
            accuracy,
            rand_index,
            mean_iou: None,
        })
        .collect();
    Ok(FolderScores {
        kind: ResultKind::Regions,
        mean_rand_index: mean(per_shape.iter().map(|s| s.rand_index)),
        shapes: per_shape,
        accuracy: m.accuracy,
        part_iou: m.part_iou,
        mean_iou: m.mean_iou,
        mapping: m.mapping,
        correspondence_ratio,
    })
}

/// Labels compared as they are, per shape ([`label_agreement`]); sources left out of the means.
fn score_labels(
    result: &Path,
    sources: &[String],
    shapes: &[Scored],
    correspondence_ratio: Option<f64>,
) -> Result<FolderScores, EvaluateError> {
    let mut per_shape = Vec::with_capacity(shapes.len());
    let mut ious: BTreeMap<i32, Vec<f64>> = BTreeMap::new();
    for (name, found, t) in shapes {
        let a = t.agreement(found).map_err(|e| rename(e, name))?;
        let source = sources.contains(name);
        if !source {
            let true_labels = t.labels();
            for p in a.parts.iter().filter(|p| true_labels.contains(&p.label)) {
                ious.entry(p.label).or_default().push(p.iou);
            }
        }
        let truth_v = &t.vertices;
        let scored: Vec<usize> = (0..truth_v.len()).filter(|&v| truth_v[v] >= 0).collect();
        let fv: Vec<i32> = scored.iter().map(|&v| found[v]).collect();
        let tv: Vec<i32> = scored.iter().map(|&v| truth_v[v]).collect();
        per_shape.push(ShapeScores {
            name: name.clone(),
            source,
            accuracy: a.accuracy,
            rand_index: super::rand_index(&fv, &tv).map_err(|e| rename(e, name))?,
            mean_iou: Some(a.mean_iou),
        });
    }
    let scored: Vec<&ShapeScores> = per_shape.iter().filter(|s| !s.source).collect();
    if scored.is_empty() {
        return Err(EvaluateError::Empty(format!(
            "{}: every shape is a source",
            result.display()
        )));
    }
    let part_iou: BTreeMap<i32, f64> = ious
        .into_iter()
        .map(|(l, v)| (l, mean(v.into_iter())))
        .collect();
    Ok(FolderScores {
        kind: ResultKind::Labels,
        accuracy: mean(scored.iter().map(|s| s.accuracy)),
        mean_rand_index: mean(scored.iter().map(|s| s.rand_index)),
        mean_iou: mean(part_iou.values().copied()),
        part_iou,
        shapes: per_shape,
        mapping: BTreeMap::new(),
        correspondence_ratio,
    })
}

/// Ground truth of one shape: per vertex always; per face too when it came from a `.seg` file.
struct Truth {
    vertices: Vec<i32>,
    faces: Option<(TriMesh, Vec<i32>)>,
    vertex_areas: Option<Vec<f64>>,
}

impl Truth {
    fn labels(&self) -> std::collections::BTreeSet<i32> {
        match &self.faces {
            Some((_, f)) => f.iter().copied().filter(|&l| l >= 0).collect(),
            None => self.vertices.iter().copied().filter(|&l| l >= 0).collect(),
        }
    }

    fn agreement(&self, found: &[i32]) -> Result<LabelAgreement, EvaluateError> {
        match (&self.faces, &self.vertex_areas) {
            (Some((mesh, faces)), _) => {
                let predicted = vertices_to_faces(mesh, found).map_err(shape_error)?;
                label_agreement(&finite_face_areas(mesh), faces, &predicted)
            }
            (None, Some(areas)) => label_agreement(areas, &self.vertices, found),
            // Without a mesh every vertex weighs the same.
            (None, None) => label_agreement(&vec![1.0; found.len()], &self.vertices, found),
        }
    }
}

fn shape_error(e: crate::labels::LabelError) -> EvaluateError {
    EvaluateError::Shape {
        shape: "0".into(),
        message: e.to_string(),
    }
}

fn rename(e: EvaluateError, name: &str) -> EvaluateError {
    match e {
        EvaluateError::Shape { message, .. } => EvaluateError::Shape {
            shape: name.to_string(),
            message,
        },
        other => other,
    }
}

fn read_truth(
    truth: &Path,
    mesh_path: &Path,
    name: &str,
    vertices: usize,
) -> Result<Truth, EvaluateError> {
    let mesh = || {
        read_mesh(mesh_path).map_err(|e| EvaluateError::Shape {
            shape: name.to_string(),
            message: format!("{} (its faces are needed): {e}", mesh_path.display()),
        })
    };
    let length = |what: &str, path: &Path, got: usize, expected: usize| EvaluateError::Shape {
        shape: name.to_string(),
        message: format!("{}: {got} labels for {expected} {what}", path.display()),
    };
    let per_vertex = truth.join(format!("{name}.labels.txt"));
    if per_vertex.is_file() {
        let labels = read_labels(&per_vertex)?;
        if labels.len() != vertices {
            return Err(length("vertices", &per_vertex, labels.len(), vertices));
        }
        let vertex_areas = mesh_path
            .is_file()
            .then(|| mesh().map(|m| m.vertex_areas()))
            .transpose()?;
        return Ok(Truth {
            vertices: labels,
            faces: None,
            vertex_areas,
        });
    }
    let seg = truth.join(format!("{name}.seg"));
    if seg.is_file() {
        let mesh = mesh()?;
        let labels = read_labels(&seg)?;
        if labels.len() != mesh.face_count() {
            return Err(length("faces", &seg, labels.len(), mesh.face_count()));
        }
        if mesh.vertex_count() != vertices {
            return Err(length("vertices", mesh_path, vertices, mesh.vertex_count()));
        }
        let per_vertex =
            faces_to_vertices(&mesh, &labels).map_err(|e| rename(shape_error(e), name))?;
        return Ok(Truth {
            vertices: per_vertex,
            faces: Some((mesh, labels)),
            vertex_areas: None,
        });
    }
    Err(EvaluateError::Shape {
        shape: name.to_string(),
        message: format!(
            "no ground truth ({} or {})",
            per_vertex.display(),
            seg.display()
        ),
    })
}

/// Names `summary.json` lists under `sources` (propagation results), empty otherwise.
fn read_sources(result: &Path) -> Result<Vec<String>, EvaluateError> {
    let path = result.join("summary.json");
    let Ok(text) = std::fs::read_to_string(&path) else {
        return Ok(Vec::new());
    };
    let value: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| EvaluateError::BadManifest {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
    Ok(value["sources"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|s| s.as_str().map(str::to_string))
                .collect()
        })
        .unwrap_or_default())
}

/// `Cor = |{p : found_a[p] ≥ 0, L(p) exists, found_b[L(p)] = found_a[p]}| / |{p : L(p) exists}|`.
fn correspondence_ratio(
    a: &[i32],
    b: &[i32],
    map: &CorrespondenceMap,
) -> Result<f64, EvaluateError> {
    let image: Vec<Option<usize>> = match map {
        CorrespondenceMap::Identity => (0..a.len()).map(|p| (p < b.len()).then_some(p)).collect(),
        CorrespondenceMap::File(path) => {
            let raw = read_labels(path)?;
            if raw.len() != a.len() {
                return Err(EvaluateError::Shape {
                    shape: path.display().to_string(),
                    message: format!("{} entries for {} vertices", raw.len(), a.len()),
                });
            }
            raw.iter()
                .map(|&q| (q >= 0 && (q as usize) < b.len()).then_some(q as usize))
                .collect()
        }
    };
    let mapped = image.iter().filter(|q| q.is_some()).count();
    let good = a
        .iter()
        .zip(&image)
        .filter(|(r, q)| **r >= 0 && q.is_some_and(|q| b[q] == **r))
        .count();
    Ok(if mapped == 0 {
        0.0
    } else {
        good as f64 / mapped as f64
    })
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 { 0.0 } else { sum / n as f64 }
}
