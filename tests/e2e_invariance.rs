//! End to end: the real `coseg` binary's bare `segment` and `propagate` on a shipped family,
//! as shipped and with every shape given a seeded random rotation, scale (0.5–2) and
//! translation (issue 39: the results should not depend on how the files are oriented). The
//! scores of the moved collection are compared with the unmoved one's.

mod common;

use common::generate::collections_dir;
use common::motion::{random_similarity, unit};
use coseg::evaluate::{GroundTruth, matched_scores, read_labels};
use coseg::mesh::{read_mesh, write_mesh};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The shipped family `family` with every mesh moved by a similarity drawn from `seed`
/// (vertex order kept, so the ground-truth labels still apply), written to a scratch folder.
fn moved_copy(family: &str, seed: u64) -> PathBuf {
    let input = collections_dir().join(family);
    let out = scratch(&format!("{family}_moved_{seed}"));
    std::fs::create_dir_all(&out).unwrap();
    let truth = GroundTruth::read(&input).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for s in &truth.manifest.shapes {
        let t = random_similarity(&mut rng);
        let m = read_mesh(input.join(&s.mesh))
            .unwrap()
            .map_positions(|p| t.apply(p))
            .unwrap();
        write_mesh(out.join(&s.mesh), &m, &[]).unwrap();
    }
    out
}

/// The shipped family `family` with each coordinate × `1 + 10⁻¹² u`, `u` uniform in
/// `[−1, 1)` drawn from `seed`: no motion, only the coordinates' last digits changed (how a
/// rotation rounds them, a thousand times larger).
fn perturbed_copy(family: &str, seed: u64) -> PathBuf {
    let input = collections_dir().join(family);
    let out = scratch(&format!("{family}_perturbed_{seed}"));
    std::fs::create_dir_all(&out).unwrap();
    let truth = GroundTruth::read(&input).unwrap();
    let rng = std::cell::RefCell::new(ChaCha8Rng::seed_from_u64(seed));
    for s in &truth.manifest.shapes {
        let m = read_mesh(input.join(&s.mesh))
            .unwrap()
            .map_positions(|p| {
                let mut r = rng.borrow_mut();
                p.map(|x| x * (1.0 + 1e-12 * (2.0 * unit(&mut r) - 1.0)))
            })
            .unwrap();
        write_mesh(out.join(&s.mesh), &m, &[]).unwrap();
    }
    out
}

fn scratch(name: &str) -> PathBuf {
    let p = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("e2e_invariance_{name}"));
    if p.exists() {
        std::fs::remove_dir_all(&p).unwrap();
    }
    p
}

