//! Tests of the evaluation against ground-truth parts: hand-computed purity and coverage, label
//! files, part grouping and the shipped collections' ground truth.

mod common;

use common::generate::collections_dir;
use coseg::evaluate::{
    EvaluateError, GroundTruth, ShapeParts, group_parts, part_coverage, part_purity, read_labels,
};
use coseg::generate::Family;
use coseg::labels::LabelError;
use proptest::prelude::*;
use std::collections::BTreeMap;

fn shape(areas: &[f64], truth: &[usize], found: &[i32]) -> ShapeParts {
    ShapeParts::new(areas.to_vec(), truth.to_vec(), found.to_vec()).unwrap()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-12
}

// ---------------------------------------------------------------- purity and coverage

#[test]
fn perfect_segmentation_scores_one() {
    let s = shape(
        &[1.0, 2.0, 0.5, 3.0, 1.5],
        &[0, 0, 1, 2, 2],
        &[4, 4, 7, 1, 1],
    );
    assert_eq!(part_purity(std::slice::from_ref(&s)).unwrap(), 1.0);
    assert_eq!(part_coverage(&[s]).unwrap(), 1.0);
}

#[test]
fn region_straddling_two_parts_gives_the_hand_computed_fractions() {
    // Areas 1, 2, 3, 4 (total 10); parts 0,0,1,1; region 0 = vertices 0..3, region 1 = vertex 3.
    let s = shape(&[1.0, 2.0, 3.0, 4.0], &[0, 0, 1, 1], &[0, 0, 0, 1]);
    // Region 0: area 6, 3 in part 0 and 3 in part 1 → 3 pure; region 1: 4 pure. (3 + 4) / 10.
    assert!(close(part_purity(std::slice::from_ref(&s)).unwrap(), 0.7));
    // Part 0 (area 3) all in region 0 → 1; part 1 (area 7) best in region 1 → 4/7.
    assert!(close(part_coverage(&[s]).unwrap(), (1.0 + 4.0 / 7.0) / 2.0));
}

#[test]
fn consistently_permuted_region_ids_score_the_same() {
    let areas = [1.0, 2.0, 3.0, 4.0, 0.5, 1.5];
    let truth = [0, 0, 1, 1, 2, 2];
    let found = [0, 1, 1, 2, 2, 0];
    let permuted: Vec<i32> = found.iter().map(|&r| [5, 0, 3][r as usize]).collect();
    let a = [shape(&areas, &truth, &found), shape(&areas, &truth, &found)];
    let b = [
        shape(&areas, &truth, &permuted),
        shape(&areas, &truth, &permuted),
    ];
    assert!(close(part_purity(&a).unwrap(), part_purity(&b).unwrap()));
    assert!(close(
        part_coverage(&a).unwrap(),
        part_coverage(&b).unwrap()
    ));
}

#[test]
fn an_id_meaning_different_parts_on_two_shapes_is_impure() {
    // Each shape alone is perfect, but id 0 is part 0 on one shape and part 1 on the other.
    let a = shape(&[1.0; 4], &[0, 0, 1, 1], &[0, 0, 1, 1]);
    let b = shape(&[1.0; 4], &[0, 0, 1, 1], &[1, 1, 0, 0]);
    assert_eq!(part_purity(std::slice::from_ref(&a)).unwrap(), 1.0);
    assert_eq!(part_purity(&[a.clone(), b.clone()]).unwrap(), 0.5);
    // Each part is split evenly between the two ids across the shapes.
    assert_eq!(part_coverage(&[a, b]).unwrap(), 0.5);
}

#[test]
fn each_shape_counts_as_unit_area() {
    // Shape b is 10× larger in area; without rescaling it would dominate the pooled scores.
    let a = shape(&[1.0; 4], &[0, 0, 1, 1], &[0, 0, 0, 1]);
    let b = shape(&[10.0; 4], &[0, 0, 1, 1], &[0, 0, 1, 1]);
    // Pooled with unit areas: region 0 = a's 3/4 (part 0: 1/2, part 1: 1/4) + b's 1/2 (part 0).
    // Region 0: area 5/4, majority part 0 with 1; region 1: area 3/4, all part 1. (1 + 3/4) / 2.
    assert!(close(part_purity(&[a.clone(), b.clone()]).unwrap(), 0.875));
    // Part 0 (area 1) all in region 0; part 1 (area 1): region 1 has 1/4 + 1/2.
    assert!(close(part_coverage(&[a.clone(), b]).unwrap(), 0.875));
    let a_scaled = shape(&[7.0; 4], &[0, 0, 1, 1], &[0, 0, 0, 1]);
    assert_eq!(
        part_purity(std::slice::from_ref(&a)).unwrap(),
        part_purity(&[a_scaled]).unwrap()
    );
}

