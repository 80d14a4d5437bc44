//! [`fuse_propagation`]: the default propagation — every correspondence route, one answer.

use super::held_out::{HeldOutInputs, held_out_routes_cached};
use super::parts_route::parts_round_trip;
use super::rigid_route::{RigidSteps, rigid_route_weighed};
use super::{
    ClassifierReport, FusedRoutes, HeldOutRoutes, PropagateError, PropagateOptions, Propagation,
    RoundTrip, Route, RouteLabels, classifier_route, fuse_routes_with, parts_route, snap_labels,
};
use crate::graph::{Cosegmentation, GraphError, GraphOptions, ShapeGraph, ShapeNode};
use crate::mesh::TriMesh;
use crate::option_range::non_negative;
use crate::parts::{
    AdaptiveCosegmentation, FeatureSet, PartsFrom, PartsRequest, SegmentCollectionOptions,
    SegmentedCollection, SharedAlignment, StopReason, segment_collection_cached_sharing,
    segment_collection_sharing, snap_part_boundaries,
};
use crate::pipeline::ShapePipelineOptions;
use crate::spectral::HeatSmoother;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Which routes [`fuse_propagation`] adds to the band-affinity transport, and how the fused
/// labels' boundaries are finished. `Default` is `coseg propagate`'s default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct RouteOptions {
    /// The parts route ([`super::parts_route`]): the collection's co-segmentation as the bare
    /// `coseg segment` makes it ([`CollectionParts`]: families and number of parts chosen from
    /// the data; its part tree cut finer when the sources have more labels than it has
    /// parts), each part named from the sources. Default `true`; `false` leaves the affinity
    /// (and the other routes) alone.
    pub parts: bool,
    /// The rigid route ([`super::rigid_route`]): each unlabelled shape registered onto the
    /// sources by a similarity, labels from the nearest surface point. Default `true`.
    pub rigid: bool,
    /// How far the fused labels' boundaries may move onto a concave crease, × √(shape area)
    /// ([`super::snap_labels`]; 0.1, the band of parts from geometry, is the parts' own band).
    /// Default `0`: the boundaries stay where the votes cross. The minimum cut moves a
    /// boundary wherever a crease-free surface offers a shorter cut (permuted copies of a
    /// smooth blob: 98.1 % fused, 74.7 % snapped; tests/propagate_fusion.rs), so it is
    /// not a default until it can tell a crease from none.
    pub snap_band: f64,
    /// Whether the rigid route relaxes its similarity to an affine map before reading the
    /// labels ([`super::refine_affine`]). Default `true`.
    pub affine: bool,
    /// Whether the rigid route then deforms its source onto each shape before reading the
    /// labels ([`super::refine_nonrigid`]: an embedded deformation graph whose stiffness is
    /// lowered while held-out samples improve). Default `true`: measured on the shared,
    /// shipped and held-out generated sets, it lost no set by more than 0.1 point of the
    /// fused accuracy and gained up to 7.7 (docs/PROPAGATION.md, "the non-rigid step").
    /// Options saved without it read as `false`, as they were made.
    #[serde(default)]
    pub nonrigid: bool,
    /// The map route ([`super::map_route`]): every unlabelled shape re-labelled through a
    /// point map to its nearest source, taken on the shapes where the routes' agreement ranks
    /// the map as the most accurate route (near-isometric collections). Reads the shapes'
    /// spectra from the per-shape cache (`cache_dir`), or computes them in memory without one.
    /// Default `true`.
    pub map: bool,
    /// The classifier ([`super::classifier_route`]): a per-vertex classifier on the band
    /// features, trained on the sources and on the vertices where every route agrees, settles
    /// the vertices where the routes disagree, weighted by its accuracy on the sources.
    /// Default `false`: on held-out generated sets it gains 0.4 points on average (−0.1 to
    /// +0.9 per family) but it costs the shipped chairs 1.6 points (a chair's seat and back
    /// share bands of the intrinsic features; docs/PROPAGATION.md, "Measured: the classifier").
    pub classifier: bool,
    /// Whether the fusion from one source reads the parts route's round trip on the source
    /// (its labels carried to its own parts and back) as a ceiling on the parts route's
    /// accuracy, and where a shape's agreement triangle credits the parts above it, reads the
    /// rigid route off its agreement with the parts and the affinity off its agreement with
    /// the rigid route ([`super::RoundTrip`]). Default `false`: TOSCA wolf +8.8 points, the
    /// man-made sets measured −0.1 to +0.5 (docs/PROPAGATION.md, "the parts route's round
    /// trip"). Options saved without it read as `false`.
    #[serde(default)]
    pub round_trip: bool,
    /// Whether the band-affinity route reads the feature families the collection chose from
    /// the data (the parts route's choice, [`CollectionParts::chosen_graph`]: the extrinsic
    /// family in the collection frame added on rigid-like collections) rather than the
    /// per-shape pipeline's intrinsic family alone. Applies with the parts route on and a
    /// pipeline of the intrinsic family alone (families given with `--features` are read as
    /// given). Default `false`: the affinity route itself gains 8–22 points on the shipped
    /// families from one source, but the fusion moves −1.3 to +2.3 (quadrupeds −1.3,
    /// goblets −0.2, humanoids +0.9, chairs +2.3): an affinity that reads the parts' own
    /// families fails where they fail, and the fusion's one-coin model counts the two as
    /// independent voters (docs/PROPAGATION.md, "the band affinity on the chosen families").
    /// Options saved without it read as `false`.
    #[serde(default)]
    pub chosen_features: bool,
}

