//! [`rigid_route`]: labels carried by a similarity alignment to a source and the nearest
//! surface point.

use super::RouteLabels;
use super::fuse_routes::cohen_kappa;
use super::refine_affine::{AffineMap, refine_affine_reading};
use super::refine_nonrigid::refine_nonrigid_reading;
use super::rigid_pair_store::{
    StoredPair, alignment_key, read_alignment, read_pair, rigid_pair_key, shape_hash,
    write_alignment, write_pair,
};
use crate::align::{
    AlignError, AlignOptions, Candidate, CollectionAlignment, FrameCase, Prepared, RegisterOptions,
    Registration, Similarity, SurfaceIndex, align_collection, nearest_corner,
    nearest_point_vertex_labels_in, register_onto_from,
};
use crate::cache::ShapeKey;
use crate::mesh::TriMesh;
use nalgebra::Matrix3;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

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
/// With `steps.affine`, the chosen similarity is then relaxed to an affine map
/// ([`super::refine_affine`]) before the labels are read, so that a shape of other proportions
/// (a taller back, a wider seat) overlays its source part on part; with `steps.nonrigid`, the
/// source is then deformed onto the shape ([`super::refine_nonrigid`]) and the labels are
/// read off the deformed source's surface. A `bool` reads as the affine step alone.
///
/// Inputs: `meshes` (#shapes, graph order), `annotations` (one per shape, `Some` per-vertex
/// labels on the sources), `steps`. Output: [`RouteLabels`] (empty on the sources) and, per shape that
/// could not be registered onto any source, a warning.
///
/// See also: [`crate::align::register_pair`], [`super::fuse_routes`].
///
/// Known issue: rigid: on posed, non-rigid shapes the alignment fits the trunk and leaves the
/// limbs wherever they are; the fusion's agreement test is what keeps such labels out.
pub fn rigid_route(
    meshes: &[TriMesh],
    annotations: &[Option<Vec<i32>>],
    steps: impl Into<RigidSteps>,
) -> (RouteLabels, Vec<String>) {
    let targets: Vec<usize> = (0..meshes.len())
        .filter(|&i| annotations[i].is_none())
        .collect();
    rigid_route_to(meshes, annotations, steps.into(), &targets)
}

/// Which steps relax the rigid route's similarity before the labels are read
/// ([`rigid_route`]). `From<bool>`: the affine step alone, or none.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct RigidSteps {
    /// Relax the similarity to an affine map ([`super::refine_affine`]).
    pub affine: bool,
    /// Then deform the source onto the shape ([`super::refine_nonrigid`]), from the affine
    /// map (or the similarity without the affine step).
    pub nonrigid: bool,
}

impl From<bool> for RigidSteps {
    fn from(affine: bool) -> Self {
        RigidSteps {
            affine,
            nonrigid: false,
        }
    }
}

/// [`rigid_route`] on the unlabelled shapes `targets` only (the others get no vote): the
/// held-out check ([`super::held_out`]) carries the labels to one source at a time.
pub(crate) fn rigid_route_to(
    meshes: &[TriMesh],
    annotations: &[Option<Vec<i32>>],
    steps: RigidSteps,
    targets: &[usize],
) -> (RouteLabels, Vec<String>) {
    rigid_route_cached(meshes, annotations, steps, targets, &RigidCache::default())
}

/// What the rigid route learns of one (source, target) pair that does not depend on the
/// labels: the registration and, per pose it was read through, which source vertex each
/// target vertex reads its label from.
#[derive(Debug, Clone)]
struct PairFit {
    /// The registration, or why it failed.
    registration: Result<Registration, String>,
    /// Per candidate pose of the registration (its index in [`Registration::candidates`]): the
    /// source vertex of every target vertex; made on the first call that reads this pose.
    nearest: BTreeMap<usize, Nearest>,
    /// The pair's entry on disk ([`super::rigid_pair_store`]), when the cache has a folder.
    disk: Option<ShapeKey>,
    /// Whether this holds something its entry on disk does not.
    dirty: bool,
}

