//! [`segment_collection_cached`]: the collection stage of parts from geometry through a cache
//! entry holding its part tree, so that a run that differs from an earlier one only in the
//! number of parts asked for (`coseg segment --parts auto|N`) reads the tree and only cuts it.
//!
//! # What is stored, and why
//! The cut ([`cut_part_tree`]) reads the leaves and the tree over them, the meshes (loaded by
//! the per-shape stage anyway) and, for `summary.json` and the mirror pairs of the final parts,
//! the shape graph and the feature choice. The entry ([`EntryKind::PartTree`]) holds the
//! leaves, the tree, the feature choice with the options it set (weights, up direction,
//! mirror-invariant columns) and its warnings, and, when the extrinsic family was chosen, its
//! band tables (computed from the collection alignment, the costly part of the choice). The
//! graph is not stored: it is rebuilt from the per-shape nodes and those tables as the feature
//! choice built it (band summaries and edge weights: a re-cut of the 22 COSEG chairs without
//! pictures, rebuild included, takes about 1 s CPU against 64 s cold, docs/PARTS.md), and an
//! entry is only written when the rebuilt graph equals the one the tree was grown on, so that
//! a re-cut is the cold run's result bit for bit.
//!
//! # Key
//! [`part_tree_key`]: every shape's per-shape key and name in order, every option of the
//! collection stage but the number of parts asked for, the cache format, this entry's layout
//! version, the crate version and a hash of the crate's sources at build time (the tree depends
//! on every algorithm of the stage, which no option names: a build with other code reads no
//! entry of another build). Anything else that changes (a file, an option) gives another key.

use super::adaptive_cosegment::{AdaptiveCosegmentation, PartTree, StopReason};
use super::aligned_extrinsic_bands::concat_tables;
use super::choose_features::SharedAlignment;
use super::choose_features::{FeatureChoice, FeatureSet};
use super::paired_advantage::PairedAdvantage;
use super::segment_collection::{
    PartTreeStage, PartsFrom, SegmentCollectionOptions, SegmentTimes, SegmentedCollection,
    cut_part_tree, part_tree_sharing, segment_collection_sharing,
};
use super::spectral_agreement::SpectralAgreement;
use crate::align::FrameCase;
use crate::bands::BandTable;
use crate::cache::{
    CacheOutcome, EntryKind, FORMAT_VERSION, Lookup, ShapeKey, encode_entry, entry_path,
    read_entry, write_entry,
};
use crate::graph::{Cosegmentation, GraphError, GraphOptions, ShapeGraph, ShapeNode};
use crate::mesh::TriMesh;
use crate::spectral::HeatSmoother;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Version of the part-tree entry's layout ([`StoredPartTree`]); part of [`part_tree_key`].
const PART_TREE_VERSION: u32 = 2;