impl Default for RouteOptions {
    fn default() -> Self {
        RouteOptions {
            parts: true,
            rigid: true,
            snap_band: 0.0,
            affine: true,
            nonrigid: true,
            map: true,
            classifier: false,
            round_trip: false,
            chosen_features: false,
        }
    }
}

impl RouteOptions {
    /// All routes off and no snapping: the band-affinity transport alone, as
    /// [`super::propagate_labels`] gives it.
    pub fn affinity_only() -> Self {
        RouteOptions {
            parts: false,
            rigid: false,
            snap_band: 0.0,
            affine: true,
            nonrigid: false,
            map: false,
            classifier: false,
            round_trip: false,
            chosen_features: false,
        }
    }

    /// The rigid route's refinement steps ([`RigidSteps`]) these options ask for.
    pub fn rigid_steps(&self) -> RigidSteps {
        RigidSteps {
            affine: self.affine,
            nonrigid: self.nonrigid,
        }
    }

    pub(crate) fn validate(&self) -> Result<(), PropagateError> {
        non_negative("snap_band", self.snap_band).map_err(PropagateError::BadOption)?;
        Ok(())
    }
}

/// The collection's co-segmentation for the parts route: the parts `coseg segment FOLDER`
/// makes with no flag (the feature families chosen from the data, the part tree of parts from
/// geometry cut where the data says), made once and kept; when the sources have more labels
/// than the data's cut has parts, the same part tree is cut finer, at the number of labels
/// (naming merges parts that carry the same label, so a finer cut loses nothing, while a
/// coarser one would have to give two labels one part).
#[derive(Debug, Clone)]
pub struct CollectionParts {
    nodes: Vec<ShapeNode>,
    /// `coseg segment`'s bare options under the propagation's pipeline and graph.
    options: SegmentCollectionOptions,
    /// Whether the per-shape pipeline holds the intrinsic family alone (no extrinsic, SDF or
    /// user columns): what the parts read when their families are taken as given.
    intrinsic_pipeline: bool,
    /// The per-shape pipeline the nodes were computed with: with `cache`, what keys each
    /// shape's part-tree entry ([`crate::pipeline::shape_key`]).
    pipeline: ShapePipelineOptions,
    /// Where the bare co-segmentation's part tree is kept between runs (the part cues' folder:
    /// the cache of the per-shape stage); `None`: grown every run.
    cache: Option<PathBuf>,
    /// The bare co-segmentation, once made.
    data: Option<DataParts>,
    /// Per number of labels above the data's count of parts: the finer co-segmentation the
    /// parts route reads and whether it read the intrinsic family alone.
    made: BTreeMap<usize, (Cosegmentation, bool)>,
}

/// What [`CollectionParts`] keeps of the bare co-segmentation: its parts, its part tree (to
/// cut finer) and what it read.
#[derive(Debug, Clone)]
struct DataParts {
    /// The data's own cut.
    segmentation: Cosegmentation,
    /// The part tree over the equal-area leaves (parts from geometry).
    tree: Option<AdaptiveCosegmentation>,
    /// Whether the parts read the intrinsic family alone.
    intrinsic: bool,
    /// The shape graph the parts were made on: the columns of the families chosen from the
    /// data (the extrinsic family's in the collection frame appended when chosen) and their
    /// weights.
    graph: ShapeGraph,
}

