//! [`propagate_collection`]: a folder of meshes and its label files in one call.

use super::map_step_collection::map_step_collection;
use super::rigid_route::RigidCache;
use super::{
    CollectionParts, FusionReport, MapStepOptions, MapStepReport, PropagateError, PropagateOptions,
    Propagation, RouteOptions, fuse_propagation, propagate_labels,
};
use crate::cache::CacheOutcome;
use crate::graph::{GraphOptions, ShapeGraph, ShapeNode, SkippedFile, load_collection};
use crate::labels::{
    LabelError, LabelKind, PartNames, match_label_files, read_part_names, read_shape_labels,
};
use crate::mesh::TriMesh;
use crate::pipeline::ShapePipelineOptions;
use crate::spectral::HeatSmoother;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Options of [`propagate_collection`]: the per-shape pipeline, the graph and the solver.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct PropagateCollectionOptions {
    /// Spectrum, features and bands of every shape (the cache key).
    pub pipeline: ShapePipelineOptions,
    /// The shape graph (as `coseg segment` builds it).
    pub graph: GraphOptions,
    /// The solver.
    pub propagate: PropagateOptions,
    /// The correspondence routes fused with the band-affinity transport, and the boundary
    /// snapping ([`fuse_propagation`]); default: every route ([`RouteOptions::default`]).
    /// [`RouteOptions::affinity_only`] gives the transport alone.
    pub routes: RouteOptions,
    /// Per-shape cache folder (default: `coseg-cache` in the system's temporary folder; the
    /// input folder is never written).
    pub cache_dir: Option<PathBuf>,
    /// Optional part names, a JSON `{label: name}` file.
    pub part_names: Option<PathBuf>,
    /// The map step ([`map_step`]) after the propagation, for near-isometric collections
    /// (default `None`: off). Each unlabelled shape is mapped to its nearest source (smallest
    /// graph summary distance); the shapes' spectra come from the full cache entries.
    pub map_step: Option<MapStepOptions>,
}

/// An annotation used as a source.
#[derive(Debug, Clone, PartialEq)]
pub struct SourceFile {
    /// Index of the shape (graph order).
    pub shape: usize,
    /// The label file.
    pub path: PathBuf,
    /// Per-vertex or per-face file.
    pub kind: LabelKind,
}

/// Result of [`propagate_collection`].
#[derive(Debug)]
pub struct PropagatedCollection {
    /// Input mesh paths (graph order).
    pub paths: Vec<PathBuf>,
    /// The meshes (graph order).
    pub meshes: Vec<TriMesh>,
    /// The shape graph (nodes hold the band tables).
    pub graph: ShapeGraph,
    /// One heat smoother per shape (empty when smoothing is off or failed; see `warnings`).
    pub smoothers: Vec<HeatSmoother>,
    /// The labels, confidences and the state for [`Propagation::update`].
    pub propagation: Propagation,
    /// The annotations used.
    pub sources: Vec<SourceFile>,
    /// Part names (empty without a names file).
    pub part_names: PartNames,
    /// Mesh files that could not be used.
    pub skipped: Vec<SkippedFile>,
    /// Where each shape's per-shape data came from (graph order): a cache hit, a miss, or a
    /// recomputed stale entry.
    pub outcomes: Vec<CacheOutcome>,
    /// What the map step did on each shape (graph order; `None` for the sources, for shapes it
    /// could not run on, and everywhere when it is off).
    pub map_steps: Vec<Option<MapStepReport>>,
    /// Per shape, what the map route of the fusion did ([`super::map_route`]; `None` for the
    /// sources, or everywhere when the route did not run).
    pub map_routes: Vec<Option<MapStepReport>>,
    /// The map step's options when it ran.
    pub map_step: Option<MapStepOptions>,
    /// Each route's labels and trust ([`fuse_propagation`]).
    pub fusion: FusionReport,
    /// Warnings for the user.
    pub warnings: Vec<String>,
}

impl PropagatedCollection {
    /// The smoothers as the solver takes them.
    pub fn smoothers(&self) -> Option<&[HeatSmoother]> {
        (!self.smoothers.is_empty()).then_some(self.smoothers.as_slice())
    }
}

