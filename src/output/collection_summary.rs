//! [`CollectionSummary`]: the `summary.json` of a collection co-segmentation.

use crate::graph::GraphKind;
use crate::parts::{SegmentCollectionOptions, SegmentedCollection};
use serde::Serialize;

/// One shape of a collection run.
#[derive(Debug, Clone, Serialize)]
pub struct CollectionShape {
    /// Output name (file stem).
    pub name: String,
    /// Input mesh file.
    pub file: String,
    /// Vertex count.
    pub vertices: usize,
    /// Area fraction of each region id on this shape (of the shape's total area), in id order.
    pub region_area_fractions: Vec<f64>,
}

/// One region tuple (region id `id` on every shape).
#[derive(Debug, Clone, Serialize)]
pub struct CollectionRegion {
    /// Region id (line value in the `.regions.txt` files).
    pub id: usize,
    /// The leftover tuple (what no extracted region claimed before refinement).
    pub leftover: bool,
    /// Confidence in `[0, 1]`: after refinement, the area-weighted mean assignment margin
    /// `(best − second best) / best` over the region's vertices; without refinement, the mean
    /// area IoU between the region and its spanning-tree neighbours' regions carried onto it.
    pub confidence: f64,
    /// Mean area IoU of the region carried around sampled triangles of the shape graph, before
    /// refinement (`None` without triangles).
    pub cycle_consistency: Option<f64>,
    /// Sweeps of the last stage that changed this tuple (refinement sweeps when refined).
    pub sweeps: usize,
    /// Whether that stage reached a fixed point.
    pub converged: bool,
    /// The co-segmentation objective of the tuple before refinement.
    pub objective: f64,
}

/// One edge of the shape graph.
#[derive(Debug, Clone, Serialize)]
pub struct CollectionEdge {
    /// Shape name of one end.
    pub a: String,
    /// Shape name of the other end.
    pub b: String,
    /// Edge weight in the co-segmentation scores.
    pub weight: f64,
    /// Cheap summary distance between the two shapes.
    pub distance: f64,
}

/// A file that could not be used.
#[derive(Debug, Clone, Serialize)]
pub struct SkippedInput {
    /// The file.
    pub path: String,
    /// Why it was skipped.
    pub error: String,
}

impl From<&crate::graph::SkippedFile> for SkippedInput {
    fn from(s: &crate::graph::SkippedFile) -> Self {
        SkippedInput {
            path: s.path.display().to_string(),
            error: s.error.clone(),
        }
    }
}

/// Contents of `summary.json` for `coseg segment`. Holds no timings, so that the same inputs
/// and options give the same file, byte for byte.
#[derive(Debug, Clone, Serialize)]
pub struct CollectionSummary {
    /// Always `"segment"`.
    pub command: &'static str,
    /// Version of coseg that wrote the file.
    pub version: &'static str,
    /// The shapes, in graph order.
    pub shapes: Vec<CollectionShape>,
    /// The region tuples, in id order.
    pub regions: Vec<CollectionRegion>,
    /// Area fraction each extracted region was cut at.
    pub area_fraction: f64,
    /// Name of the spanning-tree root of the co-segmentation.
    pub root: String,
    /// `"complete"` or `"nearest-k"`.
    pub graph: String,
    /// The graph's edges.
    pub edges: Vec<CollectionEdge>,
    /// The options used.
    pub options: SegmentCollectionOptions,
    /// Input files that were skipped, with the reason.
    pub skipped: Vec<SkippedInput>,
    /// With `--parts`: the adaptive run's thresholds, stop reason, tree and mirror
    /// candidates (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub parts: Option<crate::parts::PartsReport>,
    /// With several starts (`--starts N`): the start kept and every start's score (mean tuple
    /// confidence); absent with one start.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub starts: Option<StartsReport>,
    /// The feature families chosen from the data and why (absent when `--features` was
    /// given).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub features: Option<crate::parts::FeatureChoice>,
    /// The number of parts chosen from the part tree and why (absent with `--parts N` or
    /// equal-area regions).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub part_count: Option<crate::parts::PartCount>,
    /// `"recut"` when the part tree was read from the cache (an earlier run on the same shapes
    /// and options, another number of parts) and only cut; absent when it was grown. The one
    /// field in which a re-cut's file differs from a cold run's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub collection_stage: Option<&'static str>,
}

