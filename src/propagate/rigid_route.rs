//! [`rigid_route`]: labels carried by a similarity alignment to a source and the nearest
//! surface point.

use super::RouteLabels;
use super::refine_affine::refine_affine;
use crate::align::{
    RegisterOptions, Similarity, SurfaceIndex, nearest_point_vertex_labels, register_pair,
};
use crate::mesh::TriMesh;
use rayon::prelude::*;

/// The rigid route of the fused propagation: every unlabelled shape is registered onto each
/// source by a similarity ([`register_pair`]: rotation, uniform scale, translation, any pose)
/// and each of its vertices takes the label of the nearest point of the source's surface
/// ([`nearest_point_vertex_labels`]), from the source it registers best onto (the smallest
/// residual: with several sources, a stool listens to the stool).
///
/// Per-vertex confidence: how near the vertex lands to the source's surface (`1 / (1 + d /
/// ρ)`, `d` the distance, `ρ` the registration's residual in the same units), so a limb that
/// the alignment leaves in the air votes weakly; per shape: the registration's inlier share.
///
/// With `affine`, the chosen similarity is then relaxed to an affine map
/// ([`super::refine_affine`]) before the labels are read, so that a shape of other proportions
/// (a taller back, a wider seat) overlays its source part on part.
///
/// Inputs: `meshes` (#shapes, graph order), `annotations` (one per shape, `Some` per-vertex
/// labels on the sources), `affine`. Output: [`RouteLabels`] (empty on the sources) and, per shape that
/// could not be registered onto any source, a warning.
///
/// See also: [`crate::align::register_pair`], [`super::fuse_routes`].
///
/// Known issue: rigid: on posed, non-rigid shapes the alignment fits the trunk and leaves the
/// limbs wherever they are; the fusion's agreement test is what keeps such labels out.
pub fn rigid_route(
    meshes: &[TriMesh],
    annotations: &[Option<Vec<i32>>],
    affine: bool,
) -> (RouteLabels, Vec<String>) {
    let targets: Vec<usize> = (0..meshes.len())
        .filter(|&i| annotations[i].is_none())
        .collect();
    rigid_route_to(meshes, annotations, affine, &targets)
}

/// [`rigid_route`] on the unlabelled shapes `targets` only (the others get no vote): the
/// held-out check ([`super::held_out`]) carries the labels to one source at a time.
pub(crate) fn rigid_route_to(
    meshes: &[TriMesh],
    annotations: &[Option<Vec<i32>>],
    affine: bool,
    targets: &[usize],
) -> (RouteLabels, Vec<String>) {
    let n = meshes.len();
    let sources: Vec<usize> = (0..n).filter(|&i| annotations[i].is_some()).collect();
    let options = RegisterOptions::default();
    type Carried = Result<(Vec<i32>, Vec<f64>, f64, f64), String>;
    let results: Vec<Option<Carried>> = (0..n)
        .into_par_iter()
        .map(|i| {
            if annotations[i].is_some() || !targets.contains(&i) {
                return None;
            }
            let mut best: Option<(f64, usize, crate::align::Registration)> = None;
            let mut error = String::new();
            for &s in &sources {
                match register_pair(&meshes[s], &meshes[i], &options) {
                    Ok(r) => {
                        if best.as_ref().is_none_or(|b| r.residual < b.0) {
                            best = Some((r.residual, s, r));
                        }
                    }
                    Err(e) => error = e.to_string(),
                }
            }
            let Some((_, s, reg)) = best else {
                return Some(Err(error));
            };
            let ann = annotations[s].as_deref().unwrap_or_default();
            let radius = rms_radius(&meshes[s]);
            let mut residual = reg.residual;
            let carried = if affine {
                let fit = refine_affine(
                    &meshes[s],
                    &SurfaceIndex::new(&meshes[s]),
                    &meshes[i],
                    &reg.transform,
                    AFFINE_TRIM,
                );
                if fit.start_residual > 0.0 && fit.residual.is_finite() {
                    // The affine fit measures the same chamfer in source units: rescale its
                    // improvement onto the registration's residual.
                    residual = reg.residual * (fit.residual / fit.start_residual).min(1.0);
                }
                match meshes[i].map_positions(|p| fit.map.apply(p)) {
                    Ok(mapped) => nearest_point_vertex_labels(
                        &meshes[s],
                        ann,
                        &mapped,
                        &Similarity::identity(),
                    ),
                    Err(_) => {
                        nearest_point_vertex_labels(&meshes[s], ann, &meshes[i], &reg.transform)
                    }
                }
            } else {
                nearest_point_vertex_labels(&meshes[s], ann, &meshes[i], &reg.transform)
            };
            Some(
                carried
                    .map(|(labels, dist)| {
                        // The residual is in source RMS radii; the distances in source units.
                        let scale = radius * reg.residual.max(f64::EPSILON);
                        let conf = dist.iter().map(|d| 1.0 / (1.0 + d / scale)).collect();
                        (labels, conf, reg.inlier_share, residual)
                    })
                    .map_err(|e| e.to_string()),
            )
        })
        .collect();
    let mut out = RouteLabels::empty(n);
    let mut warnings = Vec::new();
    for (i, r) in results.into_iter().enumerate() {
        match r {
            None => {}
            Some(Ok((labels, conf, share, residual))) => {
                out.labels[i] = labels;
                out.confidence[i] = conf;
                out.shape_confidence[i] = share;
                out.residual[i] = residual;
            }
            Some(Err(e)) => warnings.push(format!("rigid route: shape {i} not registered: {e}")),
        }
    }
    (out, warnings)
}

/// Share of the nearest-point pairs (by area, each direction) the affine fit keeps: the
/// farthest tenth is taken for parts one shape has and the other lacks (an armrest, a
/// stretcher), which would otherwise pull the fit off the parts both share.
const AFFINE_TRIM: f64 = 0.9;

/// Root mean square distance of a mesh's vertices from their area-weighted centroid.
fn rms_radius(mesh: &TriMesh) -> f64 {
    let areas = mesh.vertex_areas();
    let total: f64 = areas.iter().sum::<f64>().max(f64::MIN_POSITIVE);
    let p = mesh.positions();
    let mut c = [0.0; 3];
    for (x, a) in p.iter().zip(&areas) {
        for k in 0..3 {
            c[k] += a * x[k] / total;
        }
    }
    let s: f64 = p
        .iter()
        .zip(&areas)
        .map(|(x, a)| a * (0..3).map(|k| (x[k] - c[k]).powi(2)).sum::<f64>())
        .sum();
    (s / total).sqrt()
}
