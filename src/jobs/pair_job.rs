//! [`run_pair`]: `coseg pair A B -o OUT` (and Python's `coseg.pair`) as a library call.

use super::{CacheChoice, JobError, JobShape};
use crate::cache::CacheOutcome;
use crate::output::{PairSummary, ShapeRegions, ShapeSummary, write_regions, write_visuals};
use crate::pipeline::{ShapeData, ShapePipelineOptions};
use crate::render::{RenderOptions, RenderShape};
use crate::stable::{PairShape, SegmentPairOptions, SegmentedPair, VertexMap};
use crate::stable::{correspondence_ratio, segment_pair};
use std::path::PathBuf;
use std::time::Instant;

/// Options of [`run_pair`]; `Default` is `coseg pair`'s default.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PairJob {
    /// The per-shape stage: spectrum, features, bands ([`ShapePipelineOptions::default`]).
    pub pipeline: ShapePipelineOptions,
    /// The pair stage: algorithm, refinement, map step ([`SegmentPairOptions::default`]).
    /// Its `feature_weights`, when `None`, become the feature families' shares over the band
    /// table's columns ([`ShapePipelineOptions::feature_weights`]), as every command uses them.
    pub pair: SegmentPairOptions,
    /// The per-shape cache (default [`CacheChoice::Auto`]: `<output>/.cache`).
    pub cache: CacheChoice,
    /// Folder for the region files, `summary.json` and (with [`PairJob::pictures`]) the
    /// pictures and viewer page, created if missing; `None` (default): nothing is written.
    pub output: Option<PathBuf>,
    /// Draw `preview.png`, `<name>.png` and `index.html` into the output folder (default true).
    pub pictures: bool,
    /// Ground truth for the correspondence ratio (default none).
    pub ground_truth: Option<VertexMap>,
}

impl Default for PairJob {
    fn default() -> Self {
        Self {
            pipeline: ShapePipelineOptions::default(),
            pair: SegmentPairOptions::default(),
            cache: CacheChoice::Auto,
            output: None,
            pictures: true,
            ground_truth: None,
        }
    }
}

/// What [`run_pair`] found and wrote.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct PairOutcome {
    /// The shapes' names as written (`<stem>`, the first `<stem>_a` when both are equal).
    pub names: [String; 2],
    /// Region id per vertex of A, then of B (`-1`: in no region).
    pub labels: [Vec<i32>; 2],
    /// The pair stage's result (regions, times, fallbacks, the map step as resolved).
    pub pair: SegmentedPair,
    /// The options the pair stage ran with (feature weights resolved).
    pub options: SegmentPairOptions,
    /// `summary.json`'s content.
    pub summary: PairSummary,
    /// The correspondence ratio against [`PairJob::ground_truth`].
    pub correspondence_ratio: Option<f64>,
    /// Wall time of the pair stage (s), without the per-shape stage.
    pub seconds: f64,
    /// Where each shape's data came from (`None`: computed without a cache).
    pub cache_outcomes: [Option<CacheOutcome>; 2],
    /// Warnings for the user, in shape order, each naming its file: the meshes', the cache's,
    /// then the stages that fell back.
    pub warnings: Vec<String>,
    /// The files written.
    pub written: Vec<PathBuf>,
}

/// Stable region correspondences between two shapes, from files or meshes to the written
/// result: both shapes through the per-shape stage (side by side, through the cache), then
/// [`segment_pair`], the correspondence ratio when a ground truth is given, then the region
/// files, `summary.json` and the pictures into [`PairJob::output`].
///
/// - `shapes`: A and B;
/// - returns the [`PairOutcome`]; nothing is written when `output` is `None`.
///
/// Errors: [`JobError::Shape`] naming the file whose per-shape stage failed (the first in
/// argument order), [`JobError::Stage`] naming both when the pair stage or the ratio fails,
/// [`JobError::Output`] when writing fails.
///
/// See also: [`segment_pair`], the stage alone on loaded shapes.
pub fn run_pair(shapes: [JobShape; 2], job: &PairJob) -> Result<PairOutcome, JobError> {
    let cache = job.cache.resolve(job.output.as_deref());
    let [a, b] = shapes;
    let (mut na, nb) = (a.name(), b.name());
    if na == nb {
        na = format!("{na}_a");
    }
    let (fa, fb) = (a.file(), b.file());
    // Warm, each shape's rebuild from its cache entry is mostly sequential work: two at once
    // use both cores.
    let (la, lb) = rayon::join(
        || a.load::<ShapeData>(&job.pipeline, cache.as_deref()),
        || b.load::<ShapeData>(&job.pipeline, cache.as_deref()),
    );
    let (sa, sb) = (la?, lb?);
    let mut warnings: Vec<String> = sa.warnings.iter().chain(&sb.warnings).cloned().collect();
    let mut options = job.pair.clone();
    if options.feature_weights.is_none() {
        options.feature_weights = job.pipeline.feature_weights(sa.data.bands.features);
    }
    let context = format!("{fa} x {fb}");
    let stage_err = |e: crate::stable::StableError| JobError::Stage {
        context: context.clone(),
        source: Box::new(e),
    };
    let t = Instant::now();
    let pair = segment_pair(
        PairShape {
            mesh: &sa.mesh,
            spectrum: &sa.data.spectrum,
            bands: &sa.data.bands,
            descriptors: Some(&sa.data.descriptors.values),
        },
        PairShape {
            mesh: &sb.mesh,
            spectrum: &sb.data.spectrum,
            bands: &sb.data.bands,
            descriptors: Some(&sb.data.descriptors.values),
        },
        &options,
    )
    .map_err(stage_err)?;
    let seconds = t.elapsed().as_secs_f64();
    warnings.extend(pair.fallbacks.iter().map(|f| format!("{context}: {f}")));
    let ratio = job
        .ground_truth
        .as_ref()
        .map(|m| correspondence_ratio(&pair.regions, m))
        .transpose()
        .map_err(stage_err)?;
    let summary_of = |name: &str, file: String, mesh: &crate::mesh::TriMesh| ShapeSummary {
        name: name.to_string(),
        file,
        vertices: mesh.vertex_count(),
        area: mesh.total_area(),
    };
    let summary = PairSummary::of_pair(
        [
            summary_of(&na, fa.clone(), &sa.mesh),
            summary_of(&nb, fb.clone(), &sb.mesh),
        ],
        &pair,
        &options,
        ratio,
        seconds,
    );
    let labels = [pair.regions.labels_a(), pair.regions.labels_b()];
    let mut written = Vec::new();
    if let Some(dir) = &job.output {
        let list = [
            ShapeRegions {
                name: &na,
                mesh: &sa.mesh,
                regions: &labels[0],
            },
            ShapeRegions {
                name: &nb,
                mesh: &sb.mesh,
                regions: &labels[1],
            },
        ];
        written = write_regions(dir, &list, &summary)?;
        if job.pictures {
            let pictures: Vec<RenderShape> = list.iter().map(ShapeRegions::picture).collect();
            written.extend(write_visuals(
                dir,
                &pictures,
                None,
                &RenderOptions::default(),
            )?);
        }
    }
    Ok(PairOutcome {
        names: [na, nb],
        labels,
        pair,
        options,
        summary,
        correspondence_ratio: ratio,
        seconds,
        cache_outcomes: [sa.outcome, sb.outcome],
        warnings,
        written,
    })
}