fn coseg(args: &[&std::ffi::OsStr]) {
    let run = Command::new(env!("CARGO_BIN_EXE_coseg"))
        .args(args)
        .args(["-q", "--no-pictures"])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// Bare `coseg segment FOLDER -o OUT`: vertex accuracy of the region ids mapped to the
/// family's grouped parts (pooled over the shapes).
fn segment_accuracy(family: &str, folder: &Path, tag: &str) -> f64 {
    let out = scratch(&format!("{family}_segment_{tag}"));
    coseg(&[
        "segment".as_ref(),
        folder.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    let truth = GroundTruth::read(collections_dir().join(family)).unwrap();
    let shapes: Vec<(Vec<i32>, Vec<i32>)> = truth
        .manifest
        .shapes
        .iter()
        .map(|s| {
            let found = read_labels(out.join(format!("{}.regions.txt", s.name))).unwrap();
            let parts = truth.grouped_labels(&s.name).unwrap();
            (found, parts.into_iter().map(|p| p as i32).collect())
        })
        .collect();
    matched_scores(&shapes).unwrap().accuracy
}

/// Bare `coseg propagate FOLDER --labels <first shape's labels> -o OUT`: vertex accuracy of
/// the labels carried to the other shapes (pooled).
fn propagate_accuracy(family: &str, folder: &Path, tag: &str) -> f64 {
    let input = collections_dir().join(family);
    let out = scratch(&format!("{family}_propagate_{tag}"));
    let truth = GroundTruth::read(&input).unwrap();
    let source = &truth.manifest.shapes[0];
    let labels = input.join(format!("{}.labels.txt", source.name));
    coseg(&[
        "propagate".as_ref(),
        folder.as_os_str(),
        "--labels".as_ref(),
        labels.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    let (mut right, mut all) = (0usize, 0usize);
    for s in &truth.manifest.shapes[1..] {
        let found = read_labels(out.join(format!("{}.labels.txt", s.name))).unwrap();
        let expected = read_labels(input.join(format!("{}.labels.txt", s.name))).unwrap();
        assert_eq!(found.len(), expected.len());
        right += found.iter().zip(&expected).filter(|(a, b)| a == b).count();
        all += expected.len();
    }
    right as f64 / all as f64
}

/// Both commands on `family` as shipped and changed (`changed`, tagged `tag`): the two
/// scores of each, printed (with `what`) and compared against issue 39's bar, within 1 point
/// of the unchanged collection.
fn compare(family: &str, changed: &Path, tag: &str, what: &str) {
    let shipped = &collections_dir().join(family);
    let segment = (
        // Each comparison its own scratch folders: tests may run at once.
        segment_accuracy(family, shipped, &format!("shipped_{tag}")),
        segment_accuracy(family, changed, tag),
    );
    let propagate = (
        propagate_accuracy(family, shipped, &format!("shipped_{tag}")),
        propagate_accuracy(family, changed, tag),
    );
    println!(
        "{family}, {what}: segment {:.1} % / {:.1} %, propagate {:.1} % / {:.1} % (shipped / {tag})",
        100.0 * segment.0,
        100.0 * segment.1,
        100.0 * propagate.0,
        100.0 * propagate.1
    );
    assert!(
        (segment.0 - segment.1).abs() <= 0.01,
        "segment {segment:?} (shipped, {tag})"
    );
    assert!(
        (propagate.0 - propagate.1).abs() <= 0.01,
        "propagate {propagate:?} (shipped, {tag})"
    );
}

/// Both commands on `family` as shipped and moved by `seed` ([`compare`]).
fn invariance(family: &str, seed: u64) {
    let what = format!("moved by seed {seed}");
    compare(family, &moved_copy(family, seed), "moved", &what);
}

/// The shipped `family` against its copy with each coordinate × a random 1 ± 10⁻¹² (`seed`).
fn rounding_invariance(family: &str, seed: u64) {
    let what = format!("× (1 ± 1e-12), seed {seed}");
    compare(family, &perturbed_copy(family, seed), "perturbed", &what);
}

// Not met at commit 2d118bd (docs/ALIGN.md, "Invariance of the bare commands", has the
// figures per family). Run with `cargo test --release --test e2e_invariance -- --ignored
// --nocapture`.
#[test]
#[ignore = "issue 39's invariance bar is not met yet (docs/ALIGN.md, Invariance)"]
fn chairs_segment_and_propagate_do_not_depend_on_the_files_frames() {
    invariance("chairs", 5);
}

#[test]
#[ignore = "issue 39's invariance bar is not met yet (docs/ALIGN.md, Invariance)"]
fn quadrupeds_segment_and_propagate_do_not_depend_on_the_files_frames() {
    invariance("quadrupeds", 5);
}

/// Regression (`a flat boundary's concavity came from rounding`, docs/ALIGN.md "Invariance of
/// the bare commands"): with each coordinate of the shipped chairs rounded differently (× a
/// random 1 ± 10⁻¹², no motion), bare `coseg segment` gave 80.1 % (7 parts) instead of 82.9 %
/// (6) and bare `coseg propagate` 56.6 % instead of 68.5 %: the part tree read the sign of a
/// flat seat's mean curvature, which is rounding. Both now give the shipped figures.
#[test]
fn chairs_segment_and_propagate_do_not_depend_on_rounding() {
    rounding_invariance("chairs", 1);
}

/// Regression (`a constant route's κ was rounding`, docs/ALIGN.md "Invariance of the bare
/// commands"): with each coordinate of the shipped goblets × a random 1 ± 10⁻¹², bare `coseg
/// propagate` gave 74.0 % instead of 81.9 %: the parts route named all of `goblets_04` one
/// part, Cohen's κ against it (0 in exact arithmetic) came out ±10⁻¹⁶, and its sign decided
/// the rigid route's pose there and the fusion's trust everywhere.
#[test]
fn goblets_segment_and_propagate_do_not_depend_on_rounding() {
    rounding_invariance("goblets", 2);
}
