//! The `coseg` binary on temporary folders: skipped files and `--strict`, `--quiet`, pictures,
//! and a run killed during the per-shape stage then resumed.

mod common;

use common::cli::{FAST_PIPELINE, arg as s, coseg, text};
use common::features::{blob, similarity};
use common::outputs::same_files as same;
use coseg::mesh::write_mesh;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// [`FAST_PIPELINE`] and 3 regions.
const FAST: [&str; 12] = {
    let [a, b, c, d, e, f, g, h, i, j] = FAST_PIPELINE;
    [a, b, c, d, e, f, g, h, i, j, "--regions", "3"]
};

/// `dir/in` holding [`shapes`] `(n, level)`; the folder.
fn input_folder(dir: &Path, n: usize, level: usize) -> PathBuf {
    let input = dir.join("in");
    std::fs::create_dir(&input).unwrap();
    shapes(&input, n, level);
    input
}

/// `coseg segment INPUT -o OUT -q --no-pictures FLAGS`.
fn quiet_segment(input: &Path, out: &Path, flags: &[&str]) -> Output {
    let mut args = vec!["segment", s(input), "-o", s(out), "-q", "--no-pictures"];
    args.extend(flags);
    coseg(&args)
}

/// `n` smooth blobs (level-`level` icospheres, 10·4^level + 2 vertices) in `dir`, as OBJ, OFF
/// and PLY in turn.
fn shapes(dir: &Path, n: usize, level: usize) {
    let ext = ["obj", "off", "ply"];
    for i in 0..n {
        let mesh = similarity(&blob(level), 1.0 + 0.1 * i as f64);
        write_mesh(dir.join(format!("s{i}.{}", ext[i % 3])), &mesh, &[]).unwrap();
    }
}

/// `coseg -q pair` between the first two of [`shapes`] in `dir`, writing to `out`, with no
/// pictures and 20 eigenpairs: the start of a quick pair run's arguments.
fn small_pair(dir: &Path, out: &Path) -> Vec<String> {
    let mut args: Vec<String> = ["-q", "pair"].map(String::from).to_vec();
    args.push(s(&dir.join("s0.obj")).to_string());
    args.push(s(&dir.join("s1.off")).to_string());
    args.extend(["-o", s(out), "--no-pictures", "--eigenpairs", "20"].map(String::from));
    args
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    out.sort();
    out
}

#[test]
fn broken_file_is_reported_and_skipped_with_exit_3_and_strict_fails() {
    let dir = tempfile::tempdir().unwrap();
    let input = input_folder(dir.path(), 3, 2);
    std::fs::write(input.join("broken.off"), "OFF\n4 4 0\n0 0 0\n").unwrap();
    std::fs::write(input.join("notes.txt"), "not a mesh").unwrap();
    let out = dir.path().join("out");
    let mut args = vec!["segment", s(&input), "-o", s(&out)];
    args.extend(FAST);
    let run = coseg(&args);
    let (stdout, stderr) = (text(&run.stdout), text(&run.stderr));
    assert_eq!(run.status.code(), Some(3), "{stdout}{stderr}");
    assert!(
        stderr.contains("broken.off") && stderr.contains("skipped"),
        "{stderr}"
    );
    assert!(!stderr.contains("notes.txt"), "{stderr}");
    assert!(stdout.contains("3 shapes co-segmented"), "{stdout}");
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(summary.contains("broken.off"), "{summary}");
    for name in [
        "s0.regions.txt",
        "s1.png",
        "s2.regions.ply",
        "preview.png",
        "index.html",
    ] {
        assert!(out.join(name).is_file(), "{name} missing");
    }

    let strict_out = dir.path().join("strict");
    let mut args = vec!["--strict", "segment", s(&input), "-o", s(&strict_out)];
    args.extend(FAST);
    let run = coseg(&args);
    let stderr = text(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("broken.off") && stderr.contains("--strict"),
        "{stderr}"
    );
    assert!(!strict_out.join("summary.json").exists());
}

