//! Tests of the shape-family generator and the shipped `collections/`.

mod common;

use common::cli::{arg, coseg, coseg_ok, text};
use common::generate::{
    assert_closed_oriented_single, collections_dir, consistently_oriented, read_collection_obj,
    read_labels, signed_volume,
};
use coseg::generate::{
    Collection, Family, GenerateOptions, Manifest, ScalarGrid, generate_family,
    marching_tetrahedra, obj_text, write_collection,
};
use coseg::mesh::{TriMesh, edges};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use std::sync::OnceLock;

/// The default (shipped) collection of every family, generated once per test run.
fn default_collections() -> &'static Vec<Collection> {
    static C: OnceLock<Vec<Collection>> = OnceLock::new();
    C.get_or_init(|| {
        Family::ALL
            .iter()
            .map(|&f| generate_family(f, &GenerateOptions::default()).unwrap())
            .collect()
    })
}

fn collection(family: Family) -> &'static Collection {
    default_collections()
        .iter()
        .find(|c| c.family == family)
        .unwrap()
}

fn part_index(family: Family, name: &str) -> u32 {
    family.part_names().iter().position(|n| *n == name).unwrap() as u32
}

/// Mean position of the vertices labelled `label`.
fn centroid(mesh: &TriMesh, labels: &[u32], label: u32) -> [f64; 3] {
    let mut c = [0.0; 3];
    let mut n = 0.0;
    for (p, &l) in mesh.positions().iter().zip(labels) {
        if l == label {
            for d in 0..3 {
                c[d] += p[d];
            }
            n += 1.0;
        }
    }
    assert!(n > 0.0, "no vertex has label {label}");
    c.map(|x| x / n)
}

fn param(shape: &coseg::generate::GeneratedShape, name: &str) -> f64 {
    shape
        .parameters
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("{}: no parameter {name}", shape.name))
        .1
}

fn euler_characteristic(mesh: &TriMesh) -> i64 {
    let (e, _) = edges(mesh);
    mesh.vertex_count() as i64 - e.len() as i64 + mesh.face_count() as i64
}

// ---------------------------------------------------------------- marching tetrahedra

