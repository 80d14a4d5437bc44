//! [`thickness_tree`]: a part tree over co-segmented regions that merges touching regions of
//! one thickness (and mirror pairs), for `coseg segment --parts N --parts-from thickness`.
//!
//! Why: cut into a dozen equal-area regions, the generated families' regions are nearly pure
//! (one true part each: 84–92 % of their area, docs/PARTS.md), so how well `--parts N` does
//! rests on which regions it groups. Grouping by what the affinity transports (the adaptive
//! tree) or by intrinsic look-alike merges a leg with an arm and the hips with the legs: the
//! spectral features of a limb's end differ from its root's more than from another limb's.
//! Semantic parts are made of touching pieces of about one thickness: the thickness changes
//! where a limb meets the torso, not along the limb. So the tree merges, among regions that
//! touch on most shapes (or are mirror pairs: the two arms), the two whose thickness differs
//! least, with complete linkage: a group's thickness spread stays small.
//!
//! Thickness of a region on a shape: the area-weighted geometric mean of the raw shape
//! diameter function ([`crate::features::shape_diameter`], one smoothing round) over its
//! vertices; the SDF is scale-normalised per shape, so thicknesses compare across shapes.
//! Distance of two regions: the median over shapes of `|ln t_a − ln t_b|`; of two groups, the
//! largest distance between their members (complete linkage). Each merge records the
//! similarity `exp(−distance)`: the thickness ratio (thinner over thicker, 1 = alike).

use super::{Cosegmentation, GraphError, PartMerge, PartTree};
use crate::features::{SdfOptions, shape_diameter};
use crate::mesh::TriMesh;
use rayon::prelude::*;

