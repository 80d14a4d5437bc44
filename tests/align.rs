//! The alignment stage: similarity algebra, exact closest points, pairwise registration of
//! moved copies, nearest-point labels.

mod common;

use common::motion::{net_motions, random_similarity, unit};
use coseg::align::{
    AlignError, AlignOptions, FrameCase, RegisterOptions, Similarity, align_collection,
    closest_surface_points, nearest_point_labels, nearest_point_vertex_labels, register_pair,
};
use coseg::mesh::{TriMesh, read_mesh};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::path::Path;

fn shipped(family: &str, i: usize) -> TriMesh {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("collections")
        .join(family)
        .join(format!("{family}_{i:02}.obj"));
    read_mesh(&p).unwrap()
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[test]
fn similarity_inverse_and_compose_round_trip() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for _ in 0..50 {
        let a = random_similarity(&mut rng);
        let b = random_similarity(&mut rng);
        let p = [unit(&mut rng), unit(&mut rng), unit(&mut rng)];
        let back = a.inverse().apply(a.apply(p));
        assert!(dist(back, p) < 1e-9, "{back:?} {p:?}");
        let ab = a.compose(&b).apply(p);
        assert!(dist(ab, a.apply(b.apply(p))) < 1e-9);
        assert!(
            a.compose(&a.inverse())
                .rotation_angle_to(&Similarity::identity())
                < 1e-5
        );
    }
    assert!(Similarity::identity().is_identity());
}

#[test]
fn closest_surface_points_match_brute_force() {
    let mesh = shipped("goblets", 0);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let points: Vec<[f64; 3]> = (0..200)
        .map(|_| [0, 1, 2].map(|_| 3.0 * unit(&mut rng) - 1.5))
        .collect();
    let got = closest_surface_points(&mesh, &points);
    for (p, c) in points.iter().zip(&got) {
        // The reported point lies on the reported face at the reported distance.
        let corners = mesh.corners(c.face);
        let mut q = [0.0; 3];
        for k in 0..3 {
            q[k] = (0..3).map(|i| c.barycentric[i] * corners[i][k]).sum();
        }
        assert!((dist(q, *p) - c.distance).abs() < 1e-9);
        assert!(c.barycentric.iter().all(|&w| w >= -1e-12));
        // No vertex is nearer than the closest surface point.
        let nearest_vertex = mesh
            .positions()
            .iter()
            .map(|v| dist(*v, *p))
            .fold(f64::INFINITY, f64::min);
        assert!(c.distance <= nearest_vertex + 1e-12);
    }
}

/// A shipped shape and a randomly moved copy: the registration finds the motion back (these
/// shapes have at most a mirror symmetry, which no proper rotation realises, so the pose is
/// unique), with a residual near 0 and every sample an inlier.
#[test]
fn register_pair_recovers_a_random_similarity() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for family in ["chairs", "humanoids", "quadrupeds"] {
        let mesh = shipped(family, 1);
        let motion = random_similarity(&mut rng);
        let moved = mesh.map_positions(|p| motion.apply(p)).unwrap();
        let reg = register_pair(&mesh, &moved, &RegisterOptions::default()).unwrap();
        let recovered = reg.transform.compose(&motion);
        assert!(
            recovered.rotation_angle_to(&Similarity::identity()) < 1.0,
            "{family}: {reg:?}"
        );
        assert!((recovered.scale - 1.0).abs() < 1e-6, "{family}");
        assert!(reg.residual < 0.01, "{family}: {}", reg.residual);
        assert!(reg.inlier_share > 0.99, "{family}: {}", reg.inlier_share);
        let worst = mesh
            .positions()
            .iter()
            .map(|&p| dist(recovered.apply(p), p))
            .fold(0.0, f64::max);
        let extent = mesh
            .positions()
            .iter()
            .map(|&p| dist(p, mesh.positions()[0]))
            .fold(0.0, f64::max);
        assert!(worst < 0.02 * extent, "{family}: {worst} of {extent}");
    }
}

#[test]
fn register_pair_is_deterministic() {
    let a = shipped("chairs", 0);
    let b = shipped("chairs", 3);
    let o = RegisterOptions::default();
    let r1 = register_pair(&a, &b, &o).unwrap();
    let r2 = register_pair(&a, &b, &o).unwrap();
    assert_eq!(r1, r2);
    // Two different chairs in the same frame: the given frame is kept, the residual is that of
    // similar but different shapes.
    assert!(
        r1.transform.rotation_angle_to(&Similarity::identity()) < 10.0,
        "{r1:?}"
    );
    assert!(r1.residual > 0.001 && r1.residual < 0.3, "{}", r1.residual);
}

/// A rotationally symmetric goblet: the runner-up pose (another rotation about its axis) is
/// about as good as the best one, and is reported.
#[test]
fn register_pair_reports_the_ambiguity_of_a_symmetric_shape() {
    let g = shipped("goblets", 2);
    let reg = register_pair(&g, &g, &RegisterOptions::default()).unwrap();
    assert!(reg.residual < 1e-9);
    let r = reg
        .runner_up
        .expect("a goblet turned about its axis fits as well");
    assert!(r.residual < 0.1, "{r:?}");
}

