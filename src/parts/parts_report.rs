//! [`PartsReport`]: what `summary.json` records of a parts run (`coseg segment --parts`), the
//! finest parts, the tree, pieces and mirror pairs of the final parts.

use super::adaptive_cosegment::{AdaptiveCosegmentation, AutoTuple, PartTree, StopReason, median};
use super::mirror_pairs::{Likeness, MirrorPair, mirror_pairs};
use crate::graph::Cosegmentation;
use serde::Serialize;

/// What `summary.json` records of an adaptive run (`coseg segment --parts`): the finest
/// parts' thresholds and sizes, why the extraction stopped, the tree, and which final parts
/// hold several separate pieces (mirror candidates).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartsReport {
    /// Why the extraction stopped.
    pub stop: StopReason,
    /// Per leaf (the finest parts, leftovers last): the median area fraction over shapes.
    pub leaf_areas: Vec<f64>,
    /// Per extracted leaf: threshold, per-shape sizes, separation.
    pub auto: Vec<AutoTuple>,
    /// The merge tree over the leaves.
    pub tree: PartTree,
    /// With parts from geometry: the equal-area region (of `--regions`) each leaf comes from,
    /// when some region was split into its pieces ([`AdaptiveCosegmentation::leaf_origin`]);
    /// omitted otherwise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub leaf_origin: Vec<usize>,
    /// The pairs of those leaves that are copies of one part facing the same way
    /// ([`AdaptiveCosegmentation::leaf_copies`]); omitted when none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub leaf_copies: Vec<(usize, usize)>,
    /// Per final region id: the leaves it is made of.
    pub region_leaves: Vec<Vec<usize>>,
    /// Per final region id: the median over shapes of its connected pieces holding at least
    /// 10 % of its area (`None` without meshes).
    pub pieces: Option<Vec<usize>>,
    /// Final region ids with two or more such pieces on most shapes: left/right (or other)
    /// copies of a part that intrinsic features cannot tell apart. With an extrinsic feature
    /// family (`--features spectral,extrinsic --up AXIS`, an aligned collection) heights along
    /// tilted directions tell the copies apart, and they can become parts of their own.
    pub mirror_candidates: Vec<usize>,
    /// Pairs of final region ids that are left/right copies of one part
    /// ([`super::mirror_pairs`]; empty without meshes): what an extrinsic family splits.
    pub mirror_pairs: Vec<MirrorPair>,
}

impl PartsReport {
    /// A warning for the user when the parts say little: one part for the whole collection
    /// because no tuple passed the levels (nothing was split), with the reason. `None`
    /// otherwise, also when one part is all the upper bound allowed (`--regions 1`).
    ///
    /// ```
    /// use coseg::bands::equal_count_bands;
    /// use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
    /// use coseg::parts::{adaptive_cosegment, AdaptiveOptions, PartsReport};
    /// let vals: Vec<f64> = (0..40).map(|v| ((v * 7) % 40) as f64).collect();
    /// let t = equal_count_bands(&vals, 1, 40, 4).unwrap();
    /// let nodes = (0..3).map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &[1.0; 40]).unwrap()).collect();
    /// let g = ShapeGraph::build(nodes, &GraphOptions::default()).unwrap();
    /// // A separation level of 1 (a perfect split), which this data does not reach: the first
    /// // tuple is rejected and one part remains.
    /// let mut o = AdaptiveOptions::default();
    /// o.min_separation = 1.0;
    /// let a = adaptive_cosegment(&g, &o).unwrap();
    /// let r = PartsReport::new(&a, &a.leaves, &[], None, None);
    /// assert_eq!(r.leaf_areas.len(), 1);
    /// assert!(r.warning().unwrap().contains("one part for the whole collection"));
    /// // One part because the upper bound allowed one: nothing to warn about.
    /// let mut one = AdaptiveOptions::default();
    /// one.max_parts = 1;
    /// let a = adaptive_cosegment(&g, &one).unwrap();
    /// assert_eq!(PartsReport::new(&a, &a.leaves, &[], None, None).warning(), None);
    /// ```
    pub fn warning(&self) -> Option<String> {
        let asked = matches!(
            self.stop,
            StopReason::MaxParts | StopReason::EqualAreaLeaves
        );
        (self.leaf_areas.len() == 1 && !asked).then(|| {
            format!(
                "parts of their own size: one part for the whole collection, since {}; \
                 ask for a number of parts (--parts N) or try other features (docs/PARTS.md)",
                self.stop
            )
        })
    }

