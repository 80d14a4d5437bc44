//! [`map_step_collection`]: the map step of every unlabelled shape of a propagated collection.

use super::map_step::{map_step_through, map_step_with_map};
use super::point_map_store::{point_map_key, read_point_map, write_point_map};
use super::{MapStepOptions, MapStepReport, Propagation};
use crate::graph::ShapeGraph;
use crate::maps::MapShape;
use crate::mesh::TriMesh;
use crate::pipeline::{ShapePipelineOptions, shape_key};
use rayon::prelude::*;
use std::path::Path;

/// One shape's map step: its labels and report, or why it could not run.
type MapStepOutcome = Result<(Vec<i32>, MapStepReport), String>;

/// The map step ([`map_step`](fn@super::map_step)) of [`propagate_collection`] on every unlabelled shape of
/// `propagation`, each mapped to its nearest source (smallest graph summary distance; ties:
/// the first), in parallel (one target's full per-shape data in memory per thread, the
/// sources' shared). The shapes' spectra come from `cache` under `pipeline`
/// ([`crate::pipeline::load_or_compute`]), so `pipeline` must be the one the graph was built
/// with. A shape whose data or map fails keeps its propagated labels with a warning: the step
/// is optional. A kept map replaces the shape's labels and its part shares and confidences are
/// recomputed from them (per-vertex confidences stay the propagation's margins).
///
/// Inputs: `meshes` and `annotations` (`#shapes`, graph order; `Some` per-vertex labels on the
/// sources), the `graph` and `propagation` they were solved on. Output: per shape the report
/// (`None` for sources and skipped shapes) and warnings for the user.
///
/// ```no_run
/// use coseg::propagate::{map_step_collection, propagate_collection, MapStepOptions,
///     PropagateCollectionOptions};
/// use std::path::{Path, PathBuf};
/// let options = PropagateCollectionOptions::default();
/// let mut out = propagate_collection(Path::new("poses"), &[PathBuf::from("poses/a.labels.txt")],
///     &options).unwrap();
/// let mut annotations = vec![None; out.meshes.len()];
/// annotations[out.sources[0].shape] = Some(out.propagation.labels[out.sources[0].shape].clone());
/// let cache = std::env::temp_dir().join("coseg-cache");
/// let (reports, warnings) = map_step_collection(&out.meshes, &out.graph, &annotations,
///     &mut out.propagation, &options.pipeline, &cache, &MapStepOptions::default());
/// ```
pub fn map_step_collection(
    meshes: &[TriMesh],
    graph: &ShapeGraph,
    annotations: &[Option<Vec<i32>>],
    propagation: &mut Propagation,
    pipeline: &ShapePipelineOptions,
    cache: &Path,
    options: &MapStepOptions,
) -> (Vec<Option<MapStepReport>>, Vec<String>) {
    map_step_collection_with(
        meshes,
        graph,
        annotations,
        propagation,
        pipeline,
        Some(cache),
        options,
        None,
    )
}

