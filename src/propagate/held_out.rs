//! [`held_out_accuracy`]: each route's accuracy measured on the sources themselves, every
//! source's labels carried to it from the other sources.

use super::rigid_route::{RigidCache, RigidSteps, rigid_route_weighed};
use super::solve::propagate_labels_from;
use super::{PropagateError, PropagateOptions, Propagation, Route, parts_route};
use crate::graph::{Cosegmentation, ShapeGraph};
use crate::mesh::TriMesh;
use crate::spectral::HeatSmoother;

/// What the held-out runs read: the propagation's inputs as the band-affinity solve used
/// them, and the routes to score.
#[derive(Debug, Clone, Copy)]
pub struct HeldOutInputs<'a> {
    /// The shape graph of the collection.
    pub graph: &'a ShapeGraph,
    /// The meshes (graph order; the rigid route reads them).
    pub meshes: &'a [TriMesh],
    /// Per shape (graph order): its labels, `None` for a target.
    pub annotations: &'a [Option<Vec<i32>>],
    /// The heat smoothers of the band-affinity solve, if it used them.
    pub smoothers: Option<&'a [HeatSmoother]>,
    /// The band-affinity solve's options.
    pub propagate: &'a PropagateOptions,
    /// The routes to score, in the order of the answer.
    pub routes: &'a [Route],
    /// The parts route's co-segmentation (`None`: the parts route gives no labels).
    pub segmentation: Option<&'a Cosegmentation>,
    /// The rigid route's refinement steps (affine, non-rigid; [`RigidSteps`]).
    pub steps: RigidSteps,
}

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
/// Output: per route of `inputs.routes`, its mean held-out accuracy in `[0, 1]`; `None` with
/// fewer than two annotated shapes (nothing to hold out from).
///
/// Errors: those of [`super::propagate_labels`] other than a held-out run left without labels
/// (a source whose labels no other source has is skipped).
///
/// Known issue: each source is reached from one source fewer than the targets are, so the
/// scores are a little below the routes' accuracy on the targets, for every route alike.
pub fn held_out_accuracy(inputs: &HeldOutInputs) -> Result<Option<Vec<f64>>, PropagateError> {
    Ok(held_out_routes(inputs)?.map(|h| h.accuracy))
}

/// Every route's labels on every source, each carried to from the other sources, and the
/// scores of [`held_out_accuracy`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HeldOutRoutes {
    /// The held-out sources (graph order), in the order of `labels` and `scores`.
    pub sources: Vec<usize>,
    /// Per held-out source, per route: the labels the route carried to it.
    pub labels: Vec<Vec<Vec<i32>>>,
    /// Per held-out source, per route: the route's confidences there (as in
    /// [`super::RouteLabels::confidence`]).
    pub confidence: Vec<Vec<Vec<f64>>>,
    /// Per held-out source, per route: the route's residual there (as in
    /// [`super::RouteLabels::residual`]; `NaN` where the route has none).
    pub residual: Vec<Vec<f64>>,
    /// Per held-out source, per route: the area share of its labels the route gave it.
    pub scores: Vec<Vec<f64>>,
    /// Per route: the mean of `scores` over the held-out sources.
    pub accuracy: Vec<f64>,
}

/// [`held_out_accuracy`] with every held-out run's labels ([`HeldOutRoutes`]); same inputs
/// and errors.
pub fn held_out_routes(inputs: &HeldOutInputs) -> Result<Option<HeldOutRoutes>, PropagateError> {
    held_out_routes_cached(inputs, &RigidCache::default(), false, None)
}

/// [`held_out_routes`] with the rigid route's registrations kept in `rigid` (the fusion
/// shares its propagation's cache, whose pairs of sources the held-out runs need) and, with
/// `rigid_poses`, the rigid route's pose chosen among its alternatives as the fusion chooses
/// it ([`choose_rigid_alternative`] against the routes scored before it). `affinity`: the
/// band-affinity propagation of all the sources, whose cached votes each held-out solve starts
/// from ([`propagate_labels_from`]: the same labels, the votes of the other sources not
/// transported again).
pub(crate) fn held_out_routes_cached(
    inputs: &HeldOutInputs,
    rigid: &RigidCache,
    rigid_poses: bool,
    affinity: Option<&Propagation>,
) -> Result<Option<HeldOutRoutes>, PropagateError> {
    let HeldOutInputs {
        graph,
        meshes,
        annotations,
        smoothers,
        propagate,
        routes,
        segmentation,
        steps,
    } = *inputs;
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
    let mut out = HeldOutRoutes::default();
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
        let mut labels = Vec::with_capacity(routes.len());
        let mut confidence = Vec::with_capacity(routes.len());
        let mut residual = Vec::with_capacity(routes.len());
        let mut skipped = false;
        for route in routes {
            let _t = crate::stage_timer::stage(format!("held-out {route:?} on source {s}"));
            let (l, c, e): (Vec<i32>, Vec<f64>, f64) = match route {
                Route::Affinity => {
                    match propagate_labels_from(graph, smoothers, &ann, propagate, affinity) {
                        Ok(p) => (p.labels[s].clone(), p.confidence[s].clone(), f64::NAN),
                        Err(PropagateError::NoLabels) => {
                            skipped = true;
                            break;
                        }
                        Err(e) => return Err(e),
                    }
                }
                Route::Parts => match segmentation {
                    Some(seg) => {
                        let r = parts_route(seg, &ann, &areas);
                        (r.labels[s].clone(), r.confidence[s].clone(), f64::NAN)
                    }
                    None => (Vec::new(), Vec::new(), f64::NAN),
                },
                Route::Rigid => {
                    // As the fusion takes it: the pose the routes before it agree with.
                    let others: Vec<&[i32]> = labels
                        .iter()
                        .filter(|l: &&Vec<i32>| !l.is_empty())
                        .map(|l| l.as_slice())
                        .collect();
                    let mut r = rigid_route_weighed(
                        meshes,
                        &ann,
                        steps,
                        &[s],
                        rigid,
                        rigid_poses,
                        |_| others.clone(),
                        &areas,
                    )
                    .0;
                    (
                        std::mem::take(&mut r.labels[s]),
                        std::mem::take(&mut r.confidence[s]),
                        r.residual[s],
                    )
                }
            };
            scores.push(score(&l));
            labels.push(l);
            confidence.push(c);
            residual.push(e);
        }
        if skipped {
            continue;
        }
        out.sources.push(s);
        out.labels.push(labels);
        out.confidence.push(confidence);
        out.residual.push(residual);
        out.scores.push(scores);
    }
    if out.sources.is_empty() {
        return Ok(None);
    }
    let count = out.sources.len() as f64;
    out.accuracy = (0..routes.len())
        .map(|r| out.scores.iter().map(|s| s[r]).sum::<f64>() / count)
        .collect();
    Ok(Some(out))
}
