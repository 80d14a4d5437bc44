//! The cotangent rule's shared last steps: the bounded half-cotangent weights of a corner and
//! the Laplacian assembled from per-corner weights, for every triangulation
//! ([`super::SurfaceOperators`], [`super::IntrinsicDelaunay`]).

use faer::sparse::{SparseColMat, Triplet};

/// Largest magnitude allowed for a cotangent weight. Nearly degenerate triangles have
/// unbounded cotangents; when one of a triangle's cotangents exceeds this, all three are scaled
/// down by the same factor (which keeps `L` positive semi-definite), bounding `L`'s entries at
/// the price of a local error on those triangles only. Degenerate (zero-area) triangles
/// contribute nothing.
const MAX_COTANGENT: f64 = 1e5;

/// The rule's last step, shared by every triangulation: `cot / 2` per corner, all three scaled
/// by one factor when the largest `|cot|` exceeds `MAX_COTANGENT` (c₀c₁ + c₁c₂ + c₂c₀ = 1 > 0
/// survives a common positive factor; a separate clamp per corner does not).
pub(super) fn halved_within_bound(mut cot: [f64; 3]) -> [f64; 3] {
    let big = cot.iter().fold(0.0f64, |a, c| a.max(c.abs()));
    if big > MAX_COTANGENT {
        let s = MAX_COTANGENT / big;
        for c in cot.iter_mut() {
            *c *= s;
        }
    }
    cot.map(|c| 0.5 * c)
}

/// The `d × d` Laplacian of `faces` with per-corner weights `half_cotangents` (weight of the
/// edge facing the corner).
pub(super) fn assemble(
    d: usize,
    faces: &[[u32; 3]],
    half_cotangents: &[[f64; 3]],
) -> SparseColMat<usize, f64> {
    let mut triplets = Vec::with_capacity(faces.len() * 12);
    for (idx, w) in faces.iter().zip(half_cotangents) {
        if *w == [0.0; 3] {
            continue;
        }
        for (k, &wk) in w.iter().enumerate() {
            let (a, b) = (idx[(k + 1) % 3] as usize, idx[(k + 2) % 3] as usize);
            triplets.push(Triplet::new(a, b, -wk));
            triplets.push(Triplet::new(b, a, -wk));
            triplets.push(Triplet::new(a, a, wk));
            triplets.push(Triplet::new(b, b, wk));
        }
    }
    // Duplicate entries are summed by the constructor.
    SparseColMat::try_new_from_triplets(d, d, &triplets)
        .expect("indices are in range by TriMesh's invariants")
}
