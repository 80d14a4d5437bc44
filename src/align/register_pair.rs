//! [`register_pair`]: the similarity that takes one shape onto another (rigid shapes, any
//! pose, any scale).

use super::AlignError;
use super::similarity::{Similarity, rotation_angle};
use super::surface_samples::{COARSE_SAMPLES, Prepared};
use crate::mesh::TriMesh;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

/// Options of [`register_pair`] (and of each registration of
/// the collection stage).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RegisterOptions {
    /// Surface samples per shape (default 1000): more is slower and a little more precise.
    pub samples: usize,
    /// Share of the nearest-point pairs kept in each direction (default 0.9): the rest, the
    /// farthest, are treated as outliers (parts one shape has and the other lacks).
    pub trim: f64,
    /// Iterations of the final refinement at most (default 30); it stops earlier once the
    /// rotation has settled.
    pub max_iterations: usize,
    /// Seed of the surface samples (default 0).
    pub seed: u64,
}

impl Default for RegisterOptions {
    fn default() -> Self {
        Self {
            samples: 1000,
            trim: 0.9,
            max_iterations: 30,
            seed: 0,
        }
    }
}

impl RegisterOptions {
    pub(crate) fn check(&self) -> Result<(), AlignError> {
        if self.samples < 10 {
            return Err(AlignError::BadOption(format!(
                "samples must be at least 10 (got {})",
                self.samples
            )));
        }
        if !(self.trim > 0.0 && self.trim <= 1.0) {
            return Err(AlignError::BadOption(format!(
                "trim must be in (0, 1] (got {})",
                self.trim
            )));
        }
        Ok(())
    }
}

/// One locally optimal pose of the target on the source.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Target onto source.
    pub transform: Similarity,
    /// Symmetric trimmed chamfer distance, in units of the source's RMS radius.
    pub residual: f64,
    /// Angle of this candidate's rotation from the best one's, in degrees.
    pub angle_to_best: f64,
}

/// The result of [`register_pair`].
#[derive(Debug, Clone, PartialEq)]
pub struct Registration {
    /// The similarity taking the target onto the source (apply it to target points).
    pub transform: Similarity,
    /// Symmetric trimmed chamfer distance after registration (the mean of the kept nearest-point
    /// distances, target→source and source→target, averaged), in units of the source's RMS
    /// radius: 0 for a shape and a moved copy of it, about 0.05–0.15 for two chairs.
    pub residual: f64,
    /// Share of the samples (both directions) whose nearest point on the other shape lies
    /// within two sample spacings: 1 when the surfaces overlay everywhere.
    pub inlier_share: f64,
    /// The best candidate whose rotation differs from the chosen one (by more than 20°), with
    /// its residual: a residual close to [`Registration::residual`] means the pair is ambiguous
    /// (a symmetric shape: chair front/back, left/right). `None` when every refined candidate
    /// converged to the chosen rotation.
    pub runner_up: Option<Candidate>,
    /// Every refined candidate with a distinct rotation, best first (the chosen one first).
    pub candidates: Vec<Candidate>,
}

/// Candidates refined fully after the coarse pass: the best of the 25 starts by coarse
/// residual, with distinct rotations. Four covers a chair's front/back and left/right flips
/// and the up/down flip of a box-like shape.
const REFINED: usize = 4;
/// Iterations of the coarse pass: ICP from a principal-frame start settles in a few steps;
/// the coarse pass only ranks the starts.
const COARSE_ITERATIONS: usize = 6;
/// Two rotations are "the same pose" within this angle (degrees): ICP runs from different
/// starts that reach one minimum end within a degree or two of each other; distinct
/// symmetric poses of real shapes are 90° or 180° apart.
const DISTINCT_DEGREES: f64 = 20.0;
/// A sample is an inlier within this many sample spacings (`sqrt(area / samples)`) of the
/// other surface: the spacing is what a perfectly overlaid surface leaves between samples.
const INLIER_SPACINGS: f64 = 2.0;

