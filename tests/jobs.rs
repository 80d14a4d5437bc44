//! The job layer (`coseg::jobs`): a command's whole run as one library call.

mod common;

use common::features::{blob, similarity, small_pipeline};
use coseg::jobs::{
    CacheChoice, EvalJob, JobError, JobShape, PairJob, PairOutcome, run_eval, run_pair,
};
use std::path::{Path, PathBuf};

fn small_job(output: Option<PathBuf>) -> PairJob {
    let mut job = PairJob::default();
    job.pipeline = small_pipeline(24, 4);
    job.output = output;
    job.pictures = false;
    job
}

fn two_files(dir: &Path) -> [PathBuf; 2] {
    let a = dir.join("a.off");
    let b = dir.join("b.off");
    coseg::mesh::write_mesh(&a, &blob(2), &[]).unwrap();
    coseg::mesh::write_mesh(&b, &similarity(&blob(2), 1.3), &[]).unwrap();
    [a, b]
}

/// `run_pair` on two mesh files into `out`, with the small test job.
fn pair_files(a: PathBuf, b: PathBuf, out: &Path) -> Result<PairOutcome, JobError> {
    run_pair(
        [JobShape::File(a), JobShape::File(b)],
        &small_job(Some(out.to_path_buf())),
    )
}

fn region_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".regions.txt"))
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(&p).unwrap())
        })
        .collect();
    out.sort();
    out
}

/// A shape given as a file and the same shape given in memory (with its file named) give the
/// same regions and the same region files: one loader behind both.
#[test]
fn files_and_meshes_in_memory_give_the_same_result() {
    let dir = tempfile::tempdir().unwrap();
    let [a, b] = two_files(dir.path());
    let from_files = run_pair(
        [JobShape::File(a.clone()), JobShape::File(b.clone())],
        &small_job(Some(dir.path().join("files"))),
    )
    .unwrap();
    let in_memory = |path: &Path| JobShape::Mesh {
        name: path.file_stem().unwrap().to_string_lossy().into_owned(),
        file: Some(path.to_path_buf()),
        mesh: coseg::mesh::read_mesh(path).unwrap(),
    };
    let from_meshes = run_pair(
        [in_memory(&a), in_memory(&b)],
        &small_job(Some(dir.path().join("meshes"))),
    )
    .unwrap();
    assert_eq!(from_files.names, ["a", "b"]);
    assert_eq!(from_files.names, from_meshes.names);
    assert_eq!(from_files.labels, from_meshes.labels);
    assert!(from_files.labels[0].iter().any(|&l| l >= 0));
    let (f, m) = (
        region_files(&dir.path().join("files")),
        region_files(&dir.path().join("meshes")),
    );
    assert_eq!(f.len(), 2);
    assert_eq!(f, m);
    assert_eq!(from_files.summary.shapes[0].file, a.display().to_string());
}

/// Without an output folder a job writes nothing, not even its cache (`CacheChoice::Auto`
/// caches only beside an output).
#[test]
fn a_job_without_output_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let [a, b] = two_files(dir.path());
    let before: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    let outcome = run_pair([JobShape::File(a), JobShape::File(b)], &small_job(None)).unwrap();
    assert!(outcome.written.is_empty());
    assert_eq!(outcome.cache_outcomes, [None, None]);
    let after: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(before.len(), after.len());
    assert_eq!(CacheChoice::Auto.resolve(None), None);
    assert_eq!(
        CacheChoice::Auto.resolve(Some(Path::new("out"))),
        Some(PathBuf::from("out/.cache"))
    );
    assert_eq!(CacheChoice::Off.resolve(Some(Path::new("out"))), None);
}

/// Two shapes with one name: the first is written as `<name>_a`, nothing is overwritten.
#[test]
fn two_shapes_with_one_name_are_both_written() {
    let dir = tempfile::tempdir().unwrap();
    let [a, _] = two_files(dir.path());
    let out = dir.path().join("out");
    let outcome = pair_files(a.clone(), a, &out).unwrap();
    assert_eq!(outcome.names, ["a_a", "a"]);
    assert_eq!(region_files(&out).len(), 2);
}

/// A file that is not a mesh is refused with an error naming it; nothing is written.
#[test]
fn a_bad_mesh_is_refused_with_its_name() {
    let dir = tempfile::tempdir().unwrap();
    let [a, _] = two_files(dir.path());
    let bad = dir.path().join("bad.off");
    std::fs::write(&bad, "OFF\n3 1 0\n0 0 0\n").unwrap();
    let out = dir.path().join("out");
    let err = pair_files(a, bad, &out).unwrap_err();
    let text = err.to_string();
    assert!(text.contains("bad.off"), "{text}");
    assert!(matches!(err, JobError::Mesh(_) | JobError::Shape { .. }));
    assert!(region_files_or_none(&out).is_empty());
}

fn region_files_or_none(dir: &Path) -> Vec<(String, Vec<u8>)> {
    if dir.exists() {
        region_files(dir)
    } else {
        Vec::new()
    }
}

