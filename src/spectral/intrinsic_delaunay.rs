//! [`IntrinsicDelaunay`]: the intrinsic Delaunay triangulation of a mesh, made by edge flips
//! on its edge lengths, and the cotangent Laplacian and lumped mass on it.
//!
//! Why: the cotangent Laplacian of a poor triangulation (obtuse triangles, slivers: CAD
//! exports, uneven sampling) has negative edge weights, so it violates the maximum principle
//! and its low spectrum, and every descriptor made from it, depends on how the surface was
//! triangulated. Flipping every non-Delaunay edge *intrinsically* — the surface's geometry and
//! vertices stay exactly as they are; only which geodesic edges join them changes — gives the
//! intrinsic Delaunay triangulation, whose cotangent weights are all non-negative (Bobenko &
//! Springborn 2007; Fisher, Springborn, Schröder & Bobenko 2007; Sharp, Soliman & Crane 2019).
//! The Laplacian stays `d × d` on the same vertices.
//!
//! Known issues: only manifold, consistently oriented interior edges are flipped. Boundary
//! edges, non-manifold edges (three or more faces) and edges between two faces of opposite
//! orientation are kept as they are ([`IntrinsicDelaunay::frozen_edges`] counts the last two
//! kinds); their weights can stay negative. The tufted cover of Sharp & Crane 2020, which
//! would also flip around non-manifold edges, is not implemented.

use super::cotangent_weights::{assemble, halved_within_bound};
use crate::mesh::{TriMesh, norm, sub};
use faer::sparse::SparseColMat;
use std::collections::HashMap;

const NONE: usize = usize::MAX;

/// An edge is flipped when the sum of its two opposite cotangents is below `−FLIP_TOLERANCE`
/// (exactly co-circular quads are left alone, so rounding cannot make flips cycle).
const FLIP_TOLERANCE: f64 = 1e-12;

/// The intrinsic Delaunay triangulation of a mesh (`d` vertices, `F` faces before and after:
/// a flip replaces two triangles by two).
///
/// - `faces`: `F × 3` vertex indices (the same vertices as the mesh, counter-clockwise as the
///   mesh's faces were);
/// - `lengths`: `F × 3`, the intrinsic length of edge `(faces[f][k], faces[f][k+1])`, file
///   units (an intrinsic edge is a geodesic on the mesh's surface, generally not a straight
///   segment between its endpoints);
/// - `flips`: how many flips were made; `frozen_edges`: interior edges never flipped because
///   they are non-manifold or join faces of opposite orientation.
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::IntrinsicDelaunay};
/// // A thin rhombus cut along its long diagonal: the two angles facing it are obtuse.
/// let m = TriMesh::new(
///     vec![[0., 0., 0.], [1., 0.2, 0.], [2., 0., 0.], [1., -0.2, 0.]],
///     vec![[0, 3, 2], [0, 2, 1]],
/// ).unwrap();
/// let idt = IntrinsicDelaunay::new(&m);
/// assert_eq!(idt.flips(), 1); // now cut along the short diagonal 1–3
/// let l = idt.laplacian(4);
/// assert!(l.triplet_iter().all(|t| t.row == t.col || *t.val <= 0.0)); // weights ≥ 0
/// ```
///
/// See also [`crate::spectral::SurfaceOperators`] (the cotangent operators of the mesh as
/// triangulated), [`crate::spectral::LaplacianKind`].
#[derive(Debug, Clone)]
pub struct IntrinsicDelaunay {
    faces: Vec<[u32; 3]>,
    lengths: Vec<[f64; 3]>,
    flips: usize,
    frozen_edges: usize,
}

impl IntrinsicDelaunay {
    /// Flips every non-Delaunay manifold edge of `mesh` until none is left (or, as a guard
    /// against rounding, after `50 × halfedges` flips). O(F log F) in practice.
    pub fn new(mesh: &TriMesh) -> Self {
        let faces = mesh.faces().to_vec();
        let lengths: Vec<[f64; 3]> = (0..faces.len())
            .map(|f| {
                let p = mesh.corners(f);
                [0, 1, 2].map(|k| norm(sub(p[(k + 1) % 3], p[k])))
            })
            .collect();
        let (twins, frozen_edges) = twins(&faces);
        let mut t = IntrinsicDelaunay {
            faces,
            lengths,
            flips: 0,
            frozen_edges,
        };
        t.flip_to_delaunay(twins);
        t
    }

