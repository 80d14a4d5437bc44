//! [`geometric_part_tree`]: a part tree over co-segmented regions that merges touching
//! regions of one thickness across convex boundaries (and mirror pairs), for `coseg segment
//! --parts N --parts-from geometry`.
//!
//! Why: cut into a dozen equal-area regions, the generated families' regions are nearly pure
//! (one true part each: 84–92 % of their area, docs/PARTS.md), so how well `--parts N` does
//! rests on which regions it groups. Grouping by what the affinity transports (the adaptive
//! tree) or by intrinsic look-alike merges a leg with an arm and the hips with the legs: the
//! spectral features of a limb's end differ from its root's more than from another limb's.
//! Two geometric cues of a part boundary do not depend on where along a part a cut falls:
//! the **thickness** jumps where a limb meets the torso, a stem meets a bowl; and the surface
//! is **concave** along such a junction (the minima rule of Hoffman and Richards), while a cut
//! across a limb or a torso runs over convex surface. So the tree merges, among regions that
//! touch on most shapes (or are mirror pairs: the two arms), the two of least cost
//!
//! `cost(a, b) = max_{x ∈ a, y ∈ b} d(x, y) + mean_{x ∈ a, y ∈ b touching} c(x, y)`,
//!
//! both terms dimensionless (the maximum over the pairs present together on some shape: a
//! pair never on one shape says nothing): `d(x, y)` = the (upper) median over the shapes
//! holding both of `|ln t_x − ln t_y|`,
//! `t` a region's thickness on a shape (the area-weighted geometric mean of the raw shape
//! diameter function, [`crate::features::shape_diameter`] with one smoothing round,
//! scale-normalised per shape); `c(x, y)` = the (upper) median over shapes of the concave
//! share of their common boundary (the length of boundary edges whose endpoints' mean
//! curvature sums to < 0 by more than the curvature's resolution,
//! [`crate::features::mean_curvature`], [`crate::features::mean_curvature_resolution`]: a flat
//! stretch is not concave whichever way rounding tips its sign; over the boundary's length;
//! 0 for linked regions that do not touch). Complete linkage on thickness keeps a group's
//! thickness spread small. Each merge records the similarity `exp(−cost)` (1 = alike).

use super::adaptive_cosegment::{PartMerge, PartTree};
use super::part_cues::PartCues;
use crate::features::mean_curvature_resolution;
use crate::graph::{Cosegmentation, GraphError};
use crate::mesh::{TriMesh, for_each_label_boundary};
use rayon::prelude::*;

/// The part tree of `coseg`'s tuples by thickness and boundary concavity (module docs).
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
/// Cost (besides the SDF): one mean-curvature estimate per shape and a pass over its faces.
///
/// Known issue: a region that straddles a part boundary (a shoulder: half torso, half arm) has
/// an in-between thickness and may join either side, or a third part (the head); a region
/// made of separate pieces of different parts (a hand resting on a thigh) joins them, unless
/// [`super::split_disconnected_leaves`] splits it first, as `coseg segment` does.
///
/// ```
/// use coseg::graph::{Cosegmentation, RegionTuple};
/// use coseg::parts::{geometric_part_tree};
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
/// let tree = geometric_part_tree(&[mesh], &coseg, &[]).unwrap();
/// assert_eq!(tree.merges.len(), 3);
/// assert_eq!(tree.cut(2), vec![vec![0, 1], vec![2, 3]]);
/// ```
pub fn geometric_part_tree(
    meshes: &[TriMesh],
    coseg: &Cosegmentation,
    links: &[(usize, usize)],
) -> Result<PartTree, GraphError> {
    check_meshes(meshes, coseg)?;
    let name = |i: usize| coseg.names[i].clone();
    let cues = super::part_cues::collection_cues(meshes, name, None, &mut Vec::new())?;
    geometric_part_tree_with_cues(meshes, &cues, coseg, links)
}