/// `coseg eval`'s job scores a folder and writes the scores as JSON; a folder that cannot be
/// scored is named in the error and no JSON is written.
#[test]
fn eval_job_writes_its_scores_and_names_what_it_cannot_score() {
    let dir = tempfile::tempdir().unwrap();
    let [a, b] = two_files(dir.path());
    let out = dir.path().join("out");
    let outcome = pair_files(a, b, &out).unwrap();
    let truth = dir.path().join("truth");
    std::fs::create_dir(&truth).unwrap();
    for (name, labels) in outcome.names.iter().zip(&outcome.labels) {
        let parts: Vec<i32> = labels.iter().map(|&l| l.max(0)).collect();
        coseg::labels::write_vertex_labels(&truth, name, &parts).unwrap();
    }
    let mut job = EvalJob::default();
    job.json = Some(dir.path().join("scores.json"));
    let scores = run_eval(&out, &truth, &job).unwrap();
    assert_eq!(scores.shapes.len(), 2);
    let text = std::fs::read_to_string(dir.path().join("scores.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(json["shapes"].as_array().unwrap().len(), 2);

    let missing = dir.path().join("missing");
    job.json = Some(dir.path().join("none.json"));
    let err = run_eval(&missing, &truth, &job).unwrap_err();
    assert!(err.to_string().contains("missing"), "{err}");
    assert!(!dir.path().join("none.json").exists());
}

mod propagate_job {
    use super::*;
    use coseg::jobs::{JobLabels, PropagateInput, PropagateJob, run_propagate};

    fn job(output: Option<PathBuf>) -> PropagateJob {
        let mut job = PropagateJob::default();
        job.propagation.pipeline = small_pipeline(24, 4);
        job.output = output;
        job
    }

    /// Three blobs in a folder; the first labelled by height (two parts) in `<stem>.labels.txt`.
    fn folder(dir: &Path) -> (PathBuf, Vec<i64>) {
        let shapes = dir.join("shapes");
        std::fs::create_dir_all(&shapes).unwrap();
        for (i, s) in [1.0, 1.2, 0.9].into_iter().enumerate() {
            coseg::mesh::write_mesh(
                shapes.join(format!("s{i}.off")),
                &similarity(&blob(2), s),
                &[],
            )
            .unwrap();
        }
        let m = coseg::mesh::read_mesh(shapes.join("s0.off")).unwrap();
        // Above and below the mean height: two parts whatever the blob's placement.
        let p = m.positions();
        let mid = p.iter().map(|v| v[1]).sum::<f64>() / p.len() as f64;
        let labels: Vec<i64> = p.iter().map(|v| i64::from(v[1] > mid)).collect();
        let text: String = labels.iter().map(|l| format!("{l}\n")).collect();
        std::fs::write(dir.join("s0.labels.txt"), text).unwrap();
        (shapes, labels)
    }

    /// A folder with label files and the same shapes in memory with the same labels as an
    /// array give the same labels: `coseg propagate` and `coseg.propagate` run one job.
    #[test]
    fn a_folder_and_shapes_in_memory_give_the_same_labels() {
        let dir = tempfile::tempdir().unwrap();
        let (shapes, labels) = folder(dir.path());
        let from_folder = run_propagate(
            PropagateInput::Folder {
                folder: shapes.clone(),
                labels: vec![dir.path().join("s0.labels.txt")],
            },
            &job(Some(dir.path().join("out"))),
        )
        .unwrap();
        let files: Vec<PathBuf> = (0..3).map(|i| shapes.join(format!("s{i}.off"))).collect();
        let in_memory = run_propagate(
            PropagateInput::Shapes {
                shapes: files.iter().cloned().map(JobShape::File).collect(),
                labels: vec![JobLabels::Vertex(labels), JobLabels::None, JobLabels::None],
                part_names: Default::default(),
            },
            &job(None),
        )
        .unwrap();
        let (a, b) = (&from_folder.result, &in_memory.result);
        assert_eq!(a.graph.node_count(), 3);
        assert_eq!(a.propagation.labels, b.propagation.labels);
        assert!(a.propagation.labels[1].contains(&0));
        assert!(a.propagation.labels[1].contains(&1));
        assert!(in_memory.written.is_empty());
        assert!(
            from_folder
                .written
                .iter()
                .any(|p| p.ends_with("summary.json"))
        );
        // The cache went beside the output, and into nothing without one.
        assert!(dir.path().join("out/.cache").is_dir());
        assert!(in_memory.cache_outcomes.iter().all(Option::is_none));
    }

    /// Annotations that do not fit their shapes fail before any per-shape work, naming the
    /// shape; the map step needs a folder.
    #[test]
    fn bad_annotations_are_refused_naming_the_shape() {
        let dir = tempfile::tempdir().unwrap();
        let (shapes, _) = folder(dir.path());
        let files: Vec<JobShape> = (0..3)
            .map(|i| JobShape::File(shapes.join(format!("s{i}.off"))))
            .collect();
        let run = |labels: Vec<JobLabels>, job: &PropagateJob| {
            run_propagate(
                PropagateInput::Shapes {
                    shapes: files.clone(),
                    labels,
                    part_names: Default::default(),
                },
                job,
            )
            .unwrap_err()
        };
        let e = run(
            vec![
                JobLabels::Vertex(vec![0, 1]),
                JobLabels::None,
                JobLabels::None,
            ],
            &job(None),
        );
        assert!(matches!(e, JobError::Invalid(_)), "{e}");
        assert!(e.to_string().contains("s0"), "{e}");
        let e = run(vec![JobLabels::None], &job(None));
        assert!(
            e.to_string().contains("1 label entries for 3 shapes"),
            "{e}"
        );
        let e = run(vec![JobLabels::None; 3], &job(None));
        assert!(matches!(e, JobError::Stage { .. }), "{e}");
        let e = run(
            vec![
                JobLabels::File(dir.path().join("missing.labels.txt")),
                JobLabels::None,
                JobLabels::None,
            ],
            &job(None),
        );
        assert!(matches!(e, JobError::Labels(_)), "{e}");
        assert!(e.to_string().contains("missing.labels.txt"), "{e}");
        let mut with_map = job(None);
        with_map.propagation.map_step = Some(Default::default());
        let e = run(vec![JobLabels::None; 3], &with_map);
        assert!(e.to_string().contains("map_step"), "{e}");
    }
}