/// The cache key of a collection's part tree: BLAKE3 of the cache format, the entry's layout
/// version, the crate version, the hash of the crate's sources at build time, then per shape
/// (in graph order) its per-shape key ([`crate::pipeline::shape_key`]) and name, then the
/// `Debug` form of `options` with the number of parts asked for
/// ([`super::AdaptiveOptions::parts`], [`super::AdaptiveOptions::max_parts`]) and the part-cue
/// cache folder (which changes no result) cleared.
///
/// ```
/// use coseg::cache::ShapeKey;
/// use coseg::parts::{PartsRequest, SegmentCollectionOptions, part_tree_key};
/// let keys = [ShapeKey([1; 32]), ShapeKey([2; 32])];
/// let names = ["a".to_string(), "b".to_string()];
/// let mut o = SegmentCollectionOptions::default();
/// let auto = part_tree_key(&keys, &names, &o);
/// o.request_parts(PartsRequest::Count(3), None);
/// assert_eq!(part_tree_key(&keys, &names, &o), auto); // another cut of the same tree
/// o.set_snap_band(0.05).unwrap();
/// assert_ne!(part_tree_key(&keys, &names, &o), auto);
/// ```
pub fn part_tree_key(
    shape_keys: &[ShapeKey],
    names: &[String],
    options: &SegmentCollectionOptions,
) -> ShapeKey {
    let mut o = options.clone();
    if let Some(p) = o.parts.as_mut() {
        p.parts = None;
        p.max_parts = 0;
    }
    o.cue_cache = None;
    let mut h = blake3::Hasher::new();
    h.update(b"coseg part tree key");
    h.update(&FORMAT_VERSION.to_le_bytes());
    h.update(&PART_TREE_VERSION.to_le_bytes());
    for s in [env!("CARGO_PKG_VERSION"), env!("COSEG_SOURCE_HASH")] {
        h.update(&(s.len() as u64).to_le_bytes());
        h.update(s.as_bytes());
    }
    h.update(&(shape_keys.len() as u64).to_le_bytes());
    h.update(&(names.len() as u64).to_le_bytes());
    for (k, n) in shape_keys.iter().zip(names) {
        h.update(&k.0);
        h.update(&(n.len() as u64).to_le_bytes());
        h.update(n.as_bytes());
    }
    // `Debug` names every field, those `summary.json` leaves out too (the feature-choice
    // options, the up direction), and prints floats so that they read back exactly.
    h.update(format!("{o:?}").as_bytes());
    ShapeKey(*h.finalize().as_bytes())
}

/// The feature choice as stored: [`FeatureChoice`] skips its up direction in `summary.json`
/// when there is none, which a bincode payload cannot read back.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct StoredChoice {
    extrinsic: bool,
    intrinsic_score: f64,
    aligned_score: Option<f64>,
    /// [`PairedAdvantage`]: shapes, mean, standard error, t, p-value.
    spectral_advantage: Option<(usize, f64, f64, f64, f64)>,
    significance: f64,
    spectral_agreement: Option<SpectralAgreement>,
    aligned_scores: Vec<f64>,
    frame: Option<FrameCase>,
    up: Option<[f64; 3]>,
    reason: String,
}

impl From<&FeatureChoice> for StoredChoice {
    fn from(c: &FeatureChoice) -> Self {
        Self {
            extrinsic: c.chosen == FeatureSet::IntrinsicExtrinsic,
            intrinsic_score: c.intrinsic_score,
            aligned_score: c.aligned_score,
            spectral_advantage: c
                .spectral_advantage
                .map(|a| (a.shapes, a.mean, a.standard_error, a.t, a.p_value)),
            significance: c.significance,
            spectral_agreement: c.spectral_agreement.clone(),
            aligned_scores: c.aligned_scores.clone(),
            frame: c.frame,
            up: c.up,
            reason: c.reason.clone(),
        }
    }
}

impl From<StoredChoice> for FeatureChoice {
    fn from(c: StoredChoice) -> Self {
        Self {
            chosen: if c.extrinsic {
                FeatureSet::IntrinsicExtrinsic
            } else {
                FeatureSet::Intrinsic
            },
            intrinsic_score: c.intrinsic_score,
            aligned_score: c.aligned_score,
            spectral_advantage: c.spectral_advantage.map(
                |(shapes, mean, standard_error, t, p_value)| PairedAdvantage {
                    shapes,
                    mean,
                    standard_error,
                    t,
                    p_value,
                },
            ),
            significance: c.significance,
            spectral_agreement: c.spectral_agreement,
            aligned_scores: c.aligned_scores,
            frame: c.frame,
            up: c.up,
            reason: c.reason,
        }
    }
}

/// The payload of a part-tree entry: a [`PartTreeStage`] without its graph (rebuilt from the
/// per-shape nodes and `extra_columns`).
#[derive(Debug, Clone, Serialize, Deserialize)]
struct StoredPartTree {
    /// Per shape: name, vertex count and the per-shape nodes' column count, checked against
    /// the nodes of the run that reads the entry.
    names: Vec<String>,
    vertices: Vec<usize>,
    columns: usize,
    /// Per shape, the graph's columns after the nodes' own (the extrinsic family in the
    /// collection frame, when the feature choice added it).
    extra_columns: Option<Vec<BandTable>>,
    feature_weights: Option<Vec<f64>>,
    up: Option<[f64; 3]>,
    mirror_columns: Vec<usize>,
    features: Option<StoredChoice>,
    warnings: Vec<String>,
    leaves: Cosegmentation,
    tree: PartTree,
    leaf_origin: Vec<usize>,
    leaf_copies: Vec<(usize, usize)>,
}

