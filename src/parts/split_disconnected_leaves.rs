//! [`split_disconnected_leaves`]: a region tuple whose regions fall into separate pieces that
//! border different regions (a back leg's tip and the tail's tip) becomes one tuple per kind
//! of piece, before [`super::geometric_part_tree`] groups them.
//!
//! Why: an equal-area region is defined by its features, not by where it lies, so on the
//! generated quadrupeds one of twelve regions is, on every shape, the tip of the tail *and*
//! the tips of both back legs (three pieces: the features of a thin limb's end are alike).
//! The part tree can only put that region in one part, so the tail's tip went with the legs
//! and no grouping of the twelve regions met the bar (best 84.0 % purity). The pieces are
//! told apart by what they border: the tail's tip borders the rest of the tail, a leg's tip
//! the rest of its leg. So each connected piece of a region gets a **key**, the region it
//! shares the most boundary length with, and a region splits into one tuple per key when
//! pieces of two or more keys hold a real share of it on most shapes. Keys are region ids of
//! the input, so the same kind of piece gets the same new tuple on every shape.
//!
//! The tuples split from one region are **siblings**: the features found them alike, and
//! sometimes rightly so (a chair's front and back legs, which touch nothing in common but
//! the seat). Which case it is shows in the direction the pieces face: copies of one part side
//! by side face the same way (a chair's four feet all face down), different parts in like
//! places do not (a leg's tip faces down, the tail's tip backwards). Siblings whose pieces'
//! mean normals agree ([`SplitLeaves::alike`]) are linked in the part tree like mirror pairs;
//! the others may merge without touching only at an extra cost
//! (`SIBLING_COST`), so that alike pieces of different parts (a hand resting on a
//! thigh) stay apart unless nothing cheaper is left.

use crate::graph::{Cosegmentation, GraphError};
use crate::mesh::{TriMesh, dot, for_each_label_boundary, labelled_components, norm};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// The least share of its region's area (on one shape) a piece kind must hold to count,
/// in `(0, 1)`: below it a piece is a fragment of the refinement, not a part.
const SPLIT_PIECE_SHARE: f64 = 0.15;

/// Two kinds split from one region are *alike* ([`SplitLeaves::alike`]) when the (upper)
/// median, over the shapes where both have pieces, of the angle between their pieces'
/// area-weighted mean normals is below this (degrees). Copies of one part side by side face
/// the same way (a chair's front and back feet: 14–24° on the generated chairs), different
/// parts in like places do not (a leg's tip and the tail's tip, a hand and a foot: 46° and
/// more on the generated quadrupeds and humanoids); 35° is the middle of that gap, and every
/// level tried from 30° to 60° gives the same sets meeting the bar (docs/PARTS.md, "Copies
/// and look-alikes").
const SPLIT_SAME_DIRECTION: f64 = 35.0;

