//! Every command of the real `coseg` binary on a generated adversarial corpus
//! (`tests/common/adversarial.rs`: several components, single triangles, non-manifold edges
//! and vertices, zero-area and needle triangles, duplicate and unreferenced vertices,
//! inconsistent orientation, 1e-8 and 1e8 scales, meshes smaller than the eigenpair count, a
//! strip two vertices wide), and the regression tests of issue #21.
//!
//! On each mesh a command either succeeds (warnings allowed) or refuses with a message that
//! names the file and the reason; it never panics; no output file holds a NaN or an infinity.

mod common;

use common::adversarial::{
    Case, corpus, sphere_mesh, with_collinear_slivers, with_surface_debris, write_case,
    write_sphere,
};
use common::cli::coseg;
use common::generate::collections_dir;
use coseg::mesh::{TriMesh, read_mesh, write_mesh};
use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};
use std::process::Output;

/// [`common::scratch`] in `adversarial/`.
fn scratch(name: &str) -> PathBuf {
    common::scratch("adversarial", name)
}

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// Small per-shape options so that the corpus runs in seconds unoptimised; the eigenpair
/// count (60) is still above the small meshes' vertex counts.
const PIPE: &[&str] = &[
    "--eigenpairs",
    "60",
    "--hks",
    "16",
    "--wks",
    "16",
    "--curvature",
    "16",
    "--bands",
    "8",
];

/// The arguments of `coseg ARGS -o OUT [--cache CACHE]` with the small per-shape options
/// ([`PIPE`]): how every command that writes a folder runs here.
fn args_into(args: &[&OsStr], out: &Path, cache: Option<&Path>) -> Vec<OsString> {
    let mut all: Vec<OsString> = args.iter().map(OsString::from).collect();
    all.extend(["-o".as_ref(), out.as_os_str()].map(OsString::from));
    if let Some(cache) = cache {
        all.extend(["--cache".as_ref(), cache.as_os_str()].map(OsString::from));
    }
    all.extend(PIPE.iter().map(OsString::from));
    all
}

/// What a command did on one mesh.
#[derive(Debug, PartialEq)]
enum Verdict {
    Succeeded,
    Refused,
}

/// Checks the contract on one command's result: no panic; success (0, or 3 = some inputs
/// skipped) or a refusal (1) whose message names `file`.
fn verdict(what: &str, file: &str, o: &Output) -> Verdict {
    let (stdout, stderr) = text(o);
    assert!(
        !stderr.contains("panicked") && !stderr.contains("RUST_BACKTRACE"),
        "{what}: panicked\n{stderr}"
    );
    match o.status.code() {
        Some(0) | Some(3) => Verdict::Succeeded,
        Some(1) => {
            assert!(
                stderr.contains("error: ") && stderr.contains(file),
                "{what}: refusal does not name {file}:\n{stderr}"
            );
            Verdict::Refused
        }
        code => panic!("{what}: exit {code:?}\nstdout:\n{stdout}\nstderr:\n{stderr}"),
    }
}