#[test]
fn nearest_point_labels_on_itself_take_an_incident_face() {
    let mesh = shipped("chairs", 2);
    let face_labels: Vec<i32> = (0..mesh.face_count() as i32).collect();
    let (labels, d) =
        nearest_point_labels(&mesh, &face_labels, &mesh, &Similarity::identity()).unwrap();
    assert_eq!(labels.len(), mesh.vertex_count());
    for (v, (&l, &dv)) in labels.iter().zip(&d).enumerate() {
        assert!(dv < 1e-9);
        assert!(mesh.faces()[l as usize].contains(&(v as u32)), "vertex {v}");
    }
    let vertex_labels: Vec<i32> = (0..mesh.vertex_count() as i32).collect();
    let (own, _) =
        nearest_point_vertex_labels(&mesh, &vertex_labels, &mesh, &Similarity::identity()).unwrap();
    assert_eq!(own, vertex_labels);
}

#[test]
fn nearest_point_labels_reject_a_wrong_label_count() {
    let mesh = shipped("chairs", 2);
    let err = nearest_point_labels(&mesh, &[0, 1], &mesh, &Similarity::identity()).unwrap_err();
    assert!(
        matches!(err, AlignError::LabelCount { found: 2, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("face labels"));
}

fn family(name: &str) -> Vec<TriMesh> {
    (0..6).map(|i| shipped(name, i)).collect()
}

/// The shipped families are generated in one frame: detected, every transform the identity
/// bit for bit.
#[test]
fn align_collection_keeps_already_aligned_frames_exactly() {
    for name in ["chairs", "goblets", "humanoids", "quadrupeds"] {
        let a = align_collection(&family(name), &AlignOptions::default()).unwrap();
        assert_eq!(
            a.case,
            FrameCase::AlreadyAligned,
            "{name}: {}",
            a.given_frame_share
        );
        assert!(a.shapes.iter().all(|s| s.transform.is_identity()));
    }
}

/// Quadrupeds moved at random: synchronised, every shape's recovered rotation composed with
/// its true motion is one common rotation (within 5°).
#[test]
fn align_collection_recovers_moved_quadrupeds() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut truth = Vec::new();
    let moved: Vec<TriMesh> = family("quadrupeds")
        .into_iter()
        .map(|m| {
            let t = random_similarity(&mut rng);
            truth.push(t);
            m.map_positions(|p| t.apply(p)).unwrap()
        })
        .collect();
    let a = align_collection(&moved, &AlignOptions::default()).unwrap();
    assert_eq!(a.case, FrameCase::Synchronised);
    let net = net_motions(&a, &truth);
    for n in &net {
        assert!(n.rotation_angle_to(&net[0]) < 5.0, "{n:?}");
    }
    let again = align_collection(&moved, &AlignOptions::default()).unwrap();
    assert_eq!(a, again);
}

/// Regression (the already-aligned decision sat at its threshold on goblets and humanoids,
/// share 0.50): the published families agree clearly, the same families randomly moved
/// clearly do not.
#[test]
fn already_aligned_decision_is_clear_of_its_threshold() {
    for name in ["chairs", "goblets", "humanoids", "quadrupeds"] {
        let shapes = family(name);
        let a = align_collection(&shapes, &AlignOptions::default()).unwrap();
        assert_eq!(a.case, FrameCase::AlreadyAligned, "{name}");
        assert!(
            a.given_frame_share >= 0.6,
            "{name}: {}",
            a.given_frame_share
        );
        assert!(a.shapes.iter().all(|s| s.transform.is_identity()));
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let moved: Vec<TriMesh> = shapes
            .iter()
            .map(|m| {
                let t = random_similarity(&mut rng);
                m.map_positions(|p| t.apply(p)).unwrap()
            })
            .collect();
        let b = align_collection(&moved, &AlignOptions::default()).unwrap();
        assert_eq!(b.case, FrameCase::Synchronised, "{name} moved");
        assert!(
            b.given_frame_share <= 0.3,
            "{name} moved: {}",
            b.given_frame_share
        );
    }
}

/// A shape's own symmetries are found from the data: the goblets are surfaces of revolution
/// about +y, the stools (chairs 1 and 4, no back) overlay themselves turned a quarter about y.
#[test]
fn align_collection_reports_own_symmetries() {
    let goblets = align_collection(&family("goblets"), &AlignOptions::default()).unwrap();
    let axis = goblets
        .symmetry_axis
        .expect("goblets turn about their stem");
    assert!(axis[1].abs() > 0.99, "{axis:?}");
    let chairs = align_collection(&family("chairs"), &AlignOptions::default()).unwrap();
    let quarter_about_y = |r: &[[f64; 3]; 3]| {
        let turn = Similarity {
            rotation: *r,
            scale: 1.0,
            translation: [0.0; 3],
        };
        let t = turn.apply([0.0, 1.0, 0.0]);
        dist(t, [0.0, 1.0, 0.0]) < 0.05
            && (turn.rotation_angle_to(&Similarity::identity()) - 90.0).abs() < 5.0
    };
    for i in [1, 4] {
        assert!(
            chairs.shapes[i].symmetries.iter().any(quarter_about_y),
            "stool {i}: {:?}",
            chairs.shapes[i].symmetries
        );
    }
    assert!(chairs.shapes[0].symmetries.is_empty());
}
