//! [`crease_patches`]: a fine over-segmentation of a mesh whose boundaries follow its creases.

use super::StudioError;
use crate::mesh::{TriMesh, edges};
use std::collections::{BTreeMap, BinaryHeap};

/// A convex crease costs this share of a concave one of the same angle: parts meet along
/// concave creases (the minima rule: a leg meets a seat in a concave fold), while convex
/// creases also run inside one part (the rim of a seat), so they should cut less readily.
const CONVEX_SHARE: f64 = 0.2;

/// Options of [`crease_patches`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PatchOptions {
    /// About how many patches a shape is cut into (default 64; ≥ 1): sets the area scale below
    /// which a patch still grows across a crease. More patches follow part boundaries more
    /// closely and take more clicks to label.
    pub target_patches: usize,
}

impl Default for PatchOptions {
    fn default() -> Self {
        PatchOptions { target_patches: 64 }
    }
}

/// Cuts `mesh` into patches whose boundaries follow its creases, favouring concave ones.
///
/// Inputs: a mesh (`#V` vertices) and the options. Output: one patch id per vertex (length
/// `#V`), ids `0..k` numbered by their lowest vertex. Deterministic.
///
/// Every edge `(a, b)` weighs `1 − n_a·n_b` (vertex normals), times [`CONVEX_SHARE`] when the
/// surface bends outward there (`(p_b − p_a)·(n_b − n_a) > 0`). Starting from one region per
/// vertex, the two adjacent regions of least cost `w̄_AB · min(area_A, area_B) / (A / k)` merge
/// (`w̄_AB` the mean weight of the edges between them, `A` the total area, `k` the target
/// count) until `k` regions remain: a boundary's mean weight is robust to the noise of single
/// edges, and the area factor merges crumbs first while large regions stay apart along creases.
/// Separate pieces stay separate (a shape with more pieces than `k` keeps them all).
///
/// See also: [`super::Studio::label_patch`], which labels one patch.
///
/// Known issues: inconsistently oriented faces make the concavity test unreliable (such
/// creases count as convex); a part joined to another without any crease (a smooth limb
/// root) may share a patch with it, for the brush to separate.
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::studio::{crease_patches, PatchOptions};
/// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
///     vec![[0, 1, 2], [0, 2, 3]]).unwrap();
/// let mut o = PatchOptions::default();
/// o.target_patches = 1;
/// assert_eq!(crease_patches(&m, &o).unwrap(), vec![0, 0, 0, 0]); // one patch
/// // Fewer vertices than the target: every vertex is a patch.
/// assert_eq!(crease_patches(&m, &PatchOptions::default()).unwrap(), vec![0, 1, 2, 3]);
/// ```
pub fn crease_patches(mesh: &TriMesh, options: &PatchOptions) -> Result<Vec<u32>, StudioError> {
    if options.target_patches == 0 {
        return Err(StudioError::BadRequest(
            "target_patches must be at least 1".into(),
        ));
    }
    let d = mesh.vertex_count();
    let pos = mesh.positions();
    let normals = mesh.vertex_normals();
    let areas = mesh.vertex_areas();
    let (edge_list, _) = edges(mesh);
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let weights: Vec<f64> = edge_list
        .iter()
        .map(|&[a, b]| {
            let (a, b) = (a as usize, b as usize);
            let bend = (1.0 - dot(normals[a], normals[b])).max(0.0);
            let dp = [0, 1, 2].map(|k| pos[b][k] - pos[a][k]);
            let dn = [0, 1, 2].map(|k| normals[b][k] - normals[a][k]);
            if dot(dp, dn) > 0.0 {
                CONVEX_SHARE * bend
            } else {
                bend
            }
        })
        .collect();
    let total: f64 = areas.iter().sum();
    let target_area = (total / options.target_patches as f64).max(f64::MIN_POSITIVE);
    // Region adjacency: for each region, its neighbours with the summed weight and count of
    // the edges between them.
    let mut adjacent: Vec<BTreeMap<u32, (f64, u32)>> = vec![BTreeMap::new(); d];
    for (&[a, b], &w) in edge_list.iter().zip(&weights) {
        for (x, y) in [(a, b), (b, a)] {
            let e = adjacent[x as usize].entry(y).or_insert((0.0, 0));
            e.0 += w;
            e.1 += 1;
        }
    }
    let mut area = areas.clone();
    let mut stamp = vec![0u32; d];
    let mut parent: Vec<u32> = (0..d as u32).collect();
    let cost = |area: &[f64], a: u32, b: u32, (sum, count): (f64, u32)| {
        let smaller = area[a as usize].min(area[b as usize]);
        (sum / f64::from(count)) * smaller / target_area
    };
    let mut heap = BinaryHeap::new();
    for a in 0..d as u32 {
        for (&b, &e) in &adjacent[a as usize] {
            if a < b {
                heap.push(Candidate {
                    cost: cost(&area, a, b, e),
                    a,
                    b,
                    stamps: (0, 0),
                });
            }
        }
    }
    let mut regions = d;
    while regions > options.target_patches {
        let Some(c) = heap.pop() else { break };
        let (a, b) = (c.a as usize, c.b as usize);
        if parent[a] != c.a || parent[b] != c.b || c.stamps != (stamp[a], stamp[b]) {
            continue;
        }
        // Merge the region with fewer neighbours into the other.
        let (keep, gone) = if adjacent[a].len() >= adjacent[b].len() {
            (a, b)
        } else {
            (b, a)
        };
        parent[gone] = keep as u32;
        area[keep] += area[gone];
        stamp[keep] += 1;
        regions -= 1;
        let moved = std::mem::take(&mut adjacent[gone]);
        adjacent[keep].remove(&(gone as u32));
        for (n, e) in moved {
            if n as usize == keep {
                continue;
            }
            adjacent[n as usize].remove(&(gone as u32));
            let merged = {
                let slot = adjacent[keep].entry(n).or_insert((0.0, 0));
                slot.0 += e.0;
                slot.1 += e.1;
                *slot
            };
            adjacent[n as usize].insert(keep as u32, merged);
        }
        for (&n, &e) in &adjacent[keep] {
            let (x, y) = if (keep as u32) < n {
                (keep as u32, n)
            } else {
                (n, keep as u32)
            };
            heap.push(Candidate {
                cost: cost(&area, x, y, e),
                a: x,
                b: y,
                stamps: (stamp[x as usize], stamp[y as usize]),
            });
        }
    }
    let mut ids = vec![u32::MAX; d];
    let mut out = vec![0u32; d];
    let mut next = 0u32;
    for (v, o) in out.iter_mut().enumerate() {
        let mut r = v;
        while parent[r] as usize != r {
            r = parent[r] as usize;
        }
        if ids[r] == u32::MAX {
            ids[r] = next;
            next += 1;
        }
        *o = ids[r];
    }
    Ok(out)
}

/// A merge of two regions on the heap, valid while both regions are unchanged (`stamps`).
#[derive(Debug, Clone, Copy)]
struct Candidate {
    cost: f64,
    a: u32,
    b: u32,
    stamps: (u32, u32),
}

impl PartialEq for Candidate {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == std::cmp::Ordering::Equal
    }
}

impl Eq for Candidate {}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Candidate {
    /// Reversed, so the max-heap pops the cheapest merge; ties by region indices.
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        other
            .cost
            .total_cmp(&self.cost)
            .then(other.a.cmp(&self.a))
            .then(other.b.cmp(&self.b))
            .then(other.stamps.cmp(&self.stamps))
    }
}
