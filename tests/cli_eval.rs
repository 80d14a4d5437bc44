//! `coseg eval` on a hand-made result folder: the table, the JSON and `.seg` ground truth.

mod common;

use common::cli::{arg, coseg, coseg_ok, text};
use coseg::mesh::{TriMesh, write_mesh};

#[test]
fn eval_scores_a_result_folder_against_vertex_and_face_ground_truth() {
    let dir = tempfile::tempdir().unwrap();
    let (result, truth) = (dir.path().join("out"), dir.path().join("truth"));
    std::fs::create_dir_all(&result).unwrap();
    std::fs::create_dir_all(&truth).unwrap();
    // Two squares of 4 vertices, 2 triangles each.
    let mesh = TriMesh::new(
        vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    for name in ["a", "b"] {
        write_mesh(result.join(format!("{name}.regions.ply")), &mesh, &[]).unwrap();
    }
    std::fs::write(result.join("a.regions.txt"), "4\n4\n9\n9\n").unwrap();
    std::fs::write(result.join("b.regions.txt"), "4\n9\n9\n9\n").unwrap();
    std::fs::write(truth.join("a.labels.txt"), "1\n1\n2\n2\n").unwrap();
    // Per face: face 0 (vertices 0,1,2) part 1, face 1 (0,2,3) part 2. Vertex 0 and 2 tie
    // between 1 and 2 and take 1; so b's vertex labels are 1, 1, 1, 2.
    std::fs::write(truth.join("b.seg"), "1\n2\n").unwrap();
    let json = dir.path().join("scores.json");
    let mut args = vec!["eval", arg(&result), "--truth", arg(&truth)];
    args.extend(["--map", "identity", "--json", arg(&json)]);
    let out = coseg(&args);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}{}", text(&out.stderr));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    // Region 4 → part 1 (3 votes), region 9 → part 2 (3 of 5 votes).
    // a: all right; b: vertex 1 (region 9 → 2, truth 1) and 2 (9 → 2, truth 1) wrong: 6/8.
    assert_eq!(v["accuracy"], 0.75);
    assert_eq!(v["shapes"][1]["accuracy"], 0.5);
    // Identity map: vertex p keeps its region on b for p = 0, 2, 3: 3/4.
    assert_eq!(v["correspondence_ratio"], 0.75);
    assert_eq!(v["shapes"][0]["rand_index"], 1.0);
    assert!(stdout.contains("correspondence ratio 75.00%"), "{stdout}");
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("all") && l.contains("75.00%")),
        "{stdout}"
    );
}

/// `coseg propagate` then `coseg eval` on its folder: label results are scored as they are
/// (no mapping), per shape exactly as `evaluate::vertex_label_agreement` scores them, the
/// source flagged and left out of the mean; the pictures and the viewer are written.
#[test]
fn eval_scores_a_propagation_folder_and_leaves_the_source_out() {
    let goblets = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("collections/goblets");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let labels = goblets.join("goblets_00.labels.txt");
    let mut args = vec!["propagate", arg(&goblets), "--labels", arg(&labels)];
    args.extend(["-o", arg(&out)]);
    coseg_ok(&args);
    for f in ["preview.png", "index.html", "goblets_02.png"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let json = dir.path().join("scores.json");
    let mut args = vec!["eval", arg(&out), "--truth", arg(&goblets)];
    args.extend(["--json", arg(&json)]);
    let eval = coseg_ok(&args);
    let stdout = text(&eval.stdout);
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["kind"], "labels");
    let shapes = v["shapes"].as_array().unwrap();
    assert_eq!(shapes.len(), 6);
    assert_eq!(shapes[0]["name"], "goblets_00");
    assert_eq!(shapes[0]["source"], true);
    let mut sum = 0.0;
    for (i, s) in shapes.iter().enumerate().skip(1) {
        let name = format!("goblets_0{i}");
        assert_eq!(s["name"], name.as_str());
        assert_eq!(s["source"], false);
        let mesh = coseg::mesh::read_mesh(goblets.join(format!("{name}.obj"))).unwrap();
        let truth =
            coseg::evaluate::read_labels(goblets.join(format!("{name}.labels.txt"))).unwrap();
        let got = coseg::evaluate::read_labels(out.join(format!("{name}.labels.txt"))).unwrap();
        let a = coseg::evaluate::vertex_label_agreement(&mesh, &truth, &got).unwrap();
        // serde_json reads floats without its `float_roundtrip` feature, so the value read
        // back may differ from the one written in the last bit.
        let read = s["accuracy"].as_f64().unwrap();
        assert!(
            (read - a.accuracy).abs() < 1e-15,
            "{name}: {read} vs {}",
            a.accuracy
        );
        sum += a.accuracy;
    }
    let mean = v["accuracy"].as_f64().unwrap();
    assert!((mean - sum / 5.0).abs() < 1e-12, "{mean} vs {}", sum / 5.0);
    assert!(stdout.contains("(source)"), "{stdout}");
}