/// The similarity taking `target` onto `source`, robust to pose, scale and partly different
/// shapes.
///
/// - `source`, `target`: validated meshes, any pose and size (`S`, `T` faces);
/// - returns a [`Registration`]: the transform (apply it to the target's points), the
///   residual in source RMS radii, the inlier share, the runner-up pose (ambiguity) and every
///   distinct refined pose.
///
/// Method: both shapes centred on their area-weighted centroids and scaled to unit RMS radius
/// (exact surface integrals); 25 starting rotations: the identity (the given frames) and the
/// 24 proper signed axis permutations between the two inertia frames; each start refined by a
/// few steps of trimmed ICP on seeded area-weighted samples in both directions (point pairs
/// target→source and source→target, the farthest `1 − trim` of each direction dropped, the
/// rotation and translation by Kabsch); the best [`REFINED`] distinct starts refined to
/// convergence on all samples; the lowest symmetric trimmed chamfer wins. The scale is the
/// ratio of the RMS radii. Cost: about 30k nearest-sample queries for the coarse pass and
/// up to `4 × 2 × samples × max_iterations` for the refinement, independent of the mesh
/// size beyond the moments (`O(S + T)`).
///
/// Deterministic: the samples are seeded, the candidates run independently and ties keep the
/// earlier candidate (the given frame first).
///
/// See also: [`nearest_point_labels`](super::nearest_point_labels) (labels through the
/// result).
///
/// Known issues: a rigid method: posed, non-rigid shapes (an animal sitting and standing)
/// register only roughly; for them the intrinsic features are the right tool. Shapes with
/// the same inertia spectrum in two axes (a cylinder) rely on the ICP to find the pose.
pub fn register_pair(
    source: &TriMesh,
    target: &TriMesh,
    options: &RegisterOptions,
) -> Result<Registration, AlignError> {
    options.check()?;
    let s = Prepared::new(source, options.samples, options.seed)?;
    register_onto_from(&s, target, options, &Matrix3::identity())
}

/// [`register_pair`] with the source already prepared (`Prepared::new(source, options.samples,
/// options.seed)`), for many targets registered onto one source (the source's samples and
/// indices made once), and with the first start `given` (a rotation taking the target's
/// orientation onto the source's) in place of the files' own frames: where a collection
/// alignment already relates the two shapes, its relative rotation is the start that turns
/// with the files (the identity on files whose frames agree, so their result is unchanged),
/// while the identity is a start only as long as the files happen to be posed alike.
pub(crate) fn register_onto_from(
    source: &Prepared,
    target: &TriMesh,
    options: &RegisterOptions,
    given: &Matrix3<f64>,
) -> Result<Registration, AlignError> {
    options.check()?;
    let t = Prepared::new(target, options.samples, options.seed)?;
    Ok(register_prepared(source, &t, options, given))
}

/// [`register_pair`] on shapes already prepared (their samples and indices reused), the first
/// start `given` ([`register_onto_from`]).
pub(crate) fn register_prepared(
    s: &Prepared,
    t: &Prepared,
    options: &RegisterOptions,
    given: &Matrix3<f64>,
) -> Registration {
    let starts = starting_rotations(given, &s.moments.frame, &t.moments.frame);
    let coarse: Vec<Pose> = starts
        .par_iter()
        .map(|r| coarse_icp(s, t, r, options))
        .collect();
    let mut order: Vec<usize> = (0..coarse.len()).collect();
    order.sort_by(|&a, &b| coarse[a].residual.total_cmp(&coarse[b].residual));
    let mut picked: Vec<Pose> = Vec::new();
    for &i in &order {
        if picked.len() == REFINED {
            break;
        }
        if picked
            .iter()
            .all(|p| angle(&p.rotation, &coarse[i].rotation) > DISTINCT_DEGREES)
        {
            picked.push(coarse[i]);
        }
    }
    let refined: Vec<Pose> = picked
        .par_iter()
        .map(|p| {
            icp(
                s,
                t,
                options.samples,
                *p,
                options.max_iterations,
                options.trim,
            )
        })
        .collect();
    // Refinement can bring two starts to one pose: keep the better of each.
    let mut order: Vec<usize> = (0..refined.len()).collect();
    order.sort_by(|&a, &b| refined[a].residual.total_cmp(&refined[b].residual));
    let mut distinct: Vec<Pose> = Vec::new();
    for i in order {
        if distinct
            .iter()
            .all(|p| angle(&p.rotation, &refined[i].rotation) > DISTINCT_DEGREES)
        {
            distinct.push(refined[i]);
        }
    }
    let best = distinct[0];
    let candidates: Vec<Candidate> = distinct
        .iter()
        .map(|p| Candidate {
            transform: to_similarity(s, t, p),
            residual: p.residual,
            angle_to_best: angle(&p.rotation, &best.rotation),
        })
        .collect();
    Registration {
        transform: candidates[0].transform,
        residual: best.residual,
        inlier_share: inlier_share(s, t, &best),
        runner_up: candidates.get(1).cloned(),
        candidates,
    }
}