/// `coseg segment -q --no-pictures --parts auto` with `extra` flags on two small shapes made
/// in `dir`; the run and its output folder.
fn segment_parts_auto(dir: &Path, extra: &[&str]) -> (Output, std::path::PathBuf) {
    let input = input_folder(dir, 2, 2);
    let out = dir.join("out");
    let run = quiet_segment(
        &input,
        &out,
        &[&FAST[..], &["--parts", "auto"], extra].concat(),
    );
    (run, out)
}

/// `--parts auto` printed its "parts: …" line under `--quiet`.
#[test]
fn regression_quiet_parts_auto_prints_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (run, out) = segment_parts_auto(dir.path(), &[]);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    assert!(run.stdout.is_empty(), "{}", text(&run.stdout));
    assert!(run.stderr.is_empty(), "{}", text(&run.stderr));
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(
        summary.contains("\"parts\""),
        "the parts report still goes to summary.json"
    );
}

/// `--parts` with the extrinsic family on an aligned collection records its mirror pairs in
/// summary.json (`parts.mirror_pairs`): valid region ids, each pair within the levels.
#[test]
fn parts_records_mirror_pairs() {
    let dir = tempfile::tempdir().unwrap();
    let (run, out) = segment_parts_auto(
        dir.path(),
        &[
            "--features",
            "spectral,extrinsic",
            "--up",
            "y",
            "--directions",
            "8",
        ],
    );
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let regions = summary["parts"]["region_leaves"].as_array().unwrap().len();
    let pairs = summary["parts"]["mirror_pairs"]
        .as_array()
        .expect("mirror_pairs recorded");
    for p in pairs {
        let (a, b) = (p["a"].as_u64().unwrap(), p["b"].as_u64().unwrap());
        assert!(a < b && (b as usize) < regions, "{p}");
        // A pair's reflected centroid lands nearer the other part than half their distance,
        // the two have one size and look alike (the levels themselves are the library's).
        let (ratio, balance) = (
            p["ratio"].as_f64().unwrap(),
            p["area_balance"].as_f64().unwrap(),
        );
        assert!((0.0..0.5).contains(&ratio), "{p}");
        assert!(balance > 0.5 && balance <= 1.0, "{p}");
        assert!(p["likeness"].as_f64().unwrap() > 0.0, "{p}");
    }
}

/// `--refine-sizes`: `keep` and `keep:TOL` are recorded in summary.json (the adaptive size
/// tolerance by default), `free` and no flag record nothing (the default mode's summary is
/// unchanged), anything else is refused.
#[test]
fn refine_sizes_is_recorded_and_checked() {
    let dir = tempfile::tempdir().unwrap();
    let input = input_folder(dir.path(), 2, 2);
    let run_with = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let run = quiet_segment(
            &input,
            &out,
            &[&FAST[..], &["--parts", "auto"], extra].concat(),
        );
        (run, out)
    };
    let summary = |out: &Path| std::fs::read_to_string(out.join("summary.json")).unwrap();
    let (run, out) = run_with("keep", &["--refine-sizes", "keep"]);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    let s_keep = summary(&out);
    assert!(
        s_keep.contains("\"refine_sizes\"") && s_keep.contains("\"tolerance\": 0.5"),
        "{s_keep}"
    );
    let (run, out) = run_with("keep25", &["--refine-sizes", "keep:0.25"]);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    assert!(summary(&out).contains("\"tolerance\": 0.25"));
    let (run, free) = run_with("free", &["--refine-sizes", "free"]);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    let (run, none) = run_with("none", &[]);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    assert!(!summary(&free).contains("refine_sizes"));
    assert_eq!(files(&free), files(&none));
    for bad in ["keep:-1", "keep:x", "fixed"] {
        let (run, _) = run_with(&format!("bad{bad}"), &["--refine-sizes", bad]);
        assert_eq!(run.status.code(), Some(2), "{bad}: {}", text(&run.stderr));
    }
}

