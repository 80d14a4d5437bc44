//! Jobs: a command's whole run — inputs, options, result, files — as one library call, so that
//! the command line and the Python package only translate arguments and present results.
//!
//! Entry points:
//! - [`run_pair`]`([`[`JobShape`]`; 2], &`[`PairJob`]`) -> Result<`[`PairOutcome`]`, `[`JobError`]`>`:
//!   `coseg pair` and `coseg.pair`;
//! - [`run_propagate`]`(`[`PropagateInput`]`, &`[`PropagateJob`]`) -> Result<`[`PropagateOutcome`]`, `[`JobError`]`>`:
//!   `coseg propagate` and `coseg.propagate` (a folder with label files, or shapes with one
//!   annotation each, [`JobLabels`]);
//! - [`run_eval`]`(result, truth, &`[`EvalJob`]`) -> Result<`[`FolderScores`](crate::evaluate::FolderScores)`, `[`JobError`]`>`:
//!   `coseg eval`;
//! - [`run_align`]`(folder, &`[`AlignJob`]`) -> Result<`[`AlignOutcome`]`, `[`JobError`]`>`:
//!   `coseg align`;
//! - [`run_segment`]`(`[`SegmentInput`]`, &`[`SegmentJob`]`) -> Result<`[`SegmentOutcome`]`, `[`JobError`]`>`:
//!   `coseg segment` and `coseg.segment`;
//! - [`defaults`]: every job's default by keyword, as the front ends name their options.
//!
//! Each job's options struct is `#[non_exhaustive]`, and its `Default` is the command's
//! default: `coseg pair A B -o OUT` with no other flag runs `PairJob { output: Some(OUT),
//! ..PairJob::default() }`. Shapes are given as files or as meshes already in memory
//! ([`JobShape`]); both go through the one per-shape loader
//! ([`load_shape`](crate::pipeline::load_shape),
//! [`load_shape_from_mesh`](crate::pipeline::load_shape_from_mesh)) with the same warnings.

mod align_job;
mod defaults;
mod eval_job;
mod pair_job;
mod propagate_job;
mod segment_job;

pub use align_job::{AlignJob, AlignOutcome, run_align};
pub use defaults::defaults;
pub use eval_job::{EvalJob, run_eval};
pub use pair_job::{PairJob, PairOutcome, run_pair};
pub use propagate_job::{
    ARRAY_SOURCE, JobLabels, PropagateInput, PropagateJob, PropagateOutcome, run_propagate,
};
pub use segment_job::{
    SegmentInput, SegmentJob, SegmentOutcome, SegmentProgress, run_segment,
    run_segment_with_progress,
};