/// A pose of the normalised target in the normalised source frame: `y ↦ R y + t`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pose {
    pub rotation: Matrix3<f64>,
    pub translation: Vector3<f64>,
    pub residual: f64,
}

/// The pose as a similarity in file units: `x ↦ c_s + r_s (R (x − c_t) / r_t + t)`.
pub(crate) fn to_similarity(s: &Prepared, t: &Prepared, p: &Pose) -> Similarity {
    let scale = s.moments.radius / t.moments.radius;
    let tr = s.moments.centroid + p.translation * s.moments.radius
        - p.rotation * t.moments.centroid * scale;
    let mut rotation = [[0.0; 3]; 3];
    for (i, row) in rotation.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = p.rotation[(i, j)];
        }
    }
    Similarity {
        rotation,
        scale,
        translation: [tr.x, tr.y, tr.z],
    }
}

/// The coarse pass from one start rotation: a few ICP steps on a subsample, enough to rank the
/// starts.
pub(crate) fn coarse_icp(
    s: &Prepared,
    t: &Prepared,
    start: &Matrix3<f64>,
    options: &RegisterOptions,
) -> Pose {
    icp(
        s,
        t,
        COARSE_SAMPLES.min(options.samples),
        Pose {
            rotation: *start,
            translation: Vector3::zeros(),
            residual: f64::INFINITY,
        },
        COARSE_ITERATIONS,
        options.trim,
    )
}

/// The angle (degrees) between two rotations.
pub(crate) fn angle(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    rotation_angle(&to_rows(a), &to_rows(b))
}