/// `--parts N --parts-from geometry`: N parts cut from `--regions` equal-area regions,
/// recorded in summary.json (the option, the stop reason, the leaves); `--parts auto` and no
/// `--parts` choose the number and record it; an unknown kind is refused.
#[test]
fn parts_from_geometry_is_recorded_and_checked() {
    let dir = tempfile::tempdir().unwrap();
    let input = input_folder(dir.path(), 3, 2);
    let run_with = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        // FAST without its `--regions 3`: the regions are set here.
        (
            quiet_segment(&input, &out, &[&FAST_PIPELINE[..], extra].concat()),
            out,
        )
    };
    let (run, out) = run_with(
        "t",
        &["--parts", "2", "--parts-from", "geometry", "--regions", "5"],
    );
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(
        summary["options"]["parts_from"],
        serde_json::json!({"kind": "geometry", "leaves": 5, "band": 0.1})
    );
    assert_eq!(summary["parts"]["stop"]["reason"], "equal_area_leaves");
    // Five regions, and one more leaf per kind of piece a region is split into, each
    // recorded with the region it comes from.
    let leaves = summary["parts"]["leaf_areas"].as_array().unwrap().len();
    assert!(leaves >= 5, "{leaves}");
    if leaves > 5 {
        let origin: Vec<u64> = summary["parts"]["leaf_origin"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_u64().unwrap())
            .collect();
        assert_eq!(origin.len(), leaves);
        assert_eq!(origin[..5], [0, 1, 2, 3, 4]);
        assert!(origin[5..].iter().all(|&o| o < 5), "{origin:?}");
        // Copies are pairs of leaves split from one region.
        if let Some(copies) = summary["parts"].get("leaf_copies") {
            for pair in copies.as_array().unwrap() {
                let (a, b) = (pair[0].as_u64().unwrap(), pair[1].as_u64().unwrap());
                assert!(a < b && origin[a as usize] == origin[b as usize], "{pair}");
            }
        }
    } else {
        assert!(summary["parts"].get("leaf_origin").is_none());
        assert!(summary["parts"].get("leaf_copies").is_none());
    }
    assert_eq!(
        summary["parts"]["region_leaves"].as_array().unwrap().len(),
        2
    );
    assert_eq!(summary["regions"].as_array().unwrap().len(), 2);
    // The part cues are cached beside the shapes' entries, one per shape; a rerun reads them
    // and writes the same regions; a damaged entry is recomputed and rewritten as it was.
    let cues: Vec<PathBuf> = std::fs::read_dir(out.join(".cache"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "coseg-cues"))
        .collect();
    assert_eq!(cues.len(), 3);
    let regions = std::fs::read(out.join("s0.regions.txt")).unwrap();
    let good = std::fs::read(&cues[0]).unwrap();
    let mut bytes = good.clone();
    bytes[100] ^= 1;
    std::fs::write(&cues[0], &bytes).unwrap();
    // Without its part tree: a rerun with the tree only re-cuts it and reads no cue.
    let trees: Vec<PathBuf> = std::fs::read_dir(out.join(".cache"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "coseg-tree"))
        .collect();
    assert_eq!(trees.len(), 1);
    std::fs::remove_file(&trees[0]).unwrap();
    let (run, _) = run_with(
        "t",
        &["--parts", "2", "--parts-from", "geometry", "--regions", "5"],
    );
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    assert_eq!(std::fs::read(&cues[0]).unwrap(), good);
    assert_eq!(std::fs::read(out.join("s0.regions.txt")).unwrap(), regions);
    // Without a number (`--parts auto`, or no `--parts`: the default), the part tree's cut
    // criterion chooses one, recorded with its reason.
    for (name, extra) in [
        ("auto", &["--parts", "auto", "--parts-from", "geometry"][..]),
        ("noparts", &["--parts-from", "geometry"][..]),
    ] {
        let (run, out) = run_with(name, extra);
        assert_eq!(run.status.code(), Some(0), "{name}: {}", text(&run.stderr));
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        let count = summary["part_count"]["count"].as_u64().unwrap() as usize;
        assert_eq!(
            summary["regions"].as_array().unwrap().len(),
            count,
            "{name}"
        );
        assert!(
            summary["part_count"]["reason"]
                .as_str()
                .unwrap()
                .contains("parts"),
            "{name}"
        );
    }
    let (run, _) = run_with(
        "bad",
        &["--parts", "2", "--parts-from", "size", "--regions", "5"],
    );
    assert_eq!(run.status.code(), Some(2), "{}", text(&run.stderr));
}

