//! `coseg eval` on a hand-made result folder: the table, the JSON and `.seg` ground truth.

use coseg::mesh::{TriMesh, write_mesh};
use std::process::Command;

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
    let out = Command::new(env!("CARGO_BIN_EXE_coseg"))
        .args([
            "eval",
            result.to_str().unwrap(),
            "--truth",
            truth.to_str().unwrap(),
        ])
        .args(["--map", "identity", "--json", json.to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