/// A rotation's rows, as [`rotation_angle`] and [`Similarity`] take them.
pub(crate) fn to_rows(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [
        [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
        [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
        [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
    ]
}

/// `given` (the identity: the files' own frames), then `F_s P F_tᵀ` for the 24 proper signed
/// permutation matrices `P`.
pub(crate) fn starting_rotations(
    given: &Matrix3<f64>,
    fs: &Matrix3<f64>,
    ft: &Matrix3<f64>,
) -> Vec<Matrix3<f64>> {
    let mut out = vec![*given];
    out.extend(
        signed_permutations()
            .iter()
            .map(|p| fs * p * ft.transpose()),
    );
    out
}

/// The 24 rotations of the cube: signed permutation matrices of determinant +1.
pub(crate) fn signed_permutations() -> Vec<Matrix3<f64>> {
    const PERMS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut out = Vec::with_capacity(24);
    for perm in PERMS {
        for signs in 0..8u32 {
            let mut m = Matrix3::zeros();
            for (row, &col) in perm.iter().enumerate() {
                m[(row, col)] = if signs >> row & 1 == 1 { -1.0 } else { 1.0 };
            }
            if m.determinant() > 0.0 {
                out.push(m);
            }
        }
    }
    out
}

/// Trimmed ICP in both directions from `start`, on the first `n` samples of each shape;
/// `residual` of the result is the symmetric trimmed chamfer at the returned pose.
pub(crate) fn icp(
    s: &Prepared,
    t: &Prepared,
    n: usize,
    start: Pose,
    iterations: usize,
    trim: f64,
) -> Pose {
    let mut pose = start;
    let mut scratch = Scratch::default();
    for _ in 0..iterations {
        let (residual, pairs) = match_pairs(s, t, n, &pose, trim, &mut scratch);
        pose.residual = residual;
        let next = kabsch(&pairs);
        let moved = angle(&next.0, &pose.rotation);
        let shift = (next.1 - pose.translation).norm();
        pose.rotation = next.0;
        pose.translation = next.1;
        // Settled: a thousandth of a degree and of the radius changes no nearest neighbour
        // that matters.
        if moved < 1e-3 && shift < 1e-5 {
            break;
        }
    }
    pose.residual = match_pairs(s, t, n, &pose, trim, &mut scratch).0;
    pose
}

/// A target sample and the source sample it is matched with.
type Pair = (Vector3<f64>, Vector3<f64>);

#[derive(Default)]
struct Scratch {
    forward: Vec<(f64, usize, usize)>,
    backward: Vec<(f64, usize, usize)>,
}

/// Nearest-sample pairs `(target sample, source sample)` kept after trimming each direction,
/// and the symmetric trimmed chamfer of the pose.
fn match_pairs(
    s: &Prepared,
    t: &Prepared,
    n: usize,
    pose: &Pose,
    trim: f64,
    scratch: &mut Scratch,
) -> (f64, Vec<Pair>) {
    let n_s = n.min(s.samples.len());
    let n_t = n.min(t.samples.len());
    let rt = pose.rotation.transpose();
    scratch.forward.clear();
    scratch.backward.clear();
    for (i, y) in t.samples[..n_t].iter().enumerate() {
        let (j, d) = s.index_prefix_nearest(n, &(pose.rotation * y + pose.translation));
        scratch.forward.push((d, i, j));
    }
    for (j, x) in s.samples[..n_s].iter().enumerate() {
        let (i, d) = t.index_prefix_nearest(n, &(rt * (x - pose.translation)));
        scratch.backward.push((d, i, j));
    }
    let mut pairs = Vec::with_capacity(n_s + n_t);
    let mut total = 0.0;
    for list in [&mut scratch.forward, &mut scratch.backward] {
        list.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let keep = ((list.len() as f64 * trim).ceil() as usize).clamp(1, list.len());
        let mut sum = 0.0;
        for &(d, i, j) in &list[..keep] {
            sum += d;
            pairs.push((t.samples[i], s.samples[j]));
        }
        total += sum / keep as f64;
    }
    (total / 2.0, pairs)
}

/// The rotation and translation minimising `Σ |R a + t − b|²` over the pairs `(a, b)`.
fn kabsch(pairs: &[Pair]) -> (Matrix3<f64>, Vector3<f64>) {
    let n = pairs.len() as f64;
    let ma = pairs.iter().map(|p| p.0).sum::<Vector3<f64>>() / n;
    let mb = pairs.iter().map(|p| p.1).sum::<Vector3<f64>>() / n;
    let mut h = Matrix3::zeros();
    for (a, b) in pairs {
        h += (a - ma) * (b - mb).transpose();
    }
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
    let v = vt.transpose();
    let d = (v * u.transpose()).determinant().signum();
    let r = v * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * u.transpose();
    (r, mb - r * ma)
}

/// Share of all samples (both directions) within [`INLIER_SPACINGS`] sample spacings of the
/// other shape at `pose`.
fn inlier_share(s: &Prepared, t: &Prepared, pose: &Pose) -> f64 {
    let n = s.samples.len().max(t.samples.len());
    let spacing = (s.normalised_area / s.samples.len() as f64).sqrt();
    let limit = INLIER_SPACINGS * spacing;
    let rt = pose.rotation.transpose();
    let forward = t
        .samples
        .iter()
        .filter(|y| {
            s.index_prefix_nearest(n, &(pose.rotation * *y + pose.translation))
                .1
                <= limit
        })
        .count();
    let backward = s
        .samples
        .iter()
        .filter(|x| t.index_prefix_nearest(n, &(rt * (*x - pose.translation))).1 <= limit)
        .count();
    (forward + backward) as f64 / (s.samples.len() + t.samples.len()) as f64
}