/// The graph the feature choice builds over `nodes` with `extra` columns appended and
/// `weights` set (the intrinsic family alone: no columns, no weights).
fn rebuild_graph(
    nodes: Vec<ShapeNode>,
    extra: Option<&[BandTable]>,
    weights: Option<Vec<f64>>,
    options: &GraphOptions,
) -> Result<ShapeGraph, GraphError> {
    let nodes = match extra {
        Some(tables) => nodes
            .into_iter()
            .zip(tables)
            .map(|(n, t)| ShapeNode {
                bands: concat_tables(&n.bands, t).into(),
                ..n
            })
            .collect(),
        None => nodes,
    };
    let mut graph = ShapeGraph::build(nodes, options)?;
    if extra.is_some() || weights.is_some() {
        graph.set_feature_weights(weights)?;
    }
    Ok(graph)
}

/// Columns `from..` of `t`.
fn columns_from(t: &BandTable, from: usize) -> BandTable {
    let features = t.features - from;
    let mut labels = Vec::with_capacity(t.vertices * features);
    for v in 0..t.vertices {
        labels.extend_from_slice(&t.row(v)[from..]);
    }
    BandTable {
        features,
        vertices: t.vertices,
        bands: t.bands,
        labels,
    }
}

/// Whether two graphs have the same nodes, edges and kind.
fn same_graph(a: &ShapeGraph, b: &ShapeGraph) -> bool {
    a.kind() == b.kind()
        && a.node_count() == b.node_count()
        && (0..a.node_count()).all(|i| a.node(i) == b.node(i))
        && a.edges() == b.edges()
}

/// What to store of `stage`, grown over `nodes` with `options`; `Err` when the graph rebuilt
/// from it would not be the stage's (the entry would not give the cold result).
fn stored(
    stage: &PartTreeStage,
    nodes: Vec<ShapeNode>,
    options: &SegmentCollectionOptions,
) -> Result<StoredPartTree, String> {
    let columns = nodes.first().map_or(0, |n| n.bands.features);
    let graph = &stage.graph;
    if graph.node_count() != nodes.len() || nodes.iter().any(|n| n.bands.features != columns) {
        return Err("the graph's shapes are not the nodes".into());
    }
    let wider = (0..nodes.len())
        .map(|i| graph.node(i).bands.features)
        .collect::<Vec<_>>();
    let extra_columns = if wider.iter().all(|&w| w == columns) {
        None
    } else if wider.iter().all(|&w| w > columns) {
        Some(
            (0..nodes.len())
                .map(|i| columns_from(&graph.node(i).bands, columns))
                .collect::<Vec<_>>(),
        )
    } else {
        return Err("the graph's shapes have other columns than the nodes".into());
    };
    let names = nodes.iter().map(|n| n.name.clone()).collect();
    let vertices = nodes.iter().map(|n| n.bands.vertices).collect();
    let rebuilt = rebuild_graph(
        nodes,
        extra_columns.as_deref(),
        stage.feature_weights.clone(),
        &options.graph,
    )
    .map_err(|e| e.to_string())?;
    if !same_graph(&rebuilt, graph) {
        return Err("the shape graph would not be rebuilt as it was".into());
    }
    let tree = &stage.tree;
    Ok(StoredPartTree {
        names,
        vertices,
        columns,
        extra_columns,
        feature_weights: stage.feature_weights.clone(),
        up: stage.up,
        mirror_columns: stage.mirror_columns.clone(),
        features: stage.features.as_ref().map(StoredChoice::from),
        warnings: stage.warnings.clone(),
        leaves: tree.leaves.clone(),
        tree: tree.tree.clone(),
        leaf_origin: tree.leaf_origin.clone(),
        leaf_copies: tree.leaf_copies.clone(),
    })
}