/// [`geometric_part_tree`] from cues already at hand (one [`PartCues`] per shape, graph order,
/// e.g. from the cache by [`super::load_or_compute_part_cues`]): the same tree, bit for bit,
/// without the SDF's cost.
///
/// Errors: [`GraphError::BadOption`] when the meshes or the cues do not match `coseg`.
///
/// ```
/// use coseg::graph::{Cosegmentation, RegionTuple};
/// use coseg::parts::{geometric_part_tree, geometric_part_tree_with_cues, PartCues};
/// use coseg::mesh::TriMesh;
/// let p = vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.],[0.,0.,1.],[1.,0.,1.],[1.,1.,1.],[0.,1.,1.]];
/// let f = vec![[0,2,1],[0,3,2],[4,5,6],[4,6,7],[0,1,5],[0,5,4],[1,2,6],[1,6,5],[2,3,7],[2,7,6],[3,0,4],[3,4,7]];
/// let mesh = TriMesh::new(p, f).unwrap();
/// let tuple = |r: Vec<u32>| RegionTuple { area_fractions: vec![0.5], regions: vec![r],
///     sweeps: 0, converged: true, cycled: false, objective: 0.0, confidence: 1.0,
///     cycle_consistency: None, leftover: false };
/// let coseg = Cosegmentation { names: vec!["cube".into()], vertices: vec![8], root: 0,
///     order: vec![0], parent: vec![None], alpha: 0.5,
///     tuples: vec![tuple(vec![0, 1, 2, 3]), tuple(vec![4, 5, 6, 7])] };
/// let cues = vec![PartCues::of(&mesh).unwrap()];
/// let with = geometric_part_tree_with_cues(&[mesh.clone()], &cues, &coseg, &[]).unwrap();
/// assert_eq!(with, geometric_part_tree(&[mesh], &coseg, &[]).unwrap());
/// ```
pub fn geometric_part_tree_with_cues(
    meshes: &[TriMesh],
    cues: &[PartCues],
    coseg: &Cosegmentation,
    links: &[(usize, usize)],
) -> Result<PartTree, GraphError> {
    geometric_part_tree_linked(meshes, cues, coseg, links, &[])
}

/// The extra cost (added to the module docs' `cost(a, b)`) of merging two groups that neither
/// touch nor are mirror pairs but hold *siblings*, tuples split from one region by
/// [`super::split_disconnected_leaves`]. Siblings looked alike to the features: sometimes
/// copies of one part (a chair's front and back legs), sometimes different parts in like
/// places (a hand resting on a thigh), so the merge is allowed but comes after the touching
/// ones of about the same cost. Chosen among 0, 0.15, 0.2, 0.3 and 0.6 by the sets meeting
/// the bar on seeds 1–9 of the generated families (docs/PARTS.md, "Regions split into their
/// pieces"): 0 merges hands with thighs again; from 0.2 on, the shipped chairs' front and
/// back legs stayed apart. Since then siblings whose pieces face the same way
/// ([`super::SplitLeaves::alike`]: copies side by side, such as those legs' feet) are passed
/// as links instead, as `coseg segment` does, and merge without it (docs/PARTS.md, "Copies
/// and look-alikes").
const SIBLING_COST: f64 = 0.3;