/// Per target vertex the source vertex it reads and its distance to the source's surface, and
/// the pair's residual after the refinement steps.
type Nearest = (Vec<i32>, Vec<f64>, f64);

/// The rigid route's label-independent work, kept between propagations of one collection:
/// per (source, target) pair the registration and the nearest source vertex of every target
/// vertex under each of its poses. A change of labels then costs one table look-up per vertex
/// instead of a registration and a nearest-point search per pair. Results are those of an
/// empty cache, bit for bit: what is kept is exactly what would be recomputed.
///
/// Entries are keyed by the shapes' indices and vertex counts and the refinement steps; a cache
/// serves one collection of meshes (a [`super::Propagation`] keeps one for its graph). With a
/// folder ([`RigidCache::set_folder`]) the pairs and the collection alignment are also kept on
/// disk ([`super::rigid_pair_store`], keyed by the meshes' contents), so that another run on
/// the same shapes reads them.
#[derive(Debug, Default)]
pub(crate) struct RigidCache {
    /// The cache folder of the disk entries (`None`: memory only).
    folder: Option<PathBuf>,
    /// Per shape (index, vertex count): its content hash, the disk entries' key.
    hashes: Mutex<BTreeMap<(usize, usize), [u8; 32]>>,
    pairs: Mutex<BTreeMap<PairKey, PairFit>>,
    /// Per source (index, vertex count): its registration samples and surface index, made
    /// once for all the targets read from it (a few sources, every target: the same work
    /// per pair would be repeated `#targets` times).
    sources: Mutex<BTreeMap<(usize, usize), Arc<SourceIndex>>>,
    /// The collection alignment's rotation of every shape into the collection frame, keyed
    /// by the shapes' vertex counts (made by [`RigidCache::prepare`] before the targets are
    /// registered in parallel).
    frames: Mutex<Option<Arc<CollectionFrames>>>,
}

/// The collection alignment ([`align_collection`], default options) and per shape its
/// rotation into the collection frame, for the registrations' first start (`None` when the
/// collection could not be aligned). The parts route's feature choice reads the same
/// alignment ([`RigidCache::alignment`]).
#[derive(Debug)]
struct CollectionFrames {
    vertex_counts: Vec<usize>,
    alignment: Arc<Result<CollectionAlignment, AlignError>>,
    rotations: Option<Vec<Matrix3<f64>>>,
}

/// What every pair with one source reads of it: its samples for [`register_onto_from`] (or why
/// they could not be made) and its surface index for the nearest points.
struct SourceIndex {
    prepared: Result<Prepared, String>,
    surface: SurfaceIndex,
}

impl std::fmt::Debug for SourceIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SourceIndex").finish_non_exhaustive()
    }
}

/// (source, target, source vertices, target vertices, refinement steps).
type PairKey = (usize, usize, usize, usize, RigidSteps);

