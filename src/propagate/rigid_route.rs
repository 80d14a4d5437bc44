//! [`rigid_route`]: labels carried by a similarity alignment to a source and the nearest
//! surface point.

use super::RouteLabels;
use super::refine_affine::refine_affine;
use crate::align::{
    RegisterOptions, Registration, Similarity, SurfaceIndex, nearest_point_vertex_labels,
    register_pair,
};
use crate::mesh::TriMesh;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::Mutex;

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
    rigid_route_cached(meshes, annotations, affine, targets, &RigidCache::default())
}

/// What the rigid route learns of one (source, target) pair that does not depend on the
/// labels: the registration and, once the pair was chosen, which source vertex each target
/// vertex reads its label from.
#[derive(Debug, Clone)]
struct PairFit {
    /// The registration, or why it failed.
    registration: Result<Registration, String>,
    /// Per target vertex: the source vertex whose label it takes and how far it lands from the
    /// source's surface; made on the first call that chooses this source.
    nearest: Option<Nearest>,
}

/// Per target vertex the source vertex it reads and its distance to the source's surface, and
/// the pair's residual after the affine step.
type Nearest = (Vec<i32>, Vec<f64>, f64);

/// The rigid route's label-independent work, kept between propagations of one collection:
/// per (source, target) pair the registration and the nearest source vertex of every target
/// vertex. A change of labels then costs one table look-up per vertex instead of a
/// registration and a nearest-point search per pair. Results are those of an empty cache, bit
/// for bit: what is kept is exactly what would be recomputed.
///
/// Entries are keyed by the shapes' indices and vertex counts and the affine step; a cache
/// serves one collection of meshes (a [`super::Propagation`] keeps one for its graph).
#[derive(Debug, Default)]
pub(crate) struct RigidCache {
    pairs: Mutex<BTreeMap<PairKey, PairFit>>,
}

/// (source, target, source vertices, target vertices, affine step).
type PairKey = (usize, usize, usize, usize, bool);

impl Clone for RigidCache {
    fn clone(&self) -> Self {
        RigidCache {
            pairs: Mutex::new(self.lock().clone()),
        }
    }
}

impl PartialEq for RigidCache {
    /// A cache never changes a result, so two propagations that agree elsewhere are equal
    /// whatever their caches hold.
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl RigidCache {
    fn lock(&self) -> std::sync::MutexGuard<'_, BTreeMap<PairKey, PairFit>> {
        // A panic elsewhere cannot leave an entry half written (entries are inserted whole).
        self.pairs.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn key(meshes: &[TriMesh], s: usize, i: usize, affine: bool) -> PairKey {
        (
            s,
            i,
            meshes[s].vertex_count(),
            meshes[i].vertex_count(),
            affine,
        )
    }

    /// The registration of target `i` onto source `s` (computed on the first call).
    fn registration(
        &self,
        meshes: &[TriMesh],
        s: usize,
        i: usize,
        affine: bool,
    ) -> Result<Registration, String> {
        let key = Self::key(meshes, s, i, affine);
        if let Some(f) = self.lock().get(&key) {
            return f.registration.clone();
        }
        let registration = register_pair(&meshes[s], &meshes[i], &RegisterOptions::default())
            .map_err(|e| e.to_string());
        self.lock()
            .entry(key)
            .or_insert(PairFit {
                registration,
                nearest: None,
            })
            .registration
            .clone()
    }

    /// Per vertex of target `i`: the vertex of source `s` it reads its label from and its
    /// distance to the source's surface, after `reg` (and the affine step); computed on the
    /// first call.
    fn nearest(
        &self,
        meshes: &[TriMesh],
        s: usize,
        i: usize,
        affine: bool,
        reg: &Registration,
    ) -> Result<Nearest, String> {
        let key = Self::key(meshes, s, i, affine);
        if let Some(n) = self.lock().get(&key).and_then(|f| f.nearest.clone()) {
            return Ok(n);
        }
        // The source's vertex indices as its labels: the nearest-point rule gives each target
        // vertex the index of the vertex whose label it would read.
        let index: Vec<i32> = (0..meshes[s].vertex_count() as i32).collect();
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
                    &index,
                    &mapped,
                    &Similarity::identity(),
                ),
                Err(_) => {
                    nearest_point_vertex_labels(&meshes[s], &index, &meshes[i], &reg.transform)
                }
            }
        } else {
            nearest_point_vertex_labels(&meshes[s], &index, &meshes[i], &reg.transform)
        }
        .map(|(v, d)| (v, d, residual))
        .map_err(|e| e.to_string())?;
        if let Some(f) = self.lock().get_mut(&key) {
            f.nearest = Some(carried.clone());
        }
        Ok(carried)
    }
}

/// [`rigid_route_to`] keeping the label-independent work in `cache`.
pub(crate) fn rigid_route_cached(
    meshes: &[TriMesh],
    annotations: &[Option<Vec<i32>>],
    affine: bool,
    targets: &[usize],
    cache: &RigidCache,
) -> (RouteLabels, Vec<String>) {
    let n = meshes.len();
    let sources: Vec<usize> = (0..n).filter(|&i| annotations[i].is_some()).collect();
    type Carried = Result<(Vec<i32>, Vec<f64>, f64, f64), String>;
    let results: Vec<Option<Carried>> = (0..n)
        .into_par_iter()
        .map(|i| {
            if annotations[i].is_some() || !targets.contains(&i) {
                return None;
            }
            let mut best: Option<(f64, usize, Registration)> = None;
            let mut error = String::new();
            for &s in &sources {
                match cache.registration(meshes, s, i, affine) {
                    Ok(r) => {
                        if best.as_ref().is_none_or(|b| r.residual < b.0) {
                            best = Some((r.residual, s, r));
                        }
                    }
                    Err(e) => error = e,
                }
            }
            let Some((_, s, reg)) = best else {
                return Some(Err(error));
            };
            let ann = annotations[s].as_deref().unwrap_or_default();
            let radius = rms_radius(&meshes[s]);
            if ann.len() != meshes[s].vertex_count() {
                return Some(Err(crate::align::AlignError::LabelCount {
                    expected: meshes[s].vertex_count(),
                    found: ann.len(),
                    kind: "vertex",
                }
                .to_string()));
            }
            Some(
                cache
                    .nearest(meshes, s, i, affine, &reg)
                    .map(|(from, dist, residual)| {
                        let labels = from.iter().map(|&v| ann[v as usize]).collect();
                        // The residual is in source RMS radii; the distances in source units.
                        let scale = radius * reg.residual.max(f64::EPSILON);
                        let conf = dist.iter().map(|d| 1.0 / (1.0 + d / scale)).collect();
                        (labels, conf, reg.inlier_share, residual)
                    }),
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
