//! [`run_segment`]: `coseg segment FOLDER -o OUT` (and Python's `coseg.segment`) as a library
//! call.

use super::{CacheChoice, JobError, JobShape, LoadedNodes, load_nodes};
use crate::cache::CacheOutcome;
use crate::graph::load_collection;
use crate::mesh::TriMesh;
use crate::output::{CollectionSummary, ShapeRegions, SkippedInput, write_regions, write_visuals};
use crate::parts::{
    PartsFrom, PartsRequest, SegmentCollectionOptions, SegmentedCollection, segment_collection,
    segment_collection_cached,
};
use crate::pipeline::{ShapePipelineOptions, shape_key};
use crate::render::{RenderOptions, RenderShape, collection_views_or_own};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// What [`run_segment`] works on.
#[derive(Debug, Clone)]
pub enum SegmentInput {
    /// Every mesh file directly in the folder, as `coseg segment FOLDER` reads it (files that
    /// cannot be used are skipped and reported).
    Folder(PathBuf),
    /// Shapes from files or in memory, in the order of the results.
    Shapes(Vec<JobShape>),
}

/// Options of [`run_segment`]; `Default` is `coseg segment`'s default: parts from geometry,
/// their number and the feature families chosen from the data.
///
/// The mode fields ([`SegmentJob::regions`], [`SegmentJob::parts`], [`SegmentJob::parts_from`])
/// are read as [`SegmentCollectionOptions::for_request`] reads them; they set the mode of
/// [`SegmentJob::collection`], which holds every other option of the collection stage.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct SegmentJob {
    /// The per-shape stage (default [`ShapePipelineOptions::default`]).
    pub pipeline: ShapePipelineOptions,
    /// Choose the feature families from the data (default true; `coseg segment` without
    /// `--features`); false: the families of [`SegmentJob::pipeline`] as given.
    pub choose_features: bool,
    /// Alone: that many equal-area regions per shape; with parts, the number of equal-area
    /// leaves (from geometry) or the upper bound on the number of parts (adaptive). Default
    /// `None`.
    pub regions: Option<usize>,
    /// How many parts (default `None`: [`PartsRequest::Auto`] when parts are made).
    pub parts: Option<PartsRequest>,
    /// Where the parts come from (default `None`: from geometry).
    pub parts_from: Option<PartsFrom>,
    /// How far a part boundary may move onto a concave crease, × √(shape area), with parts from
    /// geometry (default `None`: the parts' own band).
    pub snap_band: Option<f64>,
    /// The collection stage (default [`SegmentCollectionOptions::default`]): the shape graph,
    /// the co-segmentation (its area fraction, and its seed, which seeds the parts' tuples
    /// too), the starts, the boundary refinement and how it treats part sizes. Its mode
    /// (`cosegment.regions`, `parts`, `parts_from`) is the mode fields', its feature options
    /// the pipeline's ([`SegmentCollectionOptions::set_pipeline`]).
    pub collection: SegmentCollectionOptions,
    /// The per-shape cache (default [`CacheChoice::Auto`]: `<output>/.cache`; with no output,
    /// a folder uses `<folder>/.cache` and shapes in memory are computed without a cache).
    /// The part cues of parts from geometry are kept there too.
    pub cache: CacheChoice,
    /// Folder for `<name>.regions.txt`, `<name>.regions.ply` and `summary.json` (and with
    /// [`SegmentJob::pictures`] the pictures and viewer page), created if missing; `None`
    /// (default): nothing is written.
    pub output: Option<PathBuf>,
    /// Draw `preview.png`, `<name>.png` and `index.html` into the output folder (default
    /// false here; `coseg segment` turns it on unless `--no-pictures`).
    pub pictures: bool,
    /// Fail ([`JobError::Skipped`]) before co-segmenting when an input file cannot be used,
    /// instead of skipping it (default false; `coseg --strict`).
    pub strict: bool,
}

impl Default for SegmentJob {
    fn default() -> Self {
        Self {
            pipeline: ShapePipelineOptions::default(),
            choose_features: true,
            regions: None,
            parts: None,
            parts_from: None,
            snap_band: None,
            collection: SegmentCollectionOptions::default(),
            cache: CacheChoice::Auto,
            output: None,
            pictures: false,
            strict: false,
        }
    }
}

impl SegmentJob {
    /// The collection stage's options for nodes of `columns` feature columns, the part cues
    /// kept in `cue_cache`: [`SegmentJob::collection`] in the mode the mode fields select.
    ///
    /// Errors: [`JobError::Graph`] for a snap band without parts from geometry.
    pub fn collection_options(
        &self,
        columns: usize,
        cue_cache: Option<PathBuf>,
    ) -> Result<SegmentCollectionOptions, JobError> {
        let mode = SegmentCollectionOptions::for_request(self.regions, self.parts, self.parts_from);
        let mut o = self.collection.clone();
        o.cosegment.regions = mode.cosegment.regions;
        o.parts = mode.parts;
        o.parts_from = mode.parts_from;
        o.set_pipeline(&self.pipeline, !self.choose_features, columns);
        if let Some(p) = o.parts.as_mut() {
            p.seed = o.cosegment.seed;
        }
        if let Some(band) = self.snap_band {
            o.set_snap_band(band)?;
        }
        o.cue_cache = cue_cache;
        Ok(o)
    }
}

