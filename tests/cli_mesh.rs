//! Tests of the `coseg info` and `coseg convert` subcommands, running the real binary.

mod common;

use common::cli::{coseg, text};
use common::mesh::{grid, tetrahedron};
use coseg::mesh::{read_mesh, write_mesh};
use std::path::Path;

#[test]
fn info_on_good_files_exits_0_and_prints_counts_and_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let tet = dir.path().join("tet.off");
    let flat = dir.path().join("flat.ply");
    write_mesh(&tet, &tetrahedron(), &[]).unwrap();
    write_mesh(&flat, &grid(3), &[]).unwrap();
    let out = coseg(&[Path::new("info"), &tet, &flat]);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{stdout}{stderr}");
    assert!(
        stdout.contains(&format!("{}: 4 vertices, 4 faces", tet.display())),
        "{stdout}"
    );
    assert!(
        stdout.contains(&format!("{}: 16 vertices, 18 faces", flat.display())),
        "{stdout}"
    );
    // The grid is open: one boundary warning naming it; the tetrahedron is clean.
    assert!(
        stderr.contains(&format!(
            "warning: {}: open surface: 12 boundary edges",
            flat.display()
        )),
        "{stderr}"
    );
    assert!(!stderr.contains("tet.off"), "{stderr}");
}

#[test]
fn info_exit_codes_partial_and_total_failure_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.obj");
    write_mesh(&good, &tetrahedron(), &[]).unwrap();
    let bad = dir.path().join("bad.off");
    std::fs::write(&bad, "OFF\n4 4 0\n0 0 0\n").unwrap();
    let nan = dir.path().join("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();

    let out = coseg(&[Path::new("info"), &good, &bad]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains(&format!("error: {}: truncated file", bad.display())),
        "{stderr}"
    );
    assert!(text(&out.stdout).contains("good.obj: 4 vertices"));

    let out = coseg(&[Path::new("info"), &bad, &nan]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("bad.off"), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "{}: vertex 1 has a non-finite coordinate",
            nan.display()
        )),
        "{stderr}"
    );
}

#[test]
fn info_on_the_malformed_corpus_never_succeeds_or_crashes() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/malformed");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    let mut args: Vec<&Path> = vec![Path::new("info")];
    args.extend(files.iter().map(|p| p.as_path()));
    let out = coseg(&args);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for f in &files {
        assert!(
            stderr.contains(&format!("error: {}", f.display())),
            "no error naming {}: {stderr}",
            f.display()
        );
    }
}

#[test]
fn convert_round_trips_between_all_formats() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = grid(4);
    let src = dir.path().join("src.off");
    write_mesh(&src, &mesh, &[]).unwrap();
    let mut prev = src.clone();
    for name in ["a.ply", "b.obj", "c.off", "d.ply", "e.off"] {
        let next = dir.path().join(name);
        let out = coseg(&[Path::new("convert"), &prev, &next]);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        assert_eq!(read_mesh(&next).unwrap(), mesh, "{name}");
        prev = next;
    }
    assert_eq!(std::fs::read(&src).unwrap(), std::fs::read(&prev).unwrap());
}

#[test]
fn convert_failures_exit_1_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nf 1 2 3\n").unwrap();
    let out_path = dir.path().join("out.ply");
    let out = coseg(&[Path::new("convert"), &bad, &out_path]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("bad.obj: face 0 refers to vertex 1"),
        "{stderr}"
    );
    assert!(!out_path.exists());

    let good = dir.path().join("good.off");
    write_mesh(&good, &tetrahedron(), &[]).unwrap();
    let out = coseg(&[Path::new("convert"), &good, &dir.path().join("out.stl")]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("out.stl: unsupported mesh format"),
        "{stderr}"
    );
}
