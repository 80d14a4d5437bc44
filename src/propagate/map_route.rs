//! [`map_route`]: point maps as a fourth route of the fused propagation, taken where the
//! routes' own agreement says they are the most accurate.

use super::map_step_collection::map_step_collection_with;
use super::{FusionReport, MapStepOptions, MapStepReport, Propagation, RouteLabels, fuse_routes};
use crate::graph::ShapeGraph;
use crate::mesh::TriMesh;
use crate::pipeline::ShapePipelineOptions;
use std::path::Path;

/// Point maps as a route of their own: every unlabelled shape is re-labelled through a point
/// map to its nearest source ([`super::map_step`] with no agreement gate: the functional map
/// fitted to the fused parts, refined by ZoomOut, each vertex taking the source label at its
/// image), and the map's labels join the fusion's routes as one more voter. Where the one-coin
/// model of [`fuse_routes`] (each route's accuracy read off the triangles of Cohen's κ
/// between the routes) estimates the map to be the most accurate of all routes on a shape,
/// that shape takes the vote of every route with the map included; elsewhere it keeps the
/// fusion's labels.
///
/// Why a route and not a gate: on near-isometric collections (one body in several poses) a
/// point map carries the source's boundaries exactly, where every other route is blurred (a
/// TOSCA cat from one source: fused 70–94 %, mapped 81–99 %); on other collections (generated
/// bodies of other proportions, chairs, goblets) the map is worse than the fusion by 5–45
/// points. The agreement of the map with the fused labels cannot tell the two apart (a right
/// map agrees with fused labels exactly as far as they are right), but the map's agreement
/// with each route separately can: a right map agrees with every route as far as that route
/// is right, so its κ triangle puts it first, while a map bent by a non-isometric pair agrees
/// with none. No constant is fitted: the decision is the model's ranking of the routes.
///
/// Inputs: `meshes`, `graph`, `annotations` and the fused `propagation` as
/// [`super::fuse_propagation`] left them, its `fusion` report (the routes' labels),
/// `pipeline` and `cache` (the shapes' spectra, as [`super::map_step_collection`] reads them;
/// `None`: computed in memory, the same numbers).
/// Output: per shape (`None` for sources and shapes without a map) the map's source, its
/// agreement with the fused labels and whether the shape took the vote with the map; and
/// warnings. A shape whose map fails keeps the fused labels (the route is optional).
///
/// See also: [`super::map_step`] (the gated step, `coseg propagate --map-step`),
/// [`fuse_routes`].
///
/// Known issue: the map is fitted to the fused labels, so it shares some of their errors;
/// the one-coin model then credits it a little more than it deserves. Cost: one ZoomOut map
/// per unlabelled shape (about 0.36 s per 10k-vertex shape on two cores).
pub fn map_route(
    meshes: &[TriMesh],
    graph: &ShapeGraph,
    annotations: &[Option<Vec<i32>>],
    propagation: &mut Propagation,
    fusion: &FusionReport,
    pipeline: &ShapePipelineOptions,
    cache: Option<&Path>,
) -> (Vec<Option<MapStepReport>>, Vec<String>) {
    let all = vec![true; meshes.len()];
    map_route_on(
        meshes,
        graph,
        annotations,
        propagation,
        fusion,
        pipeline,
        cache,
        &all,
    )
}

/// [`map_route`] on the shapes flagged in `targets` only (one flag per shape); the others
/// get no map and keep the fusion's labels. For an incremental session (the labelling
/// studio): after an update, a map is fitted again only where the last run took it, since a
/// map costs a ZoomOut per shape while the fusion's vote is one pass.
#[allow(clippy::too_many_arguments)]
pub fn map_route_on(
    meshes: &[TriMesh],
    graph: &ShapeGraph,
    annotations: &[Option<Vec<i32>>],
    propagation: &mut Propagation,
    fusion: &FusionReport,
    pipeline: &ShapePipelineOptions,
    cache: Option<&Path>,
    targets: &[bool],
) -> (Vec<Option<MapStepReport>>, Vec<String>) {
    let n = meshes.len();
    // The triangles need two other routes to rank the map against.
    if fusion.routes.len() < 2 || annotations.iter().all(Option::is_none) {
        return (vec![None; n], Vec::new());
    }
    let mut mapped = propagation.clone();
    let ungated = MapStepOptions {
        min_agreement: 0.0,
        ..MapStepOptions::default()
    };
    let (reports, warnings) = map_step_collection_with(
        meshes,
        graph,
        annotations,
        &mut mapped,
        pipeline,
        cache,
        &ungated,
        Some(targets),
    );
    let has = |i: usize| reports[i].is_some();
    let route = RouteLabels {
        labels: (0..n)
            .map(|i| {
                if has(i) {
                    mapped.labels[i].clone()
                } else {
                    Vec::new()
                }
            })
            .collect(),
        // A point map states no confidence of its own: every vertex ranks alike.
        confidence: (0..n)
            .map(|i| {
                if has(i) {
                    vec![1.0; mapped.labels[i].len()]
                } else {
                    Vec::new()
                }
            })
            .collect(),
        shape_confidence: (0..n)
            .map(|i| reports[i].as_ref().map_or(0.0, |r| r.agreement))
            .collect(),
        residual: vec![f64::NAN; n],
    };
    let areas: Vec<&[f64]> = (0..n).map(|i| &graph.node(i).areas[..]).collect();
    let routes: Vec<&RouteLabels> = fusion.routes.iter().map(|(_, l)| l).collect();
    let (with_map, taken) = fuse_with_map(&routes, &route, &areas);
    let mut out = vec![None; n];
    for (i, rep) in reports.into_iter().enumerate() {
        let Some(rep) = rep else { continue };
        let applied = taken[i];
        if applied {
            propagation.set_labels_confidence(
                graph,
                i,
                with_map.labels[i].clone(),
                with_map.confidence[i].clone(),
            );
        }
        out[i] = Some(MapStepReport {
            source: rep.source,
            agreement: rep.agreement,
            applied,
        });
    }
    (out, warnings)
}

/// The decision of [`map_route`]: `routes` and the `map` route fused ([`fuse_routes`], the map
/// as one more voter), and per shape whether the map's estimated accuracy there is above
/// every other route's (its weight in that vote, the log-odds of its accuracy read off the
/// κ triangles, strictly the largest). Shapes where the map does not vote, or the fusion has
/// no labels, are not taken.
///
/// Inputs: `routes` and `map` over the same `#shapes` shapes, `areas` (per shape, per vertex).
/// Output: the fusion with the map (labels, confidences, weights; the map's weight last) and
/// one flag per shape.
pub fn fuse_with_map(
    routes: &[&RouteLabels],
    map: &RouteLabels,
    areas: &[&[f64]],
) -> (super::FusedRoutes, Vec<bool>) {
    let mut all: Vec<&RouteLabels> = routes.to_vec();
    all.push(map);
    let fused = fuse_routes(&all, areas);
    let m = routes.len();
    let taken = (0..areas.len())
        .map(|i| {
            let w = &fused.weights[i];
            let best_other = w[..m].iter().copied().fold(f64::NEG_INFINITY, f64::max);
            map.votes_on(i) && !fused.labels[i].is_empty() && w[m] > best_other
        })
        .collect();
    (fused, taken)
}
