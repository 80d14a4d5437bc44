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

/// The rule's last step, shared by every triangulation: a triangle whose cotangents are
/// rounding noise ([`resolved`] is false) gets three zero weights, as a zero-area one does;
/// otherwise `cot / 2` per corner, all three scaled by one factor when the largest `|cot|`
/// exceeds `MAX_COTANGENT` (c₀c₁ + c₁c₂ + c₂c₀ = 1 > 0 survives a common positive factor; a
/// separate clamp per corner does not).
pub(super) fn halved_within_bound(mut cot: [f64; 3]) -> [f64; 3] {
    if !resolved(cot) {
        return [0.0; 3];
    }
    let big = cot.iter().fold(0.0f64, |a, c| a.max(c.abs()));
    if big > MAX_COTANGENT {
        let s = MAX_COTANGENT / big;
        for c in cot.iter_mut() {
            *c *= s;
        }
    }
    cot.map(|c| 0.5 * c)
}

/// How far `c₀c₁ + c₁c₂ + c₂c₀` may be from 1 before a triangle's cotangents are taken for
/// rounding noise. The identity holds for every triangle; computed, it is off by about
/// `ε·cot²` (ε = 2⁻⁵² the relative rounding of `f64`), i.e. by less than 10⁻⁴ down to angles of
/// 10⁻⁶ rad and by far more than 1 below 10⁻⁸ rad, so any bound between 10⁻² and 1 draws the
/// same line. Within it the triangle's Laplacian is positive semi-definite with its smaller
/// non-zero eigenvalue within a factor 1.5 of the exact one.
const IDENTITY_TOLERANCE: f64 = 0.5;

/// True when the computed cotangents of a triangle are those of a triangle: they satisfy
/// `c₀c₁ + c₁c₂ + c₂c₀ = 1` (true of every triangle) within [`IDENTITY_TOLERANCE`].
///
/// Why: the Laplacian of one triangle with edge weights `w` is positive semi-definite exactly
/// when `w₀ + w₁ + w₂ ≥ 0` and `w₀w₁ + w₁w₂ + w₂w₀ ≥ 0` (its non-zero eigenvalues are the roots
/// of `λ² − 2(Σw)λ + 3Σwᵢwⱼ`); half-cotangents have `Σwᵢwⱼ = 1/4`. A triangle whose vertices
/// are collinear up to rounding (a "zero-area" triangle of a file, not exactly zero in
/// floating point) has cotangents of noise: the identity fails, `L` can be indefinite and the
/// Cholesky factorisation of `L − σM` then breaks down whatever the shift (issue #42), and
/// even when it does not, the noise joins the triangle's vertices by springs of up to
/// `MAX_COTANGENT` that the surface does not have.
pub(super) fn resolved(cot: [f64; 3]) -> bool {
    let identity = cot[0] * cot[1] + cot[1] * cot[2] + cot[2] * cot[0];
    (identity - 1.0).abs() <= IDENTITY_TOLERANCE
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
