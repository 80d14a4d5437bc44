//! [`run_propagate`]: `coseg propagate FOLDER --labels … -o OUT` (and Python's
//! `coseg.propagate`) as a library call.

use super::{CacheChoice, JobError, JobShape};
use crate::cache::CacheOutcome;
use crate::labels::{LabelKind, PartNames, read_part_names, read_shape_labels};
use crate::mesh::TriMesh;
use crate::output::{PropagationSummary, write_propagation, write_visuals};
use crate::propagate::{
    PropagateCollectionOptions, PropagateError, PropagatedCollection, SourceFile,
    propagate_collection, propagate_loaded,
};
use crate::render::{RenderOptions, RenderShape, collection_views_or_own};
use rayon::prelude::*;
use std::path::PathBuf;

/// The `label_file` a source given as an array has in `summary.json`.
pub const ARRAY_SOURCE: &str = "<array>";

/// One shape's annotation given to [`run_propagate`] with shapes in memory.
#[derive(Debug, Clone, PartialEq)]
pub enum JobLabels {
    /// The shape is not labelled.
    None,
    /// A label per vertex (`-1` or any negative value: unlabelled vertex).
    Vertex(Vec<i64>),
    /// A label file: `<stem>.seg` per face, `<stem>.labels.txt` per vertex.
    File(PathBuf),
}

/// What [`run_propagate`] works on.
#[derive(Debug, Clone)]
pub enum PropagateInput {
    /// Every mesh file directly in `folder`; `labels` are folders (label files matched to the
    /// meshes by stem) or label files, as `coseg propagate FOLDER --labels …` takes them.
    Folder {
        /// The folder of meshes.
        folder: PathBuf,
        /// Label folders or files.
        labels: Vec<PathBuf>,
    },
    /// Shapes from files or in memory, each with its annotation (one entry per shape).
    Shapes {
        /// The shapes, in the order of the results.
        shapes: Vec<JobShape>,
        /// One annotation per shape.
        labels: Vec<JobLabels>,
        /// Part names, used when [`PropagateCollectionOptions::part_names`] names no file.
        part_names: PartNames,
    },
}

/// Options of [`run_propagate`]; `Default` is `coseg propagate`'s default.
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct PropagateJob {
    /// The per-shape stage, the shape graph, the solver, the routes, the map step and the
    /// part-names file ([`PropagateCollectionOptions::default`]). Its `cache_dir` is not read:
    /// [`PropagateJob::cache`] decides.
    pub propagation: PropagateCollectionOptions,
    /// The per-shape cache (default [`CacheChoice::Auto`]: `<output>/.cache`; with no output, a
    /// folder input uses `coseg-cache` in the system's temporary folder and shapes in memory
    /// are computed without a cache).
    pub cache: CacheChoice,
    /// Folder for `<name>.labels.txt`, `<name>.seg`, `<name>.labels.ply` and `summary.json`
    /// (and with [`PropagateJob::pictures`] the pictures and viewer page), created if missing;
    /// `None` (default): nothing is written.
    pub output: Option<PathBuf>,
    /// Draw `preview.png`, `<name>.png` and `index.html` into the output folder (default
    /// false here; `coseg propagate` turns it on unless `--no-pictures`).
    pub pictures: bool,
}

/// What [`run_propagate`] found and wrote.
#[derive(Debug)]
#[non_exhaustive]
pub struct PropagateOutcome {
    /// The labels, confidences, shape graph, sources, routes and warnings.
    pub result: PropagatedCollection,
    /// `summary.json`'s content.
    pub summary: PropagationSummary,
    /// Where each shape's data came from (graph order; `None`: computed without a cache).
    pub cache_outcomes: Vec<Option<CacheOutcome>>,
    /// The files written.
    pub written: Vec<PathBuf>,
}