impl CollectionParts {
    /// The parts of the shapes `nodes` (graph order) under the per-shape `pipeline` they were
    /// computed with and the shape `graph`'s options, made as `coseg segment` makes them:
    /// with the intrinsic family alone in the pipeline the families are chosen from the data
    /// (as `coseg segment` without `--features`), otherwise the pipeline's families are taken
    /// as given (its weights, up direction and mirror-invariant columns, as `coseg segment
    /// --features …`); `cue_cache`: the cache folder where each shape's part cues and the
    /// collection's part tree are kept, as `coseg segment` keeps them
    /// ([`crate::parts::segment_collection_cached`]: a warm run with the same shapes reads
    /// the tree and only cuts it, with the same result bit for bit); `None`: computed every
    /// run.
    pub fn new(
        nodes: Vec<ShapeNode>,
        pipeline: &ShapePipelineOptions,
        graph: &GraphOptions,
        cue_cache: Option<PathBuf>,
    ) -> Self {
        let features = nodes.first().map_or(0, |n| n.bands.features);
        let f = &pipeline.families;
        let intrinsic_pipeline = f.extrinsic.is_none() && f.sdf.is_none() && f.user.is_none();
        // `coseg segment`'s bare options (`SegmentJob::collection_options` with no mode flag):
        // parts from geometry, their number chosen from the part tree, the families chosen
        // from the data unless the pipeline has others than the intrinsic one.
        let cache = cue_cache.clone();
        let mut options = SegmentCollectionOptions {
            graph: *graph,
            cue_cache,
            ..SegmentCollectionOptions::default()
        };
        options.set_pipeline(pipeline, !intrinsic_pipeline, features);
        CollectionParts {
            nodes,
            options,
            intrinsic_pipeline,
            pipeline: pipeline.clone(),
            cache,
            data: None,
            made: BTreeMap::new(),
        }
    }

    /// The co-segmentation the parts route reads for sources with `count` distinct labels:
    /// the bare co-segmentation ([`Self::data_parts`]) when it has at least `count` parts,
    /// otherwise its part tree cut at `count` parts (made on the first call for `count`).
    ///
    /// Errors: those of [`segment_collection`](crate::parts::segment_collection).
    pub fn parts(
        &mut self,
        count: usize,
        meshes: &[TriMesh],
    ) -> Result<&Cosegmentation, GraphError> {
        self.parts_smoothed(count, meshes, None)
    }

    /// [`Self::parts`] with the refinement reading `smoothers` (one per mesh, as the
    /// propagation made them) where their time is the refinement's: the same co-segmentation,
    /// without a second heat smoother per shape.
    ///
    /// Errors: those of [`segment_collection`](crate::parts::segment_collection).
    pub fn parts_smoothed(
        &mut self,
        count: usize,
        meshes: &[TriMesh],
        smoothers: Option<&[HeatSmoother]>,
    ) -> Result<&Cosegmentation, GraphError> {
        self.parts_sharing(count, meshes, smoothers, None)
    }

    /// [`Self::parts_smoothed`] with the collection alignment of `meshes` made by the caller
    /// ([`SharedAlignment`]; the rigid route's): the same co-segmentation without aligning
    /// the collection a second time.
    pub(crate) fn parts_sharing(
        &mut self,
        count: usize,
        meshes: &[TriMesh],
        smoothers: Option<&[HeatSmoother]>,
        alignment: Option<SharedAlignment<'_>>,
    ) -> Result<&Cosegmentation, GraphError> {
        if self
            .data(meshes, smoothers, alignment)?
            .segmentation
            .tuples
            .len()
            >= count
        {
            // Every tuple is a part to name, the leftovers' too (the tree's cut counts them).
            return Ok(&self.data.as_ref().expect("made above").segmentation);
        }
        if !self.made.contains_key(&count) {
            let made = self.finer_than(count, meshes, smoothers, alignment)?;
            self.made.insert(count, made);
        }
        Ok(&self.made[&count].0)
    }

    /// The bare co-segmentation of `coseg segment` (made on the first call): the parts whose
    /// number the data chose.
    ///
    /// Errors: those of [`segment_collection`](crate::parts::segment_collection).
    pub fn data_parts(
        &mut self,
        meshes: &[TriMesh],
        smoothers: Option<&[HeatSmoother]>,
    ) -> Result<&Cosegmentation, GraphError> {
        Ok(&self.data(meshes, smoothers, None)?.segmentation)
    }