/// Regression: `--parts auto --starts 3` ran one start and said nothing; several starts are
/// for the equal-area mode, so the combination is now an error that names `starts`.
#[test]
fn regression_starts_with_parts_was_silently_ignored() {
    let dir = tempfile::tempdir().unwrap();
    let (run, _) = segment_parts_auto(dir.path(), &["--starts", "3"]);
    assert_ne!(run.status.code(), Some(0));
    let err = text(&run.stderr);
    assert!(
        err.contains("starts = 3") && err.contains("--parts"),
        "{err}"
    );
}

#[test]
fn quiet_prints_nothing_on_success_and_no_pictures_writes_none() {
    let dir = tempfile::tempdir().unwrap();
    let input = input_folder(dir.path(), 2, 2);
    let out = dir.path().join("out");
    let mut args = vec![
        "segment",
        s(&input),
        "-o",
        s(&out),
        "--quiet",
        "--no-pictures",
    ];
    args.extend(FAST);
    let run = coseg(&args);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    assert!(run.stdout.is_empty(), "{}", text(&run.stdout));
    assert!(run.stderr.is_empty(), "{}", text(&run.stderr));
    assert!(out.join("summary.json").is_file());
    assert!(!out.join("preview.png").exists() && !out.join("index.html").exists());

    let pair_out = dir.path().join("pair");
    let (s0, s1) = (input.join("s0.obj"), input.join("s1.off"));
    let mut args = vec!["-q", "pair", s(&s0), s(&s1), "-o", s(&pair_out)];
    args.extend(FAST_PIPELINE);
    args.extend(["--pairs", "3"]);
    let run = coseg(&args);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    assert!(
        run.stdout.is_empty() && run.stderr.is_empty(),
        "{}{}",
        text(&run.stdout),
        text(&run.stderr)
    );
    // pair caches by default, like segment, and draws its pictures.
    assert!(std::fs::read_dir(pair_out.join(".cache")).unwrap().count() >= 2);
    assert!(pair_out.join("preview.png").is_file() && pair_out.join("s0.png").is_file());
}

#[test]
fn render_writes_a_png_of_the_expected_size_that_is_not_one_colour() {
    let dir = tempfile::tempdir().unwrap();
    shapes(dir.path(), 3, 2);
    let labels: String = (0..blob(2).vertex_count())
        .map(|i| format!("{}\n", i % 4))
        .collect();
    let lab = dir.path().join("s0.labels.txt");
    std::fs::write(&lab, labels).unwrap();
    let png_path = dir.path().join("sheet.png");
    let run = coseg(&[
        "render",
        s(&dir.path().join("s0.obj")),
        s(&dir.path().join("s1.off")),
        s(&dir.path().join("s2.ply")),
        "-o",
        s(&png_path),
        "--cell-size",
        "100",
        "--columns",
        "3",
        "--labels",
        s(&lab),
        s(&lab),
        s(&lab),
    ]);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    let dec = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(&png_path).unwrap(),
    ));
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.width, 300);
    assert!(info.height > 100, "{}", info.height);
    let mut colours: Vec<&[u8]> = buf[..info.buffer_size()].chunks(3).collect();
    colours.sort_unstable();
    colours.dedup();
    assert!(colours.len() > 20, "{} colours", colours.len());
    // A label file of the wrong length is named in the error.
    std::fs::write(&lab, "0\n1\n").unwrap();
    let run = coseg(&[
        "render",
        s(&dir.path().join("s0.obj")),
        "--labels",
        s(&lab),
        "-o",
        s(&png_path),
    ]);
    assert_eq!(run.status.code(), Some(1));
    assert!(
        text(&run.stderr).contains("s0.labels.txt"),
        "{}",
        text(&run.stderr)
    );
}