fn sphere_grid(cell: f64) -> ScalarGrid {
    let n = (2.6 / cell).ceil() as usize + 1;
    ScalarGrid::sample([-1.3; 3], cell, [n; 3], |p| {
        (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 1.0
    })
}

#[test]
fn marching_tetrahedra_sphere_is_closed_genus_zero_with_right_volume_and_area() {
    for cell in [0.3, 0.13, 0.07] {
        let (p, f) = marching_tetrahedra(&sphere_grid(cell));
        let mesh = TriMesh::new(p, f).unwrap();
        assert_closed_oriented_single(&mesh, "sphere");
        assert_eq!(euler_characteristic(&mesh), 2, "cell {cell}");
        let vol = signed_volume(&mesh);
        let exact = 4.0 / 3.0 * std::f64::consts::PI;
        // Inscribed polyhedron: error O(cell²).
        let tol = 0.5 * cell * cell + 0.005;
        assert!((vol / exact - 1.0).abs() < tol, "cell {cell}: volume {vol}");
        let area = mesh.total_area();
        assert!(
            (area / (4.0 * std::f64::consts::PI) - 1.0).abs() < tol + 0.02,
            "cell {cell}: area {area}"
        );
        for q in mesh.positions() {
            let r = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
            assert!(
                (r - 1.0).abs() < 0.1 * cell + 0.02,
                "vertex off the sphere: {r}"
            );
        }
    }
}

#[test]
fn marching_tetrahedra_torus_has_euler_characteristic_zero() {
    let cell = 0.08;
    let grid = ScalarGrid::sample([-1.6, -1.6, -0.6], cell, [41, 41, 16], |p| {
        let ring = (p[0] * p[0] + p[1] * p[1]).sqrt() - 1.0;
        (ring * ring + p[2] * p[2]).sqrt() - 0.35
    });
    let (p, f) = marching_tetrahedra(&grid);
    let mesh = TriMesh::new(p, f).unwrap();
    assert_closed_oriented_single(&mesh, "torus");
    assert_eq!(euler_characteristic(&mesh), 0);
}

#[test]
fn marching_tetrahedra_separate_blobs_give_separate_components() {
    let grid = ScalarGrid::sample([-2.0, -1.0, -1.0], 0.1, [41, 21, 21], |p| {
        let a = ((p[0] + 1.0).powi(2) + p[1] * p[1] + p[2] * p[2]).sqrt() - 0.6;
        let b = ((p[0] - 1.0).powi(2) + p[1] * p[1] + p[2] * p[2]).sqrt() - 0.6;
        a.min(b)
    });
    let (p, f) = marching_tetrahedra(&grid);
    let mesh = TriMesh::new(p, f).unwrap();
    assert_eq!(coseg::mesh::connected_components(&mesh).count, 2);
    assert!(signed_volume(&mesh) > 0.0);
}

#[test]
fn marching_tetrahedra_random_fields_are_closed_consistently_oriented_manifolds() {
    // Any sign pattern whose outer grid layer is outside must give a closed 2-manifold with
    // every directed edge used once (several components allowed).
    let mut runner = TestRunner::new_with_rng(
        Config {
            cases: 200,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    );
    let strategy = (
        prop::collection::vec(-1.0f64..1.0, 6 * 5 * 7),
        prop::sample::select(vec![-0.3, 0.0, 0.3]),
    );
    runner
        .run(&strategy, |(raw, bias)| {
            let dims = [6usize, 5, 7];
            let mut values = raw.clone();
            for k in 0..dims[2] {
                for j in 0..dims[1] {
                    for i in 0..dims[0] {
                        let idx = i + dims[0] * (j + dims[1] * k);
                        let border = i == 0
                            || j == 0
                            || k == 0
                            || i == dims[0] - 1
                            || j == dims[1] - 1
                            || k == dims[2] - 1;
                        values[idx] = if border {
                            1.0
                        } else if values[idx].abs() < 0.1 {
                            0.0 // exact zeros count as outside
                        } else {
                            values[idx] + bias
                        };
                    }
                }
            }
            let grid = ScalarGrid {
                origin: [0.5, -1.0, 2.0],
                cell: 0.7,
                dims,
                values,
            };
            let (p, f) = marching_tetrahedra(&grid);
            if f.is_empty() {
                return Ok(());
            }
            let mesh = TriMesh::new(p, f).unwrap();
            let (_, counts) = edges(&mesh);
            prop_assert!(counts.iter().all(|&c| c == 2));
            prop_assert!(consistently_oriented(&mesh));
            prop_assert!(signed_volume(&mesh) > 0.0);
            // Every vertex is used by a face.
            let mut used = vec![false; mesh.vertex_count()];
            for f in mesh.faces() {
                for &i in f {
                    used[i as usize] = true;
                }
            }
            prop_assert!(used.iter().all(|&u| u));
            Ok(())
        })
        .unwrap();
}

// ---------------------------------------------------------------- families

#[test]
fn every_shape_is_closed_manifold_single_component_and_outward() {
    for c in default_collections() {
        for s in &c.shapes {
            assert_closed_oriented_single(&s.mesh, &s.name);
            let n = s.mesh.vertex_count();
            assert!((1500..=8000).contains(&n), "{}: {n} vertices", s.name);
            assert_eq!(s.labels.len(), n);
            assert!(
                s.mesh.report().warnings.is_empty(),
                "{}: {:?}",
                s.name,
                s.mesh.report()
            );
        }
    }
}

#[test]
fn every_present_part_has_vertices_and_absent_parts_have_none() {
    for c in default_collections() {
        let names = c.family.part_names();
        for s in &c.shapes {
            assert_eq!(s.parts_present.len(), names.len());
            for (i, name) in names.iter().enumerate() {
                let count = s.labels.iter().filter(|&&l| l == i as u32).count();
                if s.parts_present[i] {
                    // At least 1% of the vertices: a real part, not a few stray labels.
                    assert!(
                        count * 100 >= s.labels.len(),
                        "{}: part {name} has {count}",
                        s.name
                    );
                } else {
                    assert_eq!(count, 0, "{}: absent part {name} labelled", s.name);
                }
            }
        }
    }
}

#[test]
fn topology_matches_the_construction() {
    // No limb touches another part (that would add a handle): animals and humanoids are
    // spheres; a cup handle adds one handle; each chair armrest closes one loop with the seat
    // and the back. Euler characteristic χ = 2 − 2·genus.
    for c in default_collections() {
        let names = c.family.part_names();
        for s in &c.shapes {
            let has = |n: &str| s.parts_present[names.iter().position(|x| *x == n).unwrap()];
            let genus = match c.family {
                Family::Quadrupeds | Family::Humanoids => 0,
                Family::Goblets => has("handle") as i64,
                Family::Chairs => has("armrest_left") as i64 + has("armrest_right") as i64,
            };
            assert_eq!(euler_characteristic(&s.mesh), 2 - 2 * genus, "{}", s.name);
        }
    }
}

#[test]
fn optional_parts_are_present_on_some_shapes_and_absent_on_others() {
    let check = |family: Family, part: &str| {
        let i = part_index(family, part) as usize;
        let c = collection(family);
        let with = c.shapes.iter().filter(|s| s.parts_present[i]).count();
        assert!(
            with >= 2 && with + 2 <= c.shapes.len(),
            "{family}/{part}: {with}"
        );
    };
    check(Family::Goblets, "handle");
    check(Family::Chairs, "back");
    check(Family::Chairs, "armrest_left");
    check(Family::Chairs, "armrest_right");
    // Mandatory parts are on every shape.
    for family in Family::ALL {
        for s in &collection(family).shapes {
            let present = s.parts_present.iter().filter(|&&p| p).count();
            assert!(present >= 3, "{}", s.name);
        }
    }
}

/// The leg parts of the quadrupeds and of the chairs (the two families name them alike).
const FOUR_LEGS: [&str; 4] = [
    "leg_front_left",
    "leg_front_right",
    "leg_back_left",
    "leg_back_right",
];

#[test]
fn labels_sit_where_the_parts_are() {
    // Quadrupeds: head in front of the torso, tail behind, legs below.
    let f = Family::Quadrupeds;
    for s in &collection(f).shapes {
        let c = |n| centroid(&s.mesh, &s.labels, part_index(f, n));
        let torso = c("torso");
        assert!(
            c("head")[0] > torso[0] && c("tail")[0] < torso[0],
            "{}",
            s.name
        );
        for leg in FOUR_LEGS {
            assert!(c(leg)[1] < torso[1], "{}: {leg}", s.name);
        }
        assert!(c("leg_front_left")[2] > 0.0 && c("leg_front_right")[2] < 0.0);
        assert!(c("leg_front_left")[0] > c("leg_back_left")[0]);
    }
    // Humanoids: head on top, legs below the torso, left on +x.
    let f = Family::Humanoids;
    for s in &collection(f).shapes {
        let c = |n| centroid(&s.mesh, &s.labels, part_index(f, n));
        let torso = c("torso");
        assert!(c("head")[1] > torso[1], "{}", s.name);
        assert!(c("leg_left")[1] < torso[1] && c("leg_right")[1] < torso[1]);
        assert!(
            c("arm_left")[0] > 0.0 && c("arm_right")[0] < 0.0,
            "{}",
            s.name
        );
        assert!(
            c("leg_left")[0] > 0.0 && c("leg_right")[0] < 0.0,
            "{}",
            s.name
        );
    }
    // Goblets: base below stem below bowl; handle on +x.
    let f = Family::Goblets;
    for s in &collection(f).shapes {
        let c = |n| centroid(&s.mesh, &s.labels, part_index(f, n));
        assert!(
            c("base")[1] < c("stem")[1] && c("stem")[1] < c("bowl")[1],
            "{}",
            s.name
        );
        if s.parts_present[part_index(f, "handle") as usize] {
            assert!(c("handle")[0] > 0.1, "{}", s.name);
        }
    }
    // Chairs: legs below the seat, back above it and behind.
    let f = Family::Chairs;
    for s in &collection(f).shapes {
        let c = |n| centroid(&s.mesh, &s.labels, part_index(f, n));
        let seat = c("seat");
        for leg in FOUR_LEGS {
            assert!(c(leg)[1] < seat[1], "{}: {leg}", s.name);
        }
        if s.parts_present[part_index(f, "back") as usize] {
            assert!(
                c("back")[1] > seat[1] && c("back")[2] < seat[2],
                "{}",
                s.name
            );
        }
    }
}

#[test]
fn proportions_and_resolutions_vary_by_large_factors() {
    let ratio = |xs: Vec<f64>| {
        let max = xs.iter().cloned().fold(f64::MIN, f64::max);
        let min = xs.iter().cloned().fold(f64::MAX, f64::min);
        max / min
    };
    let q = collection(Family::Quadrupeds);
    let legs = ratio(q.shapes.iter().map(|s| param(s, "leg_length")).collect());
    assert!(legs >= 2.0, "quadruped leg length ratio {legs}");
    let torso = ratio(q.shapes.iter().map(|s| param(s, "torso_length")).collect());
    assert!(torso >= 1.5, "quadruped torso length ratio {torso}");
    // Measured on the meshes: the height of the lowest torso vertex (≈ leg length).
    let torso_label = part_index(Family::Quadrupeds, "torso");
    let belly = ratio(
        q.shapes
            .iter()
            .map(|s| {
                let min_y = s
                    .mesh
                    .positions()
                    .iter()
                    .map(|p| p[1])
                    .fold(f64::MAX, f64::min);
                s.mesh
                    .positions()
                    .iter()
                    .zip(&s.labels)
                    .filter(|(_, l)| **l == torso_label)
                    .map(|(p, _)| p[1] - min_y)
                    .fold(f64::MAX, f64::min)
            })
            .collect(),
    );
    assert!(belly >= 1.8, "quadruped belly height ratio {belly}");
    let stems = ratio(
        collection(Family::Goblets)
            .shapes
            .iter()
            .map(|s| param(s, "stem_length"))
            .collect(),
    );
    assert!(stems >= 3.0, "goblet stem ratio {stems}");
    for c in default_collections() {
        let v = ratio(
            c.shapes
                .iter()
                .map(|s| s.mesh.vertex_count() as f64)
                .collect(),
        );
        assert!(v >= 2.0, "{}: vertex count ratio {v}", c.family);
    }
}

#[test]
fn same_seed_same_bytes_different_seed_different_shapes() {
    let options = {
        let mut opts = GenerateOptions::default();
        opts.count = 2;
        opts
    };
    let a = generate_family(Family::Humanoids, &options).unwrap();
    let b = generate_family(Family::Humanoids, &options).unwrap();
    for (x, y) in a.shapes.iter().zip(&b.shapes) {
        assert_eq!(obj_text(&x.mesh, "c"), obj_text(&y.mesh, "c"));
        assert_eq!(x.labels, y.labels);
    }
    // Shape i does not depend on the count.
    let full = collection(Family::Humanoids);
    assert_eq!(a.shapes[1].mesh, full.shapes[1].mesh);
    let other = generate_family(Family::Humanoids, &{
        let mut opts = options.clone();
        opts.seed = 2;
        opts
    })
    .unwrap();
    for (x, y) in a.shapes.iter().zip(&other.shapes) {
        assert_ne!(x.mesh.positions(), y.mesh.positions());
        assert_ne!(x.parameters, y.parameters);
    }
}

/// Issue #42: `--count 1000` named its shapes `humanoids_00` … `humanoids_99`,
/// `humanoids_100` …, which do not sort in index order.
#[test]
fn generated_names_are_zero_padded_to_the_count() {
    use coseg::generate::shape_name;
    for (count, first, last) in [
        (6, "humanoids_00", "humanoids_05"),
        (99, "humanoids_00", "humanoids_98"),
        (100, "humanoids_000", "humanoids_099"),
        (1000, "humanoids_0000", "humanoids_0999"),
        (10_000, "humanoids_00000", "humanoids_09999"),
    ] {
        assert_eq!(shape_name(Family::Humanoids, 0, count), first);
        assert_eq!(shape_name(Family::Humanoids, count - 1, count), last);
        let names: Vec<String> = (0..count)
            .map(|i| shape_name(Family::Humanoids, i, count))
            .collect();
        assert!(names.windows(2).all(|w| w[0] < w[1]), "{count}: not sorted");
    }
    // The names the generator gives are those (shipped collections: 6 shapes, `_00` … `_05`).
    let mut opts = GenerateOptions::default();
    opts.count = 1;
    let c = generate_family(Family::Goblets, &opts).unwrap();
    assert_eq!(c.shapes[0].name, "goblets_00");
}

#[test]
fn bad_count_is_an_error() {
    let r = generate_family(Family::Chairs, &{
        let mut opts = GenerateOptions::default();
        opts.count = 0;
        opts
    });
    assert!(r.is_err());
}

// ---------------------------------------------------------------- shipped files

/// Sorted file names of a directory.
fn listing(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn binary_regenerates_the_shipped_collections_byte_for_byte() {
    let tmp = tempfile::tempdir().unwrap();
    coseg_ok(&["generate", "all", "-o", arg(tmp.path())]);
    for family in Family::ALL {
        let shipped = collections_dir().join(family.name());
        let fresh = tmp.path().join(family.name());
        assert_eq!(
            listing(&shipped),
            listing(&fresh),
            "{family}: file lists differ"
        );
        for name in listing(&shipped) {
            let a = std::fs::read(shipped.join(&name)).unwrap();
            let b = std::fs::read(fresh.join(&name)).unwrap();
            assert!(
                a == b,
                "{family}/{name}: regenerated bytes differ from collections/"
            );
        }
    }
}

#[test]
fn shipped_files_agree_with_their_manifest() {
    for family in Family::ALL {
        let dir = collections_dir().join(family.name());
        let manifest: Manifest =
            serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap())
                .unwrap();
        assert_eq!(manifest.family, family.name());
        assert_eq!(manifest.parts.len(), family.part_names().len());
        assert!((6..=10).contains(&manifest.shapes.len()));
        for s in &manifest.shapes {
            let mesh = read_collection_obj(&dir.join(&s.mesh));
            let labels = read_labels(&dir.join(&s.labels));
            assert_eq!(mesh.vertex_count(), s.vertices, "{}", s.name);
            assert_eq!(mesh.face_count(), s.faces, "{}", s.name);
            assert_eq!(labels.len(), s.vertices, "{}", s.name);
            assert_closed_oriented_single(&mesh, &s.name);
            let mut counts = vec![0usize; manifest.parts.len()];
            for &l in &labels {
                counts[l as usize] += 1;
            }
            assert_eq!(counts, s.label_counts, "{}", s.name);
        }
        // The crate's own reader sees the same mesh.
        let path = dir.join(&manifest.shapes[0].mesh);
        assert_eq!(
            coseg::mesh::read_mesh(&path).unwrap(),
            read_collection_obj(&path)
        );
        // The file holds exactly the generated mesh (coordinates were rounded before writing).
        let c = collection(family);
        let first = read_collection_obj(&dir.join(&manifest.shapes[0].mesh));
        assert_eq!(first.positions(), c.shapes[0].mesh.positions());
        assert_eq!(first.faces(), c.shapes[0].mesh.faces());
    }
}

#[test]
fn write_collection_writes_manifest_that_round_trips() {
    let tmp = tempfile::tempdir().unwrap();
    let options = {
        let mut opts = GenerateOptions::default();
        opts.count = 1;
        opts
    };
    let c = generate_family(Family::Goblets, &options).unwrap();
    write_collection(&c, &options, tmp.path()).unwrap();
    let text = std::fs::read_to_string(tmp.path().join("manifest.json")).unwrap();
    let m: Manifest = serde_json::from_str(&text).unwrap();
    assert_eq!(m, Manifest::of(&c, &options));
    assert_eq!(listing(tmp.path()).len(), 3);
}

#[test]
fn binary_takes_seed_and_count_and_rejects_unknown_families() {
    let tmp = tempfile::tempdir().unwrap();
    coseg_ok(&[
        "generate",
        "goblets",
        "--seed",
        "5",
        "--count",
        "2",
        "-o",
        arg(tmp.path()),
    ]);
    let m: Manifest =
        serde_json::from_str(&std::fs::read_to_string(tmp.path().join("manifest.json")).unwrap())
            .unwrap();
    assert_eq!((m.seed, m.shapes.len()), (5, 2));
    assert_eq!(listing(tmp.path()).len(), 5);
    let bad = coseg(&["generate", "dragons", "-o", arg(&tmp.path().join("x"))]);
    assert!(!bad.status.success());
    assert!(text(&bad.stderr).contains("unknown family"));
}