/// Loads every mesh of `folder` through the per-shape cache, matches the label files of
/// `labels` (folders matched by stem, or files; see [`match_label_files`]) to them, builds the
/// shape graph and heat smoothers and runs [`propagate_labels`]. Unreadable meshes are skipped
/// (listed in `skipped`); a label file that does not fit its mesh (wrong count, a line that is
/// not an integer, an empty file) is an error naming it, and so are label inputs of which no
/// file matches a mesh and annotations that are all unlabelled (`-1`).
///
/// ```no_run
/// use coseg::propagate::{propagate_collection, PropagateCollectionOptions};
/// use std::path::{Path, PathBuf};
/// let out = propagate_collection(Path::new("chairs"), &[PathBuf::from("chairs/gt/1.seg")],
///     &PropagateCollectionOptions::default()).unwrap();
/// println!("{} shapes labelled", out.propagation.labels.len());
/// ```
pub fn propagate_collection(
    folder: &Path,
    labels: &[PathBuf],
    options: &PropagateCollectionOptions,
) -> Result<PropagatedCollection, PropagateError> {
    options.propagate.validate()?;
    options.routes.validate()?;
    let cache = options
        .cache_dir
        .clone()
        .unwrap_or_else(|| std::env::temp_dir().join("coseg-cache"));
    let timer = crate::stage_timer::stage("per-shape stage (load_collection)");
    let loaded = load_collection(folder, &options.pipeline, &cache, |_, _, _| {})?;
    drop(timer);
    let mut warnings = loaded.warnings.clone();
    let stems: Vec<String> = loaded.nodes.iter().map(|n| n.name.clone()).collect();
    let (matched, w) = match_label_files(labels, &stems)?;
    if matched.is_empty() && !stems.is_empty() {
        // Say which inputs matched nothing (the warnings would be lost with the error).
        let inputs: Vec<String> = labels.iter().map(|p| p.display().to_string()).collect();
        return Err(LabelError::Match {
            path: inputs.join(", "),
            message: format!(
                "no label file (<stem>.seg or <stem>.labels.txt) matches a mesh of {}",
                folder.display()
            ),
        }
        .into());
    }
    warnings.extend(w);
    let mut annotations: Vec<Option<Vec<i32>>> = vec![None; stems.len()];
    let mut sources = Vec::new();
    let mut unlabelled = Vec::new();
    for (i, path) in matched {
        let l = read_shape_labels(&path, &loaded.meshes[i], &stems[i])?;
        if l.vertex_labels.iter().all(|&x| x < 0) {
            warnings.push(format!("{}: no labelled vertex, not used", path.display()));
            unlabelled.push(path.display().to_string());
            continue;
        }
        sources.push(SourceFile {
            shape: i,
            path,
            kind: l.kind,
        });
        annotations[i] = Some(l.vertex_labels);
    }
    if sources.is_empty() {
        if !unlabelled.is_empty() {
            return Err(LabelError::Unlabelled {
                paths: unlabelled.join(", "),
            }
            .into());
        }
        return Err(PropagateError::NoLabels);
    }
    let part_names = match &options.part_names {
        Some(p) => read_part_names(p)?,
        None => PartNames::new(),
    };
    let mut with_cache = options.clone();
    with_cache.cache_dir = Some(cache.clone());
    let mut solved = propagate_loaded(loaded.nodes, &loaded.meshes, &annotations, &with_cache)?;
    warnings.extend(solved.warnings);
    let map_steps = match &options.map_step {
        Some(ms) => {
            ms.validate()
                .map_err(|e| PropagateError::BadOption(e.to_string()))?;
            let _t = crate::stage_timer::stage("map step");
            let (reports, w) = map_step_collection(
                &loaded.meshes,
                &solved.graph,
                &annotations,
                &mut solved.propagation,
                &options.pipeline,
                &cache,
                ms,
            );
            warnings.extend(w);
            reports
        }
        None => vec![None; loaded.meshes.len()],
    };
    Ok(PropagatedCollection {
        paths: loaded.paths,
        meshes: loaded.meshes,
        graph: solved.graph,
        smoothers: solved.smoothers,
        propagation: solved.propagation,
        sources,
        part_names,
        skipped: loaded.skipped,
        outcomes: loaded.outcomes,
        map_steps,
        map_step: options.map_step.clone(),
        map_routes: solved.map_route,
        fusion: solved.fusion,
        warnings,
    })
}

/// Result of [`propagate_loaded`]: the collection stage of [`propagate_collection`].
#[derive(Debug)]
pub struct PropagatedShapes {
    /// The shape graph (nodes hold the band tables).
    pub graph: ShapeGraph,
    /// One heat smoother per shape (empty when smoothing is off or failed; see `warnings`).
    pub smoothers: Vec<HeatSmoother>,
    /// The labels and confidences.
    pub propagation: Propagation,
    /// Each route's labels and trust ([`fuse_propagation`]).
    pub fusion: FusionReport,
    /// The collection's co-segmentations made for the parts route (`None` when the route is
    /// off), kept so that a caller fusing again after [`Propagation::update`] does not make
    /// them again.
    pub parts: Option<CollectionParts>,
    /// Per shape, what the map route did ([`super::map_route`]; `None` for the sources, or
    /// everywhere when the route did not run).
    pub map_route: Vec<Option<MapStepReport>>,
    /// Warnings for the user (smoothing turned off, a route left out).
    pub warnings: Vec<String>,
}

