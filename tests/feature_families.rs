//! Tests of the feature families beyond the spectrum (src/features/{extrinsic,sdf,user}.rs):
//! oracles, invariances, the alignment rule and determinism.

mod common;

use common::features::{blob, icosphere, permutation, permute_mesh, similarity, spearman};
use coseg::bands::equal_count_bands;
use coseg::features::{
    Alignment, Axis, ExtrinsicOptions, FeatureColumns, SdfOptions, extrinsic_features,
    height_directions, read_user_features, shape_diameter, shape_frame, user_feature_path,
};
use coseg::mesh::TriMesh;

fn ext(directions: usize, alignment: Alignment) -> ExtrinsicOptions {
    let mut o = ExtrinsicOptions::default();
    o.directions = directions;
    o.alignment = alignment;
    o
}

fn up(s: &str) -> Alignment {
    Alignment::Up(s.parse().unwrap())
}

fn bands_of(c: &FeatureColumns) -> Vec<u8> {
    equal_count_bands(&c.values, c.len(), c.vertices, 20)
        .unwrap()
        .labels
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn axis_parses_signs_and_rejects_junk() {
    assert_eq!(
        "-Z".parse::<Axis>().unwrap(),
        Axis {
            index: 2,
            positive: false
        }
    );
    assert_eq!("+x".parse::<Axis>().unwrap(), "x".parse::<Axis>().unwrap());
    assert!("w".parse::<Axis>().is_err());
    assert!("".parse::<Axis>().is_err());
}

#[test]
fn height_directions_are_unit_and_cover_the_hemisphere() {
    let d = height_directions(200, true);
    assert!(d.iter().all(|u| u[2] > 0.0));
    // The mean of a uniform cover of the upper hemisphere is (0, 0, 1/2).
    let mean: Vec<f64> = (0..3)
        .map(|k| d.iter().map(|u| u[k]).sum::<f64>() / 200.0)
        .collect();
    assert!(mean[0].abs() < 0.02 && mean[1].abs() < 0.02, "{mean:?}");
    assert!((mean[2] - 0.5).abs() < 0.01, "{mean:?}");
    let full = height_directions(200, false);
    assert!(full.iter().any(|u| u[2] < -0.9) && full.iter().any(|u| u[2] > 0.9));
    for u in d.iter().chain(&full) {
        assert!((u[0] * u[0] + u[1] * u[1] + u[2] * u[2] - 1.0).abs() < 1e-12);
    }
}

#[test]
fn distances_on_a_sphere_are_the_unit_area_radius_and_the_axis_distance() {
    let m = icosphere(3);
    let c = extrinsic_features(&m, &ext(0, up("+y"))).unwrap();
    assert_eq!(c.names, ["ext_centroid", "ext_axis"]);
    let s = 1.0 / m.total_area().sqrt();
    for (v, p) in m.positions().iter().enumerate() {
        assert!(
            (c.column(0)[v] - s).abs() < 1e-9,
            "centroid distance at {v}"
        );
        let axis = (p[0] * p[0] + p[2] * p[2]).sqrt() * s;
        assert!((c.column(1)[v] - axis).abs() < 1e-9, "axis distance at {v}");
    }
}

#[test]
fn the_up_rule_is_a_cyclic_frame_so_relabelled_axes_give_identical_columns() {
    // Up = +Y on M is the frame (z, x, y); M' = (z, x, y) with up = +Z is the same frame.
    let m = blob(2);
    let cyc = m.map_positions(|p| [p[2], p[0], p[1]]).unwrap();
    let a = extrinsic_features(&m, &ext(30, up("+y"))).unwrap();
    let b = extrinsic_features(&cyc, &ext(30, up("+z"))).unwrap();
    assert_eq!(a, b);
    // The negative axis turns the shape upside down: heights along the up direction reverse.
    let neg = extrinsic_features(&m, &ext(30, up("-y"))).unwrap();
    let f = shape_frame(&m, up("-y"));
    assert_eq!(f.axes[2], [0.0, -1.0, 0.0]);
    assert_ne!(a.column(0), neg.column(0));
}

#[test]
fn extrinsic_columns_ignore_translation_and_uniform_scaling() {
    let m = blob(2);
    let moved = m
        .map_positions(|p| [2.5 * p[0] + 7.0, 2.5 * p[1] - 3.0, 2.5 * p[2] + 0.5])
        .unwrap();
    let a = extrinsic_features(&m, &ext(40, up("z"))).unwrap();
    let b = extrinsic_features(&moved, &ext(40, up("z"))).unwrap();
    assert!(max_abs_diff(&a.values, &b.values) < 1e-9);
}

#[test]
fn a_rotated_copy_gets_the_same_bands_after_pca_alignment() {
    let m = blob(3);
    let rotated = similarity(&m, 1.7);
    let a = extrinsic_features(&m, &ext(60, Alignment::Pca)).unwrap();
    let b = extrinsic_features(&rotated, &ext(60, Alignment::Pca)).unwrap();
    assert!(max_abs_diff(&a.values, &b.values) < 1e-9);
    assert_eq!(bands_of(&a), bands_of(&b));
    // Without alignment the rotation does change the bands (so the test can fail).
    let c = extrinsic_features(&rotated, &ext(60, up("z"))).unwrap();
    let d = extrinsic_features(&m, &ext(60, up("z"))).unwrap();
    assert_ne!(bands_of(&c), bands_of(&d));
}

#[test]
fn pca_sign_rule_makes_a_mirror_image_give_the_same_columns() {
    let m = blob(2);
    let mirrored = m.map_positions(|p| [-p[0], p[1], p[2]]).unwrap();
    let a = extrinsic_features(&m, &ext(30, Alignment::Pca)).unwrap();
    let b = extrinsic_features(&mirrored, &ext(30, Alignment::Pca)).unwrap();
    assert!(max_abs_diff(&a.values, &b.values) < 1e-9);
}

#[test]
fn pca_up_is_the_axis_of_largest_variance() {
    // A long thin box along x: up must be ±x.
    let m = icosphere(2)
        .map_positions(|p| [5.0 * p[0], p[1], 0.5 * p[2]])
        .unwrap();
    let f = shape_frame(&m, Alignment::Pca);
    assert!(f.axes[2][0].abs() > 0.999, "{:?}", f.axes);
    assert!(f.axes[0][2].abs() > 0.999, "{:?}", f.axes);
}

#[test]
fn an_extrinsic_family_without_columns_is_an_error() {
    let mut o = ext(0, up("y"));
    o.centroid_distance = false;
    o.axis_distance = false;
    let m = TriMesh::new(
        vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]],
        vec![[0, 1, 2]],
    )
    .unwrap();
    assert!(extrinsic_features(&m, &o).is_err());
}