/// Whether `s` fits `nodes` and is whole: every index it holds in range, so that cutting it
/// cannot fail or panic.
fn check(s: &StoredPartTree, nodes: &[ShapeNode]) -> Result<(), String> {
    let n = nodes.len();
    let fits = s.names.len() == n
        && s.vertices.len() == n
        && nodes.iter().zip(&s.names).all(|(a, b)| a.name == *b)
        && nodes
            .iter()
            .zip(&s.vertices)
            .all(|(a, &d)| a.bands.vertices == d && a.bands.features == s.columns);
    if !fits {
        return Err("stale entry (other shapes)".into());
    }
    let l = &s.leaves;
    let shape_ok = l.names == s.names
        && l.vertices == s.vertices
        && l.root < n
        && l.order.len() == n
        && l.order.iter().all(|&i| i < n)
        && l.parent.len() == n
        && l.parent.iter().flatten().all(|&i| i < n);
    let tuples_ok = l.tuples.iter().all(|t| {
        t.regions.len() == n
            && t.area_fractions.len() == n
            && t.regions
                .iter()
                .zip(&s.vertices)
                .all(|(r, &d)| r.iter().all(|&v| (v as usize) < d))
    });
    let leaves = l.tuples.len();
    let tree_ok = s.tree.leaves == leaves
        && leaves > 0
        && s.tree.merges.len() < leaves
        && s.tree
            .merges
            .iter()
            .enumerate()
            .all(|(k, m)| m.a < leaves + k && m.b < leaves + k && m.a != m.b)
        && s.leaf_copies.iter().all(|&(a, b)| a < leaves && b < leaves);
    let tables_ok = s.extra_columns.as_ref().is_none_or(|t| {
        t.len() == n
            && t.iter().zip(nodes).all(|(t, node)| {
                t.vertices == node.bands.vertices
                    && t.bands == node.bands.bands
                    && t.labels.len() == t.vertices * t.features
                    && t.labels.iter().all(|&b| (b as usize) < t.bands)
            })
    });
    if shape_ok && tuples_ok && tree_ok && tables_ok {
        Ok(())
    } else {
        Err("inconsistent part tree".into())
    }
}

/// The stage `s` stores, over `nodes` (checked by [`check`]).
fn restore(
    s: StoredPartTree,
    nodes: Vec<ShapeNode>,
    options: &SegmentCollectionOptions,
) -> Result<PartTreeStage, String> {
    let graph = rebuild_graph(
        nodes,
        s.extra_columns.as_deref(),
        s.feature_weights.clone(),
        &options.graph,
    )
    .map_err(|e| format!("its graph cannot be rebuilt ({e})"))?;
    Ok(PartTreeStage {
        graph,
        tree: AdaptiveCosegmentation {
            leaves: s.leaves,
            auto: Vec::new(),
            stop: StopReason::EqualAreaLeaves,
            tree: s.tree,
            leaf_origin: s.leaf_origin,
            leaf_copies: s.leaf_copies,
        },
        features: s.features.map(FeatureChoice::from),
        up: s.up,
        mirror_columns: s.mirror_columns,
        feature_weights: s.feature_weights,
        warnings: s.warnings,
        run_warnings: Vec::new(),
        times: SegmentTimes::default(),
    })
}