/// Every output file under `dir` (recursively, the cache excepted) holds no NaN or infinity:
/// text files have no `nan`/`inf` token and no `null` among JSON numbers, PLY meshes read back
/// (the reader rejects non-finite coordinates), `.npy` arrays are finite.
fn assert_no_nan(dir: &Path) {
    let mut stack = vec![dir.to_path_buf()];
    let mut checked = 0;
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if path.is_dir() {
                if name != ".cache" {
                    stack.push(path);
                }
                continue;
            }
            checked += 1;
            let ext = path.extension().map(|e| e.to_string_lossy().into_owned());
            match ext.as_deref() {
                Some("ply") | Some("off") | Some("obj") => {
                    read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
                }
                Some("npy") => {
                    let bytes = std::fs::read(&path).unwrap();
                    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
                    let values: Vec<f64> = npy.into_vec().unwrap_or_default();
                    assert!(
                        values.iter().all(|x| x.is_finite()),
                        "{}: non-finite value",
                        path.display()
                    );
                }
                Some("png") => {
                    // Pictures: a valid PNG is all there is to check (colours, not numbers).
                    let file = std::fs::File::open(&path).unwrap();
                    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
                        .read_info()
                        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
                    reader.next_frame(&mut buf).unwrap();
                }
                Some("html") => {
                    // The viewer page: its numbers are the JSON of the `coseg-data` script.
                    let t = std::fs::read_to_string(&path).unwrap();
                    let open = "<script id=\"coseg-data\" type=\"application/json\">";
                    let start = t.find(open).expect("viewer data script") + open.len();
                    let end = start + t[start..].find("</script>").unwrap();
                    let v: serde_json::Value = serde_json::from_str(&t[start..end]).unwrap();
                    check_json(&v, &path.display().to_string(), "");
                }
                Some("json") => {
                    let v: serde_json::Value =
                        serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
                    check_json(&v, &path.display().to_string(), "");
                }
                _ => {
                    let t = std::fs::read_to_string(&path).unwrap();
                    for tok in t.split(|c: char| c.is_whitespace() || c == ',') {
                        let l = tok.to_ascii_lowercase();
                        assert!(
                            !(l.contains("nan") || l.contains("inf")),
                            "{}: token {tok:?}",
                            path.display()
                        );
                    }
                }
            }
        }
    }
    assert!(checked > 0, "{}: no output file", dir.display());
}

/// serde_json writes a NaN as `null`: no array may mix numbers and nulls or hold only nulls,
/// and no numeric field may be null where its siblings in an array of objects are numbers.
fn check_json(v: &serde_json::Value, file: &str, at: &str) {
    use serde_json::Value;
    match v {
        Value::Array(items) => {
            let nulls = items.iter().filter(|x| x.is_null()).count();
            assert!(nulls == 0, "{file}: null (a NaN?) in array {at}");
            if items.iter().all(|x| x.is_object()) {
                let keys: std::collections::BTreeSet<&String> = items
                    .iter()
                    .flat_map(|x| x.as_object().unwrap().keys())
                    .collect();
                for k in keys {
                    let numbers = items.iter().filter(|x| x[k].is_number()).count();
                    let nulls = items.iter().filter(|x| x[k].is_null()).count();
                    assert!(
                        numbers == 0 || nulls == 0,
                        "{file}: {at}[].{k} mixes numbers and nulls (a NaN?)"
                    );
                }
            }
            for (i, x) in items.iter().enumerate() {
                check_json(x, file, &format!("{at}[{i}]"));
            }
        }
        Value::Object(map) => {
            for (k, x) in map {
                check_json(x, file, &format!("{at}.{k}"));
            }
        }
        _ => {}
    }
}

