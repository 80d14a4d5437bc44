//! The part-tree cache (`coseg::parts::segment_collection_cached`) through the `coseg` binary:
//! a run that differs from an earlier one only in `--parts` reads the part tree and re-cuts it,
//! and writes what a run that grew the tree would write, byte for byte (`summary.json` but its
//! `collection_stage` field); an entry that cannot be trusted is grown again with a warning.

mod common;

use common::cli::{FAST_PIPELINE, arg as s, coseg, text};
use common::outputs::{output_files as files, same_files as same};
use std::path::{Path, PathBuf};

/// The shipped chairs.
fn chairs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("collections/chairs")
}

/// The one part-tree entry of `cache`.
fn tree_entry(cache: &Path) -> PathBuf {
    let trees: Vec<PathBuf> = std::fs::read_dir(cache)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "coseg-tree"))
        .collect();
    assert_eq!(trees.len(), 1, "{trees:?}");
    trees[0].clone()
}

/// Cold `--parts 3`, then `--parts auto` re-cut from its tree; the entry truncated, `--parts
/// auto` grows the tree again (with a warning) and writes what the re-cut wrote; then `--parts
/// 3` re-cut from that tree writes what the cold run wrote. Pictures included.
#[test]
fn another_number_of_parts_only_recuts_and_writes_the_cold_runs_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let chairs = chairs();
    let run = |out: &str, parts: &str| {
        let out = dir.path().join(out);
        let mut args = vec!["segment", s(&chairs), "-o", s(&out), "--cache", s(&cache)];
        args.extend(["--parts", parts]);
        args.extend(FAST_PIPELINE);
        let r = coseg(&args);
        assert_eq!(r.status.code(), Some(0), "{}", text(&r.stderr));
        (files(&out), text(&r.stdout), text(&r.stderr))
    };
    let recut = "collection stage: re-cut from the cache";
    let (cold3, out, _) = run("cold3", "3");
    assert!(!out.contains(recut), "{out}");
    assert!(cold3.iter().any(|f| f.0 == "preview.png"));
    assert!(cold3.iter().any(|f| f.0 == "index.html"));
    let entry = tree_entry(&cache);

    let (warm_auto, out, _) = run("warm-auto", "auto");
    assert!(out.contains(recut), "{out}");
    let summary = std::fs::read_to_string(dir.path().join("warm-auto/summary.json")).unwrap();
    assert!(summary.contains("\"collection_stage\": \"recut\""));

    // A truncated entry: not trusted, grown again, the same result as the re-cut.
    let bytes = std::fs::read(&entry).unwrap();
    std::fs::write(&entry, &bytes[..bytes.len() / 2]).unwrap();
    let (grown_auto, out, err) = run("grown-auto", "auto");
    assert!(!out.contains(recut), "{out}");
    assert!(err.contains("not trusted"), "{err}");
    same(&grown_auto, &warm_auto, "--parts auto grown / re-cut");
    assert_eq!(
        tree_entry(&cache),
        entry,
        "the entry is rewritten under its key"
    );

    let (warm3, out, _) = run("warm3", "3");
    assert!(out.contains(recut), "{out}");
    same(&cold3, &warm3, "--parts 3 cold / re-cut");
}

/// Another option of the collection stage (here the snap band) is another tree: grown, not
/// re-cut.
#[test]
fn another_option_grows_another_tree() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let chairs = chairs();
    let run = |out: &str, extra: &[&str]| {
        let out = dir.path().join(out);
        let mut args = vec![
            "-q",
            "segment",
            s(&chairs),
            "-o",
            s(&out),
            "--cache",
            s(&cache),
            "--no-pictures",
        ];
        args.extend(extra);
        args.extend(FAST_PIPELINE);
        let r = coseg(&args);
        assert_eq!(r.status.code(), Some(0), "{}", text(&r.stderr));
    };
    run("a", &[]);
    run("b", &["--snap-band", "0.05"]);
    let trees = std::fs::read_dir(&cache)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "coseg-tree")
        })
        .count();
    assert_eq!(trees, 2);
    let summary = std::fs::read_to_string(dir.path().join("b/summary.json")).unwrap();
    assert!(!summary.contains("collection_stage"), "{summary}");
}
