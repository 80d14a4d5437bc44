//! End to end: the real `coseg` binary on the shipped quadrupeds, humanoids, chairs and
//! goblets with
//! `--parts 4 --parts-from geometry`, scored against the generated ground truth.

mod common;

use common::cli::{arg, coseg_ok};
use common::generate::collections_dir;
use coseg::evaluate::{GroundTruth, ShapeParts, part_coverage, part_purity, read_labels};
use coseg::mesh::read_mesh;
use std::path::PathBuf;

/// Four parts of a shipped family from twelve equal-area regions grouped by thickness and
/// concavity, their boundaries snapped to creases (`--parts 4 --parts-from geometry`, default
/// band), scored against the generated ground truth: (purity, coverage) of the grouped parts.
fn parts_from_geometry(family: &str) -> (f64, f64) {
    let input = collections_dir().join(family);
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("e2e_parts_{family}"));
    if out.exists() {
        std::fs::remove_dir_all(&out).unwrap();
    }
    let mut args = vec![
        "segment",
        arg(&input),
        "-o",
        arg(&out),
        "-q",
        "--no-pictures",
    ];
    args.extend(["--parts", "4", "--parts-from", "geometry"]);
    args.extend([
        "--features",
        "spectral,extrinsic",
        "--up",
        "y",
        "--normals",
        "16",
    ]);
    coseg_ok(&args);
    let truth = GroundTruth::read(&input).unwrap();
    let shapes: Vec<ShapeParts> = truth
        .manifest
        .shapes
        .iter()
        .map(|s| {
            let mesh = read_mesh(input.join(&s.mesh)).unwrap();
            let ids = read_labels(out.join(format!("{}.regions.txt", s.name))).unwrap();
            ShapeParts::of_mesh(&mesh, truth.grouped_labels(&s.name).unwrap(), ids).unwrap()
        })
        .collect();
    let scores = (
        part_purity(&shapes).unwrap(),
        part_coverage(&shapes).unwrap(),
    );
    println!(
        "{family} --parts 4 --parts-from geometry: purity {:.3}, coverage {:.3}",
        scores.0, scores.1
    );
    scores
}

/// [`parts_from_geometry`] on `family` reaches at least `purity` and `coverage`.
fn meets_the_bar(family: &str, purity: f64, coverage: f64) {
    let (p, c) = parts_from_geometry(family);
    assert!(
        p >= purity && c >= coverage,
        "{family}: {p:.3} / {c:.3}, floors {purity} / {coverage}"
    );
}

/// The bar of the parts issue is coverage ≥ 75 % at purity ≥ 85 %; the floors keep a margin
/// below what was measured (docs/PARTS.md, "Boundaries snapped to creases" and "Regions split
/// into their pieces").
#[test]
fn quadrupeds_parts_from_geometry_meet_the_bar() {
    // Measured 0.851 / 0.912 (before the regions were split into their pieces 0.784 / 0.818:
    // one region held a back leg's tip and the tail's).
    meets_the_bar("quadrupeds", 0.84, 0.88);
}

#[test]
fn humanoids_parts_from_geometry_meet_the_bar() {
    // Measured 0.952 / 0.946 (without snapping 0.914 / 0.909; adaptive `--parts 4`: 0.668 /
    // 0.739).
    meets_the_bar("humanoids", 0.92, 0.92);
}

#[test]
fn chairs_parts_from_geometry_meet_the_bar() {
    // Measured 0.906 / 0.786. commit 6256292 (regions split into their pieces, every sibling merge
    // at an extra cost): 0.907 / 0.731, the front and back legs two parts; now their feet,
    // facing the same way, are copies linked like mirror pairs (docs/PARTS.md, "Copies and
    // look-alikes").
    meets_the_bar("chairs", 0.88, 0.76);
    // The summary names the copies: pairs of leaves split from one region (the feet).
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("e2e_parts_chairs");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let origin = summary["parts"]["leaf_origin"].as_array().unwrap();
    let copies = summary["parts"]["leaf_copies"].as_array().unwrap();
    assert!(!copies.is_empty());
    for pair in copies {
        let (a, b) = (pair[0].as_u64().unwrap(), pair[1].as_u64().unwrap());
        assert!(a < b && origin[a as usize] == origin[b as usize], "{pair}");
    }
}

#[test]
fn goblets_parts_from_geometry_meet_the_bar() {
    // Measured 0.921 / 0.826 (without snapping 0.916 / 0.821).
    meets_the_bar("goblets", 0.90, 0.80);
}