/// What [`run_segment`] found and wrote.
#[derive(Debug)]
#[non_exhaustive]
pub struct SegmentOutcome {
    /// The co-segmentation, its shape graph, times, part tree and choices.
    pub result: SegmentedCollection,
    /// The collection stage's options the job ran with.
    pub options: SegmentCollectionOptions,
    /// `summary.json`'s content.
    pub summary: CollectionSummary,
    /// The input file of each shape (graph order; a shape's name when given in memory).
    pub files: Vec<String>,
    /// The meshes (graph order).
    pub meshes: Vec<TriMesh>,
    /// The region of each vertex, per shape (graph order; the last region the leftovers).
    pub labels: Vec<Vec<i32>>,
    /// Files that could not be used.
    pub skipped: Vec<SkippedInput>,
    /// Where each shape's data came from (graph order; `None`: computed without a cache).
    pub cache_outcomes: Vec<Option<CacheOutcome>>,
    /// Where the part tree came from ([`crate::parts::segment_collection_cached`]):
    /// [`CacheOutcome::Hit`] when it was read from the cache and only re-cut; `None` without a
    /// cache or in a mode without a part tree (equal-area regions, adaptive parts).
    pub part_tree_cache: Option<CacheOutcome>,
    /// Warnings for the user: the meshes', the cache's, the stages', the parts'.
    pub warnings: Vec<String>,
    /// Time spent reading meshes and in the per-shape stage, summed over shapes (across
    /// threads: either can exceed the wall time).
    pub load_times: (Duration, Duration),
    /// Time spent writing the files.
    pub write_time: Duration,
    /// The files written.
    pub written: Vec<PathBuf>,
}

impl SegmentOutcome {
    /// How many files the job was given (used and skipped).
    pub fn total_files(&self) -> usize {
        self.files.len() + self.skipped.len()
    }
}

/// Where [`run_segment_with_progress`] is.
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub enum SegmentProgress<'a> {
    /// Reading a folder's meshes: `done` of `total`, now `file`.
    Shape {
        /// Shapes done.
        done: usize,
        /// Shapes in all.
        total: usize,
        /// The file being read.
        file: &'a Path,
    },
    /// A stage without steps has begun (`"co-segmentation and refinement"`, `"pictures"`).
    Stage(&'static str),
}

/// Consistent co-segmentation of a collection, from the inputs to the written result: the
/// per-shape stage of every shape (through the cache), [`crate::parts::segment_collection`]
/// (with a cache, through [`crate::parts::segment_collection_cached`]: a part tree grown by an
/// earlier run on the same shapes and options, whatever its number of parts, is only re-cut),
/// `summary.json`, the region files and, if asked, the pictures.
///
/// - `input`: a folder, or shapes;
/// - returns the [`SegmentOutcome`]; nothing is written when `output` is `None`.
///
/// Errors: [`JobError::Invalid`] for fewer than 2 usable shapes or bad options;
/// [`JobError::Skipped`] with [`SegmentJob::strict`]; [`JobError::Shape`] /
/// [`JobError::Mesh`] naming the shape whose per-shape stage or file failed (shapes given one
/// by one); [`JobError::Stage`] when reading the folder fails; [`JobError::Graph`] when the
/// co-segmentation fails or refuses its options;
/// [`JobError::Output`] when writing fails.
///
/// See also: [`crate::parts::segment_collection`], the stage alone.
pub fn run_segment(input: SegmentInput, job: &SegmentJob) -> Result<SegmentOutcome, JobError> {
    run_segment_with_progress(input, job, |_| {})
}