/// [`geometric_part_tree_with_cues`] with sibling pairs of leaves (`siblings`, e.g.
/// [`super::SplitLeaves::siblings`]): groups holding siblings are linked too, their merge
/// costing `SIBLING_COST` more (unless they also touch or hold a mirror pair). The same tree
/// as [`geometric_part_tree_with_cues`] when `siblings` is empty.
///
/// Errors: [`GraphError::BadOption`] when the meshes or the cues do not match `coseg`.
///
/// ```
/// use coseg::graph::{Cosegmentation, RegionTuple};
/// use coseg::parts::{geometric_part_tree_linked, PartCues};
/// use coseg::mesh::TriMesh;
/// // Two separate triangles: two leaves that do not touch, alike in thickness.
/// let p = vec![[0.,0.,0.],[1.,0.,0.],[0.,1.,0.],[5.,0.,0.],[6.,0.,0.],[5.,1.,0.]];
/// let mesh = TriMesh::new(p, vec![[0, 1, 2], [3, 4, 5]]).unwrap();
/// let tuple = |r: Vec<u32>| RegionTuple { area_fractions: vec![0.5], regions: vec![r],
///     sweeps: 0, converged: true, cycled: false, objective: 0.0, confidence: 1.0,
///     cycle_consistency: None, leftover: false };
/// let coseg = Cosegmentation { names: vec!["s".into()], vertices: vec![6], root: 0,
///     order: vec![0], parent: vec![None], alpha: 0.5,
///     tuples: vec![tuple(vec![0, 1, 2]), tuple(vec![3, 4, 5])] };
/// let cues = vec![PartCues { thickness: vec![1.0; 6], mean_curvature: vec![0.0; 6] }];
/// let tree = geometric_part_tree_linked(&[mesh.clone()], &cues, &coseg, &[], &[(0, 1)]).unwrap();
/// // Siblings merge at a cost that a link (a touching boundary, a mirror pair) does not have.
/// let linked = geometric_part_tree_linked(&[mesh], &cues, &coseg, &[(0, 1)], &[]).unwrap();
/// assert_eq!(linked.merges[0].similarity, 1.0);
/// assert!(tree.merges[0].similarity > 0.0 && tree.merges[0].similarity < 1.0);
/// ```
pub fn geometric_part_tree_linked(
    meshes: &[TriMesh],
    cues: &[PartCues],
    coseg: &Cosegmentation,
    links: &[(usize, usize)],
    siblings: &[(usize, usize)],
) -> Result<PartTree, GraphError> {
    check_meshes(meshes, coseg)?;
    if cues.len() != meshes.len()
        || cues.iter().zip(meshes).any(|(c, m)| {
            c.thickness.len() != m.vertex_count() || c.mean_curvature.len() != m.vertex_count()
        })
    {
        return Err(GraphError::BadOption(
            "geometric part tree: one set of part cues per shape, with the shape's vertex count, is needed"
                .into(),
        ));
    }
    let l = coseg.tuples.len();
    // ln_t[i][leaf]: the leaf's log thickness on shape i (NaN where the leaf is empty).
    let ln_t: Vec<Vec<f64>> = meshes
        .iter()
        .zip(cues)
        .enumerate()
        .map(|(i, (mesh, c))| {
            let s = &c.thickness;
            let w = mesh.vertex_areas();
            let mut acc = vec![(0.0, 0.0); l];
            for (leaf, tuple) in coseg.tuples.iter().enumerate() {
                for &v in &tuple.regions[i] {
                    let v = v as usize;
                    acc[leaf].0 += w[v] * s[v].max(f64::MIN_POSITIVE).ln();
                    acc[leaf].1 += w[v];
                }
            }
            acc.iter()
                .map(|&(s, w)| if w > 0.0 { s / w } else { f64::NAN })
                .collect()
        })
        .collect();
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
    // Marks each pair (both ways) in an #leaves by #leaves relation; pairs out of range are
    // ignored.
    let mark = |m: &mut Vec<Vec<bool>>, pairs: &[(usize, usize)]| {
        for &(a, b) in pairs {
            if a < l && b < l {
                m[a][b] = true;
                m[b][a] = true;
            }
        }
    };
    let (mut linked, concave) = boundaries(meshes, cues, coseg);
    mark(&mut linked, links);
    let mut sibling = vec![vec![false; l]; l];
    mark(&mut sibling, siblings);
    Ok(PartTree {
        leaves: l,
        merges: merge_order(&distance, &linked, &sibling, &concave),
    })
}