// ---- shape diameter function ----

fn shipped_chair() -> TriMesh {
    let p =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("collections/chairs/chairs_00.obj");
    coseg::mesh::read_mesh(&p).unwrap()
}

/// The shipped chair, the default SDF options, and the SDF of the chair before and after a
/// similarity (rotation, translation, scale 3.5).
fn chair_sdf_before_and_after_a_similarity() -> (TriMesh, SdfOptions, FeatureColumns, FeatureColumns)
{
    let m = shipped_chair();
    let o = SdfOptions::default();
    let base = shape_diameter(&m, &o).unwrap();
    let moved = shape_diameter(&similarity(&m, 3.5), &o).unwrap();
    (m, o, base, moved)
}

#[test]
fn sdf_of_a_sphere_is_the_median_chord_of_the_cone() {
    // A ray leaving a unit sphere at angle θ from the inner normal has chord 2 cos θ; the cone
    // is a Fibonacci cap, so the median chord is that of the median angle's cosine.
    let m = icosphere(4);
    let mut o = SdfOptions::default();
    o.rays = 31;
    o.smoothing_rounds = vec![0];
    let c = shape_diameter(&m, &o).unwrap();
    let zmin = (60f64).to_radians().cos();
    // The 16th of 31 cap samples (index 15) has z = 1 − (1 − zmin)·15.5/31.
    let z_med = 1.0 - (1.0 - zmin) * 15.5 / 31.0;
    let expected = 2.0 * z_med / m.total_area().sqrt();
    for (v, &x) in c.column(0).iter().enumerate() {
        assert!(
            (x - expected).abs() < 0.02 * expected,
            "vertex {v}: {x} vs {expected}"
        );
    }
}