    fn data(
        &mut self,
        meshes: &[TriMesh],
        smoothers: Option<&[HeatSmoother]>,
        alignment: Option<SharedAlignment<'_>>,
    ) -> Result<&DataParts, GraphError> {
        if self.data.is_none() {
            let s = match &self.cache {
                // The nodes' own keys: a part-tree entry written by `coseg segment` on the
                // same shapes under the same options is this tree too.
                Some(dir) if meshes.len() == self.nodes.len() => {
                    let keys: Vec<_> = meshes
                        .iter()
                        .map(|m| crate::pipeline::shape_key(m, &self.pipeline))
                        .collect();
                    segment_collection_cached_sharing(
                        self.nodes.clone(),
                        meshes,
                        &self.options,
                        dir,
                        &keys,
                        smoothers,
                        alignment,
                    )?
                    .0
                }
                _ => segment_collection_sharing(
                    self.nodes.clone(),
                    meshes,
                    &self.options,
                    smoothers,
                    alignment,
                )?,
            };
            let intrinsic = self.read_intrinsic(&s);
            let tree = s
                .adaptive
                .filter(|a| matches!(a.stop, StopReason::EqualAreaLeaves));
            self.data = Some(DataParts {
                segmentation: s.segmentation,
                tree,
                intrinsic,
                graph: s.graph,
            });
        }
        Ok(self.data.as_ref().expect("made above"))
    }

    /// Whether the co-segmentation `s` read the intrinsic family alone: the families it chose
    /// from the data, or the pipeline's when taken as given.
    fn read_intrinsic(&self, s: &SegmentedCollection) -> bool {
        s.features.as_ref().map_or(self.intrinsic_pipeline, |c| {
            c.chosen == FeatureSet::Intrinsic
        })
    }

    /// More than the data's cut of parts, `count`: its tree cut finer, or (a tree with fewer
    /// leaves than `count`) a co-segmentation into `count` parts made for it.
    fn finer_than(
        &mut self,
        count: usize,
        meshes: &[TriMesh],
        smoothers: Option<&[HeatSmoother]>,
        alignment: Option<SharedAlignment<'_>>,
    ) -> Result<(Cosegmentation, bool), GraphError> {
        let band = match self.options.parts_from {
            PartsFrom::Geometry { band, .. } => band,
            PartsFrom::Adaptive => 0.0,
        };
        let data = self.data(meshes, smoothers, alignment)?;
        if let Some(tree) = data.tree.as_ref().filter(|a| a.tree.leaves >= count) {
            let cut = snap_part_boundaries(meshes, &tree.cut(count), band)?;
            return Ok((cut, data.intrinsic));
        }
        // More labels than the tree has leaves: as many equal-area leaves as labels, cut at
        // the number of labels.
        let mut o = self.options.clone();
        o.request_parts(PartsRequest::Count(count), None);
        o.set_parts_from(
            PartsFrom::Geometry {
                leaves: crate::parts::GEOMETRY_LEAVES.max(count),
                band,
            },
            None,
        );
        let s = segment_collection_sharing(self.nodes.clone(), meshes, &o, smoothers, alignment)?;
        let intrinsic = self.read_intrinsic(&s);
        Ok((s.segmentation, intrinsic))
    }

    /// The shape graph over the feature families the collection chose from the data, when
    /// they are not the per-shape pipeline's: `Some` when the pipeline holds the intrinsic
    /// family alone and the bare co-segmentation ([`Self::data_parts`], made here if it was
    /// not yet) chose the extrinsic family too, in the collection frame; `None` when the
    /// pipeline's own graph reads the same families. The graph's nodes are the pipeline's
    /// with the extrinsic columns appended, its feature weights the choice's (one share each
    /// for the spectral columns, the heights and distances, and the normal columns).
    ///
    /// Errors: those of [`segment_collection`](crate::parts::segment_collection).
    pub fn chosen_graph(
        &mut self,
        meshes: &[TriMesh],
        smoothers: Option<&[HeatSmoother]>,
    ) -> Result<Option<ShapeGraph>, GraphError> {
        self.chosen_graph_sharing(meshes, smoothers, None)
    }

    /// [`Self::chosen_graph`] with the collection alignment of `meshes` made by the caller
    /// ([`SharedAlignment`]; the rigid route's).
    pub(crate) fn chosen_graph_sharing(
        &mut self,
        meshes: &[TriMesh],
        smoothers: Option<&[HeatSmoother]>,
        alignment: Option<SharedAlignment<'_>>,
    ) -> Result<Option<ShapeGraph>, GraphError> {
        if !self.intrinsic_pipeline {
            return Ok(None);
        }
        let data = self.data(meshes, smoothers, alignment)?;
        Ok((!data.intrinsic).then(|| data.graph.clone()))
    }

