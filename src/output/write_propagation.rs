//! [`write_propagation`]: label files, coloured meshes and `summary.json` of a propagation.

use super::{OutputError, region_colors, write_summary};
use crate::graph::GraphOptions;
use crate::labels::{LabelKind, vertices_to_faces, write_face_labels, write_vertex_labels};
use crate::mesh::{PlyVertexProperty, write_mesh};
use crate::propagate::{
    ClassifierShape, MapStepOptions, MapStepReport, PropagateOptions, PropagatedCollection,
};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// One part in the `summary.json` of a propagation.
#[derive(Debug, Clone, Serialize)]
pub struct PropagatedPart {
    /// The label.
    pub label: i32,
    /// Its name from the part-names file, if any.
    pub name: Option<String>,
    /// Share of the shape's area (per shape) or mean share over shapes (collection).
    pub area_fraction: f64,
    /// Area-weighted mean per-vertex confidence over the part's vertices.
    pub confidence: f64,
}

/// One shape in the `summary.json` of a propagation.
#[derive(Debug, Clone, Serialize)]
pub struct PropagatedShape {
    /// Output name (file stem).
    pub name: String,
    /// Input mesh file.
    pub file: String,
    /// Vertex count.
    pub vertices: usize,
    /// The annotation file when the shape is a source.
    pub label_file: Option<String>,
    /// `"vertex"` or `"face"` for a source.
    pub label_kind: Option<LabelKind>,
    /// Area-weighted mean per-vertex confidence.
    pub confidence: f64,
    /// Per part present in the collection.
    pub parts: Vec<PropagatedPart>,
    /// What the map step did (only with `--map-step`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub map_step: Option<MapStepReport>,
    /// The name of the source the map step mapped this shape to.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub map_source: Option<String>,
    /// What the map route of the fusion did (a point map to `source`, its agreement with the
    /// fused labels, and whether the shape took the vote with the map:
    /// [`crate::propagate::map_route`]); absent where the route did not run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub map_route: Option<MapStepReport>,
    /// What the classifier refinement did on the shape (the area shares where the routes
    /// disagree and where it changed the fused label: [`crate::propagate::classifier_route`]);
    /// absent where it did not run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub classifier: Option<ClassifierShape>,
}

/// `summary.json` of `coseg propagate`: no timings, so reruns give the same bytes.
#[derive(Debug, Clone, Serialize)]
pub struct PropagationSummary {
    /// Always `"propagate"`.
    pub command: &'static str,
    /// The coseg version that wrote the file.
    pub version: &'static str,
    /// Names of the source shapes.
    pub sources: Vec<String>,
    /// Every shape, graph order.
    pub shapes: Vec<PropagatedShape>,
    /// Every part over the collection (mean area share and confidence over the shapes).
    pub parts: Vec<PropagatedPart>,
    /// Sweeps of the solver and whether the last changed nothing.
    pub sweeps: usize,
    /// Whether the last sweep changed no label.
    pub converged: bool,
    /// Mesh files skipped, with the reason.
    pub skipped: Vec<String>,
    /// The solver's options.
    pub options: PropagateOptions,
    /// The graph's options.
    pub graph: GraphOptions,
    /// The map step's options (only with `--map-step`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub map_step: Option<MapStepOptions>,
}

impl PropagationSummary {
    /// The summary of `c`.
    pub fn of(c: &PropagatedCollection, graph: &GraphOptions, options: &PropagateOptions) -> Self {
        let p = &c.propagation;
        let name_of = |l: i32| c.part_names.get(&l).cloned();
        let n = c.graph.node_count();
        let shapes: Vec<PropagatedShape> = (0..n)
            .map(|i| {
                let src = c.sources.iter().find(|s| s.shape == i);
                PropagatedShape {
                    name: c.graph.node(i).name.clone(),
                    file: c.paths[i].display().to_string(),
                    vertices: c.graph.node(i).bands.vertices,
                    label_file: src.map(|s| s.path.display().to_string()),
                    label_kind: src.map(|s| s.kind),
                    confidence: p.shape_confidence[i],
                    parts: p
                        .parts
                        .iter()
                        .enumerate()
                        .map(|(r, &l)| PropagatedPart {
                            label: l,
                            name: name_of(l),
                            area_fraction: p.part_shares[i][r],
                            confidence: p.part_confidence[i][r],
                        })
                        .collect(),
                    map_step: c.map_steps.get(i).cloned().flatten(),
                    map_source: c
                        .map_steps
                        .get(i)
                        .and_then(|r| r.as_ref())
                        .map(|r| c.graph.node(r.source).name.clone()),
                    map_route: c.map_routes.get(i).cloned().flatten(),
                    classifier: c
                        .fusion
                        .classifier
                        .as_ref()
                        .and_then(|r| r.shapes.get(i).copied().flatten()),
                }
            })
            .collect();
        let parts = p
            .parts
            .iter()
            .enumerate()
            .map(|(r, &l)| {
                let present: Vec<usize> = (0..n).filter(|&i| p.part_shares[i][r] > 0.0).collect();
                let k = present.len().max(1) as f64;
                PropagatedPart {
                    label: l,
                    name: name_of(l),
                    area_fraction: (0..n).map(|i| p.part_shares[i][r]).sum::<f64>() / n as f64,
                    confidence: present
                        .iter()
                        .map(|&i| p.part_confidence[i][r])
                        .sum::<f64>()
                        / k,
                }
            })
            .collect();
        PropagationSummary {
            command: "propagate",
            version: env!("CARGO_PKG_VERSION"),
            sources: c
                .sources
                .iter()
                .map(|s| c.graph.node(s.shape).name.clone())
                .collect(),
            shapes,
            parts,
            sweeps: p.sweeps,
            converged: p.converged,
            skipped: c
                .skipped
                .iter()
                .map(|s| format!("{}: {}", s.path.display(), s.error))
                .collect(),
            options: options.clone(),
            graph: *graph,
            map_step: c.map_step.clone(),
        }
    }
}

/// Writes into `dir` (created if missing), for every shape, `<name>.labels.txt` (per vertex),
/// `<name>.seg` (per face, [`vertices_to_faces`]) and `<name>.labels.ply` (coloured by label,
/// integer `label` vertex property), then `summary.json`. Every file is written atomically.
/// Returns the written paths.
///
/// See also [`crate::propagate::propagate_collection`], which makes `c`; docs/OUTPUTS.md
/// describes the files.
pub fn write_propagation(
    dir: &Path,
    c: &PropagatedCollection,
    summary: &PropagationSummary,
) -> Result<Vec<PathBuf>, OutputError> {
    std::fs::create_dir_all(dir).map_err(|source| {
        OutputError::Io(crate::FileError {
            path: dir.display().to_string(),
            source,
        })
    })?;
    let mut out = Vec::new();
    for i in 0..c.graph.node_count() {
        let name = &c.graph.node(i).name;
        let labels = &c.propagation.labels[i];
        out.push(write_vertex_labels(dir, name, labels)?);
        out.push(write_face_labels(
            dir,
            name,
            &vertices_to_faces(&c.meshes[i], labels)?,
        )?);
        let ply = dir.join(format!("{name}.labels.ply"));
        write_mesh(
            &ply,
            &c.meshes[i],
            &[
                PlyVertexProperty::Color(region_colors(labels)),
                PlyVertexProperty::Int("label".into(), labels.clone()),
            ],
        )?;
        out.push(ply);
    }
    out.push(write_summary(dir, summary)?);
    Ok(out)
}