/// Runs `info`, `spectrum`, `features`, `pair` (against a clean sphere, and against itself)
/// and `segment` (with two clean spheres) on `case`; returns the verdict of each.
fn run_all(case: &Case, root: &Path, partner: &Path) -> Vec<(String, Verdict)> {
    let dir = root.join(case.file.replace('.', "_"));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("input");
    std::fs::create_dir_all(&input).unwrap();
    let mesh = write_case(&input, case);
    let file = case.file;
    let cache = root.join("cache");
    let mut out = Vec::new();
    let mut record = |what: &str, o: Output, outputs: Option<&Path>| {
        let label = format!("{what} on {file} ({})", case.what);
        let v = verdict(&label, file, &o);
        if v == Verdict::Succeeded
            && let Some(d) = outputs
        {
            assert_no_nan(d);
        }
        out.push((what.to_string(), v));
    };

    let o = coseg(&["info".as_ref(), mesh.as_os_str()]);
    record("info", o, None);

    let o = coseg(&[
        "spectrum".as_ref(),
        mesh.as_os_str(),
        "-k".as_ref(),
        "60".as_ref(),
        "--json".as_ref(),
    ]);
    let spectrum_dir = dir.join("spectrum");
    std::fs::create_dir_all(&spectrum_dir).unwrap();
    std::fs::write(spectrum_dir.join("spectrum.json"), &o.stdout).unwrap();
    let ok = o.status.success();
    record("spectrum", o, ok.then_some(spectrum_dir.as_path()));

    for format in ["npy", "csv"] {
        let fdir = dir.join(format!("features_{format}"));
        let args = args_into(
            &[
                "features".as_ref(),
                mesh.as_os_str(),
                "--format".as_ref(),
                format.as_ref(),
            ],
            &fdir,
            Some(&cache),
        );
        record(&format!("features {format}"), coseg(&args), Some(&fdir));
    }

    for (what, other) in [("pair with a sphere", partner), ("pair with itself", &mesh)] {
        let pdir = dir.join(what.replace(' ', "_"));
        let args = args_into(
            &[
                "pair".as_ref(),
                mesh.as_os_str(),
                other.as_ref(),
                "--refine-rounds".as_ref(),
                "3".as_ref(),
                "--map-size".as_ref(),
                "30".as_ref(),
            ],
            &pdir,
            Some(&cache),
        );
        record(what, coseg(&args), Some(&pdir));
    }

    let folder = dir.join("collection");
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::copy(&mesh, folder.join(file)).unwrap();
    for seed in [11, 12] {
        write_sphere(&folder.join(format!("sphere{seed}.off")), seed);
    }
    let sdir = dir.join("segment");
    let args = args_into(
        &[
            "segment".as_ref(),
            folder.as_os_str(),
            "--regions".as_ref(),
            "3".as_ref(),
            "--refine-rounds".as_ref(),
            "3".as_ref(),
        ],
        &sdir,
        Some(&cache),
    );
    record("segment", coseg(&args), Some(&sdir));

    // propagate, both ways over the same folder: from a clean sphere's per-vertex labels onto
    // the case (a labels folder, matched by stem), and from the case's per-face `.seg` onto
    // the spheres (a file).
    let stem = file.split('.').next().unwrap();
    let from_sphere = dir.join("labels_sphere");
    std::fs::create_dir_all(&from_sphere).unwrap();
    let sphere = read_mesh(folder.join("sphere11.off")).unwrap();
    write_lines(
        &from_sphere.join("sphere11.labels.txt"),
        &sphere_vertex_labels(&sphere),
    );
    let from_case = dir.join("labels_case");
    std::fs::create_dir_all(&from_case).unwrap();
    let case_mesh = read_mesh(&mesh).unwrap();
    let seg = from_case.join(format!("{stem}.seg"));
    write_lines(&seg, &case_face_labels(&case_mesh));
    for (what, labels, parts) in [
        ("propagate from a sphere", &from_sphere, &[1, 2][..]),
        ("propagate from the case", &seg, &[3, 4][..]),
    ] {
        let pdir = dir.join(what.replace(' ', "_"));
        let args = args_into(
            &[
                "propagate".as_ref(),
                folder.as_os_str(),
                "--labels".as_ref(),
                labels.as_ref(),
            ],
            &pdir,
            Some(&cache),
        );
        let o = coseg(&args);
        let ok = matches!(o.status.code(), Some(0) | Some(3));
        record(what, o, Some(&pdir));
        if ok {
            check_propagated(&pdir, &folder, parts);
        }
    }
    out
}

/// Writes one integer per line.
fn write_lines(path: &Path, labels: &[i32]) {
    let text: String = labels.iter().map(|l| format!("{l}\n")).collect();
    std::fs::write(path, text).unwrap();
}

/// Per-vertex labels of a clean sphere: 1 above z = 0.15, 2 below -0.15, unlabelled (-1 or
/// another negative value, which means the same) between.
fn sphere_vertex_labels(m: &TriMesh) -> Vec<i32> {
    m.positions()
        .iter()
        .enumerate()
        .map(|(i, p)| match p[2] {
            z if z > 0.15 => 1,
            z if z < -0.15 => 2,
            _ if i % 2 == 0 => -1,
            _ => -7,
        })
        .collect()
}

