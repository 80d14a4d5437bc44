//! [`held_out_accuracy`]: each route's accuracy measured on the sources themselves, every
//! source's labels carried to it from the other sources.

use super::rigid_route::rigid_route_to;
use super::{PropagateError, PropagateOptions, Route, parts_route, propagate_labels};
use crate::graph::{Cosegmentation, ShapeGraph};
use crate::mesh::TriMesh;
use crate::spectral::HeatSmoother;

/// Each route's accuracy on the sources, measured against the user's own labels: every source
/// in turn is left unlabelled, each route carries the other sources' labels to it, and the
/// area share of its annotated vertices that receive their own label is the route's score
/// there (a vertex the route gives no label counts as wrong); the scores are averaged over
/// the sources.
///
/// This is the one estimate of a route's accuracy that does not depend on how the routes'
/// errors relate: the agreement model of [`super::fuse_routes`] assumes they fail
/// independently, which two routes reading the same intrinsic features do not (both confuse a
/// part with its mirror image).
///
/// Inputs: `graph`, `meshes`, `annotations` (#shapes, graph order), `smoothers` and
/// `propagate` as the band-affinity solve used them, `routes` (the routes to score, in the
/// order of the answer), `segmentation` (the parts route's co-segmentation), `affine` (the
/// rigid route's affine step). Output: per route, its mean held-out accuracy in `[0, 1]`;
/// `None` with fewer than two annotated shapes (nothing to hold out from).
///
/// Errors: those of [`propagate_labels`] other than a held-out run left without labels
/// (a source whose labels no other source has is skipped).
///
/// Known issue: each source is reached from one source fewer than the targets are, so the
/// scores are a little below the routes' accuracy on the targets, for every route alike.
#[allow(clippy::too_many_arguments)]
pub fn held_out_accuracy(
    graph: &ShapeGraph,
    meshes: &[TriMesh],
    annotations: &[Option<Vec<i32>>],
    smoothers: Option<&[HeatSmoother]>,
    propagate: &PropagateOptions,
    routes: &[Route],
    segmentation: Option<&Cosegmentation>,
    affine: bool,
) -> Result<Option<Vec<f64>>, PropagateError> {
    let n = annotations.len();
    let sources: Vec<usize> = (0..n)
        .filter(|&i| {
            annotations[i]
                .as_ref()
                .is_some_and(|a| a.iter().any(|&l| l >= 0))
        })
        .collect();
    if sources.len() < 2 {
        return Ok(None);
    }
    let areas: Vec<&[f64]> = (0..n).map(|i| graph.node(i).areas.as_slice()).collect();
    let mut sum = vec![0.0; routes.len()];
    let mut count = 0usize;
    for &s in &sources {
        let mut ann = annotations.to_vec();
        let truth = ann[s].take().unwrap_or_default();
        let score = |labels: &[i32]| -> f64 {
            let (mut hit, mut total) = (0.0, 0.0);
            for ((&t, &l), &a) in truth.iter().zip(labels).zip(areas[s]) {
                if t >= 0 {
                    total += a;
                    if l == t {
                        hit += a;
                    }
                }
            }
            if total > 0.0 { hit / total } else { 0.0 }
        };
        let mut scores = Vec::with_capacity(routes.len());
        let mut skipped = false;
        for route in routes {
            let labels: Vec<i32> = match route {
                Route::Affinity => match propagate_labels(graph, smoothers, &ann, propagate) {
                    Ok(p) => p.labels[s].clone(),
                    Err(PropagateError::NoLabels) => {
                        skipped = true;
                        break;
                    }
                    Err(e) => return Err(e),
                },
                Route::Parts => match segmentation {
                    Some(seg) => parts_route(seg, &ann, &areas).labels[s].clone(),
                    None => Vec::new(),
                },
                Route::Rigid => rigid_route_to(meshes, &ann, affine, &[s]).0.labels[s].clone(),
            };
            scores.push(score(&labels));
        }
        if skipped {
            continue;
        }
        for (x, v) in scores.into_iter().enumerate() {
            sum[x] += v;
        }
        count += 1;
    }
    Ok((count > 0).then(|| sum.iter().map(|v| v / count as f64).collect()))
}