/// [`map_step_collection`] with the cache optional: without one, each shape's spectrum is
/// computed in memory ([`crate::pipeline::compute_shape_data`], the same numbers a cache
/// entry holds), so shapes given as arrays get the same maps as their files; and with
/// `targets` (one flag per shape) only the flagged unlabelled shapes are mapped.
#[allow(clippy::too_many_arguments)]
pub(crate) fn map_step_collection_with(
    meshes: &[TriMesh],
    graph: &ShapeGraph,
    annotations: &[Option<Vec<i32>>],
    propagation: &mut Propagation,
    pipeline: &ShapePipelineOptions,
    cache: Option<&Path>,
    options: &MapStepOptions,
    targets: Option<&[bool]>,
) -> (Vec<Option<MapStepReport>>, Vec<String>) {
    let wanted = |i: usize| annotations[i].is_none() && targets.is_none_or(|t| t[i]);
    if !(0..meshes.len()).any(wanted) {
        return (vec![None; meshes.len()], Vec::new());
    }
    let shape_data = |m: &TriMesh| match cache {
        Some(c) => crate::pipeline::load_or_compute(m, pipeline, c).map(|r| r.data),
        None => crate::pipeline::compute_shape_data(m, pipeline),
    };
    let n = meshes.len();
    let name = |i: usize| graph.node(i).name.clone();
    let sources: Vec<usize> = (0..n).filter(|&i| annotations[i].is_some()).collect();
    // The nearest source by summary distance (ties: the first), as an index into `sources`.
    let nearest = |i: usize| {
        (0..sources.len())
            .min_by(|&a, &b| {
                graph
                    .summary_distance(i, sources[a])
                    .total_cmp(&graph.summary_distance(i, sources[b]))
            })
            .expect("at least one source")
    };
    let source_labels = |k: usize| annotations[sources[k]].as_deref().unwrap_or_default();
    // Per target, where its map is kept in the cache folder ([`point_map_key`]).
    let entry = |i: usize, k: usize| {
        cache.map(|c| {
            let key = point_map_key(
                &shape_key(&meshes[sources[k]], pipeline),
                &shape_key(&meshes[i], pipeline),
                source_labels(k),
                &propagation.labels[i],
                options,
            );
            (c, key)
        })
    };
    // Maps fitted by an earlier run to the same shapes and labels: read, not fitted again
    // (nor the shapes' spectra loaded for them).
    let stored: Vec<Option<Vec<u32>>> = (0..n)
        .into_par_iter()
        .map(|i| {
            if !wanted(i) {
                return None;
            }
            let k = nearest(i);
            let (c, key) = entry(i, k)?;
            let (s, t) = (meshes[sources[k]].vertex_count(), meshes[i].vertex_count());
            read_point_map(c, &key, s, t)
        })
        .collect();
    let missing = (0..n).any(|i| wanted(i) && stored[i].is_none());
    let source_data: Vec<_> = match missing {
        true => sources
            .par_iter()
            .map(|&s| shape_data(&meshes[s]))
            .collect(),
        false => Vec::new(),
    };
    let mut warnings = Vec::new();
    let mut loaded = Vec::with_capacity(sources.len());
    for (&s, d) in sources.iter().zip(source_data) {
        match d {
            Ok(d) => loaded.push(d),
            Err(e) => {
                warnings.push(format!("map step off: source {}: {e}", name(s)));
                return (vec![None; n], warnings);
            }
        }
    }
    let results: Vec<Option<MapStepOutcome>> = (0..n)
        .into_par_iter()
        .map(|i| {
            if !wanted(i) {
                return None;
            }
            let k = nearest(i);
            let s = sources[k];
            if let Some(map) = &stored[i] {
                let areas = &graph.node(i).areas;
                let (labels, report) = map_step_through(
                    source_labels(k),
                    &propagation.labels[i],
                    areas,
                    s,
                    map,
                    options,
                );
                return Some(Ok((labels, report)));
            }
            let run = || -> MapStepOutcome {
                let data = shape_data(&meshes[i]).map_err(|e| e.to_string())?;
                let source = MapShape {
                    spectrum: &loaded[k].spectrum,
                    positions: meshes[s].positions(),
                    labels: source_labels(k),
                    descriptors: None,
                };
                let target = MapShape {
                    spectrum: &data.spectrum,
                    positions: meshes[i].positions(),
                    labels: &propagation.labels[i],
                    descriptors: None,
                };
                let (labels, report, map) =
                    map_step_with_map(&source, &target, &graph.node(i).areas, s, options)
                        .map_err(|e| e.to_string())?;
                if let Some((c, key)) = entry(i, k) {
                    // Not written: the next run fits the map again, with the same result.
                    let _ = write_point_map(c, &key, &map);
                }
                Ok((labels, report))
            };
            Some(run())
        })
        .collect();
    let mut reports = vec![None; n];
    for (i, r) in results.into_iter().enumerate() {
        match r {
            None => {}
            Some(Err(e)) => warnings.push(format!("shape {}: map step skipped: {e}", name(i))),
            Some(Ok((labels, report))) => {
                if report.applied {
                    propagation.set_labels(graph, i, labels);
                } else {
                    warnings.push(format!(
                        "shape {}: map step rejected (its labels agree with the propagation on {:.1} % of the area, below {:.1} %)",
                        name(i),
                        100.0 * report.agreement,
                        100.0 * options.min_agreement
                    ));
                }
                reports[i] = Some(report);
            }
        }
    }
    (reports, warnings)
}