#[test]
fn sdf_orients_each_component_and_sees_their_thickness() {
    // Two disjoint spheres, radii 1 and 2, the small one wound inwards: the orientation fix
    // must still cast its rays inside, so the SDF ratio is the radius ratio.
    let (p1, f1) = common::shapes::icosphere_parts(3, 1.0);
    let (p2, f2) = common::shapes::icosphere_parts(3, 2.0);
    let n1 = p1.len() as u32;
    let mut pos = p1.clone();
    pos.extend(p2.iter().map(|p| [p[0] + 10.0, p[1], p[2]]));
    let mut faces: Vec<[u32; 3]> = f1.iter().map(|f| [f[0], f[2], f[1]]).collect();
    faces.extend(f2.iter().map(|f| [f[0] + n1, f[1] + n1, f[2] + n1]));
    let m = TriMesh::new(pos, faces).unwrap();
    let mut o = SdfOptions::default();
    o.smoothing_rounds = vec![0];
    let c = shape_diameter(&m, &o).unwrap();
    let col = c.column(0);
    let small = col[..n1 as usize].iter().sum::<f64>() / n1 as f64;
    let big = col[n1 as usize..].iter().sum::<f64>() / (col.len() - n1 as usize) as f64;
    assert!((big / small - 2.0).abs() < 0.05, "{big} / {small}");
}

#[test]
fn sdf_ranks_survive_rigid_motion_scaling_and_permutation_on_a_shipped_shape() {
    let (m, o, base, moved) = chair_sdf_before_and_after_a_similarity();
    let perm = permutation(m.vertex_count(), 7);
    let permuted = shape_diameter(&permute_mesh(&m, &perm), &o).unwrap();
    for f in 0..base.len() {
        let r = spearman(base.column(f), moved.column(f));
        assert!(r >= 0.99, "column {f}: Spearman {r} after a similarity");
        let back: Vec<f64> = {
            let mut b = vec![0.0; perm.len()];
            for (new, &old) in perm.iter().enumerate() {
                b[old] = permuted.column(f)[new];
            }
            b
        };
        let r = spearman(base.column(f), &back);
        assert!(r >= 0.99, "column {f}: Spearman {r} after a permutation");
    }
}

/// Regression (`the SDF cones were oriented by file axes`, docs/ALIGN.md "Invariance of the
/// bare commands"): each vertex's cone was turned about its normal by a basis computed from
/// the normal's file coordinates, so a rotated chair cast other rays and its thicknesses
/// differed by 1 % (median) and 15 % (worst vertex). The cone now turns with the mesh (the
/// vertex's first edge): a moved, scaled chair gives the same values up to rounding.
#[test]
fn sdf_cones_turn_with_the_mesh_so_a_rotated_chair_keeps_its_thicknesses() {
    let (_, _, base, moved) = chair_sdf_before_and_after_a_similarity();
    for f in 0..base.len() {
        let worst = base
            .column(f)
            .iter()
            .zip(moved.column(f))
            .map(|(a, b)| (a - b).abs() / a.abs().max(1e-300))
            .fold(0.0, f64::max);
        // Rounding of the moved coordinates only (a ray grazing an edge may still switch
        // triangles, at the same distance to rounding).
        assert!(worst < 1e-6, "column {f}: relative difference {worst}");
    }
}

#[test]
fn sdf_is_bit_identical_across_runs_and_thread_counts() {
    let m = shipped_chair();
    let o = SdfOptions::default();
    let run = |threads| crate::common::on_threads(threads, || shape_diameter(&m, &o).unwrap());
    let a = run(1);
    let b = run(2);
    let c = run(2);
    assert_eq!(a, b);
    assert_eq!(b, c);
}

#[test]
fn sdf_rejects_a_degenerate_cone() {
    let m = icosphere(1);
    let mut o = SdfOptions::default();
    o.cone_degrees = 180.0;
    assert!(shape_diameter(&m, &o).is_err());
    o.cone_degrees = 120.0;
    o.rays = 0;
    assert!(shape_diameter(&m, &o).is_err());
}

// ---- user features ----