/// `coseg`'s tuples with each disconnected tuple split by the kind of its pieces (module
/// docs).
///
/// Inputs: `meshes` (#shapes, graph order, #V_i vertices each, as `coseg`'s regions index
/// them) and `coseg` (#T tuples). On each shape, every connected piece of a region (vertices
/// joined by mesh edges within the region) gets as key the other region it shares the most
/// boundary length with (ties: the lowest id; pieces bordering nothing, whole components of the mesh, share one key). A key
/// *counts* on a shape when its pieces hold at least `SPLIT_PIECE_SHARE` of the region's
/// area there. A tuple splits when at least two keys count on at least half of the shapes
/// each, and two or more of those keys count together on at least half of the shapes; it then
/// becomes one tuple per such key, each shape's pieces going to their key's tuple (pieces of
/// other keys, to the largest kind's).
///
/// Output: a [`SplitLeaves`]: a [`Cosegmentation`] with #T + #new tuples, and where each
/// came from: tuple `t` keeps its id and its largest
/// kind of piece (largest summed share over shapes; ties, the lowest key), the other kinds
/// are appended in order of tuple then key. A new tuple copies its tuple's statistics
/// (confidence, sweeps, …; never `leftover`) and has its own area fractions; it may be empty
/// on a shape where its kind of piece is missing. Tuples that do not split are returned as
/// they are, bit for bit. Which siblings face the same way ([`SplitLeaves::alike`]) is
/// measured with the meshes' vertex normals.
///
/// Errors: [`GraphError::BadOption`] when the meshes do not match `coseg`.
///
/// Cost: one union–find and one pass over the faces per shape (shapes in parallel).
/// Deterministic: the same result whatever the thread count.
///
/// Known issue: only separate pieces are told apart; a connected region that straddles a
/// junction (half head, half torso) is left as it is.
///
/// See also: [`super::geometric_part_tree_linked`], [`crate::mesh::labelled_components`].
///
/// ```
/// use coseg::graph::{Cosegmentation, RegionTuple};
/// use coseg::parts::{split_disconnected_leaves};
/// use coseg::mesh::TriMesh;
/// // A strip of 8 vertices in two rows: columns 0..4 left to right. Region 0 is both end
/// // columns (two pieces, one bordering region 1, the other region 2); regions 1 and 2 the
/// // middle columns.
/// let mut p = Vec::new();
/// for c in 0..4 { p.push([c as f64, 0.0, 0.0]); p.push([c as f64, 1.0, 0.0]); }
/// let mut f = Vec::new();
/// for c in 0..3u32 { let a = 2 * c; f.push([a, a + 2, a + 1]); f.push([a + 1, a + 2, a + 3]); }
/// let mesh = TriMesh::new(p, f).unwrap();
/// let tuple = |r: Vec<u32>| RegionTuple { area_fractions: vec![0.25], regions: vec![r],
///     sweeps: 0, converged: true, cycled: false, objective: 0.0, confidence: 1.0,
///     cycle_consistency: None, leftover: false };
/// let coseg = Cosegmentation { names: vec!["strip".into()], vertices: vec![8], root: 0,
///     order: vec![0], parent: vec![None], alpha: 0.25,
///     tuples: vec![tuple(vec![0, 1, 6, 7]), tuple(vec![2, 3]), tuple(vec![4, 5])] };
/// let split = split_disconnected_leaves(&[mesh], &coseg).unwrap();
/// assert_eq!(split.segmentation.tuples.len(), 4);
/// assert_eq!(split.segmentation.tuples[0].regions[0], vec![0, 1]);
/// assert_eq!(split.segmentation.tuples[3].regions[0], vec![6, 7]);
/// assert_eq!(split.siblings(), vec![(0, 3)]);
/// // The strip is flat: both ends face the same way, so they are copies, not look-alikes.
/// assert_eq!(split.alike, vec![(0, 3)]);
/// ```
pub fn split_disconnected_leaves(
    meshes: &[TriMesh],
    coseg: &Cosegmentation,
) -> Result<SplitLeaves, GraphError> {
    if !coseg.matches(meshes) {
        return Err(GraphError::BadOption(
            "splitting disconnected regions: one mesh per shape, with the shape's vertex count, is needed"
                .into(),
        ));
    }
    let n = meshes.len();
    let t = coseg.tuples.len();
    let shapes: Vec<ShapePieces> = meshes
        .par_iter()
        .enumerate()
        .map(|(i, mesh)| ShapePieces::of(mesh, &coseg.labels(i), t))
        .collect();
    // kinds[r]: the keys region r splits into, the largest kind first; empty when it does
    // not split.
    let kinds: Vec<Vec<usize>> = (0..t)
        .map(|r| {
            let counting = |s: &ShapePieces| -> Vec<usize> {
                s.shares[r]
                    .iter()
                    .filter(|&(_, &a)| a >= SPLIT_PIECE_SHARE)
                    .map(|(&k, _)| k)
                    .collect()
            };
            let mut count = BTreeMap::<usize, usize>::new();
            for s in &shapes {
                for k in counting(s) {
                    *count.entry(k).or_default() += 1;
                }
            }
            let keys: Vec<usize> = count
                .into_iter()
                .filter(|&(_, c)| 2 * c >= n)
                .map(|(k, _)| k)
                .collect();
            let together = shapes
                .iter()
                .filter(|s| counting(s).iter().filter(|k| keys.contains(k)).count() >= 2)
                .count();
            if keys.len() < 2 || 2 * together < n {
                return Vec::new();
            }
            let total = |k: usize| -> f64 {
                shapes
                    .iter()
                    .map(|s| s.shares[r].get(&k).copied().unwrap_or(0.0))
                    .sum()
            };
            // The largest kind first (ties: the lowest key), then the others in key order.
            let main = keys
                .iter()
                .copied()
                .max_by(|&a, &b| total(a).total_cmp(&total(b)).then(b.cmp(&a)))
                .expect("two keys or more");
            let mut out = vec![main];
            out.extend(keys.into_iter().filter(|&k| k != main));
            out
        })
        .collect();
    // The new tuples' ids: (region, index into kinds[region]) for every kind after the first.
    let mut new_ids = BTreeMap::<(usize, usize), usize>::new();
    for (r, k) in kinds.iter().enumerate() {
        for j in 1..k.len() {
            let id = t + new_ids.len();
            new_ids.insert((r, j), id);
        }
    }
    // The tuple of region r's kind j; ids grow with j, so a pair a < b stays in order.
    let leaf = |r: usize, j: usize| if j == 0 { r } else { new_ids[&(r, j)] };
    let mut alike = Vec::new();
    for (r, keys) in kinds.iter().enumerate() {
        for a in 0..keys.len() {
            for b in a + 1..keys.len() {
                if face_alike(&shapes, r, keys[a], keys[b]) {
                    alike.push((leaf(r, a), leaf(r, b)));
                }
            }
        }
    }
    alike.sort_unstable();
    let mut origin: Vec<usize> = (0..t).collect();
    origin.extend(new_ids.keys().map(|&(r, _)| r));
    if new_ids.is_empty() {
        return Ok(SplitLeaves {
            segmentation: coseg.clone(),
            origin,
            alike,
        });
    }
    let mut tuples = coseg.tuples.clone();
    for &(r, _) in new_ids.keys() {
        let mut copy = coseg.tuples[r].clone();
        copy.leftover = false;
        tuples.push(copy);
    }
    for (i, s) in shapes.iter().enumerate() {
        let areas = &s.areas;
        let total: f64 = areas.iter().sum();
        let mut regions: Vec<Vec<u32>> = vec![Vec::new(); tuples.len()];
        for (r, tuple) in coseg.tuples.iter().enumerate() {
            for &v in &tuple.regions[i] {
                let key = s.piece_key[s.piece[v as usize] as usize];
                let id = kinds[r]
                    .iter()
                    .position(|&k| k == key)
                    .map_or(r, |j| leaf(r, j));
                regions[id].push(v);
            }
        }
        for (id, region) in regions.into_iter().enumerate() {
            if id < t && kinds[id].is_empty() {
                continue;
            }
            tuples[id].area_fractions[i] = if total > 0.0 {
                region.iter().map(|&v| areas[v as usize]).sum::<f64>() / total
            } else {
                0.0
            };
            tuples[id].regions[i] = region;
        }
    }
    Ok(SplitLeaves {
        segmentation: Cosegmentation {
            tuples,
            ..coseg.clone()
        },
        origin,
        alike,
    })
}