/// `coseg pair --family-weights` reaches the pair's affinity: with two families, the extrinsic
/// family weighed far above or far below the spectral one gives other regions (were the
/// weights ignored, the two runs would write the same files); scaling every weight alike
/// changes nothing.
#[test]
fn pair_weighs_the_feature_families() {
    let dir = tempfile::tempdir().unwrap();
    shapes(dir.path(), 2, 2);
    let regions = |weights: &str| {
        let out = dir.path().join(format!("pair-{weights}"));
        let prefix = small_pair(dir.path(), &out);
        let mut args: Vec<&str> = prefix.iter().map(String::as_str).collect();
        args.extend([
            "--hks",
            "6",
            "--wks",
            "6",
            "--curvature",
            "6",
            "--bands",
            "6",
            "--pairs",
            "4",
            "--features",
            "spectral,extrinsic",
            "--up",
            "pca",
            "--directions",
            "12",
            "--family-weights",
            weights,
        ]);
        let run = coseg(&args);
        assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
        std::fs::read(out.join("s0.regions.txt")).unwrap()
    };
    let spectral_led = regions("extrinsic=0.0625");
    assert_ne!(spectral_led, regions("extrinsic=16"));
    // Only the shares count (powers of two, so that the normalised weights are exactly equal).
    assert_eq!(spectral_led, regions("spectral=16"));
}