fn write_npy_f64(path: &std::path::Path, rows: u64, cols: u64, data: &[f64], fortran: bool) {
    use npyz::WriterBuilder;
    let mut out = Vec::new();
    let mut w = npyz::WriteOptions::new()
        .default_dtype()
        .shape(&[rows, cols])
        .order(if fortran {
            npyz::Order::Fortran
        } else {
            npyz::Order::C
        })
        .writer(&mut out)
        .begin_nd()
        .unwrap();
    w.extend(data.iter().copied()).unwrap();
    w.finish().unwrap();
    std::fs::write(path, out).unwrap();
}

#[test]
fn user_npy_reads_c_and_fortran_order_exactly() {
    let dir = tempfile::tempdir().unwrap();
    // 3 vertices × 2 features; values with no short decimal form, to catch any rounding.
    let f0 = [0.1f64, 1.0 / 3.0, -2.5e-300];
    let f1 = [std::f64::consts::PI, -0.0, 7e300];
    let c_order: Vec<f64> = (0..3).flat_map(|v| [f0[v], f1[v]]).collect();
    let f_order: Vec<f64> = f0.iter().chain(&f1).copied().collect();
    let (a, b) = (dir.path().join("a.npy"), dir.path().join("b.npy"));
    write_npy_f64(&a, 3, 2, &c_order, false);
    write_npy_f64(&b, 3, 2, &f_order, true);
    for p in [&a, &b] {
        let c = read_user_features(p, 3).unwrap();
        assert_eq!(c.names, ["user_000", "user_001"]);
        assert_eq!(c.column(0), &f0);
        assert_eq!(c.column(1), &f1);
    }
    assert_eq!(user_feature_path(dir.path(), "a").unwrap(), a);
    let err = read_user_features(&a, 4).unwrap_err().to_string();
    assert!(err.contains("a.npy") && err.contains("3 rows"), "{err}");
}

#[test]
fn user_npy_float32_is_widened_exactly() {
    use npyz::WriterBuilder;
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.npy");
    let data = [0.1f32, 0.2, 0.3];
    let mut out = Vec::new();
    let mut w = npyz::WriteOptions::new()
        .default_dtype()
        .shape(&[3])
        .writer(&mut out)
        .begin_nd()
        .unwrap();
    w.extend(data.iter().copied()).unwrap();
    w.finish().unwrap();
    std::fs::write(&p, out).unwrap();
    let c = read_user_features(&p, 3).unwrap();
    assert_eq!(c.column(0), &data.map(f64::from));
}

#[test]
fn user_csv_header_names_columns_and_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("x.csv");
    std::fs::write(&p, "1,2\n3,4\n").unwrap();
    let c = read_user_features(&p, 2).unwrap();
    assert_eq!(c.names, ["user_000", "user_001"]);
    assert_eq!(c.column(1), &[2.0, 4.0]);
    for (text, needle) in [
        ("a,b\n1,2\n3\n", "line 3"),
        ("a,b\n1,2\n3,x\n", "not a number"),
        ("a,b\n1,2\n3,nan\n", "not finite"),
        ("a,a\n1,2\n3,4\n", "twice"),
        ("", "empty"),
    ] {
        std::fs::write(&p, text).unwrap();
        let e = read_user_features(&p, 2).unwrap_err().to_string();
        assert!(e.contains("x.csv") && e.contains(needle), "{text:?}: {e}");
    }
    let missing = read_user_features(&dir.path().join("nope.csv"), 2).unwrap_err();
    assert!(missing.to_string().contains("nope.csv"));
}

// ---- families in the per-shape pipeline ----

fn small_pipeline() -> coseg::pipeline::ShapePipelineOptions {
    let mut o = coseg::pipeline::ShapePipelineOptions::default();
    o.spectrum.eigenpairs = 12;
    o.descriptors.hks_count = 4;
    o.descriptors.wks_count = 4;
    o.descriptors.curvature_count = 4;
    o.bands.bands = 5;
    o
}