    /// The report of `adaptive` whose final segmentation (after the cut, and refinement if
    /// any) is `fin`; `meshes` (graph order, may be empty) give the pieces and the mirror
    /// pairs, `up` (the aligned collection's up direction, if any) the mirror test's planes,
    /// `likeness` what mirror pairs must look alike on ([`super::mirror_pairs`]).
    ///
    /// ```
    /// use coseg::bands::equal_count_bands;
    /// use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
    /// use coseg::parts::{adaptive_cosegment, AdaptiveOptions, PartsReport};
    /// let vals: Vec<f64> = (0..40).map(|v| ((v * 7) % 40) as f64).collect();
    /// let t = equal_count_bands(&vals, 1, 40, 4).unwrap();
    /// let nodes = (0..3).map(|i| ShapeNode::new(format!("s{i}"), t.clone(), &[1.0; 40]).unwrap()).collect();
    /// let g = ShapeGraph::build(nodes, &GraphOptions::default()).unwrap();
    /// let a = adaptive_cosegment(&g, &AdaptiveOptions::default()).unwrap();
    /// let r = PartsReport::new(&a, &a.leaves, &[], None, None);
    /// assert_eq!(r.region_leaves.len(), a.leaves.tuples.len());
    /// assert!(r.pieces.is_none() && r.mirror_pairs.is_empty());
    /// ```
    pub fn new(
        adaptive: &AdaptiveCosegmentation,
        fin: &Cosegmentation,
        meshes: &[crate::mesh::TriMesh],
        up: Option<[f64; 3]>,
        likeness: Option<Likeness<'_>>,
    ) -> Self {
        let mut region_leaves = adaptive.tree.cut(fin.tuples.len());
        let leftover_leaf = adaptive.leaves.tuples.len().saturating_sub(1);
        if let Some(p) = region_leaves
            .iter()
            .position(|g| g.contains(&leftover_leaf))
        {
            let g = region_leaves.remove(p);
            region_leaves.push(g);
        }
        let pieces = fin.matches(meshes).then(|| {
            (0..fin.tuples.len())
                .map(|r| {
                    let counts: Vec<f64> = meshes
                        .iter()
                        .enumerate()
                        .map(|(i, m)| region_pieces(m, &fin.labels(i), r as i32) as f64)
                        .collect();
                    median(&counts) as usize
                })
                .collect::<Vec<_>>()
        });
        let mirror_candidates = pieces
            .as_ref()
            .map(|p| (0..p.len()).filter(|&r| p[r] >= 2).collect())
            .unwrap_or_default();
        Self {
            stop: adaptive.stop,
            leaf_areas: adaptive
                .leaves
                .tuples
                .iter()
                .map(|t| median(&t.area_fractions))
                .collect(),
            auto: adaptive.auto.clone(),
            tree: adaptive.tree.clone(),
            leaf_origin: adaptive.leaf_origin.clone(),
            leaf_copies: adaptive.leaf_copies.clone(),
            region_leaves,
            pieces,
            mirror_candidates,
            mirror_pairs: mirror_pairs(meshes, fin, up, likeness),
        }
    }
}

/// Connected pieces (through mesh edges) of the vertices labelled `r`, counting those with at
/// least 10 % of the region's area.
fn region_pieces(mesh: &crate::mesh::TriMesh, labels: &[i32], r: i32) -> usize {
    let comps = crate::mesh::labelled_components(mesh, labels);
    let areas = mesh.vertex_areas();
    let mut piece = std::collections::BTreeMap::<u32, f64>::new();
    let mut total = 0.0;
    for v in 0..labels.len() {
        if labels[v] == r {
            *piece.entry(comps.labels[v]).or_default() += areas[v];
            total += areas[v];
        }
    }
    piece.values().filter(|&&a| a >= 0.1 * total).count()
}