/// Whether the pieces of keys `a` and `b` of region `r` face the same way: the upper median,
/// over the shapes where both have pieces with a mean normal, of the angle between their
/// mean normals is below `SPLIT_SAME_DIRECTION`.
fn face_alike(shapes: &[ShapePieces], r: usize, a: usize, b: usize) -> bool {
    let mut angles: Vec<f64> = shapes
        .iter()
        .filter_map(|s| {
            let (u, v) = (s.direction[r].get(&a)?, s.direction[r].get(&b)?);
            let (nu, nv) = (norm(*u), norm(*v));
            (nu > 0.0 && nv > 0.0).then(|| {
                (dot(*u, *v) / (nu * nv))
                    .clamp(-1.0, 1.0)
                    .acos()
                    .to_degrees()
            })
        })
        .collect();
    if angles.is_empty() {
        return false;
    }
    angles.sort_by(f64::total_cmp);
    angles[angles.len() / 2] < SPLIT_SAME_DIRECTION
}

/// What [`split_disconnected_leaves`] returns.
#[derive(Debug, Clone, PartialEq)]
pub struct SplitLeaves {
    /// The tuples after the split (#T + #new).
    pub segmentation: Cosegmentation,
    /// For each of them, the input tuple it comes from (`origin[t] = t` for the first #T).
    pub origin: Vec<usize>,
    /// The sibling pairs `(a, b)`, `a < b`, in order, whose pieces face the same way
    /// (`SPLIT_SAME_DIRECTION`): copies of one part side by side (a chair's front and back
    /// feet), which the part tree links like mirror pairs; the other siblings are look-alikes
    /// of different parts until shown otherwise.
    pub alike: Vec<(usize, usize)>,
}