#[test]
fn vertices_in_no_region_leave_purity_and_lower_coverage() {
    // Vertex 3 (part 1) is in no region.
    let s = shape(&[1.0; 4], &[0, 0, 1, 1], &[0, 0, 1, -1]);
    assert_eq!(part_purity(std::slice::from_ref(&s)).unwrap(), 1.0);
    assert_eq!(part_coverage(&[s]).unwrap(), 0.75);
}

#[test]
fn one_region_over_everything_is_impure_but_covers_all() {
    let s = shape(&[1.0, 1.0, 1.0, 1.0, 4.0], &[0, 1, 2, 3, 3], &[0; 5]);
    assert!(close(
        part_purity(std::slice::from_ref(&s)).unwrap(),
        5.0 / 8.0
    ));
    assert_eq!(part_coverage(&[s]).unwrap(), 1.0);
}

#[test]
fn coverage_is_a_plain_mean_over_parts() {
    // Part 0 is tiny and missed (in no region); part 1 is large and fully covered.
    let s = shape(&[1.0, 99.0], &[0, 1], &[-1, 0]);
    assert_eq!(part_coverage(&[s]).unwrap(), 0.5);
}

#[test]
fn malformed_inputs_are_errors() {
    assert!(matches!(part_purity(&[]), Err(EvaluateError::Empty(_))));
    assert!(matches!(part_coverage(&[]), Err(EvaluateError::Empty(_))));
    assert!(ShapeParts::new(vec![1.0; 3], vec![0; 3], vec![0; 2]).is_err());
    assert!(ShapeParts::new(vec![1.0, -1.0], vec![0; 2], vec![0; 2]).is_err());
    assert!(ShapeParts::new(vec![1.0, f64::NAN], vec![0; 2], vec![0; 2]).is_err());
    // Public fields can be set inconsistently after construction: the scores check again.
    let mut s = shape(&[1.0; 2], &[0, 0], &[0, 0]);
    s.found.pop();
    let e = part_purity(&[shape(&[1.0], &[0], &[0]), s]).unwrap_err();
    assert!(e.to_string().contains("shape 1"), "{e}");
    // Every vertex outside the regions: nothing to take purity of.
    let none = shape(&[1.0; 2], &[0, 1], &[-1, -1]);
    assert!(part_purity(std::slice::from_ref(&none)).is_err());
    assert_eq!(part_coverage(&[none]).unwrap(), 0.0);
}

fn arb_shapes() -> impl Strategy<Value = Vec<ShapeParts>> {
    prop::collection::vec(
        prop::collection::vec((0.01f64..5.0, 0usize..4, -1i32..5), 1..30),
        1..4,
    )
    .prop_map(|shapes| {
        shapes
            .into_iter()
            .map(|vs| {
                let areas = vs.iter().map(|v| v.0).collect();
                let truth = vs.iter().map(|v| v.1).collect();
                // At least one vertex in a region so purity is defined.
                let mut found: Vec<i32> = vs.iter().map(|v| v.2).collect();
                found[0] = found[0].max(0);
                ShapeParts::new(areas, truth, found).unwrap()
            })
            .collect()
    })
}

proptest! {
    #[test]
    fn scores_lie_in_unit_interval_and_ignore_id_names(shapes in arb_shapes(), shift in 1i32..50) {
        let (p, c) = (part_purity(&shapes).unwrap(), part_coverage(&shapes).unwrap());
        prop_assert!((0.0..=1.0 + 1e-12).contains(&p));
        prop_assert!((0.0..=1.0 + 1e-12).contains(&c));
        // Renaming every id the same way on all shapes (reversed and shifted) changes nothing.
        let renamed: Vec<ShapeParts> = shapes
            .iter()
            .map(|s| {
                let mut s = s.clone();
                for f in &mut s.found {
                    if *f >= 0 {
                        *f = 100 - *f + shift;
                    }
                }
                s
            })
            .collect();
        prop_assert!((part_purity(&renamed).unwrap() - p).abs() < 1e-12);
        prop_assert!((part_coverage(&renamed).unwrap() - c).abs() < 1e-12);
    }
}

// ---------------------------------------------------------------- label files

#[test]
fn read_labels_reads_ground_truth_and_region_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.regions.txt");
    std::fs::write(&path, "3\n-1\n 0 \n\n12\n").unwrap();
    assert_eq!(read_labels(&path).unwrap(), vec![3, -1, 0, 12]);
    let shipped = collections_dir().join("goblets/goblets_00.labels.txt");
    let labels = read_labels(&shipped).unwrap();
    assert!(!labels.is_empty() && labels.iter().all(|&l| (0..4).contains(&l)));
}