    /// Whether the co-segmentation for `count` labels, once made, read the intrinsic family
    /// alone (the families chosen from the data, or the pipeline's when taken as given);
    /// `None` before [`Self::parts`] made it.
    pub fn intrinsic_only(&self, count: usize) -> Option<bool> {
        match &self.data {
            Some(d) if d.segmentation.tuples.len() >= count => Some(d.intrinsic),
            _ => self.made.get(&count).map(|m| m.1),
        }
    }
}

/// What [`fuse_propagation`] did.
#[derive(Debug, Clone, Default)]
pub struct FusionReport {
    /// Each route's own labels, in the order of [`FusedRoutes::weights`].
    pub routes: Vec<(Route, RouteLabels)>,
    /// The fused labels (before the boundary snapping) and each route's trust per shape.
    pub fused: FusedRoutes,
    /// Optional routes that could not run, for the user.
    pub warnings: Vec<String>,
    /// Per route (the order of `routes`), its accuracy on the sources, each carried to from
    /// the others ([`super::held_out_accuracy`]); `None` with fewer than two sources.
    pub held_out: Option<Vec<f64>>,
    /// The held-out runs themselves (each source's labels from every route); `None` with
    /// fewer than two sources.
    pub held_out_runs: Option<HeldOutRoutes>,
    /// What the classifier did ([`super::classifier_route`]); `None` where it did not run.
    pub classifier: Option<ClassifierReport>,
}