/// [`run_segment`], telling `progress` where it is (the command line draws its bars).
pub fn run_segment_with_progress(
    input: SegmentInput,
    job: &SegmentJob,
    mut progress: impl FnMut(SegmentProgress) + Send,
) -> Result<SegmentOutcome, JobError> {
    let cache = job.cache.resolve(job.output.as_deref());
    let (loaded, cue_cache) = match input {
        SegmentInput::Folder(folder) => {
            let cache = match (&job.cache, cache) {
                (_, Some(c)) => c,
                (CacheChoice::Auto, None) => folder.join(".cache"),
                _ => {
                    return Err(JobError::Invalid(format!(
                        "{}: a folder is read through a per-shape cache; give a cache folder",
                        folder.display()
                    )));
                }
            };
            let c = load_collection(&folder, &job.pipeline, &cache, |done, total, file| {
                progress(SegmentProgress::Shape { done, total, file })
            })
            .map_err(|e| JobError::Stage {
                context: format!("reading {}", folder.display()),
                source: Box::new(e),
            })?;
            if c.nodes.is_empty() && c.skipped.is_empty() {
                return Err(JobError::Invalid(format!(
                    "{}: no mesh files (.obj, .off, .ply)",
                    folder.display()
                )));
            }
            let loaded = Loaded {
                files: c.paths.iter().map(|p| p.display().to_string()).collect(),
                nodes: LoadedNodes {
                    meshes: c.meshes,
                    nodes: c.nodes,
                    outcomes: c.outcomes.into_iter().map(Some).collect(),
                    warnings: c.warnings,
                },
                skipped: c.skipped.iter().map(SkippedInput::from).collect(),
                times: (c.read_time, c.shape_time),
            };
            (loaded, Some(cache))
        }
        SegmentInput::Shapes(shapes) => {
            check_count(shapes.len())?;
            let files: Vec<String> = shapes.iter().map(JobShape::file).collect();
            let t0 = Instant::now();
            let nodes = load_nodes(shapes, &job.pipeline, cache.as_deref())?;
            let loaded = Loaded {
                files,
                nodes,
                skipped: Vec::new(),
                times: (Duration::ZERO, t0.elapsed()),
            };
            (loaded, cache)
        }
    };
    if job.strict && !loaded.skipped.is_empty() {
        return Err(JobError::Skipped(loaded.skipped));
    }
    let Loaded {
        files,
        nodes:
            LoadedNodes {
                meshes,
                nodes,
                outcomes,
                mut warnings,
            },
        skipped,
        times,
    } = loaded;
    check_count(nodes.len())?;
    let cache_dir = cue_cache.clone();
    let options = job.collection_options(nodes[0].bands.features, cue_cache)?;
    progress(SegmentProgress::Stage("co-segmentation and refinement"));
    let (result, part_tree_cache) = match &cache_dir {
        Some(dir) => {
            let keys: Vec<_> = meshes.iter().map(|m| shape_key(m, &job.pipeline)).collect();
            segment_collection_cached(nodes, &meshes, &options, dir, &keys)?
        }
        None => (segment_collection(nodes, &meshes, &options)?, None),
    };
    warnings.extend(result.warnings.iter().cloned());
    let mut summary = CollectionSummary::new(&result, &files, &options, skipped.clone());
    summary.parts = result.parts_report(&meshes);
    if part_tree_cache == Some(CacheOutcome::Hit) {
        summary.collection_stage = Some(RECUT);
    }
    warnings.extend(summary.parts.as_ref().and_then(|p| p.warning()));
    let seg = &result.segmentation;
    let labels: Vec<Vec<i32>> = (0..seg.names.len()).map(|i| seg.labels(i)).collect();
    let t_write = Instant::now();
    let mut written = Vec::new();
    if let Some(dir) = &job.output {
        let shapes = ShapeRegions::collection(&seg.names, &meshes, &labels);
        written = write_regions(dir, &shapes, &summary)?;
        if job.pictures {
            progress(SegmentProgress::Stage("pictures"));
            written.extend(draw(dir, &shapes, &meshes, &summary, &mut warnings)?);
        }
    }
    Ok(SegmentOutcome {
        result,
        options,
        summary,
        files,
        meshes,
        labels,
        skipped,
        cache_outcomes: outcomes,
        part_tree_cache,
        warnings,
        load_times: times,
        write_time: t_write.elapsed(),
        written,
    })
}

/// `summary.json`'s `collection_stage` when the part tree was read from the cache.
const RECUT: &str = "recut";

/// The shapes a run segments, before the co-segmentation.
struct Loaded {
    files: Vec<String>,
    nodes: LoadedNodes,
    skipped: Vec<SkippedInput>,
    times: (Duration, Duration),
}

/// A co-segmentation needs two shapes.
fn check_count(n: usize) -> Result<(), JobError> {
    if n < 2 {
        return Err(JobError::Invalid(format!(
            "co-segmentation needs at least 2 readable shapes, got {n}"
        )));
    }
    Ok(())
}

/// preview.png, <name>.png and index.html, legends naming each region by its confidence.
/// Every shape seen from the collection's one view ([`collection_views_or_own`]; `meshes` in
/// the order of `shapes`).
fn draw(
    out: &Path,
    shapes: &[ShapeRegions],
    meshes: &[TriMesh],
    summary: &CollectionSummary,
    warnings: &mut Vec<String>,
) -> Result<Vec<PathBuf>, JobError> {
    let (views, warning) = collection_views_or_own(meshes, None);
    warnings.extend(warning);
    let pictures: Vec<RenderShape> = shapes
        .iter()
        .zip(views)
        .map(|(s, v)| RenderShape {
            view: Some(v),
            ..s.picture()
        })
        .collect();
    let names: Vec<String> = summary
        .regions
        .iter()
        .map(|r| {
            // In the parts modes every part is a part: the leftover tuple of the regions
            // they are grouped from is merged into one of them, not shown as "leftovers".
            if r.leftover && summary.parts.is_none() {
                "leftovers".to_string()
            } else {
                format!("({:.0}%)", 100.0 * r.confidence)
            }
        })
        .collect();
    Ok(write_visuals(
        out,
        &pictures,
        Some(&names),
        &RenderOptions::default(),
    )?)
}