#[test]
fn read_labels_errors_name_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.labels.txt");
    std::fs::write(&path, "0\n1\n2.5\n").unwrap();
    let e = read_labels(&path).unwrap_err();
    assert!(
        matches!(&e, EvaluateError::Label(LabelError::BadLabel { line: 3, text, .. }) if text == "2.5"),
        "{e:?}"
    );
    assert!(e.to_string().contains("bad.labels.txt:3"), "{e}");
    let missing = dir.path().join("missing.txt");
    let e = read_labels(&missing).unwrap_err();
    assert!(e.to_string().contains("missing.txt"), "{e}");
}

// ---------------------------------------------------------------- part groups

fn strings(names: &[&str]) -> Vec<String> {
    names.iter().map(|s| s.to_string()).collect()
}

#[test]
fn group_parts_merges_members_in_order_of_first_appearance() {
    let parts = strings(&["a", "x1", "b", "y1", "x2", "y2"]);
    let groups = BTreeMap::from([
        ("y".to_string(), strings(&["y1", "y2"])),
        ("x".to_string(), strings(&["x2", "x1"])),
    ]);
    let g = group_parts(&parts, &groups).unwrap();
    assert_eq!(g.names, ["a", "x", "b", "y"]);
    assert_eq!(g.of_part, [0, 1, 2, 3, 1, 3]);
    assert_eq!(g.apply(&[5, 0, 4]).unwrap(), vec![3, 0, 1]);
    assert!(g.apply(&[6]).is_err());
    assert!(g.apply(&[-1]).is_err());
    // No groups: labels unchanged.
    let g = group_parts(&parts, &BTreeMap::new()).unwrap();
    assert_eq!(g.of_part, [0, 1, 2, 3, 4, 5]);
}

#[test]
fn group_parts_rejects_unknown_and_doubly_grouped_parts() {
    let parts = strings(&["a", "b", "c"]);
    let unknown = BTreeMap::from([("g".to_string(), strings(&["a", "z"]))]);
    assert!(
        group_parts(&parts, &unknown)
            .unwrap_err()
            .to_string()
            .contains("\"z\"")
    );
    let twice = BTreeMap::from([
        ("g".to_string(), strings(&["a", "b"])),
        ("h".to_string(), strings(&["b", "c"])),
    ]);
    assert!(
        group_parts(&parts, &twice)
            .unwrap_err()
            .to_string()
            .contains("\"b\"")
    );
}

// ---------------------------------------------------------------- shipped ground truth

#[test]
fn shipped_ground_truth_groups_mirror_parts() {
    let expected: [(Family, &[&str]); 4] = [
        (Family::Quadrupeds, &["torso", "head", "leg", "tail"]),
        (Family::Humanoids, &["torso", "head", "arm", "leg"]),
        (Family::Goblets, &["bowl", "stem", "base", "handle"]),
        (Family::Chairs, &["seat", "leg", "back", "armrest"]),
    ];
    for (family, names) in expected {
        let truth = GroundTruth::read(collections_dir().join(family.name())).unwrap();
        assert_eq!(truth.groups.names, names, "{family}");
        assert_eq!(truth.manifest.parts, family.part_names(), "{family}");
        for s in &truth.manifest.shapes {
            let labels = truth.grouped_labels(&s.name).unwrap();
            assert_eq!(labels.len(), s.vertices, "{}", s.name);
            // Grouping only renames: vertex counts per grouped part add up from the manifest.
            let mut counts = vec![0usize; names.len()];
            for (part, &n) in s.label_counts.iter().enumerate() {
                counts[truth.groups.of_part[part]] += n;
            }
            for (g, &n) in counts.iter().enumerate() {
                assert_eq!(labels.iter().filter(|&&l| l == g).count(), n, "{}", s.name);
            }
        }
    }
}

#[test]
fn ground_truth_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let e = GroundTruth::read(dir.path()).unwrap_err();
    assert!(e.to_string().contains("manifest.json"), "{e}");
    std::fs::write(dir.path().join("manifest.json"), "{ not json").unwrap();
    let e = GroundTruth::read(dir.path()).unwrap_err();
    assert!(matches!(e, EvaluateError::BadManifest { .. }), "{e:?}");
    // A labels file one line short.
    let src = collections_dir().join("goblets");
    std::fs::copy(src.join("manifest.json"), dir.path().join("manifest.json")).unwrap();
    let text = std::fs::read_to_string(src.join("goblets_00.labels.txt")).unwrap();
    let short: String = text.lines().skip(1).map(|l| format!("{l}\n")).collect();
    std::fs::write(dir.path().join("goblets_00.labels.txt"), short).unwrap();
    let e = GroundTruth::read(dir.path())
        .unwrap()
        .grouped_labels("goblets_00")
        .unwrap_err();
    assert!(e.to_string().contains("goblets_00.labels.txt"), "{e}");
    let e = GroundTruth::read(dir.path())
        .unwrap()
        .grouped_labels("nope")
        .unwrap_err();
    assert!(e.to_string().contains("nope"), "{e}");
}