use crate::cache::CacheOutcome;
use crate::graph::ShapeNode;
use crate::mesh::TriMesh;
use crate::pipeline::{LoadedShape, PipelineError, ShapeBands, ShapeContent, ShapePipelineOptions};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Errors of a job: each names the file or the shape concerned.
#[derive(Debug, Error)]
pub enum JobError {
    /// A shape's per-shape stage failed (or its mesh could not be read).
    #[error("{name}: {source}")]
    Shape {
        /// The shape's file, or its name when given in memory.
        name: String,
        /// The pipeline's error.
        #[source]
        source: PipelineError,
    },
    /// A mesh file could not be read (the message names the file).
    #[error(transparent)]
    Mesh(#[from] crate::mesh::MeshError),
    /// The stage itself failed on these shapes.
    #[error("{context}: {source}")]
    Stage {
        /// The shapes concerned (`A x B`).
        context: String,
        /// The stage's error.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// A label or part-names file could not be read, or does not fit its shape (the message
    /// names the file).
    #[error(transparent)]
    Labels(#[from] crate::labels::LabelError),
    /// Writing the outputs failed.
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    /// The alignment failed, or its files could not be read or written (the message names
    /// the file).
    #[error(transparent)]
    Align(#[from] crate::align::AlignError),
    /// The co-segmentation failed or refused its options.
    #[error(transparent)]
    Graph(#[from] crate::graph::GraphError),
    /// Input files could not be used, and the job was asked to fail rather than skip them
    /// ([`SegmentJob::strict`]).
    #[error("{} input file(s) could not be used: {}", .0.len(), .0.iter().map(|s| s.error.as_str()).collect::<Vec<_>>().join("; "))]
    Skipped(Vec<crate::output::SkippedInput>),
    /// Invalid inputs or options (e.g. two shapes with one name).
    #[error("{0}")]
    Invalid(String),
}

/// A shape given to a job.
#[derive(Debug, Clone)]
pub enum JobShape {
    /// A mesh file (.obj, .off, .ply), read by the job; its stem names the shape.
    File(PathBuf),
    /// A mesh already in memory.
    Mesh {
        /// The shape's name (output file stem).
        name: String,
        /// The file it came from, when known: resolves user features and prefixes warnings
        /// (the name otherwise).
        file: Option<PathBuf>,
        /// The mesh.
        mesh: TriMesh,
    },
}

impl JobShape {
    /// The shape's name: the file's stem, or the given name.
    pub fn name(&self) -> String {
        match self {
            JobShape::File(p) => p
                .file_stem()
                .map_or_else(|| "shape".into(), |s| s.to_string_lossy().into_owned()),
            JobShape::Mesh { name, .. } => name.clone(),
        }
    }

    /// The file the shape came from, or its name (what `summary.json` records and warnings
    /// name).
    pub fn file(&self) -> String {
        match self {
            JobShape::File(p) => p.display().to_string(),
            JobShape::Mesh { name, file, .. } => file
                .as_ref()
                .map_or_else(|| name.clone(), |f| f.display().to_string()),
        }
    }

    /// The shape's name, the file it came from (when known) and its mesh: a file is read
    /// (its reader's warnings returned, prefixed by its path), a mesh is returned as it is.
    fn read(self) -> Result<ReadShape, JobError> {
        let name = self.name();
        match self {
            JobShape::File(path) => {
                let (mesh, report) = crate::mesh::read_mesh_with_report(&path)?;
                let warnings = report
                    .warnings
                    .iter()
                    .map(|w| format!("{}: {w}", path.display()))
                    .collect();
                Ok((name, Some(path), mesh, warnings))
            }
            JobShape::Mesh { file, mesh, .. } => Ok((name, file, mesh, Vec::new())),
        }
    }

    /// The shape through the per-shape stage (and `cache`).
    fn load<T: ShapeContent>(
        self,
        pipeline: &ShapePipelineOptions,
        cache: Option<&Path>,
    ) -> Result<LoadedShape<T>, JobError> {
        let name = self.file();
        match self {
            JobShape::File(path) => crate::pipeline::load_shape(&path, pipeline, cache),
            JobShape::Mesh { name, file, mesh } => {
                // A trailing dot: the whole name is the stem, even with dots in it.
                let path = file.unwrap_or_else(|| PathBuf::from(format!("{name}.")));
                crate::pipeline::load_shape_from_mesh(mesh, &path, pipeline, cache)
            }
        }
        .map_err(|source| match source {
            PipelineError::Mesh(e) => JobError::Mesh(e),
            source => JobError::Shape { name, source },
        })
    }
}

/// A shape read by [`JobShape::read`]: name, file, mesh, the reader's warnings.
type ReadShape = (String, Option<PathBuf>, TriMesh, Vec<String>);

/// Where a job keeps its per-shape cache.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum CacheChoice {
    /// `<output>/.cache` when the job writes an output folder, no cache otherwise (default).
    #[default]
    Auto,
    /// This folder (read if valid, written otherwise).
    Dir(PathBuf),
    /// Compute everything, read and write nothing.
    Off,
}

impl CacheChoice {
    /// The cache folder for a job writing to `output`.
    pub fn resolve(&self, output: Option<&Path>) -> Option<PathBuf> {
        match self {
            CacheChoice::Auto => output.map(|o| o.join(".cache")),
            CacheChoice::Dir(d) => Some(d.clone()),
            CacheChoice::Off => None,
        }
    }
}

/// Shapes through the per-shape stage: their meshes and graph nodes, where each shape's data
/// came from, and the warnings (the meshes', the cache's).
struct LoadedNodes {
    meshes: Vec<TriMesh>,
    nodes: Vec<ShapeNode>,
    outcomes: Vec<Option<CacheOutcome>>,
    warnings: Vec<String>,
}

/// Every shape read and through the per-shape stage side by side (through `cache` when given);
/// the first error, naming its shape, stops the job.
fn load_nodes(
    shapes: Vec<JobShape>,
    pipeline: &ShapePipelineOptions,
    cache: Option<&Path>,
) -> Result<LoadedNodes, JobError> {
    let read: Vec<_> = shapes.into_par_iter().map(JobShape::read).collect();
    let mut warnings = Vec::new();
    let mut meshes = Vec::with_capacity(read.len());
    for r in read {
        let (name, file, mesh, w) = r?;
        warnings.extend(w);
        meshes.push((name, file, mesh));
    }
    let mut loaded = load_read(meshes, pipeline, cache)?;
    warnings.append(&mut loaded.warnings);
    loaded.warnings = warnings;
    Ok(loaded)
}

/// Shapes already read ([`JobShape::read`]: name, file, mesh) through the per-shape stage side
/// by side (through `cache` when given).
fn load_read(
    shapes: Vec<(String, Option<PathBuf>, TriMesh)>,
    pipeline: &ShapePipelineOptions,
    cache: Option<&Path>,
) -> Result<LoadedNodes, JobError> {
    let names: Vec<(String, String)> = shapes
        .iter()
        .map(|(name, file, _)| {
            let file = file
                .as_ref()
                .map_or_else(|| name.clone(), |f| f.display().to_string());
            (name.clone(), file)
        })
        .collect();
    let loaded: Vec<_> = shapes
        .into_par_iter()
        .map(|(name, file, mesh)| {
            JobShape::Mesh { name, file, mesh }.load::<ShapeBands>(pipeline, cache)
        })
        .collect();
    let mut out = LoadedNodes {
        meshes: Vec::with_capacity(loaded.len()),
        nodes: Vec::with_capacity(loaded.len()),
        outcomes: Vec::with_capacity(loaded.len()),
        warnings: Vec::new(),
    };
    for (l, (name, file)) in loaded.into_iter().zip(names) {
        let l = l?;
        out.warnings.extend(l.warnings);
        out.outcomes.push(l.outcome);
        let node = ShapeNode::new(name, l.data.bands, &l.data.vertex_areas).map_err(|e| {
            JobError::Stage {
                context: file,
                source: Box::new(e),
            }
        })?;
        out.nodes.push(node);
        out.meshes.push(l.mesh);
    }
    Ok(out)
}