    /// The triangles, `F × 3`.
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// Intrinsic edge lengths, `F × 3` (edge `k` joins corners `k` and `k+1`).
    pub fn lengths(&self) -> &[[f64; 3]] {
        &self.lengths
    }

    /// Number of edge flips made.
    pub fn flips(&self) -> usize {
        self.flips
    }

    /// Interior edges left unflipped because they are non-manifold or join two faces of
    /// opposite orientation.
    pub fn frozen_edges(&self) -> usize {
        self.frozen_edges
    }

    /// `cot(θ_k) / 2` per corner of the intrinsic triangles (`F × 3`), under the rule of
    /// [`crate::spectral::SurfaceOperators`] (degenerate faces give zeros; one common factor
    /// when a cotangent exceeds `MAX_COTANGENT`).
    pub fn half_cotangents(&self) -> Vec<[f64; 3]> {
        self.lengths
            .iter()
            .map(half_cotangents_of_lengths)
            .collect()
    }

    /// The cotangent Laplacian of the intrinsic triangulation, `d × d` (`d` = the mesh's
    /// vertex count), symmetric positive semi-definite, `L 1 = 0`.
    pub fn laplacian(&self, d: usize) -> SparseColMat<usize, f64> {
        assemble(d, &self.faces, &self.half_cotangents())
    }

    /// Lumped (barycentric) vertex areas of the intrinsic triangles, length `d`, squared file
    /// units. They sum to the mesh's area (flips preserve area).
    pub fn vertex_areas(&self, d: usize) -> Vec<f64> {
        let mut m = vec![0.0; d];
        for (f, l) in self.faces.iter().zip(&self.lengths) {
            let a = heron(l[0], l[1], l[2]) / 3.0;
            for &v in f {
                m[v as usize] += a;
            }
        }
        m
    }

    fn flip_to_delaunay(&mut self, mut twin: Vec<usize>) {
        let halfedges = twin.len();
        let mut queued = vec![false; halfedges];
        let mut stack: Vec<usize> = Vec::new();
        for h in 0..halfedges {
            if twin[h] != NONE && h < twin[h] {
                queued[h] = true;
                stack.push(h);
            }
        }
        let max_flips = 50 * halfedges;
        // Last in, first out: the order is fixed by the input, so the result is deterministic.
        while let Some(h) = stack.pop() {
            queued[h] = false;
            if self.flips >= max_flips {
                break;
            }
            let g = twin[h];
            if g == NONE {
                continue;
            }
            if let Some(outer) = self.try_flip(h, g, &mut twin) {
                self.flips += 1;
                for e in outer {
                    let e = if twin[e] != NONE {
                        e.min(twin[e])
                    } else {
                        continue;
                    };
                    if !queued[e] {
                        queued[e] = true;
                        stack.push(e);
                    }
                }
            }
        }
    }

