//! [`collection_views`]: one view for a whole collection, so that every picture shows its
//! shape from the same side.
//!
//! Each shape's own [canonical view](super::canonical_frame) follows its principal axes, which
//! flip and swap from shape to shape (one chair seen from the front, the next lying on its
//! side). Here the view is set once, in the collection frame of
//! [`crate::align::align_collection`], and carried to each shape by its rotation into that
//! frame: the same camera for every shape, up on screen the collection's up.

use super::ViewFrame;
use super::canonical_view::weighted_centroid;
use crate::align::{AlignError, CollectionAlignment, FrameCase};
use crate::mesh::{TriMesh, cross, dot, norm, sub};

/// Azimuth of the camera from the collection's short horizontal axis toward its long one
/// (degrees): a three-quarter view, the usual product shot, shows a shape's long side and one
/// end at once, where a straight side or end view hides parts behind others (a quadruped's
/// far legs, a chair's back legs).
const AZIMUTH_DEGREES: f64 = 30.0;
/// Elevation of the camera above the horizontal plane (degrees): from slightly above, seats
/// and tops are seen without losing the silhouette.
const ELEVATION_DEGREES: f64 = 20.0;
/// A third moment below this share of `σ³` is no lean (a symmetric collection): the sign then
/// comes from the axis' largest component, as [`super::canonical_frame`] does.
const NO_LEAN: f64 = 1e-3;

/// One view frame per shape, all looking at their shape from the same side of the
/// collection frame.
///
/// - `meshes`: the shapes (#S), in the order of `alignment.shapes`;
/// - `alignment`: their collection alignment ([`crate::align::align_collection`]);
/// - returns #S [`ViewFrame`]s, centred on each shape's area-weighted centroid, with screen
///   up along the collection's up axis and a three-quarter view from slightly above.
///
/// The rule:
/// - **Up**: when the files' frames already agree (or there is one shape) the files are
///   trusted as written, `+y` up — the convention of `--up`'s default (the alignment's own up
///   rule reads the geometry and names another axis on upright chairs, docs/ALIGN.md). When
///   the shapes were moved into a synchronised frame, that frame's up axis.
/// - **Around up**: the principal axes of the pooled horizontal spread (every shape centred,
///   rotated into the collection frame, one equal weight per shape): the camera looks mostly
///   across the long axis, turned by 30° toward its heavier end, from the lighter side of the
///   short axis (a chair is seen from its seat's side, not its back's), 20° from above.
///
/// See also: [`super::canonical_frame`] (each shape alone), [`collection_views_or_own`] (with
/// the fallback the pictures use).
pub fn collection_views(meshes: &[TriMesh], alignment: &CollectionAlignment) -> Vec<ViewFrame> {
    let up = match alignment.case {
        FrameCase::AlreadyAligned | FrameCase::Single => [0.0, 1.0, 0.0],
        FrameCase::Synchronised => alignment.up,
    };
    let rotations: Vec<&[[f64; 3]; 3]> = alignment
        .shapes
        .iter()
        .map(|s| &s.transform.rotation)
        .collect();
    let weighted: Vec<(Vec<f64>, [f64; 3])> = meshes.iter().map(weighted_centroid).collect();
    let toward = camera_direction(meshes, &rotations, &weighted, up);
    let screen_up = normalise(sub(up, scale(toward, dot(up, toward))));
    let right = cross(screen_up, toward);
    weighted
        .iter()
        .zip(&rotations)
        .map(|(&(_, center), r)| {
            // Collection-frame directions into the file: the transpose of the rotation.
            let back = |v: [f64; 3]| {
                [
                    r[0][0] * v[0] + r[1][0] * v[1] + r[2][0] * v[2],
                    r[0][1] * v[0] + r[1][1] * v[1] + r[2][1] * v[2],
                    r[0][2] * v[0] + r[1][2] * v[1] + r[2][2] * v[2],
                ]
            };
            ViewFrame {
                center,
                axes: [back(right), back(screen_up), back(toward)],
            }
        })
        .collect()
}