/// Part labels from a few annotated shapes to all the others, from the inputs to the written
/// result: the per-shape stage of every shape (through the cache), the annotations, the
/// propagation with its routes ([`propagate_collection`] for a folder, [`propagate_loaded`]
/// for shapes), `summary.json`, the label files and, if asked, the pictures.
///
/// - `input`: a folder with label folders/files, or shapes with one annotation each;
/// - returns the [`PropagateOutcome`]; nothing is written when `output` is `None`.
///
/// Errors: [`JobError::Invalid`] for annotations that do not fit their shapes (naming the
/// shape) or options that need a folder; [`JobError::Shape`] / [`JobError::Mesh`] naming the
/// shape whose per-shape stage or file failed; [`JobError::Stage`] when the propagation fails
/// (no labelled vertex, no readable mesh, bad options); [`JobError::Output`] when writing fails.
///
/// See also: [`propagate_collection`], [`propagate_loaded`], the stage alone;
/// [`crate::propagate::Propagation::update`] for the incremental mode.
pub fn run_propagate(
    input: PropagateInput,
    job: &PropagateJob,
) -> Result<PropagateOutcome, JobError> {
    let cache = job.cache.resolve(job.output.as_deref());
    let mut options = job.propagation.clone();
    options.cache_dir = cache.clone();
    let stage = |context: String| {
        move |e: PropagateError| JobError::Stage {
            context,
            source: Box::new(e),
        }
    };
    let (mut result, cache_outcomes) = match input {
        PropagateInput::Folder { folder, labels } => {
            let context = format!("propagating labels over {}", folder.display());
            let result =
                propagate_collection(&folder, &labels, &options).map_err(stage(context))?;
            let outcomes = result.outcomes.iter().cloned().map(Some).collect();
            (result, outcomes)
        }
        PropagateInput::Shapes {
            shapes,
            labels,
            part_names,
        } => {
            if options.map_step.is_some() {
                return Err(JobError::Invalid(
                    "map_step: the map step needs the shapes' spectra from a folder's cache; \
                     give a folder, not shapes in memory"
                        .into(),
                ));
            }
            let part_names = match &options.part_names {
                Some(p) => read_part_names(p)?,
                None => part_names,
            };
            propagate_shapes(shapes, labels, part_names, cache.as_deref(), &options)?
        }
    };
    if result.graph.node_count() == 0 {
        return Err(JobError::Invalid("no readable mesh".into()));
    }
    let summary = PropagationSummary::of(&result, &options.graph, &options.propagate);
    let mut written = Vec::new();
    if let Some(dir) = &job.output {
        let timer = crate::stage_timer::stage("writing labels");
        written = write_propagation(dir, &result, &summary)?;
        drop(timer);
        if job.pictures {
            let _t = crate::stage_timer::stage("pictures");
            // The propagation's own collection alignment (its rigid route's, made once).
            let alignment = result.propagation.rigid.alignment(&result.meshes);
            let (views, warning) = collection_views_or_own(&result.meshes, Some(&alignment));
            result.warnings.extend(warning);
            let p = &result.propagation;
            let pictures: Vec<RenderShape> = (0..result.graph.node_count())
                .map(|i| RenderShape {
                    name: &result.graph.node(i).name,
                    mesh: &result.meshes[i],
                    labels: &p.labels[i],
                    confidence: Some(p.shape_confidence[i]),
                    view: Some(views[i]),
                })
                .collect();
            let names = legend_names(&p.parts, &result.part_names);
            written.extend(write_visuals(
                dir,
                &pictures,
                (!result.part_names.is_empty()).then_some(names.as_slice()),
                &RenderOptions::default(),
            )?);
        }
    }
    Ok(PropagateOutcome {
        result,
        summary,
        cache_outcomes,
        written,
    })
}