    /// Flips the edge of halfedges `h` (a→b in face f0) and `g` (b→a in f1) if it is not
    /// Delaunay and the flip is geometrically valid; returns the four outer halfedges.
    fn try_flip(&mut self, h: usize, g: usize, twin: &mut [usize]) -> Option<[usize; 4]> {
        let (f0, k0, f1, k1) = (h / 3, h % 3, g / 3, g % 3);
        let (c, d) = (self.faces[f0][(k0 + 2) % 3], self.faces[f1][(k1 + 2) % 3]);
        let (a, b) = (self.faces[f0][k0], self.faces[f0][(k0 + 1) % 3]);
        if c == d || c == a || c == b || d == a || d == b {
            return None;
        }
        let l_ab = self.lengths[f0][k0];
        let (l_bc, l_ca) = (
            self.lengths[f0][(k0 + 1) % 3],
            self.lengths[f0][(k0 + 2) % 3],
        );
        let (l_ad, l_db) = (
            self.lengths[f1][(k1 + 1) % 3],
            self.lengths[f1][(k1 + 2) % 3],
        );
        let (area0, area1) = (heron(l_ab, l_bc, l_ca), heron(l_ab, l_ad, l_db));
        if area0 <= 0.0 || area1 <= 0.0 {
            return None;
        }
        // Cotangents of the angles at c and d, which face the edge ab.
        let cot_c = (l_bc * l_bc + l_ca * l_ca - l_ab * l_ab) / (4.0 * area0);
        let cot_d = (l_ad * l_ad + l_db * l_db - l_ab * l_ab) / (4.0 * area1);
        if cot_c + cot_d >= -FLIP_TOLERANCE {
            return None;
        }
        // Lay the two triangles out in the plane: a at the origin, b on the +x axis, c above,
        // d below; the new edge is the segment cd.
        let xc = (l_ab * l_ab + l_ca * l_ca - l_bc * l_bc) / (2.0 * l_ab);
        let xd = (l_ab * l_ab + l_ad * l_ad - l_db * l_db) / (2.0 * l_ab);
        let (yc, yd) = (2.0 * area0 / l_ab, -2.0 * area1 / l_ab);
        let l_cd = (xc - xd).hypot(yc - yd);
        if !(heron(l_ca, l_ad, l_cd) > 0.0 && heron(l_db, l_bc, l_cd) > 0.0) {
            return None;
        }
        let (h_bc, h_ca) = (3 * f0 + (k0 + 1) % 3, 3 * f0 + (k0 + 2) % 3);
        let (h_ad, h_db) = (3 * f1 + (k1 + 1) % 3, 3 * f1 + (k1 + 2) % 3);
        let (t_bc, t_ca, t_ad, t_db) = (twin[h_bc], twin[h_ca], twin[h_ad], twin[h_db]);
        // f0 becomes (c, a, d): c→a, a→d, d→c; f1 becomes (d, b, c): d→b, b→c, c→d.
        self.faces[f0] = [c, a, d];
        self.lengths[f0] = [l_ca, l_ad, l_cd];
        self.faces[f1] = [d, b, c];
        self.lengths[f1] = [l_db, l_bc, l_cd];
        let link = |twin: &mut [usize], x: usize, y: usize| {
            twin[x] = y;
            if y != NONE {
                twin[y] = x;
            }
        };
        link(twin, 3 * f0, t_ca);
        link(twin, 3 * f0 + 1, t_ad);
        link(twin, 3 * f0 + 2, 3 * f1 + 2);
        link(twin, 3 * f1, t_db);
        link(twin, 3 * f1 + 1, t_bc);
        Some([3 * f0, 3 * f0 + 1, 3 * f1, 3 * f1 + 1])
    }
}

/// Twin of every halfedge (`3f + k`: corner k → k+1 of face f), `NONE` on boundary edges and
/// on edges that cannot be flipped (non-manifold, or two faces of opposite orientation), and
/// the number of interior edges of the latter kinds.
fn twins(faces: &[[u32; 3]]) -> (Vec<usize>, usize) {
    let mut by_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::with_capacity(faces.len() * 2);
    for (f, idx) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (idx[k], idx[(k + 1) % 3]);
            by_edge
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(3 * f + k);
        }
    }
    let mut twin = vec![NONE; faces.len() * 3];
    let mut frozen = 0;
    let source = |h: usize| faces[h / 3][h % 3];
    for hs in by_edge.values() {
        match hs.as_slice() {
            [_] => {}
            &[h, g] if source(h) != source(g) => {
                twin[h] = g;
                twin[g] = h;
            }
            _ => frozen += 1,
        }
    }
    (twin, frozen)
}

/// Area of a triangle from its side lengths (Kahan's stable form of Heron's formula); 0 for
/// lengths that violate the triangle inequality.
pub(super) fn heron(a: f64, b: f64, c: f64) -> f64 {
    let mut s = [a, b, c];
    s.sort_by(|x, y| y.total_cmp(x));
    let [a, b, c] = s;
    let q = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
    if q > 0.0 { 0.25 * q.sqrt() } else { 0.0 }
}

/// Half-cotangents of a triangle given its side lengths `l[k] = |corner k → corner k+1|`, under
/// the rule of [`crate::spectral::SurfaceOperators`].
fn half_cotangents_of_lengths(l: &[f64; 3]) -> [f64; 3] {
    let area = heron(l[0], l[1], l[2]);
    if area.is_nan() || area <= 0.0 || !area.is_finite() {
        return [0.0; 3];
    }
    // Corner k lies between edges k and k+2; the edge facing it is k+1.
    halved_within_bound([0, 1, 2].map(|k| {
        let (u, v, w) = (l[k], l[(k + 2) % 3], l[(k + 1) % 3]);
        (u * u + v * v - w * w) / (4.0 * area)
    }))
}