/// The collection stage of [`propagate_collection`] on shapes already through the per-shape
/// stage (from a folder, or from arrays in memory): builds the shape graph of `nodes` under
/// `options.graph` and one heat smoother per mesh (`meshes[i]` is `nodes[i]`'s; smoothing is
/// turned off with a warning when one fails), then runs [`propagate_labels`] with
/// `annotations` (one per node, per-vertex, `< 0` = unlabelled) and fuses it with the other
/// routes of `options.routes` ([`fuse_propagation`]). `options.pipeline` gives the families'
/// weights (and the parts route's up direction); `options.cache_dir`, when given, keeps the
/// shapes' part cues. The same shapes and annotations give the same labels as
/// [`propagate_collection`] on their files.
pub fn propagate_loaded(
    nodes: Vec<ShapeNode>,
    meshes: &[TriMesh],
    annotations: &[Option<Vec<i32>>],
    options: &PropagateCollectionOptions,
) -> Result<PropagatedShapes, PropagateError> {
    options.propagate.validate()?;
    options.routes.validate()?;
    if meshes.len() != nodes.len() {
        return Err(PropagateError::BadOption(format!(
            "{} meshes for {} shapes",
            meshes.len(),
            nodes.len()
        )));
    }
    let mut warnings = Vec::new();
    let features = nodes.first().map_or(0, |n| n.bands.features);
    let mut parts = options.routes.parts.then(|| {
        CollectionParts::new(
            nodes.clone(),
            &options.pipeline,
            &options.graph,
            options.cache_dir.clone(),
        )
    });
    let time = options.propagate.smoothing_time;
    let timer = crate::stage_timer::stage("heat smoothers");
    let smoothers: Vec<HeatSmoother> = if time > 0.0 {
        match meshes
            .par_iter()
            .map(|m| HeatSmoother::new(m, time))
            .collect::<Result<Vec<_>, _>>()
        {
            Ok(s) => s,
            Err(e) => {
                warnings.push(format!("heat smoothing off: {e}"));
                Vec::new()
            }
        }
    } else {
        Vec::new()
    };
    drop(timer);
    let smooth = (!smoothers.is_empty()).then_some(smoothers.as_slice());
    // The rigid route's cache, made before the affinity solve so that the feature choice and
    // the rigid route read one collection alignment; its registrations, which do not depend
    // on the labels, are kept beside the per-shape entries for the next run on the same
    // shapes.
    let mut rigid = RigidCache::default();
    rigid.set_folder(options.cache_dir.clone());
    // With `chosen_features` the band affinity reads the families the collection chose (the
    // extrinsic family in the collection frame on rigid-like collections: the intrinsic
    // bands alone cannot tell a seat from a back or a left leg from its mirror image). A
    // choice that fails leaves the pipeline's families (the parts route then reports the
    // failure).
    let chosen = match parts.as_mut() {
        Some(p) if options.routes.chosen_features => {
            let _t = crate::stage_timer::stage("parts route (co-segmentation)");
            let alignment = || rigid.alignment(meshes);
            p.chosen_graph_sharing(meshes, smooth, Some(&alignment))
                .ok()
                .flatten()
        }
        _ => None,
    };
    let graph = match chosen {
        Some(g) => g,
        None => {
            let _t = crate::stage_timer::stage("shape graph");
            let mut graph = ShapeGraph::build(nodes, &options.graph)?;
            // The families' shares of the affinity (`--family-weights`), as `coseg segment`
            // uses them.
            graph.set_feature_weights(options.pipeline.feature_weights(features))?;
            graph
        }
    };
    let timer = crate::stage_timer::stage("affinity route (propagate_labels)");
    let mut propagation = propagate_labels(&graph, smooth, annotations, &options.propagate)?;
    propagation.rigid = rigid;
    drop(timer);
    let fusion = fuse_propagation(
        &graph,
        meshes,
        annotations,
        &mut propagation,
        parts.as_mut(),
        smooth,
        &options.propagate,
        &options.routes,
    )?;
    warnings.extend(fusion.warnings.iter().cloned());
    let map_route = match options.routes.map {
        true => {
            let _t = crate::stage_timer::stage("map route");
            let (reports, w) = super::map_route(
                meshes,
                &graph,
                annotations,
                &mut propagation,
                &fusion,
                &options.pipeline,
                options.cache_dir.as_deref(),
            );
            warnings.extend(w);
            reports
        }
        false => vec![None; meshes.len()],
    };
    Ok(PropagatedShapes {
        graph,
        smoothers,
        propagation,
        fusion,
        parts,
        map_route,
        warnings,
    })
}