/// [`segment_collection`](super::segment_collection) through the part-tree cache in `cache_dir`: with parts from geometry
/// (the default), the part tree of these shapes and options ([`part_tree_key`];
/// `shape_keys[i]` is shape `i`'s per-shape key) is read from its entry when there is one and
/// only cut ([`cut_part_tree`]), else grown ([`part_tree`](super::part_tree)), written, and cut. The result is
/// [`segment_collection`](super::segment_collection)'s, bit for bit, either way. In the other modes (equal-area regions,
/// adaptive parts) nothing is cached and the outcome is `None`.
///
/// The outcome says where the tree came from: [`CacheOutcome::Hit`] (read, only cut),
/// [`CacheOutcome::Miss`] (grown), [`CacheOutcome::Recomputed`] (an entry that could not be
/// trusted, with the reason, also among the result's warnings). An entry that cannot be
/// written is a warning too; the result does not depend on it.
///
/// Errors: those of [`segment_collection`](super::segment_collection); [`GraphError::BadOption`] when `shape_keys` or
/// `meshes` are not one per node.
pub fn segment_collection_cached(
    nodes: Vec<ShapeNode>,
    meshes: &[TriMesh],
    options: &SegmentCollectionOptions,
    cache_dir: &Path,
    shape_keys: &[ShapeKey],
) -> Result<(SegmentedCollection, Option<CacheOutcome>), GraphError> {
    segment_collection_cached_sharing(nodes, meshes, options, cache_dir, shape_keys, None, None)
}

/// [`segment_collection_cached`] reading the caller's heat smoothers and collection alignment
/// where a tree is grown ([`segment_collection_sharing`](super::segment_collection_sharing)): the same result, bit for bit.
pub(crate) fn segment_collection_cached_sharing(
    nodes: Vec<ShapeNode>,
    meshes: &[TriMesh],
    options: &SegmentCollectionOptions,
    cache_dir: &Path,
    shape_keys: &[ShapeKey],
    smoothers: Option<&[HeatSmoother]>,
    alignment: Option<SharedAlignment<'_>>,
) -> Result<(SegmentedCollection, Option<CacheOutcome>), GraphError> {
    let geometry =
        options.parts.is_some() && matches!(options.parts_from, PartsFrom::Geometry { .. });
    if !geometry {
        let result = segment_collection_sharing(nodes, meshes, options, smoothers, alignment)?;
        return Ok((result, None));
    }
    if shape_keys.len() != nodes.len() || meshes.len() != nodes.len() {
        return Err(GraphError::BadOption(format!(
            "a cached collection stage needs one key and one mesh per shape ({} shapes, {} keys, {} meshes)",
            nodes.len(),
            shape_keys.len(),
            meshes.len()
        )));
    }
    let names: Vec<String> = nodes.iter().map(|n| n.name.clone()).collect();
    let key = part_tree_key(shape_keys, &names, options);
    let path = entry_path(cache_dir, &key, EntryKind::PartTree);
    let mut warnings = Vec::new();
    let lookup = {
        let _t = crate::stage_timer::stage("parts: read part tree");
        read_entry(&path, EntryKind::PartTree, &key, |s: &StoredPartTree| {
            check(s, &nodes)
        })
    };
    let untrusted = match lookup {
        Lookup::Hit(s) => match restore(s, nodes.clone(), options) {
            Ok(stage) => {
                let result = cut_part_tree(stage, meshes, options)?;
                return Ok((result, Some(CacheOutcome::Hit)));
            }
            Err(reason) => Some(reason),
        },
        Lookup::Missing => None,
        Lookup::Untrusted(reason) => Some(reason),
    };
    let outcome = match untrusted {
        Some(reason) => {
            let reason = format!(
                "part tree cache entry {} not trusted ({reason}): grown again",
                path.display()
            );
            warnings.push(reason.clone());
            CacheOutcome::Recomputed { reason }
        }
        None => CacheOutcome::Miss,
    };
    let kept = nodes.clone();
    let stage = part_tree_sharing(nodes, meshes, options, smoothers, alignment)?;
    match stored(&stage, kept, options) {
        Ok(s) => {
            let written = std::fs::create_dir_all(cache_dir)
                .and_then(|()| write_entry(&path, &encode_entry(EntryKind::PartTree, &key, &s)));
            if let Err(e) = written {
                warnings.push(format!(
                    "part tree cache entry {} not written ({e}); the next run grows it again",
                    path.display()
                ));
            }
        }
        Err(reason) => warnings.push(format!(
            "the part tree was not cached ({reason}); the next run grows it again"
        )),
    }
    let mut result = cut_part_tree(stage, meshes, options)?;
    result.warnings.extend(warnings);
    Ok((result, Some(outcome)))
}