/// [`collection_views`] of `meshes`, or each shape's own [canonical view](super::canonical_frame)
/// when the alignment failed (with the reason, for a warning: pictures are an optional stage
/// and never stop a run).
///
/// `alignment`: the caller's [`crate::align::align_collection`] of `meshes` with its defaults
/// when it has one (a propagation's rigid route does); `None` aligns here, about 0.1–0.2 s of
/// CPU per shape.
pub fn collection_views_or_own(
    meshes: &[TriMesh],
    alignment: Option<&Result<CollectionAlignment, AlignError>>,
) -> (Vec<ViewFrame>, Option<String>) {
    let made;
    let alignment = match alignment {
        Some(a) => a,
        None => {
            made = crate::align::align_collection(meshes, &crate::align::AlignOptions::default());
            &made
        }
    };
    match alignment {
        Ok(alignment) => (collection_views(meshes, alignment), None),
        Err(e) => (
            meshes.iter().map(super::canonical_frame).collect(),
            Some(format!(
                "pictures: the collection could not be aligned ({e}); each shape is shown in its own principal frame"
            )),
        ),
    }
}

/// The camera's direction (toward the viewer) in the collection frame: from the pooled
/// horizontal spread of the shapes (see [`collection_views`]).
fn camera_direction(
    meshes: &[TriMesh],
    rotations: &[&[[f64; 3]; 3]],
    weighted: &[(Vec<f64>, [f64; 3])],
    up: [f64; 3],
) -> [f64; 3] {
    // Two horizontal axes: any pair orthogonal to up, then turned onto the principal axes.
    let helper = if up[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let h0 = normalise(cross(helper, up));
    let h1 = cross(up, h0);
    // Every vertex's (h0, h1) coordinates after centring its shape and rotating it into the
    // collection frame, with its weight (one equal weight per shape), in mesh order.
    let for_each = |f: &mut dyn FnMut(f64, f64, f64)| {
        for ((mesh, r), (w, c)) in meshes.iter().zip(rotations).zip(weighted) {
            let total: f64 = w.iter().sum();
            for (p, &wi) in mesh.positions().iter().zip(w) {
                let d = sub(*p, *c);
                let q = [dot(r[0], d), dot(r[1], d), dot(r[2], d)];
                f(dot(q, h0), dot(q, h1), wi / total);
            }
        }
    };
    let mut m2 = [0.0; 3];
    for_each(&mut |a, b, w| {
        m2[0] += w * a * a;
        m2[1] += w * a * b;
        m2[2] += w * b * b;
    });
    // Long axis of the 2 × 2 spread: the angle ½·atan2(2 m_ab, m_aa − m_bb) from h0.
    let theta = 0.5 * (2.0 * m2[1]).atan2(m2[0] - m2[2]);
    let long = add(scale(h0, theta.cos()), scale(h1, theta.sin()));
    let short = cross(up, long);
    let lean = |axis: [f64; 3]| {
        let (a, b) = (dot(axis, h0), dot(axis, h1));
        let (mut s2, mut s3, mut sw) = (0.0, 0.0, 0.0);
        for_each(&mut |x, y, w| {
            let t = a * x + b * y;
            s2 += w * t * t;
            s3 += w * t * t * t;
            sw += w;
        });
        let sigma = (s2 / sw.max(f64::MIN_POSITIVE)).sqrt();
        if s3.abs() > NO_LEAN * sw * sigma.powi(3) {
            s3.signum()
        } else {
            let k = (0..3).fold(0, |b, k| {
                if axis[k].abs() > axis[b].abs() + 1e-12 {
                    k
                } else {
                    b
                }
            });
            axis[k].signum()
        }
    };
    let long = scale(long, lean(long));
    let short = scale(short, -lean(short));
    let (a, e) = (AZIMUTH_DEGREES.to_radians(), ELEVATION_DEGREES.to_radians());
    let horizontal = normalise(add(scale(short, a.cos()), scale(long, a.sin())));
    normalise(add(scale(horizontal, e.cos()), scale(up, e.sin())))
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    a.map(|x| x * s)
}

fn normalise(a: [f64; 3]) -> [f64; 3] {
    let n = norm(a);
    if n > 0.0 { scale(a, 1.0 / n) } else { a }
}