/// The merges of the module docs from the leaves' thickness distances `d`, which leaves may
/// merge (`linked`: touching or mirror pairs; `sibling`: at `SIBLING_COST` more) and their
/// boundaries' concave shares `c` (NaN where they do not touch); all #leaves by #leaves.
fn merge_order(
    distance: &[Vec<f64>],
    linked: &[Vec<bool>],
    sibling: &[Vec<bool>],
    concave: &[Vec<f64>],
) -> Vec<PartMerge> {
    let l = distance.len();
    let mut members: Vec<Vec<usize>> = (0..l).map(|x| vec![x]).collect();
    let mut alive = vec![true; l];
    let mut merges = Vec::with_capacity(l.saturating_sub(1));
    let cost = |ma: &[usize], mb: &[usize]| -> f64 {
        let pairs = || ma.iter().flat_map(|&x| mb.iter().map(move |&y| (x, y)));
        // Leaves never present on one shape together say nothing about each other's
        // thickness; only when no pair is ever together is the distance unknown (infinite).
        let thickness = pairs()
            .map(|(x, y)| distance[x][y])
            .filter(|d| d.is_finite())
            .fold(None, |m: Option<f64>, d| Some(m.map_or(d, |m| m.max(d))))
            .unwrap_or(f64::INFINITY);
        let shares: Vec<f64> = pairs()
            .map(|(x, y)| concave[x][y])
            .filter(|c| c.is_finite())
            .collect();
        let share = if shares.is_empty() {
            0.0
        } else {
            shares.iter().sum::<f64>() / shares.len() as f64
        };
        thickness + share
    };
    while merges.len() + 1 < l {
        // (unlinked, cost, a, b): linked pairs first, then the cheapest.
        let mut best: Option<(bool, f64, usize, usize)> = None;
        for a in 0..members.len() {
            for b in a + 1..members.len() {
                if !(alive[a] && alive[b]) {
                    continue;
                }
                let any = |m: &[Vec<bool>]| {
                    members[a]
                        .iter()
                        .any(|&x| members[b].iter().any(|&y| m[x][y]))
                };
                let (touch, siblings) = (any(linked), any(sibling));
                let extra = if touch || !siblings {
                    0.0
                } else {
                    SIBLING_COST
                };
                let key = (
                    !(touch || siblings),
                    cost(&members[a], &members[b]) + extra,
                    a,
                    b,
                );
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
    merges
}

/// The upper median of `v` (non-empty): for an even length the higher middle value, so the
/// distance is one that a shape of the collection shows. (The mean of the two middle values
/// scores lower on the generated families, docs/PARTS.md: the merges are close calls.)
fn upper_median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// For each pair of tuples: whether they share a mesh edge on at least half of the shapes,
/// and then the (upper) median over those shapes of the concave share of their boundary
/// (module docs; NaN where they do not touch).
fn boundaries(
    meshes: &[TriMesh],
    cues: &[PartCues],
    coseg: &Cosegmentation,
) -> (Vec<Vec<bool>>, Vec<Vec<f64>>) {
    let l = coseg.tuples.len();
    // Per shape (in parallel, one task each): (concave length, length) of each pair's
    // boundary edges; an interior edge is seen from both of its faces, so both sums count it
    // twice.
    let lengths: Vec<Vec<Vec<(f64, f64)>>> = meshes
        .par_iter()
        .zip(cues)
        .enumerate()
        .map(|(i, (mesh, cues))| {
            let h = &cues.mean_curvature;
            // Concave only beyond what the coordinates resolve: on a flat stretch the sign of
            // `H` is rounding ([`mean_curvature_resolution`]).
            let flat = mean_curvature_resolution(mesh);
            let labels = coseg.labels(i);
            let mut len = vec![vec![(0.0, 0.0); l]; l];
            for_each_label_boundary(mesh, &labels, |u, v, e| {
                let (x, y) = (labels[u] as usize, labels[v] as usize);
                let c = if h[u] + h[v] < -(flat[u] + flat[v]) {
                    e
                } else {
                    0.0
                };
                for (a, b) in [(x, y), (y, x)] {
                    len[a][b].0 += c;
                    len[a][b].1 += e;
                }
            });
            len
        })
        .collect();
    let mut shares: Vec<Vec<Vec<f64>>> = vec![vec![Vec::new(); l]; l];
    for len in &lengths {
        for (row, out) in len.iter().zip(shares.iter_mut()) {
            for (&(c, e), out) in row.iter().zip(out.iter_mut()) {
                if e > 0.0 {
                    out.push(c / e);
                }
            }
        }
    }
    let touch = shares
        .iter()
        .map(|row| {
            row.iter()
                .map(|v| 2 * v.len() >= meshes.len() && !v.is_empty())
                .collect()
        })
        .collect::<Vec<Vec<bool>>>();
    let concave = shares
        .into_iter()
        .zip(&touch)
        .map(|(row, t)| {
            row.into_iter()
                .zip(t)
                .map(|(v, &t)| if t { upper_median(v) } else { f64::NAN })
                .collect()
        })
        .collect();
    (touch, concave)
}

fn check_meshes(meshes: &[TriMesh], coseg: &Cosegmentation) -> Result<(), GraphError> {
    if coseg.matches(meshes) {
        Ok(())
    } else {
        Err(GraphError::BadOption(
            "geometric part tree: one mesh per shape, with the shape's vertex count, is needed"
                .into(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::RegionTuple;

    /// Cues with the meshes' mean curvature and a constant thickness (the boundary tests
    /// read only the curvature; the strips are open, so the SDF would not mean much).
    fn curvature_only(meshes: &[TriMesh]) -> Vec<PartCues> {
        meshes
            .iter()
            .map(|m| PartCues {
                thickness: vec![1.0; m.vertex_count()],
                mean_curvature: crate::features::mean_curvature(m),
            })
            .collect()
    }

    /// A chain of four regions of one thickness, 0–1–2–3: the concave boundary (1, 2) is merged
    /// last, so two parts are {0, 1} and {2, 3}; with a convex one there it would not be.
    #[test]
    fn a_concave_boundary_between_regions_of_one_thickness_is_merged_last() {
        let d = vec![vec![0.0; 4]; 4];
        let mut linked = vec![vec![false; 4]; 4];
        let mut c = vec![vec![f64::NAN; 4]; 4];
        for (a, b, share) in [(0, 1, 0.1), (1, 2, 0.9), (2, 3, 0.1)] {
            linked[a][b] = true;
            linked[b][a] = true;
            c[a][b] = share;
            c[b][a] = share;
        }
        let tree = PartTree {
            leaves: 4,
            merges: merge_order(&d, &linked, &vec![vec![false; 4]; 4], &c),
        };
        assert_eq!(tree.cut(2), vec![vec![0, 1], vec![2, 3]]);
        assert_eq!(tree.merges[2].similarity, (-0.9f64).exp());
        // Convex everywhere but (0, 1): {0, 1} is the part boundary now.
        c[0][1] = 0.9;
        c[1][0] = 0.9;
        c[1][2] = 0.1;
        c[2][1] = 0.1;
        let tree = PartTree {
            leaves: 4,
            merges: merge_order(&d, &linked, &vec![vec![false; 4]; 4], &c),
        };
        assert_eq!(tree.cut(2), vec![vec![0], vec![1, 2, 3]]);
    }

    /// The concave share counts boundary edges whose endpoints' mean curvature sums to < 0,
    /// by length; regions touch when they share an edge on at least half of the shapes.
    #[test]
    fn boundaries_measure_the_concave_share_and_touching() {
        // A 4 × 1 strip of squares, x = 0..4, normals towards +z, folded along x = 2 by
        // z = fold · |x − 2|; regions by x: 0 (x ≤ 1), 1 (x = 2), 2 (x ≥ 3). Flat (fold 0):
        // H = 0 everywhere; a valley (fold 1): H < 0 on the crease, 0 on the planar slopes,
        // so every boundary edge (each has a crease end) is concave; a ridge: none is.
        let strip = |fold: f64| {
            let p: Vec<[f64; 3]> = (0..10)
                .map(|i| {
                    let x = (i / 2) as f64;
                    [x, (i % 2) as f64, fold * (x - 2.0).abs()]
                })
                .collect();
            let f: Vec<[u32; 3]> = (0..4u32)
                .flat_map(|k| {
                    [
                        [2 * k, 2 * k + 2, 2 * k + 1],
                        [2 * k + 1, 2 * k + 2, 2 * k + 3],
                    ]
                })
                .collect();
            TriMesh::new(p, f).unwrap()
        };
        let tuple = |r: Vec<u32>| RegionTuple::given(vec![r], vec![0.0]);
        let coseg = Cosegmentation {
            names: vec!["s".into()],
            vertices: vec![10],
            root: 0,
            order: vec![0],
            parent: vec![None],
            alpha: 0.0,
            tuples: vec![
                tuple(vec![0, 1, 2, 3]),
                tuple(vec![4, 5]),
                tuple(vec![6, 7, 8, 9]),
            ],
        };
        for (fold, share) in [(0.0, 0.0), (1.0, 1.0), (-1.0, 0.0)] {
            let (touch, concave) = {
                let m = [strip(fold)];
                boundaries(&m, &curvature_only(&m), &coseg)
            };
            assert!(touch[0][1] && touch[1][2] && !touch[0][2]);
            assert_eq!(
                (concave[0][1], concave[1][2]),
                (share, share),
                "fold {fold}"
            );
            assert!(concave[0][2].is_nan());
        }
        // Two shapes, the valley and the flat strip: the upper median is the valley's share.
        let two = Cosegmentation {
            names: vec!["a".into(), "b".into()],
            vertices: vec![10, 10],
            order: vec![0, 1],
            parent: vec![None, Some(0)],
            tuples: coseg
                .tuples
                .iter()
                .map(|t| RegionTuple {
                    regions: vec![t.regions[0].clone(), t.regions[0].clone()],
                    area_fractions: vec![0.0, 0.0],
                    ..t.clone()
                })
                .collect(),
            ..coseg.clone()
        };
        let m = [strip(1.0), strip(0.0)];
        let (_, concave) = boundaries(&m, &curvature_only(&m), &two);
        assert_eq!(concave[0][1], 1.0);
    }
}