/// Which of several co-segmentation starts was kept ([`SegmentCollectionOptions::starts`]).
#[derive(Debug, Clone, serde::Serialize)]
pub struct StartsReport {
    /// Index of the start kept (0 = the default start).
    pub chosen: usize,
    /// Mean tuple confidence of each start ([`crate::parts::start_score`]).
    pub scores: Vec<f64>,
}

impl CollectionSummary {
    /// Builds the summary of `result`; `files[i]` is the input file of shape `i` (graph order).
    ///
    /// ```
    /// use coseg::bands::equal_count_bands;
    /// use coseg::graph::{ShapeNode};
    /// use coseg::parts::{segment_collection, SegmentCollectionOptions};
    /// use coseg::output::CollectionSummary;
    /// let t = equal_count_bands(&[0.0, 1.0, 2.0, 3.0], 1, 4, 4).unwrap();
    /// let nodes: Vec<ShapeNode> =
    ///     (0..2).map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &[1.0; 4]).unwrap()).collect();
    /// let mut opts = SegmentCollectionOptions::equal_areas(6);
    /// opts.refine = None;
    /// let out = segment_collection(nodes, &[], &opts).unwrap();
    /// let files = vec!["s0.obj".to_string(), "s1.obj".to_string()];
    /// let sum = CollectionSummary::new(&out, &files, &opts, vec![]);
    /// assert_eq!(sum.shapes.len(), 2);
    /// assert!(serde_json::to_string(&sum).unwrap().contains("\"command\":\"segment\""));
    /// ```
    pub fn new(
        result: &SegmentedCollection,
        files: &[String],
        options: &SegmentCollectionOptions,
        skipped: Vec<SkippedInput>,
    ) -> Self {
        let seg = &result.segmentation;
        let shapes = seg
            .names
            .iter()
            .enumerate()
            .map(|(i, name)| CollectionShape {
                name: name.clone(),
                file: files.get(i).cloned().unwrap_or_default(),
                vertices: seg.vertices[i],
                region_area_fractions: seg.tuples.iter().map(|t| t.area_fractions[i]).collect(),
            })
            .collect();
        let regions = seg
            .tuples
            .iter()
            .enumerate()
            .map(|(id, t)| CollectionRegion {
                id,
                leftover: t.leftover,
                confidence: t.confidence,
                cycle_consistency: t.cycle_consistency,
                sweeps: t.sweeps,
                converged: t.converged,
                objective: t.objective,
            })
            .collect();
        let graph = match result.graph.kind() {
            GraphKind::Complete => "complete".to_string(),
            GraphKind::Nearest(k) => format!("nearest-{k}"),
        };
        let edges = result
            .graph
            .edges()
            .iter()
            .map(|(i, j, e)| CollectionEdge {
                a: seg.names[*i].clone(),
                b: seg.names[*j].clone(),
                weight: e.weight,
                distance: e.distance,
            })
            .collect();
        Self {
            command: "segment",
            version: env!("CARGO_PKG_VERSION"),
            shapes,
            regions,
            area_fraction: seg.alpha,
            root: seg.names[seg.root].clone(),
            graph,
            edges,
            options: options.clone(),
            skipped,
            parts: None,
            starts: (result.start_scores.len() > 1).then(|| StartsReport {
                chosen: result.start,
                scores: result.start_scores.clone(),
            }),
            features: result.features.clone(),
            part_count: result.part_count.clone(),
            collection_stage: None,
        }
    }
}