/// The part tree of `coseg`'s tuples by thickness (module docs).
///
/// Inputs: `meshes` (#shapes, graph order, #V_i vertices each, as `coseg`'s regions index
/// them); `coseg` (its tuples are the leaves); `links`, pairs of leaves that may merge without
/// touching (mirror pairs from [`super::mirror_pairs`]). Leaves touch when they share a mesh
/// edge on at least half of the shapes. When no touching or linked groups remain (the regions
/// form separate islands) the closest groups merge anyway, so the tree always has
/// #leaves − 1 merges and [`PartTree::cut`] gives any count.
///
/// Output: a [`PartTree`] over `coseg.tuples` (merges in order, closest first; ties: the lowest
/// node ids). Deterministic: the SDF is computed per vertex in parallel, independently of the
/// thread count.
///
/// Errors: [`GraphError::BadOption`] when the meshes do not match `coseg`;
/// [`GraphError::Thickness`] when a shape's SDF cannot be computed.
///
/// Cost: one SDF per shape (a BVH and 30 rays per vertex; ~0.1 s for 5k vertices), then
/// O(#leaves³ × #shapes) for the merges.
///
/// See also: [`super::AdaptiveCosegmentation::regroup`] (the transport-similarity tree),
/// [`super::SegmentCollectionOptions::parts_from`].
///
/// Known issue: a region that straddles a part boundary (a shoulder: half torso, half arm) has
/// an in-between thickness and may join either side, or a third part (the head).
///
/// ```
/// use coseg::graph::{thickness_tree, Cosegmentation, RegionTuple};
/// use coseg::mesh::TriMesh;
/// // A column of octagonal rings along y: a thick lower half and a thin upper half; the
/// // regions are rings 0–3, 4–7, 8–11 and 12–15 (the caps' centres in the end regions).
/// let width = |k: usize| if k < 8 { 1.0 } else { 0.25 };
/// let mut p = Vec::new();
/// for k in 0..16 {
///     for j in 0..8 {
///         let a = j as f64 * std::f64::consts::FRAC_PI_4;
///         p.push([width(k) * a.cos(), k as f64 * 0.5, width(k) * a.sin()]);
///     }
/// }
/// p.push([0.0, 0.0, 0.0]);
/// p.push([0.0, 7.5, 0.0]);
/// let mut f = Vec::new();
/// for k in 0..15u32 {
///     for j in 0..8u32 {
///         let (a, b) = (8 * k + j, 8 * k + (j + 1) % 8);
///         f.push([a, a + 8, b]);
///         f.push([b, a + 8, b + 8]);
///     }
/// }
/// for j in 0..8u32 {
///     f.push([128, j, (j + 1) % 8]);
///     f.push([129, 120 + (j + 1) % 8, 120 + j]);
/// }
/// let mesh = TriMesh::new(p, f).unwrap();
/// let region = |r: u32| -> Vec<u32> {
///     let mut v: Vec<u32> = (32 * r..32 * (r + 1)).collect();
///     if r == 0 { v.push(128) }
///     if r == 3 { v.push(129) }
///     v
/// };
/// let tuple = |r: u32| RegionTuple { area_fractions: vec![0.25], regions: vec![region(r)],
///     sweeps: 0, converged: true, cycled: false, objective: 0.0, confidence: 1.0,
///     cycle_consistency: None, leftover: false };
/// let coseg = Cosegmentation { names: vec!["s".into()], vertices: vec![130], root: 0,
///     order: vec![0], parent: vec![None], alpha: 0.25, tuples: (0..4).map(tuple).collect() };
/// let tree = thickness_tree(&[mesh], &coseg, &[]).unwrap();
/// assert_eq!(tree.merges.len(), 3);
/// assert_eq!(tree.cut(2), vec![vec![0, 1], vec![2, 3]]);
/// ```
pub fn thickness_tree(
    meshes: &[TriMesh],
    coseg: &Cosegmentation,
    links: &[(usize, usize)],
) -> Result<PartTree, GraphError> {
    let l = coseg.tuples.len();
    if !coseg.matches(meshes) {
        return Err(GraphError::BadOption(
            "thickness tree: one mesh per shape, with the shape's vertex count, is needed".into(),
        ));
    }
    let sdf = SdfOptions {
        smoothing_rounds: vec![1],
        ..SdfOptions::default()
    };
    // ln_t[i][leaf]: the leaf's log thickness on shape i (NaN where the leaf is empty).
    let ln_t: Vec<Vec<f64>> = meshes
        .par_iter()
        .enumerate()
        .map(|(i, mesh)| {
            let c = shape_diameter(mesh, &sdf).map_err(|source| GraphError::Thickness {
                name: coseg.names[i].clone(),
                source,
            })?;
            let s = c.column(0);
            let w = mesh.vertex_areas();
            let mut acc = vec![(0.0, 0.0); l];
            for (leaf, tuple) in coseg.tuples.iter().enumerate() {
                for &v in &tuple.regions[i] {
                    let v = v as usize;
                    acc[leaf].0 += w[v] * s[v].max(f64::MIN_POSITIVE).ln();
                    acc[leaf].1 += w[v];
                }
            }
            Ok(acc
                .iter()
                .map(|&(s, w)| if w > 0.0 { s / w } else { f64::NAN })
                .collect())
        })
        .collect::<Result<_, GraphError>>()?;
    let distance: Vec<Vec<f64>> = (0..l)
        .map(|a| {
            (0..l)
                .map(|b| {
                    let d: Vec<f64> = ln_t
                        .iter()
                        .map(|t| (t[a] - t[b]).abs())
                        .filter(|d| d.is_finite())
                        .collect();
                    if d.is_empty() {
                        f64::INFINITY
                    } else {
                        upper_median(d)
                    }
                })
                .collect()
        })
        .collect();
    let mut linked = touching(meshes, coseg);
    for &(a, b) in links {
        if a < l && b < l {
            linked[a][b] = true;
            linked[b][a] = true;
        }
    }
    let mut members: Vec<Vec<usize>> = (0..l).map(|x| vec![x]).collect();
    let mut alive = vec![true; l];
    let mut merges = Vec::with_capacity(l.saturating_sub(1));
    let group_distance = |ma: &[usize], mb: &[usize]| -> f64 {
        ma.iter()
            .flat_map(|&x| mb.iter().map(move |&y| (x, y)))
            .map(|(x, y)| distance[x][y])
            .fold(0.0, f64::max)
    };
    while merges.len() + 1 < l {
        // (unlinked, distance, a, b): linked pairs first, then the closest.
        let mut best: Option<(bool, f64, usize, usize)> = None;
        for a in 0..members.len() {
            for b in a + 1..members.len() {
                if !(alive[a] && alive[b]) {
                    continue;
                }
                let touch = members[a]
                    .iter()
                    .any(|&x| members[b].iter().any(|&y| linked[x][y]));
                let key = (!touch, group_distance(&members[a], &members[b]), a, b);
                if best.is_none_or(|bk| (key.0, key.1) < (bk.0, bk.1)) {
                    best = Some(key);
                }
            }
        }
        let Some((_, d, a, b)) = best else {
            break;
        };
        let mut m = members[a].clone();
        m.extend_from_slice(&members[b]);
        members.push(m);
        alive[a] = false;
        alive[b] = false;
        alive.push(true);
        merges.push(PartMerge {
            a,
            b,
            similarity: (-d).exp(),
        });
    }
    Ok(PartTree { leaves: l, merges })
}

/// The upper median of `v` (non-empty): for an even length the higher middle value, so the
/// distance is one that a shape of the collection shows. (The mean of the two middle values
/// scores lower on the generated families, docs/PARTS.md: the merges are close calls.)
fn upper_median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// `touch[a][b]`: tuples `a` and `b` share a mesh edge on at least half of the shapes.
fn touching(meshes: &[TriMesh], coseg: &Cosegmentation) -> Vec<Vec<bool>> {
    let l = coseg.tuples.len();
    let mut count = vec![vec![0usize; l]; l];
    for (i, mesh) in meshes.iter().enumerate() {
        let labels = coseg.labels(i);
        let mut seen = vec![vec![false; l]; l];
        for f in mesh.faces() {
            for k in 0..3 {
                let (x, y) = (labels[f[k] as usize], labels[f[(k + 1) % 3] as usize]);
                if x >= 0 && y >= 0 && x != y {
                    seen[x as usize][y as usize] = true;
                    seen[y as usize][x as usize] = true;
                }
            }
        }
        for (c, s) in count.iter_mut().zip(&seen) {
            for (c, &s) in c.iter_mut().zip(s) {
                *c += usize::from(s);
            }
        }
    }
    count
        .iter()
        .map(|row| row.iter().map(|&c| 2 * c >= meshes.len()).collect())
        .collect()
}