impl Clone for RigidCache {
    fn clone(&self) -> Self {
        RigidCache {
            folder: self.folder.clone(),
            hashes: Mutex::new(
                self.hashes
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .clone(),
            ),
            pairs: Mutex::new(self.lock().clone()),
            sources: Mutex::new(self.lock_sources().clone()),
            frames: Mutex::new(self.lock_frames().clone()),
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
    /// Keeps the pairs and the collection alignment in `folder` too (`None`: in memory only).
    pub(crate) fn set_folder(&mut self, folder: Option<PathBuf>) {
        self.folder = folder;
    }

    /// The content hash of shape `i` (made once).
    fn hash(&self, meshes: &[TriMesh], i: usize) -> [u8; 32] {
        let key = (i, meshes[i].vertex_count());
        let mut hashes = self.hashes.lock().unwrap_or_else(|e| e.into_inner());
        *hashes.entry(key).or_insert_with(|| shape_hash(&meshes[i]))
    }

    /// Writes every pair that holds something its disk entry does not. A pair that cannot be
    /// written is left for the next run to make again: no result depends on the disk.
    fn store(&self) {
        let Some(folder) = &self.folder else { return };
        let mut pairs = self.lock();
        for fit in pairs.values_mut().filter(|f| f.dirty) {
            if let Some(key) = &fit.disk {
                let stored =
                    StoredPair::new(&fit.registration, fit.nearest.iter().map(|(k, n)| (*k, n)));
                let _ = write_pair(folder, key, &stored);
            }
            fit.dirty = false;
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, BTreeMap<PairKey, PairFit>> {
        // A panic elsewhere cannot leave an entry half written (entries are inserted whole).
        self.pairs.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn lock_sources(
        &self,
    ) -> std::sync::MutexGuard<'_, BTreeMap<(usize, usize), Arc<SourceIndex>>> {
        self.sources.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn lock_frames(&self) -> std::sync::MutexGuard<'_, Option<Arc<CollectionFrames>>> {
        self.frames.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Aligns the collection `meshes` ([`align_collection`], default options) unless this
    /// cache holds its alignment already. Called before the targets are registered in
    /// parallel: the alignment runs in parallel itself, and made inside a worker it could
    /// wait on itself.
    fn prepare(&self, meshes: &[TriMesh]) {
        self.alignment(meshes);
    }

    /// The collection alignment of `meshes` ([`align_collection`], default options), made on
    /// the first call (as [`Self::prepare`]) and kept: the rigid route's starts and the parts
    /// route's feature choice read this one alignment ([`crate::parts::SharedAlignment`]).
    pub(crate) fn alignment(
        &self,
        meshes: &[TriMesh],
    ) -> Arc<Result<CollectionAlignment, AlignError>> {
        let counts: Vec<usize> = meshes.iter().map(TriMesh::vertex_count).collect();
        if let Some(f) = self
            .lock_frames()
            .as_ref()
            .filter(|f| f.vertex_counts == counts)
        {
            return f.alignment.clone();
        }
        let matrix = |r: &[[f64; 3]; 3]| Matrix3::from_fn(|i, j| r[i][j]);
        let alignment = Arc::new(self.align(meshes));
        let rotations = alignment.as_ref().as_ref().ok().map(|a| {
            a.shapes
                .iter()
                .map(|s| match a.case {
                    // Bit for bit the files' own frames: the start the route always had.
                    FrameCase::AlreadyAligned | FrameCase::Single => Matrix3::identity(),
                    FrameCase::Synchronised => matrix(&s.transform.rotation),
                })
                .collect()
        });
        *self.lock_frames() = Some(Arc::new(CollectionFrames {
            vertex_counts: counts,
            alignment: alignment.clone(),
            rotations,
        }));
        alignment
    }

    /// [`align_collection`] of `meshes` (default options), read from the cache folder when it
    /// holds it and written there when made.
    fn align(&self, meshes: &[TriMesh]) -> Result<CollectionAlignment, AlignError> {
        let Some(folder) = &self.folder else {
            return align_collection(meshes, &AlignOptions::default());
        };
        let hashes: Vec<[u8; 32]> = (0..meshes.len()).map(|i| self.hash(meshes, i)).collect();
        let key = alignment_key(&hashes);
        if let Some(a) = read_alignment(folder, &key, meshes.len()) {
            return Ok(a);
        }
        let made = align_collection(meshes, &AlignOptions::default());
        if let Ok(a) = &made {
            // Not written: the next run aligns again, with the same result.
            let _ = write_alignment(folder, &key, a);
        }
        made
    }

    /// The first start of the registration of target `i` onto source `s`: the collection
    /// alignment's relative rotation `G_sᵀ G_i` (`G` each shape's rotation into the collection
    /// frame), the identity when the files' frames already agree or the collection was not
    /// aligned ([`Self::prepare`]).
    ///
    /// Why: the identity start (the files' own frames) wins on aligned chairs (a stool onto
    /// an armchair, docs/ALIGN.md) but is just another start once the files are moved; the
    /// relative rotation is that start on aligned files and turns with the files otherwise.
    /// Not also composed with the target's own symmetries (a stool's quarter turns), although
    /// its placement in the collection frame is any of them: measured on the shipped chairs,
    /// those starts reach lower residuals with worse labels (bare `coseg propagate` 68.8 →
    /// 59.5 %).
    fn start(&self, meshes: &[TriMesh], s: usize, i: usize) -> Matrix3<f64> {
        let frames = self.lock_frames().clone();
        frames
            .filter(|f| f.vertex_counts.len() == meshes.len())
            .and_then(|f| f.rotations.as_ref().map(|g| g[s].transpose() * g[i]))
            .unwrap_or_else(Matrix3::identity)
    }

    /// Source `s`'s samples and surface index (made on the first call; two threads asking
    /// at once may both make it, and the first one stored is kept: they are equal).
    fn source(&self, meshes: &[TriMesh], s: usize) -> Arc<SourceIndex> {
        let key = (s, meshes[s].vertex_count());
        if let Some(x) = self.lock_sources().get(&key) {
            return x.clone();
        }
        let o = RegisterOptions::default();
        let made = Arc::new(SourceIndex {
            prepared: Prepared::new(&meshes[s], o.samples, o.seed).map_err(|e| e.to_string()),
            surface: SurfaceIndex::new(&meshes[s]),
        });
        self.lock_sources().entry(key).or_insert(made).clone()
    }

    fn key(meshes: &[TriMesh], s: usize, i: usize, steps: RigidSteps) -> PairKey {
        (
            s,
            i,
            meshes[s].vertex_count(),
            meshes[i].vertex_count(),
            steps,
        )
    }

    /// The registration of target `i` onto source `s` (computed on the first call).
    fn registration(
        &self,
        meshes: &[TriMesh],
        s: usize,
        i: usize,
        steps: RigidSteps,
    ) -> Result<Registration, String> {
        let key = Self::key(meshes, s, i, steps);
        if let Some(f) = self.lock().get(&key) {
            return f.registration.clone();
        }
        // `register_pair(source, target)` with the source prepared once, started from the
        // collection frame.
        let start = self.start(meshes, s, i);
        let disk = self.folder.as_ref().map(|folder| {
            let rows = std::array::from_fn(|r| std::array::from_fn(|c| start[(r, c)]));
            let (hs, hi) = (self.hash(meshes, s), self.hash(meshes, i));
            let steps_bits = [steps.affine, steps.nonrigid];
            (
                folder,
                rigid_pair_key(&hs, &hi, steps_bits, &rows, AFFINE_TRIM),
            )
        });
        if let Some((folder, k)) = &disk
            && let Some(stored) = read_pair(
                folder,
                k,
                meshes[s].vertex_count(),
                meshes[i].vertex_count(),
            )
        {
            let (registration, nearest) = stored.into_parts();
            return self
                .lock()
                .entry(key)
                .or_insert(PairFit {
                    registration,
                    nearest: nearest.into_iter().collect(),
                    disk: Some(*k),
                    dirty: false,
                })
                .registration
                .clone();
        }
        let registration = match &self.source(meshes, s).prepared {
            Ok(source) => {
                register_onto_from(source, &meshes[i], &RegisterOptions::default(), &start)
                    .map_err(|e| e.to_string())
            }
            Err(e) => Err(e.clone()),
        };
        self.lock()
            .entry(key)
            .or_insert(PairFit {
                registration,
                nearest: BTreeMap::new(),
                disk: disk.map(|(_, k)| k),
                dirty: true,
            })
            .registration
            .clone()
    }

    /// Per vertex of target `i`: the vertex of source `s` it reads its label from and its
    /// distance to the source's surface, after the registration's candidate pose `pose` (and
    /// the refinement steps); computed on the first call.
    fn nearest(
        &self,
        meshes: &[TriMesh],
        s: usize,
        i: usize,
        steps: RigidSteps,
        pose: &Candidate,
        index_of_pose: usize,
    ) -> Result<Nearest, String> {
        let key = Self::key(meshes, s, i, steps);
        if let Some(n) = self
            .lock()
            .get(&key)
            .and_then(|f| f.nearest.get(&index_of_pose).cloned())
        {
            return Ok(n);
        }
        // The source's vertex indices as its labels: the nearest-point rule gives each target
        // vertex the index of the vertex whose label it would read.
        let index: Vec<i32> = (0..meshes[s].vertex_count() as i32).collect();
        let mut residual = pose.residual;
        let source = self.source(meshes, s);
        let nearest_labels = |target: &TriMesh, transform: &Similarity| {
            nearest_point_vertex_labels_in(&source.surface, &meshes[s], &index, target, transform)
        };
        let mut map = AffineMap::from_similarity(&pose.transform);
        let mut closest = None;
        if steps.affine {
            let (fit, points) = refine_affine_reading(
                &meshes[s],
                &source.surface,
                &meshes[i],
                &pose.transform,
                AFFINE_TRIM,
            );
            if fit.start_residual > 0.0 && fit.residual.is_finite() {
                // The affine fit measures the same chamfer in source units: rescale its
                // improvement onto the registration's residual.
                residual = pose.residual * (fit.residual / fit.start_residual).min(1.0);
            }
            map = fit.map;
            closest = points;
        }
        if steps.nonrigid
            && let Some((fit, points)) =
                refine_nonrigid_reading(&meshes[s], &meshes[i], &map, AFFINE_TRIM)
        {
            if fit.start_residual > 0.0 && fit.residual.is_finite() {
                // Its own chamfer (samples against the deformed samples), so its own ratio.
                residual *= (fit.residual / fit.start_residual).min(1.0);
            }
            // The labels are read off the deformed source: same faces, same vertices.
            closest = Some(points);
        }
        let carried = match closest {
            // The last step paired every target vertex with its closest source point under
            // the map (and deformation) it returns: the nearest-point labels, already made.
            Some(closest) => {
                let faces = meshes[s].faces();
                Ok(closest
                    .iter()
                    .map(|c| (nearest_corner(faces, c) as i32, c.distance))
                    .unzip())
            }
            None if steps.affine => match meshes[i].map_positions(|p| map.apply(p)) {
                Ok(mapped) => nearest_labels(&mapped, &Similarity::identity()),
                Err(_) => nearest_labels(&meshes[i], &pose.transform),
            },
            None => nearest_labels(&meshes[i], &pose.transform),
        }
        .map(|(v, d)| (v, d, residual))
        .map_err(|e| e.to_string())?;
        if let Some(f) = self.lock().get_mut(&key) {
            f.nearest.insert(index_of_pose, carried.clone());
            f.dirty = true;
        }
        Ok(carried)
    }
}

/// [`rigid_route_to`] keeping the label-independent work in `cache`: every target's first
/// alternative of [`rigid_alternatives_cached`] (the source it registers best onto, the
/// registration's best pose).
pub(crate) fn rigid_route_cached(
    meshes: &[TriMesh],
    annotations: &[Option<Vec<i32>>],
    steps: RigidSteps,
    targets: &[usize],
    cache: &RigidCache,
) -> (RouteLabels, Vec<String>) {
    let (alternatives, warnings) =
        rigid_alternatives_cached(meshes, annotations, steps, targets, cache, false);
    let chosen: Vec<usize> = vec![0; meshes.len()];
    (choose_alternatives(alternatives, &chosen), warnings)
}

/// [`rigid_route_cached`] with the pose chosen as the fusion takes it: where `weigh_poses`
/// and the registration's choice on a target is the outlier among `others(i)` (the labels the
/// routes that fail independently of it give shape `i`; [`rigid_choice_is_outlier`]), every
/// other source and pose is carried there and [`choose_rigid_alternative`] takes one.
/// `areas`: per shape, its vertex areas. The other alternatives are carried only for those
/// targets: elsewhere they could not be taken, and carrying each costs an affine fit.
#[allow(clippy::too_many_arguments)]
pub(crate) fn rigid_route_weighed<'a>(
    meshes: &[TriMesh],
    annotations: &[Option<Vec<i32>>],
    steps: RigidSteps,
    targets: &[usize],
    cache: &RigidCache,
    weigh_poses: bool,
    others: impl Fn(usize) -> Vec<&'a [i32]>,
    areas: &[&[f64]],
) -> (RouteLabels, Vec<String>) {
    let (mut alternatives, warnings) =
        rigid_alternatives_cached(meshes, annotations, steps, targets, cache, false);
    let outliers: Vec<usize> = targets
        .iter()
        .copied()
        .filter(|&i| {
            weigh_poses
                && alternatives[i]
                    .first()
                    .is_some_and(|a| rigid_choice_is_outlier(&a.labels, &others(i), areas[i]))
        })
        .collect();
    if !outliers.is_empty() {
        let (more, _) =
            rigid_alternatives_cached(meshes, annotations, steps, &outliers, cache, true);
        for (i, m) in more.into_iter().enumerate() {
            if !m.is_empty() {
                alternatives[i] = m;
            }
        }
    }
    let chosen: Vec<usize> = alternatives
        .iter()
        .enumerate()
        .map(|(i, alts)| {
            if alts.len() < 2 {
                return 0;
            }
            let alts: Vec<&[i32]> = alts.iter().map(|a| a.labels.as_slice()).collect();
            choose_rigid_alternative(&alts, &others(i), areas[i])
        })
        .collect();
    (choose_alternatives(alternatives, &chosen), warnings)
}

/// One way the rigid route can carry the labels onto a shape: a source and one locally
/// optimal pose of the shape on it ([`Registration::candidates`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RigidAlternative {
    /// The source (graph order).
    pub source: usize,
    /// The pose: its index in the registration's candidates (0: the lowest residual).
    pub pose: usize,
    /// Per vertex: the label of the nearest source surface point under the pose (relaxed to
    /// affine with the route's affine step).
    pub labels: Vec<i32>,
    /// Per vertex: `1 / (1 + d / ρ)` ([`rigid_route`]).
    pub confidence: Vec<f64>,
    /// The registration's inlier share (at its best pose).
    pub inlier_share: f64,
    /// The symmetric trimmed chamfer of the pose (after the affine step), in source RMS
    /// radii.
    pub residual: f64,
}

/// Every way the rigid route can carry the labels onto each unlabelled shape (graph order;
/// empty on the sources and where no registration succeeded): per source, per distinct pose
/// of the registration onto it ([`Registration::candidates`]). The route's own choice comes
/// first (the source the shape registers best onto, its best pose), then the other sources'
/// best poses by residual, then every source's other poses in its registration's order.
/// With `all = false`, the route's own choice alone ([`rigid_route`]).
///
/// Why: a registration's poses of nearly equal residual are the geometry's own ambiguity (a
/// humanoid turned about its axis, a goblet upside down): the residual cannot choose among
/// them, and the fusion lets the other routes do it ([`super::fuse_propagation`]).
/// Cost: one affine fit and nearest-point search per (source, pose), up to four poses.
pub fn rigid_alternatives(
    meshes: &[TriMesh],
    annotations: &[Option<Vec<i32>>],
    steps: impl Into<RigidSteps>,
    all: bool,
) -> (Vec<Vec<RigidAlternative>>, Vec<String>) {
    let targets: Vec<usize> = (0..meshes.len())
        .filter(|&i| annotations[i].is_none())
        .collect();
    rigid_alternatives_cached(
        meshes,
        annotations,
        steps.into(),
        &targets,
        &RigidCache::default(),
        all,
    )
}

/// [`rigid_alternatives`] on the shapes `targets`, keeping the label-independent work in
/// `cache`.
pub(crate) fn rigid_alternatives_cached(
    meshes: &[TriMesh],
    annotations: &[Option<Vec<i32>>],
    steps: RigidSteps,
    targets: &[usize],
    cache: &RigidCache,
    all: bool,
) -> (Vec<Vec<RigidAlternative>>, Vec<String>) {
    let n = meshes.len();
    let sources: Vec<usize> = (0..n).filter(|&i| annotations[i].is_some()).collect();
    if targets.iter().any(|&i| annotations[i].is_none()) {
        cache.prepare(meshes);
    }
    type Carried = Result<Vec<RigidAlternative>, String>;
    let results: Vec<Option<Carried>> = (0..n)
        .into_par_iter()
        .map(|i| {
            if annotations[i].is_some() || !targets.contains(&i) {
                return None;
            }
            let mut registered: Vec<(usize, Registration)> = Vec::new();
            let mut error = String::new();
            for &s in &sources {
                match cache.registration(meshes, s, i, steps) {
                    Ok(r) => registered.push((s, r)),
                    Err(e) => error = e,
                }
            }
            if registered.is_empty() {
                return Some(Err(error));
            }
            // Stable: equal residuals keep the sources' order, as the route always did.
            registered.sort_by(|a, b| a.1.residual.total_cmp(&b.1.residual));
            let mut wanted: Vec<(usize, usize)> = vec![(0, 0)];
            if all {
                wanted.extend((1..registered.len()).map(|k| (k, 0)));
                for (k, (_, r)) in registered.iter().enumerate() {
                    wanted.extend((1..r.candidates.len()).map(|c| (k, c)));
                }
            }
            let mut out = Vec::with_capacity(wanted.len());
            for (k, c) in wanted {
                let (s, reg) = &registered[k];
                let s = *s;
                let ann = annotations[s].as_deref().unwrap_or_default();
                if ann.len() != meshes[s].vertex_count() {
                    return Some(Err(crate::align::AlignError::LabelCount {
                        expected: meshes[s].vertex_count(),
                        found: ann.len(),
                        kind: "vertex",
                    }
                    .to_string()));
                }
                let first = Candidate {
                    transform: reg.transform,
                    residual: reg.residual,
                    angle_to_best: 0.0,
                };
                let pose = reg.candidates.get(c).unwrap_or(&first);
                let radius = rms_radius(&meshes[s]);
                match cache.nearest(meshes, s, i, steps, pose, c) {
                    Ok((from, dist, residual)) => {
                        let labels = from.iter().map(|&v| ann[v as usize]).collect();
                        // The residual is in source RMS radii; the distances in source units.
                        let scale = radius * pose.residual.max(f64::EPSILON);
                        let confidence = dist.iter().map(|d| 1.0 / (1.0 + d / scale)).collect();
                        out.push(RigidAlternative {
                            source: s,
                            pose: c,
                            labels,
                            confidence,
                            inlier_share: reg.inlier_share,
                            residual,
                        });
                    }
                    Err(e) if out.is_empty() => return Some(Err(e)),
                    Err(_) => {}
                }
            }
            Some(Ok(out))
        })
        .collect();
    cache.store();
    let mut out = vec![Vec::new(); n];
    let mut warnings = Vec::new();
    for (i, r) in results.into_iter().enumerate() {
        match r {
            None => {}
            Some(Ok(a)) => out[i] = a,
            Some(Err(e)) => warnings.push(format!("rigid route: shape {i} not registered: {e}")),
        }
    }
    (out, warnings)
}

/// The rigid route's labels on every shape from its alternatives: on shape `i` the
/// alternative `chosen[i]` (the first where `chosen[i]` is out of range).
fn choose_alternatives(alternatives: Vec<Vec<RigidAlternative>>, chosen: &[usize]) -> RouteLabels {
    let mut out = RouteLabels::empty(alternatives.len());
    for (i, alts) in alternatives.into_iter().enumerate() {
        let k = chosen
            .get(i)
            .copied()
            .filter(|&k| k < alts.len())
            .unwrap_or(0);
        if let Some(a) = alts.into_iter().nth(k) {
            out.labels[i] = a.labels;
            out.confidence[i] = a.confidence;
            out.shape_confidence[i] = a.inlier_share;
            out.residual[i] = a.residual;
        }
    }
    out
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

/// Which of one shape's rigid alternatives ([`rigid_alternatives`], the route's own choice
/// first) the fusion takes, given the labels of other routes that fail independently of each
/// other on the shape (`others`, each as long as `areas`; a route that says nothing there is
/// left out). The route's own choice stands unless
///
/// 1. it is the outlier: it agrees with each other route less than every two other routes
///    agree with each other (Cohen's κ over the area; under the one-coin model of
///    [`super::fuse_routes`] `κ_rq = κ_r κ_q`, so this says the registration's choice is
///    estimated less accurate than every other route), and
/// 2. another alternative agrees better with *every* other route (each κ strictly higher);
///
/// then the alternative with the highest κ sum is taken (ties: the earliest). With fewer than
/// two other routes the own choice stands.
///
/// Why: a pose the geometry cannot tell from the best one (residuals within a few percent: a
/// humanoid turned about its axis, measured in docs/PROPAGATION.md) is wrong on most of the
/// shape, and every independent correspondence says so at once. Where the registration's
/// choice agrees with the others as well as they agree among themselves it is not collapsed,
/// and a pose the others prefer by a hair shares their errors rather than fixes its own (a
/// COSEG chair, 95.3 % right, replaced by a pose right on 90.5 %); a pose preferred by one
/// route alone shares that route's error (the parts' seam a little off). Routes that fail
/// together (the band affinity and parts both read from the intrinsic family, which confuse
/// a part with its mirror image alike) are one piece of evidence, not two: the caller passes
/// them only where they do not share their features. No threshold: every comparison is
/// between agreements on the same shape.
///
/// Output: an index into `alternatives` (0 with fewer than two other routes or a single
/// alternative).
pub fn choose_rigid_alternative(
    alternatives: &[&[i32]],
    others: &[&[i32]],
    areas: &[f64],
) -> usize {
    let others = voting(others, areas);
    if others.len() < 2 || alternatives.len() < 2 {
        return 0;
    }
    let agreement = |labels: &[i32]| -> Vec<f64> {
        others
            .iter()
            .map(|o| cohen_kappa(labels, o, areas))
            .collect()
    };
    if !rigid_choice_is_outlier(alternatives[0], &others, areas) {
        return 0;
    }
    let own = agreement(alternatives[0]);
    let mut best = (own.iter().sum::<f64>(), 0);
    for (k, alt) in alternatives.iter().enumerate().skip(1) {
        if alt.len() != areas.len() {
            continue;
        }
        let a = agreement(alt);
        let sum: f64 = a.iter().sum();
        if a.iter().zip(&own).all(|(x, y)| x > y) && sum > best.0 {
            best = (sum, k);
        }
    }
    best.1
}

/// Whether the rigid route's own labels on a shape (`own`) are the outlier among the routes:
/// they agree with each of the `others` (routes that fail independently; each as long as
/// `areas`, a route that says nothing there left out) less than every two of those agree with
/// each other (Cohen's κ over the area). The first test of [`choose_rigid_alternative`], cheap
/// enough to run before the other poses are carried at all. False with fewer than two other
/// routes.
pub fn rigid_choice_is_outlier(own: &[i32], others: &[&[i32]], areas: &[f64]) -> bool {
    let others = voting(others, areas);
    if others.len() < 2 || own.len() != areas.len() {
        return false;
    }
    let mut among = f64::INFINITY;
    for (x, a) in others.iter().enumerate() {
        for b in &others[x + 1..] {
            among = among.min(cohen_kappa(a, b, areas));
        }
    }
    others.iter().all(|o| cohen_kappa(own, o, areas) < among)
}

/// The routes of `others` that say something on the shape (each as long as `areas`, some
/// vertex labelled).
fn voting<'a>(others: &[&'a [i32]], areas: &[f64]) -> Vec<&'a [i32]> {
    others
        .iter()
        .copied()
        .filter(|o| o.len() == areas.len() && o.iter().any(|&l| l >= 0))
        .collect()
}