/// Per-face labels of a corpus mesh: 3 or 4 by the side of its face centroid against the
/// mean of the centroids along x (at least one face 3), every fifth face unlabelled.
fn case_face_labels(m: &TriMesh) -> Vec<i32> {
    let p = m.positions();
    let cx: Vec<f64> = m
        .faces()
        .iter()
        .map(|f| f.iter().map(|&v| p[v as usize][0]).sum::<f64>() / 3.0)
        .collect();
    let mean = cx.iter().sum::<f64>() / cx.len() as f64;
    cx.iter()
        .enumerate()
        .map(|(f, &x)| match f {
            0 => 3,
            _ if f % 5 == 4 => -1,
            _ if x < mean => 3,
            _ => 4,
        })
        .collect()
}

/// `coseg propagate`'s outputs in `out` for the meshes of `folder`: for every mesh a
/// `.labels.txt` of one label per vertex and a `.seg` of one per face, each label a part of
/// the sources (`parts`) or -1; `summary.json`, `index.html` and the pictures are there (their
/// finiteness is [`assert_no_nan`]'s).
fn check_propagated(out: &Path, folder: &Path, parts: &[i32]) {
    let read = |p: PathBuf| -> Vec<i32> {
        std::fs::read_to_string(&p)
            .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
            .lines()
            .map(|l| l.parse().unwrap())
            .collect()
    };
    for entry in std::fs::read_dir(folder).unwrap() {
        let path = entry.unwrap().path();
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        let m = read_mesh(&path).unwrap();
        let v = read(out.join(format!("{stem}.labels.txt")));
        let f = read(out.join(format!("{stem}.seg")));
        assert_eq!(v.len(), m.vertex_count(), "{stem}.labels.txt");
        assert_eq!(f.len(), m.face_count(), "{stem}.seg");
        for l in v.iter().chain(&f) {
            assert!(*l == -1 || parts.contains(l), "{stem}: label {l}");
        }
        assert!(v.iter().any(|l| parts.contains(l)), "{stem}: no part");
    }
    for name in ["summary.json", "index.html", "preview.png"] {
        assert!(out.join(name).is_file(), "{}: no {name}", out.display());
    }
}

/// The whole corpus through every command. Every case must succeed on every command: each
/// of these meshes is one the method can work on (with warnings), so a refusal is a bug.
#[test]
fn every_command_on_the_adversarial_corpus_succeeds_without_nan() {
    let root = scratch("corpus");
    let partner = root.join("partner.off");
    write_sphere(&partner, 10);
    let mut table = Vec::new();
    for case in corpus() {
        for (what, v) in run_all(&case, &root, &partner) {
            table.push(format!("{:<18} {:<24} {v:?}", case.file, what));
            assert_eq!(
                v,
                Verdict::Succeeded,
                "{what} refused {} ({})",
                case.file,
                case.what
            );
        }
    }
    println!("{}", table.join("\n"));
}