fn cache_entries(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|r| {
            r.map(|e| e.unwrap().path())
                .filter(|p| p.extension().is_some_and(|e| e == "coseg-shape"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

#[test]
fn run_killed_during_per_shape_stage_resumes_to_identical_outputs_redoing_only_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    std::fs::create_dir(&input).unwrap();
    let n = 6;
    shapes(&input, n, 4);
    let mut fast: Vec<&str> = FAST.to_vec();
    fast[1] = "60";
    // Reference: an uninterrupted run.
    let reference = dir.path().join("reference");
    let mut args = vec!["--threads", "1", "segment", s(&input), "-o", s(&reference)];
    args.extend(&fast);
    let run = coseg(&args);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));

    let out = dir.path().join("out");
    let cache = out.join(".cache");
    let mut args = vec!["--threads", "1", "segment", s(&input), "-o", s(&out)];
    args.extend(&fast);
    let mut child = Command::new(env!("CARGO_BIN_EXE_coseg"))
        .args(&args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while cache_entries(&cache).is_empty() {
        assert!(
            t0.elapsed() < Duration::from_secs(300),
            "no cache entry after 300 s"
        );
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before it could be killed"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let done = cache_entries(&cache);
    assert!(
        !done.is_empty() && done.len() < n,
        "killed with {} of {n} shapes cached: not during the per-shape stage",
        done.len()
    );
    assert!(
        !out.join("summary.json").exists(),
        "killed before any output"
    );
    let stamps: Vec<_> = done
        .iter()
        .map(|p| std::fs::metadata(p).unwrap().modified().unwrap())
        .collect();

    let run = coseg(&args);
    let stdout = text(&run.stdout);
    assert_eq!(run.status.code(), Some(0), "{stdout}{}", text(&run.stderr));
    // Only the unfinished shapes were computed again.
    assert!(
        stdout.contains(&format!("({} cached)", done.len())),
        "{stdout}"
    );
    for (p, t) in done.iter().zip(&stamps) {
        assert_eq!(
            std::fs::metadata(p).unwrap().modified().unwrap(),
            *t,
            "{} rewritten",
            p.display()
        );
    }
    assert_eq!(cache_entries(&cache).len(), n);
    let (a, b) = (files(&reference), files(&out));
    assert_eq!(
        a.iter().map(|f| &f.0).collect::<Vec<_>>(),
        b.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert!(
            x == y,
            "{name} differs between the resumed and the uninterrupted run"
        );
    }
}

#[test]
fn help_shows_an_example_for_every_subcommand_and_the_shared_flags() {
    let top = text(&coseg(&["--help"]).stdout);
    assert!(
        top.contains("Examples:") && top.contains("--quiet") && top.contains("--strict"),
        "{top}"
    );
    for cmd in [
        "info", "spectrum", "convert", "features", "generate", "pair", "segment", "render", "eval",
    ] {
        let out = coseg(&[cmd, "--help"]);
        let help = text(&out.stdout);
        assert_eq!(out.status.code(), Some(0), "{cmd}");
        assert!(
            help.contains(&format!("coseg {cmd} ")),
            "{cmd} --help has no example:\n{help}"
        );
        assert!(help.contains("--threads"), "{cmd}");
    }
}

/// `--starts N` records the kept start and every score; one start (the default) writes no
/// `starts` entry, and the kept start's regions are those of its own seeded run.
#[test]
fn segment_starts_records_the_choice_and_keeps_that_starts_regions() {
    let dir = tempfile::tempdir().unwrap();
    let input = input_folder(dir.path(), 3, 2);
    let run_with = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let run = quiet_segment(&input, &out, &[&FAST[..], extra].concat());
        assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        (out, summary)
    };
    let (_, one) = run_with("one", &[]);
    assert!(one.get("starts").is_none());
    let (many_out, many) = run_with("many", &["--starts", "3"]);
    let chosen = many["starts"]["chosen"].as_u64().unwrap();
    let scores = many["starts"]["scores"].as_array().unwrap();
    assert_eq!(scores.len(), 3);
    let best = scores
        .iter()
        .map(|x| x.as_f64().unwrap())
        .fold(f64::MIN, f64::max);
    assert_eq!(scores[chosen as usize].as_f64().unwrap(), best);
    let seed = chosen.to_string();
    let (single_out, _) = if chosen == 0 {
        run_with("single", &[])
    } else {
        run_with("single", &["--seed", &seed])
    };
    for name in ["s0", "s1", "s2"] {
        let file = format!("{name}.regions.txt");
        assert_eq!(
            std::fs::read(many_out.join(&file)).unwrap(),
            std::fs::read(single_out.join(&file)).unwrap(),
            "{file}"
        );
    }
    let bad = coseg(&[
        "segment",
        s(&input),
        "-o",
        s(&dir.path().join("bad")),
        "--starts",
        "0",
    ]);
    assert_ne!(bad.status.code(), Some(0));
}

/// The cache stores the `f32` spectrum and recomputes descriptors and bands on a warm load
/// (issue #19's compact cache): a warm run must write the cold run's files byte for byte —
/// `segment` (from the compact bands entries), `pair` (from the full entries, rebuilt), with
/// another thread count, from a cache filled by the other command, and without any cache;
/// `features --spectrum` writes the rebuilt descriptors and spectrum themselves, so that any
/// difference at rounding level shows (the region files would hide it).
#[test]
fn warm_runs_write_the_cold_runs_files_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let input = input_folder(dir.path(), 3, 3);
    let cache = dir.path().join("cache");
    let run = |threads: &str, cmd: &[&str], out: &str, cache: Option<&Path>| {
        let out = dir.path().join(out);
        let mut args = vec!["--threads", threads];
        args.extend(cmd);
        args.extend(["-o", s(&out), "--no-pictures"]);
        match cache {
            Some(c) => args.extend(["--cache", s(c)]),
            None if cmd[0] == "pair" => args.push("--no-cache"),
            None => {}
        }
        args.extend(&FAST[..FAST.len() - 2]);
        if cmd[0] == "segment" {
            args.extend(&FAST[FAST.len() - 2..]);
        } else {
            args.extend(["--pairs", "3"]);
        }
        let r = coseg(&args);
        assert_eq!(r.status.code(), Some(0), "{}", text(&r.stderr));
        (files(&out), text(&r.stdout))
    };
    let segment = ["segment", s(&input)];
    let (cold, cold_out) = run("1", &segment, "seg-cold", Some(&cache));
    assert!(cold_out.contains("(0 cached)"), "{cold_out}");
    let (warm, warm_out) = run("2", &segment, "seg-warm", Some(&cache));
    assert!(warm_out.contains("(3 cached)"), "{warm_out}");
    same(&cold, &warm, "segment cold / warm");

    let (a, b) = (input.join("s0.obj"), input.join("s1.off"));
    let pair = ["pair", s(&a), s(&b)];
    let pair_cache = dir.path().join("pair-cache");
    let (cold, _) = run("1", &pair, "pair-cold", Some(&pair_cache));
    let (warm, _) = run("2", &pair, "pair-warm", Some(&pair_cache));
    same(&cold, &warm, "pair cold / warm");
    // The full entries written by `segment` serve `pair` too.
    let (from_segment, _) = run("1", &pair, "pair-from-segment", Some(&cache));
    same(&cold, &from_segment, "pair cold / from segment's cache");
    let (uncached, _) = run("3", &pair, "pair-uncached", None);
    same(&cold, &uncached, "pair cold / no cache");
    // pair read its two shapes from segment's cache: nothing was added.
    assert_eq!(std::fs::read_dir(&cache).unwrap().count(), 6);

    let features = |threads: &str, out: &str, cache: Option<&Path>| {
        let out = dir.path().join(out);
        let mut args = vec![
            "--threads",
            threads,
            "features",
            s(&a),
            "-o",
            s(&out),
            "--spectrum",
        ];
        if let Some(c) = cache {
            args.extend(["--cache", s(c)]);
        }
        args.extend(&FAST[..FAST.len() - 2]);
        let r = coseg(&args);
        assert_eq!(r.status.code(), Some(0), "{}", text(&r.stderr));
        (files(&out), text(&r.stderr))
    };
    let feature_cache = dir.path().join("feature-cache");
    let (cold, log) = features("1", "features-cold", Some(&feature_cache));
    assert!(log.contains("cache miss"), "{log}");
    assert!(cold.iter().any(|f| f.0 == "descriptors.npy"));
    let (warm, log) = features("2", "features-warm", Some(&feature_cache));
    assert!(log.contains("cache hit"), "{log}");
    same(&cold, &warm, "features cold / warm");
    let (uncached, _) = features("3", "features-uncached", None);
    same(&cold, &uncached, "features cold / no cache");
}

/// Regression: the band-affinity kernel read an undocumented `KERNEL` variable on every
/// operator application, smoothed its tables with the numbers it held and panicked on
/// anything else. The environment must not reach the method: `coseg pair` with a stray
/// `KERNEL` (malformed, then well-formed) succeeds and writes what it writes without one.
#[test]
fn regression_kernel_environment_variable_is_ignored() {
    let dir = tempfile::tempdir().unwrap();
    shapes(dir.path(), 2, 2);
    let regions = |kernel: Option<&str>| {
        let out = dir
            .path()
            .join(format!("pair-{}", kernel.unwrap_or("none")));
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_coseg"));
        cmd.args(small_pair(dir.path(), &out))
            .args(["--bands", "6", "--pairs", "4"]);
        match kernel {
            Some(k) => cmd.env("KERNEL", k),
            None => cmd.env_remove("KERNEL"),
        };
        let run = cmd.output().expect("run coseg");
        assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
        std::fs::read(out.join("s0.regions.txt")).unwrap()
    };
    let clean = regions(None);
    assert_eq!(clean, regions(Some("not,numbers")));
    assert_eq!(clean, regions(Some("1,3")));
}