impl SplitLeaves {
    /// The sibling pairs `(a, b)`, `a < b`: tuples split from one input tuple, in order.
    ///
    /// ```
    /// use coseg::graph::{Cosegmentation};
    /// use coseg::parts::{SplitLeaves};
    /// let segmentation = Cosegmentation { names: vec![], vertices: vec![], root: 0,
    ///     order: vec![], parent: vec![], alpha: 0.0, tuples: vec![] };
    /// let s = SplitLeaves { segmentation, origin: vec![0, 1, 2, 0, 0, 2], alike: vec![] };
    /// assert_eq!(s.siblings(), vec![(0, 3), (0, 4), (2, 5), (3, 4)]);
    /// ```
    pub fn siblings(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for (a, &x) in self.origin.iter().enumerate() {
            for (b, &y) in self.origin.iter().enumerate().skip(a + 1) {
                if x == y {
                    out.push((a, b));
                }
            }
        }
        out
    }
}

/// The key of a piece that borders no other region (a whole component of the mesh).
const ISLAND: usize = usize::MAX;

/// One shape's pieces: each vertex's piece, each piece's key, and per region the share of its
/// area held by each key's pieces; the vertex areas they were measured with.
struct ShapePieces {
    areas: Vec<f64>,
    piece: Vec<u32>,
    piece_key: Vec<usize>,
    shares: Vec<BTreeMap<usize, f64>>,
    /// direction[region][key]: the area-weighted sum of the vertex normals of the region's
    /// pieces of that key (its direction is their mean normal).
    direction: Vec<BTreeMap<usize, [f64; 3]>>,
}

impl ShapePieces {
    fn of(mesh: &TriMesh, labels: &[i32], regions: usize) -> Self {
        let comps = labelled_components(mesh, labels);
        let piece = comps.labels;
        // border[(piece, other region)]: boundary length, each edge once per face side.
        let mut border = BTreeMap::<(u32, usize), f64>::new();
        for_each_label_boundary(mesh, labels, |u, v, e| {
            *border.entry((piece[u], labels[v] as usize)).or_default() += e;
            *border.entry((piece[v], labels[u] as usize)).or_default() += e;
        });
        let mut piece_key = vec![ISLAND; comps.count];
        let mut best = vec![0.0f64; comps.count];
        for (&(c, y), &len) in &border {
            // BTreeMap order: ascending region, so a strict > keeps the lowest id on ties.
            if len > best[c as usize] {
                best[c as usize] = len;
                piece_key[c as usize] = y;
            }
        }
        let areas = mesh.vertex_areas();
        let mut region_area = vec![0.0; regions];
        let normals = mesh.vertex_normals();
        let mut shares = vec![BTreeMap::<usize, f64>::new(); regions];
        let mut direction = vec![BTreeMap::<usize, [f64; 3]>::new(); regions];
        for (v, &x) in labels.iter().enumerate() {
            if x < 0 {
                continue;
            }
            let key = piece_key[piece[v] as usize];
            region_area[x as usize] += areas[v];
            *shares[x as usize].entry(key).or_default() += areas[v];
            let d = direction[x as usize].entry(key).or_insert([0.0; 3]);
            for (d, n) in d.iter_mut().zip(normals[v]) {
                *d += areas[v] * n;
            }
        }
        for (share, &a) in shares.iter_mut().zip(&region_area) {
            for s in share.values_mut() {
                *s = if a > 0.0 { *s / a } else { 0.0 };
            }
        }
        Self {
            areas,
            piece,
            piece_key,
            shares,
            direction,
        }
    }
}