/// Regression (#21, case 1): on a shape with disjoint small pieces (a shipped quadruped with 30
/// single triangles lying on its surface, unconnected) the map step failed the whole pair with
/// `eigensolver failed: ZoomOut: sampled eigenbasis is singular`. Now the step runs (its
/// samples cover every basis function, its fit is null-space aware) and summary.json lists
/// no fallback.
#[test]
fn pair_on_multi_component_shapes_runs_the_map_step() {
    let dir = scratch("multi_component_pair");
    let shipped = |n: &str| {
        let m = read_mesh(collections_dir().join("quadrupeds").join(n)).unwrap();
        (m.positions().to_vec(), m.faces().to_vec())
    };
    let a = dir.join("a.off");
    let b = dir.join("b.off");
    for (path, name) in [(&a, "quadrupeds_01.obj"), (&b, "quadrupeds_03.obj")] {
        let (p, f) = with_surface_debris(shipped(name), 30, 0.005);
        write_mesh(path, &TriMesh::new(p, f).unwrap(), &[]).unwrap();
    }
    let out = dir.join("out");
    let o = coseg(&[
        "pair".as_ref(),
        a.as_os_str(),
        b.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--eigenpairs".as_ref(),
        "60".as_ref(),
        "--map-size".as_ref(),
        "60".as_ref(),
    ]);
    let (_, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    assert!(!stderr.contains("singular"), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert!(summary["map_guided"].is_object(), "{summary}");
    assert_eq!(summary["fallbacks"], serde_json::json!([]), "{summary}");
    assert_no_nan(&out);
}

/// Regression (#21, case 2): `coseg segment same -o same` wrote `<name>.regions.ply` beside
/// the meshes and the next run read them as new shapes (6 from 3). coseg's own outputs are now
/// left out, with a warning naming them, and the second run co-segments the same 3 shapes
/// into byte-identical files.
#[test]
fn segment_into_its_own_input_folder_does_not_read_its_outputs() {
    let dir = scratch("same_folder");
    for seed in [1, 2, 3] {
        write_sphere(&dir.join(format!("s{seed}.off")), seed);
    }
    let run = || {
        let args = args_into(
            &[
                "segment".as_ref(),
                dir.as_os_str(),
                "--regions".as_ref(),
                "3".as_ref(),
            ],
            &dir,
            None,
        );
        coseg(&args)
    };
    let first = run();
    let (stdout, stderr) = text(&first);
    assert!(first.status.success(), "{stderr}");
    assert!(stdout.contains("3 shapes co-segmented"), "{stdout}");
    let before = std::fs::read(dir.join("s1.regions.txt")).unwrap();
    let second = run();
    let (stdout, stderr) = text(&second);
    assert!(second.status.success(), "{stderr}");
    assert!(stdout.contains("3 shapes co-segmented"), "{stdout}");
    assert!(
        stderr.contains("not reading 3 file(s)") && stderr.contains("s1.regions.ply"),
        "{stderr}"
    );
    assert_eq!(std::fs::read(dir.join("s1.regions.txt")).unwrap(), before);
}

/// Regression (#21, case 3): `g.obj` and `g.off` in one folder stopped the run with
/// `invalid shape name "g (duplicate)"`. They are now named `g_obj` and `g_off` (documented
/// in `coseg::graph::load_collection`), with a warning.
#[test]
fn two_files_with_one_stem_get_distinct_output_names() {
    let dir = scratch("one_stem");
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    for (seed, name) in [(1, "g.obj"), (2, "g.off"), (3, "h.ply")] {
        write_sphere(&input.join(name), seed);
    }
    let out = dir.join("out");
    let args = args_into(
        &[
            "segment".as_ref(),
            input.as_ref(),
            "--regions".as_ref(),
            "3".as_ref(),
        ],
        &out,
        None,
    );
    let o = coseg(&args);
    let (_, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    assert!(stderr.contains("share the stem \"g\""), "{stderr}");
    for name in ["g_obj", "g_off", "h"] {
        assert!(out.join(format!("{name}.regions.txt")).is_file(), "{name}");
        assert!(out.join(format!("{name}.regions.ply")).is_file(), "{name}");
    }
}

/// Regression (#21, case 4; #18): a mesh with fewer vertices than `--eigenpairs` was an error
/// in `spectrum`, `features`, `pair` and `segment` alike; now every stage computes as many
/// eigenpairs as the mesh has and says so.
#[test]
fn a_mesh_smaller_than_the_eigenpair_count_runs_everywhere_with_a_warning() {
    let dir = scratch("small_mesh");
    let small = corpus()
        .into_iter()
        .find(|c| c.file == "tetrahedron.off")
        .unwrap();
    let mesh = write_case(&dir, &small);
    let o = coseg(&[
        "spectrum".as_ref(),
        mesh.as_os_str(),
        "-k".as_ref(),
        "200".as_ref(),
    ]);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    assert_eq!(stdout.lines().count(), 4, "{stdout}");
    assert!(stderr.contains("4 of the 200 eigenpairs"), "{stderr}");
    let fdir = dir.join("features");
    let o = coseg(&[
        "features".as_ref(),
        mesh.as_os_str(),
        "-o".as_ref(),
        fdir.as_os_str(),
    ]);
    let (_, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    assert!(stderr.contains("4 of the 200 eigenpairs"), "{stderr}");
    assert_no_nan(&fdir);
}

/// Regression (#18): a missing file was reported as `…: No such file or directory (os error
/// 2): No such file or directory (os error 2)`. Each cause is now printed once.
#[test]
fn a_missing_file_is_reported_once() {
    let dir = scratch("missing");
    let missing = dir.join("missing.off");
    for args in [
        vec!["info".into(), missing.clone().into_os_string()],
        vec!["spectrum".into(), missing.clone().into_os_string()],
        vec![
            "pair".into(),
            missing.clone().into_os_string(),
            missing.clone().into_os_string(),
            "-o".into(),
            dir.join("out").into_os_string(),
        ],
        vec![
            "features".into(),
            missing.clone().into_os_string(),
            "-o".into(),
            dir.join("out").into_os_string(),
        ],
    ] {
        let o = coseg(&args);
        let (_, stderr) = text(&o);
        assert!(!o.status.success());
        assert!(stderr.contains("missing.off"), "{stderr}");
        assert_eq!(
            stderr.matches("No such file or directory").count(),
            1,
            "{args:?}: {stderr}"
        );
    }
}

/// An optional stage that cannot run leaves the previous stage's regions and says why: here
/// the map step gets shapes carrying different descriptor counts (its validation rejects
/// them), and the result is exactly the run without the map step.
#[test]
fn segment_pair_falls_back_to_the_refined_regions_when_the_map_step_cannot_run() {
    use coseg::pipeline::compute_shape_data;
    use coseg::stable::{PairShape, PairStage, SegmentPairOptions, segment_pair};
    let mut pipe = common::features::small_pipeline(40, 8);
    pipe.bands.bands = 6;
    let meshes: Vec<TriMesh> = [1, 2].iter().map(|&s| sphere_mesh(s)).collect();
    let data: Vec<_> = meshes
        .iter()
        .map(|m| compute_shape_data(m, &pipe).unwrap())
        .collect();
    let d = meshes[1].vertex_count();
    let b_values = &data[1].descriptors.values;
    // B loses its last descriptor column.
    let descriptors = [
        &data[0].descriptors.values[..],
        &b_values[..b_values.len() - d],
    ];
    let shape = |i: usize| PairShape {
        mesh: &meshes[i],
        spectrum: &data[i].spectrum,
        bands: &data[i].bands,
        descriptors: Some(descriptors[i]),
    };
    let mut map_step = coseg::maps::MapGuidedOptions::default();
    map_step.point_map.zoomout.final_size = 40;
    let options = {
        let mut opts = SegmentPairOptions::default();
        opts.map_step = coseg::maps::MapStep::Options(map_step.clone());
        opts
    };
    let out = segment_pair(shape(0), shape(1), &options).unwrap();
    assert_eq!(out.fallbacks.len(), 1, "{:?}", out.fallbacks);
    assert_eq!(out.fallbacks[0].stage, PairStage::MapGuided);
    assert!(
        out.fallbacks[0].reason.contains("descriptors"),
        "{}",
        out.fallbacks[0]
    );
    let without = {
        let mut opts = options.clone();
        opts.map_step = coseg::maps::MapStep::Off;
        opts
    };
    let reference = segment_pair(shape(0), shape(1), &without).unwrap();
    assert!(reference.fallbacks.is_empty());
    assert_eq!(out.regions.labels_b(), reference.regions.labels_b());
    assert_eq!(out.regions.labels_a(), reference.regions.labels_a());
    // A wrong option is still the caller's error, not a fallback.
    map_step.map_weight = f64::NAN;
    let bad = {
        let mut opts = options;
        opts.map_step = coseg::maps::MapStep::Options(map_step);
        opts
    };
    assert!(segment_pair(shape(0), shape(1), &bad).is_err());
}

/// `coseg propagate` refuses a label file that does not fit its mesh, with exit code 1 and a
/// message naming the file and the reason, and writes no output: wrong length (per vertex and
/// per face), a line that is not an integer, an empty file, bytes that are not text, a label
/// out of range, only unlabelled lines, and label inputs that match no mesh.
#[test]
fn propagate_refuses_bad_label_files_naming_them() {
    let dir = scratch("bad_labels");
    let folder = dir.join("meshes");
    std::fs::create_dir_all(&folder).unwrap();
    for seed in [1, 2, 3] {
        write_sphere(&folder.join(format!("s{seed}.off")), seed);
    }
    let m = read_mesh(folder.join("s1.off")).unwrap();
    let (d, nf) = (m.vertex_count(), m.face_count());
    let lines = |n: usize, f: &dyn Fn(usize) -> String| -> Vec<u8> {
        (0..n)
            .map(|i| format!("{}\n", f(i)))
            .collect::<String>()
            .into_bytes()
    };
    let mut not_text = lines(d, &|i| (i % 2).to_string());
    not_text[4] = 0xff; // line 3 of "0\n1\n0\n…"
    let cases: Vec<(&str, &str, Vec<u8>, Vec<String>)> = vec![
        (
            "short per-vertex file",
            "s1.labels.txt",
            lines(5, &|_| "1".into()),
            vec![format!("5 labels, but the mesh s1 has {d} vertices")],
        ),
        (
            "long .seg",
            "s1.seg",
            lines(nf + 1, &|_| "2".into()),
            vec![format!("{} labels, but the mesh s1 has {nf} faces", nf + 1)],
        ),
        (
            "a decimal on line 7",
            "s1.labels.txt",
            lines(d, &|i| if i == 6 { "1.5".into() } else { "1".into() }),
            vec!["s1.labels.txt:7: \"1.5\" is not an integer label".into()],
        ),
        (
            "a word on line 1",
            "s1.seg",
            lines(nf, &|i| if i == 0 { "seat".into() } else { "1".into() }),
            vec!["s1.seg:1: \"seat\" is not an integer label".into()],
        ),
        (
            "an empty .seg",
            "s1.seg",
            Vec::new(),
            vec![format!("0 labels, but the mesh s1 has {nf} faces")],
        ),
        (
            "an empty per-vertex file",
            "s1.labels.txt",
            b"\n\n".to_vec(),
            vec![format!("0 labels, but the mesh s1 has {d} vertices")],
        ),
        (
            "a byte that is not text",
            "s1.labels.txt",
            not_text,
            vec!["s1.labels.txt:3:".into(), "is not an integer label".into()],
        ),
        (
            "a label beyond i32",
            "s1.seg",
            lines(nf, &|i| {
                if i == 9 {
                    "99999999999".into()
                } else {
                    "0".into()
                }
            }),
            vec!["s1.seg:10: \"99999999999\" is not an integer label".into()],
        ),
        (
            "only unlabelled lines",
            "s1.labels.txt",
            lines(d, &|_| "-1".into()),
            vec!["s1.labels.txt: no label ≥ 0".into()],
        ),
        (
            "a file for no mesh",
            "chair.seg",
            lines(nf, &|_| "1".into()),
            vec!["chair.seg: no mesh has the stem \"chair\"".into()],
        ),
    ];
    let cache = dir.join("cache");
    for (i, (what, name, bytes, expected)) in cases.iter().enumerate() {
        let labels = dir.join(format!("labels{i}"));
        std::fs::create_dir_all(&labels).unwrap();
        let file = labels.join(name);
        std::fs::write(&file, bytes).unwrap();
        let out = dir.join(format!("out{i}"));
        let args = args_into(
            &[
                "propagate".as_ref(),
                folder.as_os_str(),
                "--labels".as_ref(),
                file.as_os_str(),
            ],
            &out,
            Some(&cache),
        );
        let o = coseg(&args);
        let (_, stderr) = text(&o);
        assert_eq!(
            verdict(what, name, &o),
            Verdict::Refused,
            "{what}: {stderr}"
        );
        assert!(
            stderr.contains(&file.display().to_string()),
            "{what}: {stderr}"
        );
        for e in expected {
            assert!(
                stderr.contains(e.as_str()),
                "{what}: expected {e:?} in\n{stderr}"
            );
        }
        let written: Vec<_> = std::fs::read_dir(&out)
            .map(|r| r.map(|e| e.unwrap().file_name()).collect())
            .unwrap_or_default();
        assert!(
            written.iter().all(|n| n == ".cache"),
            "{what}: wrote {written:?}"
        );
    }
    // A labels folder of which no file matches a mesh: refused, naming the folder.
    let stray = dir.join("stray");
    std::fs::create_dir_all(&stray).unwrap();
    std::fs::write(stray.join("chair.labels.txt"), "1\n").unwrap();
    let args = args_into(
        &[
            "propagate".as_ref(),
            folder.as_ref(),
            "--labels".as_ref(),
            stray.as_os_str(),
        ],
        &dir.join("out_stray"),
        Some(&cache),
    );
    let o = coseg(&args);
    let (_, stderr) = text(&o);
    assert_eq!(verdict("stray folder", "stray", &o), Verdict::Refused);
    assert!(
        stderr.contains(&stray.display().to_string()) && stderr.contains("matches a mesh"),
        "{stderr}"
    );
}

/// Regression (#42): a mesh with 20 triangles collinear up to rounding ("zero-area" in the
/// file, not exactly in floating point) and duplicated triangles was dropped from every
/// collection: `eigensolver failed: Cholesky of L − σM (σ = −10): NonPositivePivot`, because
/// the noise cotangents of those triangles made `L` indefinite. Now the Laplacian treats them
/// as zero-area, with a warning naming the file, and the shape runs through the default
/// `coseg segment` and `coseg propagate` (a shipped humanoid's labels onto it).
#[test]
fn cholesky_failing_on_collinear_slivers_no_longer_drops_the_shape() {
    let dir = scratch("collinear_slivers");
    let shapes = dir.join("shapes");
    std::fs::create_dir_all(&shapes).unwrap();
    let humanoids = collections_dir().join("humanoids");
    for i in 0..2 {
        let name = format!("humanoids_0{i}.obj");
        std::fs::copy(humanoids.join(&name), shapes.join(&name)).unwrap();
    }
    let base = read_mesh(humanoids.join("humanoids_03.obj")).unwrap();
    let (p, f) = with_collinear_slivers((base.positions().to_vec(), base.faces().to_vec()), 20);
    let sliver = shapes.join("slivers.off");
    write_mesh(&sliver, &TriMesh::new(p, f).unwrap(), &[]).unwrap();
    let warned = |stderr: &str| {
        stderr.lines().any(|l| {
            l.contains("slivers.off") && l.contains("20 triangles are collinear up to rounding")
        })
    };

    let out = dir.join("segment");
    let o = coseg(&[
        "segment".as_ref(),
        shapes.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--no-pictures".as_ref(),
    ]);
    let (_, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(warned(&stderr), "{stderr}");
    assert!(out.join("slivers.regions.txt").is_file(), "{stderr}");

    let labels = dir.join("labels");
    std::fs::create_dir_all(&labels).unwrap();
    std::fs::copy(
        humanoids.join("humanoids_00.labels.txt"),
        labels.join("humanoids_00.labels.txt"),
    )
    .unwrap();
    let out = dir.join("propagate");
    let o = coseg(&[
        "propagate".as_ref(),
        shapes.as_os_str(),
        "--labels".as_ref(),
        labels.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    let (_, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(warned(&stderr), "{stderr}");
    check_propagated(&out, &shapes, &[0, 1, 2, 3, 4, 5]);
    assert_no_nan(&out);
}