/// Fuses the band-affinity `propagation` with the other correspondence routes of `options`
/// ([`fuse_routes`]) and, with a `snap_band` above 0, moves the fused boundaries onto
/// creases ([`snap_labels`]); the fused labels and their margins replace the unlabelled
/// shapes' labels and confidences in `propagation` (the sources keep their annotations), so that
/// [`Propagation::update`] continues from them.
///
/// With two sources or more each route's trust is set by its accuracy on the sources
/// themselves ([`super::held_out_accuracy`], [`fuse_routes_with`]): every source carried to from
/// the others by each route and scored against its own labels.
///
/// Inputs: `graph`, `meshes` (#shapes, graph order), `annotations` (as given to
/// [`super::propagate_labels`]), the affinity `propagation` of them, `parts` (the
/// collection's co-segmentations, reused across calls; `None` skips the parts route),
/// `smoothers` and `propagate` as the affinity solve used them (the held-out runs repeat it).
/// Output: the [`FusionReport`]. An optional route that fails (its co-segmentation cannot be
/// made) is left out with a warning.
///
/// Errors: [`PropagateError::BadOption`] for invalid options or inputs that do not fit.
#[allow(clippy::too_many_arguments)]
pub fn fuse_propagation(
    graph: &ShapeGraph,
    meshes: &[TriMesh],
    annotations: &[Option<Vec<i32>>],
    propagation: &mut Propagation,
    parts: Option<&mut CollectionParts>,
    smoothers: Option<&[HeatSmoother]>,
    propagate: &PropagateOptions,
    options: &RouteOptions,
) -> Result<FusionReport, PropagateError> {
    options.validate()?;
    let n = graph.node_count();
    if meshes.len() != n || annotations.len() != n {
        return Err(PropagateError::BadOption(format!(
            "{} meshes and {} annotations for {n} shapes",
            meshes.len(),
            annotations.len()
        )));
    }
    let areas: Vec<&[f64]> = (0..n).map(|i| graph.node(i).areas.as_slice()).collect();
    let mut report = FusionReport::default();
    let mut affinity = RouteLabels::empty(n);
    for i in (0..n).filter(|&i| annotations[i].is_none()) {
        affinity.labels[i] = propagation.labels[i].clone();
        affinity.confidence[i] = propagation.confidence[i].clone();
        affinity.shape_confidence[i] = propagation.shape_confidence[i];
    }
    report.routes.push((Route::Affinity, affinity));
    let mut segmentation = None;
    let mut parts_intrinsic = false;
    let mut parts_trip = None;
    if let (true, Some(parts)) = (options.parts, parts) {
        let count = propagation.parts.len();
        let _t = crate::stage_timer::stage("parts route (co-segmentation)");
        // The collection alignment the rigid route starts from, made here once for both.
        let rigid = &propagation.rigid;
        let alignment = || rigid.alignment(meshes);
        match parts.parts_sharing(count, meshes, smoothers, Some(&alignment)) {
            Ok(_) => {
                parts_intrinsic = parts.intrinsic_only(count).unwrap_or(true);
                let seg = parts.parts(count, meshes)?;
                report
                    .routes
                    .push((Route::Parts, parts_route(seg, annotations, &areas)));
                parts_trip = parts_round_trip(seg, annotations, &areas);
                segmentation = Some(seg);
            }
            Err(e) => report
                .warnings
                .push(format!("parts route off: the co-segmentation failed: {e}")),
        }
    }
    // The rigid route's other poses and sources are weighed only against routes that fail
    // independently: parts from the intrinsic family share the affinity's mirror confusions
    // (`choose_rigid_alternative`).
    let rigid_poses = segmentation.is_some() && !parts_intrinsic;
    if options.rigid {
        let targets: Vec<usize> = (0..n).filter(|&i| annotations[i].is_none()).collect();
        let _t = crate::stage_timer::stage("rigid route");
        let (rigid, warnings) = rigid_route_weighed(
            meshes,
            annotations,
            options.rigid_steps(),
            &targets,
            &propagation.rigid,
            rigid_poses,
            |i| {
                report
                    .routes
                    .iter()
                    .filter(|(_, r)| r.votes_on(i))
                    .map(|(_, r)| r.labels[i].as_slice())
                    .collect()
            },
            &areas,
        );
        report.warnings.extend(warnings);
        report.routes.push((Route::Rigid, rigid));
    }
    let names: Vec<Route> = report.routes.iter().map(|(r, _)| *r).collect();
    let held_out = HeldOutInputs {
        graph,
        meshes,
        annotations,
        smoothers,
        propagate,
        routes: &names,
        segmentation,
        steps: options.rigid_steps(),
    };
    let timer = crate::stage_timer::stage("held-out routes on the sources");
    report.held_out_runs = held_out_routes_cached(
        &held_out,
        &propagation.rigid,
        rigid_poses,
        Some(propagation),
    )?;
    drop(timer);
    let _t = crate::stage_timer::stage("fusion and snapping");
    report.held_out = report.held_out_runs.as_ref().map(|h| h.accuracy.clone());
    let refs: Vec<&RouteLabels> = report.routes.iter().map(|(_, r)| r).collect();
    // The band affinity and the parts route fail together where both read the intrinsic
    // family alone (parts on the intrinsic family imply a pipeline without other families,
    // so the affinity reads it alone too): intrinsic descriptors cannot tell a part from its mirror image, so both
    // confuse the same pairs. Parts made with the extrinsic family (an aligned collection,
    // chosen from the data) do not share that failure, and modelling a shared failure that
    // is not there reads a rigid alignment that collapsed (agreeing with neither) as the
    // pair failing together and hands the shape to it (shipped humanoids from one source:
    // docs/PROPAGATION.md).
    let shared = names
        .iter()
        .position(|&r| r == Route::Affinity)
        .zip(names.iter().position(|&r| r == Route::Parts))
        .filter(|_| parts_intrinsic);
    // The parts route's round trip on the sources measures its accuracy; the band affinity
    // reads the same band features, so it is the partner whose agreement with the parts is
    // not read (`fuse_routes_with`).
    let position = |route: Route| names.iter().position(|&r| r == route);
    let round_trip = match (
        position(Route::Parts),
        position(Route::Affinity),
        parts_trip,
    ) {
        (Some(route), Some(partner), Some(accuracy)) if options.round_trip => Some(RoundTrip {
            route,
            partner,
            accuracy,
        }),
        _ => None,
    };
    report.fused = fuse_routes_with(
        &refs,
        &areas,
        report.held_out.as_deref(),
        shared,
        round_trip,
    );
    if options.classifier {
        let _t = crate::stage_timer::stage("classifier");
        report.classifier = Some(classifier_route(
            graph,
            annotations,
            &refs,
            &mut report.fused,
            smoothers,
        ));
    }
    let snapped = snap_labels(meshes, &report.fused.labels, options.snap_band)?;
    for (i, labels) in snapped.into_iter().enumerate() {
        if annotations[i].is_some() || labels.is_empty() {
            continue;
        }
        let conf = report.fused.confidence[i].clone();
        propagation.set_labels_confidence(graph, i, labels, conf);
    }
    Ok(report)
}
