//! [`parts_route`]: labels carried part by part through the collection's own co-segmentation,
//! each part named from the labelled shapes.

use super::RouteLabels;
use crate::graph::Cosegmentation;

/// The parts route of the fused propagation: every tuple (part) of `segmentation` is named by
/// the area-weighted majority of the annotated labels it covers on the labelled shapes, and
/// every vertex of every unlabelled shape takes its part's name.
///
/// The co-segmentation is consistent across the collection (part `r` is the same part on
/// every shape), so a part that is mostly one label on the sources is that label on every
/// shape: labels move part by part and the boundaries are the parts'. The part's *purity*
/// (the share of its annotated source area that carries its name) is each of its vertices'
/// confidence: a part split between two labels on the sources names its vertices weakly.
/// A part that covers no annotated area on any source (a part only the unlabelled shapes
/// have) is named `-1` with confidence 0: no source says what it is, and the fusion leaves
/// the decision to the other routes.
///
/// Inputs: `segmentation` over `#shapes` shapes (graph order), `annotations` (one per shape,
/// `Some` per-vertex labels on the sources, `< 0` = unlabelled vertex), `areas` (per shape,
/// per vertex). Output: [`RouteLabels`] with labels and confidences on every unlabelled shape
/// (empty vectors on the sources) and, as the route's confidence on each shape, the
/// area-weighted purity of its parts.
///
/// See also: [`crate::parts::segment_collection`] (the co-segmentation, as `coseg segment
/// --parts N --parts-from geometry` makes it), [`super::fuse_routes`].
///
/// Known issue: when the co-segmentation's parts straddle the labelled parts (a seat and the
/// top of the legs in one part), the purity says so but the boundary stays the part's; the
/// fusion's other routes and the boundary snapping are what move it.
pub fn parts_route(
    segmentation: &Cosegmentation,
    annotations: &[Option<Vec<i32>>],
    areas: &[&[f64]],
) -> RouteLabels {
    let n = annotations.len();
    let region_of: Vec<Vec<i32>> = (0..n).map(|i| segmentation.labels(i)).collect();
    let names = part_names(segmentation.tuples.len(), &region_of, annotations, areas);
    let mut out = RouteLabels::empty(n);
    for i in 0..n {
        if annotations[i].is_some() {
            continue;
        }
        let (labels, conf): (Vec<i32>, Vec<f64>) = region_of[i]
            .iter()
            .map(|&r| if r >= 0 { names[r as usize] } else { (-1, 0.0) })
            .unzip();
        let total: f64 = areas[i].iter().sum();
        out.shape_confidence[i] = if total > 0.0 {
            conf.iter().zip(areas[i]).map(|(c, a)| c * a).sum::<f64>() / total
        } else {
            0.0
        };
        out.labels[i] = labels;
        out.confidence[i] = conf;
    }
    out
}

/// The parts route's accuracy on the sources themselves: their labels carried to their own
/// parts and back (each part named as [`parts_route`] names it, each source vertex given its
/// part's name), the area share of the annotated source area that gets its own label back;
/// `None` without annotated area in a part.
///
/// A round trip, measured against labels the user gave: where the co-segmentation's parts
/// straddle the labelled parts, no naming of them can give the sources their labels back,
/// and the route cannot do better on the other shapes than the parts allow on the sources.
pub(crate) fn parts_round_trip(
    segmentation: &Cosegmentation,
    annotations: &[Option<Vec<i32>>],
    areas: &[&[f64]],
) -> Option<f64> {
    let n = annotations.len();
    let region_of: Vec<Vec<i32>> = (0..n).map(|i| segmentation.labels(i)).collect();
    let names = part_names(segmentation.tuples.len(), &region_of, annotations, areas);
    let (mut right, mut total) = (0.0, 0.0);
    for (i, ann) in annotations.iter().enumerate() {
        let Some(ann) = ann else { continue };
        for (v, (&l, &r)) in ann.iter().zip(&region_of[i]).enumerate() {
            if l >= 0 && r >= 0 {
                total += areas[i][v];
                if names[r as usize].0 == l {
                    right += areas[i][v];
                }
            }
        }
    }
    (total > 0.0).then(|| right / total)
}

/// Each part's name (the area-weighted majority of the annotated labels it covers on the
/// sources, ties to the smallest label; `-1` where it covers none) and purity.
fn part_names(
    tuples: usize,
    region_of: &[Vec<i32>],
    annotations: &[Option<Vec<i32>>],
    areas: &[&[f64]],
) -> Vec<(i32, f64)> {
    // Area of each label inside each tuple, summed over the sources.
    let mut tally: Vec<std::collections::BTreeMap<i32, f64>> = vec![Default::default(); tuples];
    for (i, ann) in annotations.iter().enumerate() {
        let Some(ann) = ann else { continue };
        for (v, (&l, &r)) in ann.iter().zip(&region_of[i]).enumerate() {
            if l >= 0 && r >= 0 {
                *tally[r as usize].entry(l).or_insert(0.0) += areas[i][v];
            }
        }
    }
    tally
        .iter()
        .map(|t| {
            let total: f64 = t.values().sum();
            // Ties: the smallest label (BTreeMap order), so the result is deterministic.
            let best = t.iter().fold(None::<(i32, f64)>, |b, (&l, &a)| match b {
                Some((_, ba)) if ba >= a => b,
                _ => Some((l, a)),
            });
            match best {
                Some((l, a)) if total > 0.0 => (l, a / total),
                _ => (-1, 0.0),
            }
        })
        .collect()
}