#[test]
fn user_features_round_trip_exactly_through_the_cache() {
    use coseg::cache::CacheOutcome;
    use coseg::features::{FeatureFamilies, UserSource};
    use coseg::pipeline::load_or_compute;
    let dir = tempfile::tempdir().unwrap();
    let m = blob(1);
    let d = m.vertex_count();
    // Values that print long and widen from f32 oddly, to catch any lossy step.
    let f0: Vec<f64> = (0..d).map(|v| (v as f64 * 0.731).sin() / 3.0).collect();
    let f1: Vec<f64> = (0..d).map(|v| 1e-300 * v as f64 - 7.0).collect();
    let c_order: Vec<f64> = (0..d).flat_map(|v| [f0[v], f1[v]]).collect();
    let npy = dir.path().join("feats").join("blob.npy");
    std::fs::create_dir_all(npy.parent().unwrap()).unwrap();
    write_npy_f64(&npy, d as u64, 2, &c_order, false);
    let mut o = small_pipeline();
    let mut fam = FeatureFamilies::default();
    fam.user = Some(UserSource::Dir(npy.parent().unwrap().to_path_buf()));
    o.families = fam
        .for_shape(std::path::Path::new("somewhere/blob.off"))
        .unwrap();
    let cache = dir.path().join("cache");
    let first = load_or_compute(&m, &o, &cache).unwrap();
    let second = load_or_compute(&m, &o, &cache).unwrap();
    assert_eq!(second.outcome, CacheOutcome::Hit);
    assert_eq!(first.data, second.data);
    let t = &second.data.descriptors;
    assert_eq!(t.extra_names, ["user_000", "user_001"]);
    let s = t.spectral_count();
    assert_eq!(t.feature(s), &f0[..]);
    assert_eq!(t.feature(s + 1), &f1[..]);
    // Another file content is another key: the cache never serves stale user features.
    let mut changed = c_order.clone();
    changed[0] += 1.0;
    write_npy_f64(&npy, d as u64, 2, &changed, false);
    o.families = fam.for_shape(std::path::Path::new("blob.off")).unwrap();
    let third = load_or_compute(&m, &o, &cache).unwrap();
    assert_eq!(third.outcome, CacheOutcome::Miss);
    assert_eq!(third.data.descriptors.feature(s)[0], f0[0] + 1.0);
}