/// Shapes in memory: annotations first (bad labels fail before the per-shape stage runs),
/// then every shape through the per-shape stage side by side, then [`propagate_loaded`].
fn propagate_shapes(
    shapes: Vec<JobShape>,
    labels: Vec<JobLabels>,
    part_names: PartNames,
    cache: Option<&std::path::Path>,
    options: &PropagateCollectionOptions,
) -> Result<(PropagatedCollection, Vec<Option<CacheOutcome>>), JobError> {
    if labels.len() != shapes.len() {
        return Err(JobError::Invalid(format!(
            "{} label entries for {} shapes (give None for an unlabelled shape)",
            labels.len(),
            shapes.len()
        )));
    }
    let names: Vec<String> = shapes.iter().map(JobShape::name).collect();
    let files: Vec<String> = shapes.iter().map(JobShape::file).collect();
    // Meshes first, then the annotations: bad labels fail before the per-shape stage runs.
    let read: Vec<_> = shapes.into_par_iter().map(JobShape::read).collect();
    let mut shapes = Vec::with_capacity(read.len());
    let mut warnings = Vec::new();
    for r in read {
        let (name, file, mesh, w) = r?;
        warnings.extend(w);
        shapes.push((name, file, mesh));
    }
    let meshes: Vec<&TriMesh> = shapes.iter().map(|(_, _, m)| m).collect();
    let (annotations, sources, w) = annotations_of(&names, &meshes, labels)?;
    if sources.is_empty() {
        return Err(JobError::Stage {
            context: "propagating labels".into(),
            source: Box::new(PropagateError::NoLabels),
        });
    }
    let loaded = super::load_read(shapes, &options.pipeline, cache)?;
    warnings.extend(loaded.warnings);
    warnings.extend(w);
    let (meshes, nodes, outcomes) = (loaded.meshes, loaded.nodes, loaded.outcomes);
    let solved =
        propagate_loaded(nodes, &meshes, &annotations, options).map_err(|e| JobError::Stage {
            context: "propagating labels".into(),
            source: Box::new(e),
        })?;
    warnings.extend(solved.warnings);
    let n = meshes.len();
    let result = PropagatedCollection {
        paths: files.iter().map(PathBuf::from).collect(),
        meshes,
        graph: solved.graph,
        smoothers: solved.smoothers,
        propagation: solved.propagation,
        sources,
        part_names,
        skipped: Vec::new(),
        // Shapes in memory: the job's `cache_outcomes` say where their data came from.
        outcomes: Vec::new(),
        map_steps: vec![None; n],
        map_step: None,
        map_routes: solved.map_route,
        fusion: solved.fusion,
        warnings,
    };
    Ok((result, outcomes))
}

/// Per-shape vertex labels (`None`: unannotated), the sources among them, and warnings.
type Annotations = (Vec<Option<Vec<i32>>>, Vec<SourceFile>, Vec<String>);

/// The annotations of the shapes (per vertex, `-1` = unlabelled) and the sources among them,
/// or the error naming the shape whose labels do not fit it. An annotation without a labelled
/// vertex is not used (a warning), as `coseg propagate` treats such a file.
fn annotations_of(
    names: &[String],
    meshes: &[&TriMesh],
    inputs: Vec<JobLabels>,
) -> Result<Annotations, JobError> {
    let mut annotations = Vec::with_capacity(names.len());
    let mut sources = Vec::new();
    let mut warnings = Vec::new();
    for (i, ((name, mesh), input)) in names.iter().zip(meshes).zip(inputs).enumerate() {
        let (labels, path, kind) = match input {
            JobLabels::None => {
                annotations.push(None);
                continue;
            }
            JobLabels::File(path) => {
                let l = read_shape_labels(&path, mesh, name)?;
                (l.vertex_labels, path, l.kind)
            }
            JobLabels::Vertex(a) => {
                let d = mesh.vertex_count();
                if a.len() != d {
                    return Err(JobError::Invalid(format!(
                        "labels of shape {i} ({name}): {} labels for a mesh of {d} vertices",
                        a.len()
                    )));
                }
                let mut labels = Vec::with_capacity(d);
                for (v, &x) in a.iter().enumerate() {
                    let l = i32::try_from(x).map_err(|_| {
                        JobError::Invalid(format!(
                            "labels of shape {i} ({name}): vertex {v} has label {x}, outside \
                             the 32-bit label range"
                        ))
                    })?;
                    labels.push(l.max(-1));
                }
                (labels, PathBuf::from(ARRAY_SOURCE), LabelKind::Vertex)
            }
        };
        if labels.iter().all(|&l| l < 0) {
            warnings.push(format!("{name}: no labelled vertex, not used"));
            annotations.push(None);
            continue;
        }
        sources.push(SourceFile {
            shape: i,
            path,
            kind,
        });
        annotations.push(Some(labels));
    }
    Ok((annotations, sources, warnings))
}

/// Legend text per label value `0..=max`: the part's name when given, else empty (the legend
/// then shows the bare label).
fn legend_names(parts: &[i32], names: &PartNames) -> Vec<String> {
    let max = parts.iter().copied().max().unwrap_or(-1).max(-1);
    (0..=max)
        .map(|l| names.get(&l).cloned().unwrap_or_default())
        .collect()
}