#[test]
fn a_missing_user_file_names_the_folder_and_the_shape() {
    use coseg::features::{FeatureFamilies, UserSource};
    let dir = tempfile::tempdir().unwrap();
    let mut fam = FeatureFamilies::default();
    fam.user = Some(UserSource::Dir(dir.path().to_path_buf()));
    let e = fam
        .for_shape(std::path::Path::new("x/chair7.off"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("chair7.npy") && e.contains("chair7.off"), "{e}");
}

#[test]
fn a_collection_mixing_families_is_deterministic_bit_for_bit() {
    use coseg::features::{FeatureFamilies, parse_families};
    use coseg::parts::{SegmentCollectionOptions, segment_collection};
    let meshes = [blob(2), similarity(&blob(2), 2.0), icosphere(2)];
    let mut o = small_pipeline();
    let (_, fam): (bool, FeatureFamilies) =
        parse_families("spectral,extrinsic,sdf", Alignment::Pca).unwrap();
    o.families = fam;
    o.families.weights.sdf = 2.0;
    let run = || {
        let nodes = common::graph::shape_nodes(&meshes, &o, "s");
        let features = nodes[0].bands.features;
        let mut s = SegmentCollectionOptions::equal_areas(3);
        s.feature_weights = o.feature_weights(features);
        assert!(s.feature_weights.is_some());
        let out = segment_collection(nodes.clone(), &meshes, &s).unwrap();
        (
            nodes,
            (0..3)
                .map(|i| out.segmentation.labels(i))
                .collect::<Vec<_>>(),
        )
    };
    let (na, la) = run();
    let (nb, lb) = run();
    assert_eq!(na, nb);
    assert_eq!(la, lb);
    // 12 spectral + 102 extrinsic + 3 sdf columns.
    assert_eq!(na[0].bands.features, 12 + 102 + 3);
}

#[test]
fn family_weights_give_each_family_its_total_share() {
    let mut o = small_pipeline();
    let (_, fam) = coseg::features::parse_families("spectral,sdf", Alignment::Pca).unwrap();
    o.families = fam;
    o.families.weights.sdf = 3.0;
    let w = o.feature_weights(12 + 3).unwrap();
    let spectral: f64 = w[..12].iter().sum();
    let sdf: f64 = w[12..].iter().sum();
    assert!((spectral - 1.0).abs() < 1e-12 && (sdf - 3.0).abs() < 1e-12);
    assert_eq!(small_pipeline().feature_weights(12), None);
}

/// The normal columns are a family of their own in the weights: position (heights and
/// distances) and orientation each get their share, whatever the column counts, and the
/// columns the weights treat as normals are the ones named `ext_nrm_*` (the last extrinsic
/// columns).
#[test]
fn normal_columns_get_a_family_share_of_their_own() {
    let mut o = small_pipeline();
    o.set_families("spectral,extrinsic", "y", 6, 4, "normals=2")
        .unwrap();
    // 12 spectral, 6 heights + 2 distances, 4 normals.
    let w = o.feature_weights(12 + 8 + 4).unwrap();
    assert_eq!(w.len(), 24);
    let share = |r: std::ops::Range<usize>| w[r].iter().sum::<f64>();
    assert!((share(0..12) - 1.0).abs() < 1e-12);
    assert!((share(12..20) - 1.0).abs() < 1e-12);
    assert!((share(20..24) - 2.0).abs() < 1e-12);
    assert!(w[12..20].iter().all(|&x| x == 1.0 / 8.0));
    assert!(w[20..].iter().all(|&x| x == 2.0 / 4.0));
    let c = extrinsic_features(&blob(1), o.families.extrinsic.as_ref().unwrap()).unwrap();
    let normal_names: Vec<bool> = c.names.iter().map(|n| n.starts_with("ext_nrm_")).collect();
    assert_eq!(normal_names, [vec![false; 8], vec![true; 4]].concat());
    // Without normals the extrinsic family keeps one share over its columns, as before.
    let mut p = small_pipeline();
    p.set_families("spectral,extrinsic", "y", 6, 0, "").unwrap();
    let w = p.feature_weights(12 + 8).unwrap();
    assert!(w[12..].iter().all(|&x| x == 1.0 / 8.0));
    // The extrinsic family alone with normals: two families, so weights are given.
    let mut q = small_pipeline();
    q.set_families("extrinsic", "y", 6, 4, "").unwrap();
    let w = q.feature_weights(8 + 4).unwrap();
    assert!(w[..8].iter().all(|&x| x == 1.0 / 8.0) && w[8..].iter().all(|&x| x == 0.25));
    let mut fw = coseg::features::FamilyWeights::default();
    coseg::features::parse_family_weights("normals=0.5", &mut fw).unwrap();
    assert_eq!((fw.extrinsic, fw.normals), (1.0, 0.5));
}

#[test]
fn normal_columns_are_absolute_cosines_whatever_the_winding() {
    // A horizontal square (normal ±y, the up axis) and a vertical one (normal ±z) far apart.
    let pos = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 0.0, 1.0],
        [0.0, 0.0, 1.0],
        [5.0, 0.0, 0.0],
        [6.0, 0.0, 0.0],
        [6.0, 1.0, 0.0],
        [5.0, 1.0, 0.0],
    ];
    let faces = vec![[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7]];
    let flipped: Vec<[u32; 3]> = faces.iter().map(|f| [f[0], f[2], f[1]]).collect();
    let mut o = ext(0, up("+y"));
    o.centroid_distance = false;
    o.axis_distance = false;
    o.normal_directions = 12;
    let a = extrinsic_features(&TriMesh::new(pos.clone(), faces).unwrap(), &o).unwrap();
    let b = extrinsic_features(&TriMesh::new(pos, flipped).unwrap(), &o).unwrap();
    assert_eq!(a.names.len(), 12);
    assert_eq!(a.names[0], "ext_nrm_000");
    assert_eq!(a.values, b.values);
    // Frame for up = +y: (z, x, y). Horizontal patch: n = up, so |n·u| = u_up; vertical
    // patch: n = ±z = frame x, so |n·u| = |u_x|.
    let dirs = height_directions(12, true);
    for (k, u) in dirs.iter().enumerate() {
        let col = &a.values[k * 8..(k + 1) * 8];
        for (v, &x) in col.iter().enumerate() {
            let expect = if v < 4 { u[2].abs() } else { u[0].abs() };
            assert!((x - expect).abs() < 1e-12, "dir {k} vertex {v}");
        }
    }
}
