//! Label propagation (`coseg::propagate`) on synthetic band tables, and `coseg propagate`
//! end to end on the shipped `collections/goblets`.

mod common;

use common::cli::{arg, coseg};
use common::generate::collections_dir;
use coseg::bands::{BandTable, equal_count_bands};
use coseg::evaluate::{read_labels, vertex_label_agreement};
use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
use coseg::mesh::read_mesh;
use coseg::propagate::{PropagateError, PropagateOptions, propagate_labels};
use std::path::{Path, PathBuf};

/// `count` shapes of `d` vertices whose features are those of one base shape, vertex order
/// rotated by `i · shift` on shape `i` (vertex `v` of shape `i` is base vertex
/// `(v + i·shift) mod d`): the ground-truth map is known.
fn rotated_tables(count: usize, d: usize, shift: usize) -> Vec<BandTable> {
    let features = 12;
    let base: Vec<Vec<f64>> = (0..features)
        .map(|f| {
            (0..d)
                .map(|v| {
                    let x = v as f64 / d as f64;
                    (x + 0.05 * f as f64).powf(1.0 + f as f64 / 4.0)
                        + 0.1 * (std::f64::consts::PI * x * (1.0 + f as f64 / 6.0)).sin()
                })
                .collect()
        })
        .collect();
    (0..count)
        .map(|i| {
            let mut vals = vec![0.0; d * features];
            for v in 0..d {
                let b = (v + i * shift) % d;
                for f in 0..features {
                    vals[f * d + v] = base[f][b];
                }
            }
            equal_count_bands(&vals, features, d, 8).unwrap()
        })
        .collect()
}

fn graph_of(tables: Vec<BandTable>) -> ShapeGraph {
    let d = tables[0].vertices;
    let nodes = tables
        .into_iter()
        .enumerate()
        .map(|(i, t)| ShapeNode::new(format!("s{i}"), t, &vec![1.0; d]).unwrap())
        .collect();
    ShapeGraph::build(nodes, &GraphOptions::default()).unwrap()
}

/// Base-vertex parts: three intervals of the base shape, read on shape `i`.
fn truth(i: usize, d: usize, shift: usize) -> Vec<i32> {
    (0..d)
        .map(|v| {
            let b = (v + i * shift) % d;
            (3 * b / d) as i32 + 10
        })
        .collect()
}

#[test]
fn identical_shapes_receive_the_annotation_exactly() {
    let d = 90;
    let g = graph_of(rotated_tables(4, d, 0));
    let ann = vec![Some(truth(0, d, 0)), None, None, None];
    let p = propagate_labels(&g, None, &ann, &PropagateOptions::default()).unwrap();
    assert_eq!(p.parts, vec![10, 11, 12]);
    // Bands of 90 / 8 vertices straddle the part boundaries (at 30 and 60), so only vertices
    // a band away from a boundary are certain.
    let t = truth(0, d, 0);
    for i in 1..4 {
        for v in (0..d).filter(|v| [30usize, 60].iter().all(|b| v.abs_diff(*b) > 12)) {
            assert_eq!(p.labels[i][v], t[v], "shape {i} vertex {v}");
        }
    }
    assert!(p.converged);
    assert!(p.sources[0] && !p.sources[1]);
}

#[test]
fn labels_follow_the_correspondence_on_permuted_shapes() {
    let (d, shift) = (120, 17);
    let g = graph_of(rotated_tables(5, d, shift));
    let ann: Vec<Option<Vec<i32>>> = (0..5)
        .map(|i| (i == 0).then(|| truth(0, d, shift)))
        .collect();
    let p = propagate_labels(&g, None, &ann, &PropagateOptions::default()).unwrap();
    for i in 1..5 {
        let t = truth(i, d, shift);
        let right = (0..d).filter(|&v| p.labels[i][v] == t[v]).count();
        // Measured 100 of 120 on shape 1 with the default size prior (0.25); a labelling that
        // ignored the correspondence would get about a third.
        assert!(right as f64 >= 0.8 * d as f64, "shape {i}: {right} of {d}");
    }
}

#[test]
fn partial_annotations_keep_their_labels_and_fill_the_rest() {
    let d = 90;
    let g = graph_of(rotated_tables(3, d, 0));
    let full = truth(0, d, 0);
    let partial: Vec<i32> = full
        .iter()
        .enumerate()
        .map(|(v, &l)| if v % 3 == 0 { l } else { -1 })
        .collect();
    let p = propagate_labels(
        &g,
        None,
        &[Some(partial.clone()), None, None],
        &PropagateOptions::default(),
    )
    .unwrap();
    for (v, &l) in partial.iter().enumerate() {
        if l >= 0 {
            assert_eq!(p.labels[0][v], l);
            assert_eq!(p.confidence[0][v], 1.0);
        }
        assert!(p.labels[0][v] >= 0);
    }
    let right = (0..d).filter(|&v| p.labels[1][v] == full[v]).count();
    assert!(right as f64 >= 0.9 * d as f64, "{right}");
}

#[test]
fn propagation_is_deterministic_and_confidences_are_in_range() {
    let (d, shift) = (100, 7);
    let g = graph_of(rotated_tables(4, d, shift));
    let ann = vec![Some(truth(0, d, shift)), None, None, None];
    let o = PropagateOptions::default();
    let a = propagate_labels(&g, None, &ann, &o).unwrap();
    let b = propagate_labels(&g, None, &ann, &o).unwrap();
    assert_eq!(a, b);
    for i in 0..4 {
        assert!(a.confidence[i].iter().all(|c| (0.0..=1.0).contains(c)));
        let s: f64 = a.part_shares[i].iter().sum();
        assert!((s - 1.0).abs() < 1e-9);
    }
}

#[test]
fn incremental_update_reuses_votes_and_fixes_the_new_source() {
    let (d, shift) = (100, 9);
    let g = graph_of(rotated_tables(5, d, shift));
    let o = PropagateOptions::default();
    let ann: Vec<Option<Vec<i32>>> = (0..5)
        .map(|i| (i == 0).then(|| truth(0, d, shift)))
        .collect();
    let mut p = propagate_labels(&g, None, &ann, &o).unwrap();
    let stats = p.update(&g, None, 3, Some(truth(3, d, shift)), &o).unwrap();
    assert!(p.sources[3]);
    assert_eq!(p.labels[3], truth(3, d, shift));
    // Only the new source's votes and the votes of shapes that changed are recomputed: fewer
    // transports than a fresh run's first pass (4 targets × sources and neighbours × 3 parts).
    assert!(stats.transports < 4 * 4 * 3, "{stats:?}");
    // The quick update (default): one pass, each of the three unlabelled shapes re-assigned
    // once, and at least the new source's votes on them (3 targets × 3 parts) computed.
    assert_eq!(stats.shape_updates, 3, "{stats:?}");
    assert!(stats.transports >= 3 * 3, "{stats:?}");
    // With relays updated the sweeps run to the fixed point: at least as many re-scorings.
    let mut full = o.clone();
    full.update_relays = true;
    let mut q = propagate_labels(&g, None, &ann, &o).unwrap();
    let s2 = q
        .update(&g, None, 3, Some(truth(3, d, shift)), &full)
        .unwrap();
    assert!(s2.shape_updates >= 3, "{s2:?}");
    assert_eq!(q.labels[3], truth(3, d, shift));
    // Removing it again leaves a valid propagation from shape 0 alone.
    p.update(&g, None, 3, None, &o).unwrap();
    assert!(!p.sources[3]);
}

#[test]
fn bad_annotations_are_reported() {
    let d = 60;
    let g = graph_of(rotated_tables(2, d, 0));
    let o = PropagateOptions::default();
    let e = propagate_labels(&g, None, &[None, None], &o).unwrap_err();
    assert!(matches!(e, PropagateError::NoLabels), "{e}");
    let e = propagate_labels(&g, None, &[Some(vec![-1; d]), None], &o).unwrap_err();
    assert!(matches!(e, PropagateError::NoLabels), "{e}");
    let e = propagate_labels(&g, None, &[Some(vec![0; 3]), None], &o)
        .unwrap_err()
        .to_string();
    assert!(e.contains("s0") && e.contains("3 labels"), "{e}");
    let mut bad = PropagateOptions::default();
    bad.size_prior = 2.0;
    assert!(propagate_labels(&g, None, &[Some(vec![0; d]), None], &bad).is_err());
    let mut p = propagate_labels(&g, None, &[Some(vec![0; d]), None], &o).unwrap();
    let e = p
        .update(&g, None, 1, Some(vec![5; d]), &o)
        .unwrap_err()
        .to_string();
    assert!(e.contains("label 5"), "{e}");
}

/// `coseg propagate collections/goblets --labels goblets_00.labels.txt`: per-vertex accuracy
/// over the five other goblets, measured 0.746 (`eval_propagate labelled collections/goblets`,
/// per shape 0.766, 0.671, 0.780, 0.885, 0.627); the floor sits a little below.
const GOBLET_FLOOR: f64 = 0.72;

/// `coseg propagate collections/chairs --labels chairs_00.labels.txt --features
/// spectral,extrinsic --up y`: per-vertex accuracy over the five other chairs (eight parts,
/// left and right legs apart), measured 0.691 (`eval_propagate labelled collections/chairs
/// --features spectral,extrinsic --area-weighted false`; spectral alone gives 0.28 on average, it cannot tell the
/// mirror-image legs apart); the floor sits a little below.
const CHAIR_FLOOR: f64 = 0.66;

/// `coseg propagate FOLDER --labels LABELS -o OUT --cache CACHE EXTRA`.
fn propagate_cli(
    folder: &Path,
    labels: &Path,
    out: &Path,
    cache: &Path,
    extra: &[&str],
) -> std::process::Output {
    let mut args = vec!["propagate", arg(folder), "--labels", arg(labels)];
    args.extend(["-o", arg(out), "--cache", arg(cache)]);
    args.extend(extra);
    coseg(&args)
}

#[test]
fn coseg_propagate_on_the_shipped_chairs_with_the_extrinsic_family() {
    let dir = collections_dir().join("chairs");
    let out = std::env::temp_dir().join(format!("coseg-propagate-chairs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let src = dir.join("chairs_00.labels.txt");
    let extra = [
        "--features",
        "spectral,extrinsic",
        "--up",
        "y",
        "--no-pictures",
    ];
    let r = propagate_cli(&dir, &src, &out.join("a"), &out.join("cache"), &extra);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let mut accs = Vec::new();
    for i in 1..6 {
        let name = format!("chairs_0{i}");
        let mesh = read_mesh(dir.join(format!("{name}.obj"))).unwrap();
        let truth = read_labels(dir.join(format!("{name}.labels.txt"))).unwrap();
        let got = read_labels(out.join("a").join(format!("{name}.labels.txt"))).unwrap();
        accs.push(
            vertex_label_agreement(&mesh, &truth, &got)
                .unwrap()
                .accuracy,
        );
    }
    let mean = accs.iter().sum::<f64>() / accs.len() as f64;
    println!(
        "chairs from chairs_00 (spectral + extrinsic): per-vertex accuracy {accs:?}, mean {mean:.4}"
    );
    assert!(mean >= CHAIR_FLOOR, "mean accuracy {mean}");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn coseg_propagate_on_the_shipped_goblets() {
    let dir = collections_dir().join("goblets");
    let out = std::env::temp_dir().join(format!("coseg-propagate-e2e-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let src = dir.join("goblets_00.labels.txt");
    let run = |o: &PathBuf| propagate_cli(&dir, &src, o, &out.join("cache"), &[]);
    let o1 = out.join("a");
    let r = run(&o1);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let mut accs = Vec::new();
    for i in 1..6 {
        let name = format!("goblets_0{i}");
        let mesh = read_mesh(dir.join(format!("{name}.obj"))).unwrap();
        let truth = read_labels(dir.join(format!("{name}.labels.txt"))).unwrap();
        let got = read_labels(o1.join(format!("{name}.labels.txt"))).unwrap();
        assert_eq!(got.len(), mesh.vertex_count());
        let seg = read_labels(o1.join(format!("{name}.seg"))).unwrap();
        assert_eq!(seg.len(), mesh.face_count());
        assert!(o1.join(format!("{name}.labels.ply")).is_file());
        accs.push(
            vertex_label_agreement(&mesh, &truth, &got)
                .unwrap()
                .accuracy,
        );
    }
    let mean = accs.iter().sum::<f64>() / accs.len() as f64;
    println!("goblets from goblets_00: per-vertex accuracy {accs:?}, mean {mean:.4}");
    assert!(mean >= GOBLET_FLOOR, "mean accuracy {mean}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(o1.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["sources"], serde_json::json!(["goblets_00"]));
    assert_eq!(summary["shapes"].as_array().unwrap().len(), 6);
    // The parts route's part tree is kept in the cache as `coseg segment` keeps it, and the
    // rerun reads it instead of growing it again: the same bytes below.
    let trees = std::fs::read_dir(out.join("cache"))
        .unwrap()
        .filter(|e| {
            let p = e.as_ref().unwrap().path();
            p.extension()
                .is_some_and(|x| x == coseg::cache::PART_TREE_EXTENSION)
        })
        .count();
    assert_eq!(trees, 1, "one part-tree entry in the cache");
    // A rerun writes the same bytes.
    let o2 = out.join("b");
    assert!(run(&o2).status.success());
    for f in [
        "summary.json",
        "goblets_03.labels.txt",
        "goblets_03.seg",
        "goblets_03.labels.ply",
    ] {
        assert_eq!(
            std::fs::read(o1.join(f)).unwrap(),
            std::fs::read(o2.join(f)).unwrap(),
            "{f} differs on rerun"
        );
    }
    // A label file for no mesh is an error naming it.
    let bad = out.join("nomesh.labels.txt");
    std::fs::write(&bad, "0\n").unwrap();
    let r = propagate_cli(&dir, &bad, &out.join("c"), &out.join("cache"), &[]);
    assert!(!r.status.success());
    assert!(String::from_utf8_lossy(&r.stderr).contains("nomesh.labels.txt"));
    std::fs::remove_dir_all(&out).unwrap();
}

/// Uneven sampling: on the source, part 0 is 10 large vertices in band 0 plus 30 tiny ones in
/// band 1 (a densely meshed patch), part 1 is 4 large vertices in band 0 and 6 in band 1.
/// By vertex count part 0 lies mostly in band 1 (30 / 40) and part 1 mostly in band 0
/// (4 / 10 beats 10 / 40); by area part 0 lies in band 0 (10 / 10.3) and part 1 in band 1.
/// The target has one vertex per band: its labels flip with `area_weighted`.
#[test]
fn area_weighted_votes_follow_the_parts_area_not_their_vertex_count() {
    let mut src_labels = Vec::new();
    let (mut bands, mut areas) = (Vec::new(), Vec::new());
    let mut push = |count: usize, band: u8, area: f64, part: i32| {
        for _ in 0..count {
            bands.push(band);
            areas.push(area);
            src_labels.push(part);
        }
    };
    push(10, 0, 1.0, 0);
    push(30, 1, 0.01, 0);
    push(4, 0, 1.0, 1);
    push(6, 1, 1.0, 1);
    let d = bands.len();
    let source = BandTable {
        features: 1,
        vertices: d,
        bands: 2,
        labels: bands,
    };
    let target = BandTable {
        features: 1,
        vertices: 2,
        bands: 2,
        labels: vec![0, 1],
    };
    let nodes = vec![
        ShapeNode::new("src", source, &areas).unwrap(),
        ShapeNode::new("dst", target, &[1.0, 1.0]).unwrap(),
    ];
    let g = ShapeGraph::build(nodes, &GraphOptions::default()).unwrap();
    let ann = vec![Some(src_labels), None];
    let mut o = PropagateOptions::default();
    o.size_prior = 0.0;
    o.area_weighted = false;
    let p = propagate_labels(&g, None, &ann, &o).unwrap();
    assert_eq!(p.labels[1], vec![1, 0]);
    o.area_weighted = true;
    let p = propagate_labels(&g, None, &ann, &o).unwrap();
    assert_eq!(p.labels[1], vec![0, 1]);
}

/// Two kinds of shape that share most features (so each source's transport reaches both
/// kinds strongly) but label their parts in opposite conventions; the last two features tell
/// the kinds apart (anti-correlated with the others on kind B), so their summaries differ.
/// Shapes: A (source), B and B (sources), A (target).
fn two_kinds(d: usize) -> (ShapeGraph, Vec<i32>, Vec<i32>) {
    let features = 12;
    let table = |kind_b: bool| {
        let mut vals = vec![0.0; d * features];
        for f in 0..features {
            for v in 0..d {
                let x = v as f64 / d as f64;
                let y = (x + 0.05 * f as f64).powf(1.0 + f as f64 / 8.0);
                vals[f * d + v] = if kind_b && f >= 10 { -y } else { y };
            }
        }
        equal_count_bands(&vals, features, d, 8).unwrap()
    };
    let tables = vec![table(false), table(true), table(true), table(false)];
    let a: Vec<i32> = (0..d).map(|v| if 2 * v < d { 10 } else { 11 }).collect();
    let b: Vec<i32> = a.iter().map(|&l| 21 - l).collect();
    (graph_of(tables), a, b)
}

/// Several sources vote on every shape; a source like the target (small summary distance)
/// must outweigh unlike ones, even outnumbered: the kind-A target follows the one kind-A
/// source's convention, not the two kind-B sources'. With every source counting alike (the
/// default) the two B votes win.
#[test]
fn sources_like_the_target_outweigh_unlike_ones() {
    let d = 80;
    let (g, a, b) = two_kinds(d);
    assert!(g.summary_distance(0, 3) < 1e-12 && g.summary_distance(1, 2) < 1e-12);
    assert!(g.summary_distance(0, 1) > 0.1);
    let ann = vec![Some(a.clone()), Some(b.clone()), Some(b), None];
    let right =
        |p: &coseg::propagate::Propagation| (0..d).filter(|&v| p.labels[3][v] == a[v]).count();
    let flat = PropagateOptions::default();
    assert_eq!(flat.similarity_power, 0.0);
    let mut o = flat.clone();
    o.similarity_power = 4.0;
    let p = propagate_labels(&g, None, &ann, &o).unwrap();
    let q = propagate_labels(&g, None, &ann, &flat).unwrap();
    let (r, rq) = (right(&p), right(&q));
    eprintln!(
        "similarity power {}: {r}; 0: {rq} of {d}",
        o.similarity_power
    );
    assert!(r >= d - 4, "{r} of {d}");
    assert!(rq < d / 2, "without similarity weights: {rq} of {d}");
}

/// Three parts of the asymmetric blob by its x coordinate, and the same parts with the
/// strip `0.35 ≤ x < 0.6` given part 1 instead of 2 (a misplaced boundary, as a propagation
/// leaves one).
fn blob_parts(mesh: &coseg::mesh::TriMesh) -> (Vec<i32>, Vec<i32>) {
    let part = |x: f64| {
        if x < -0.4 {
            0
        } else if x < 0.35 {
            1
        } else {
            2
        }
    };
    let truth: Vec<i32> = mesh.positions().iter().map(|p| part(p[0])).collect();
    let rough = mesh
        .positions()
        .iter()
        .map(|p| {
            if (0.35..0.6).contains(&p[0]) {
                1
            } else {
                part(p[0])
            }
        })
        .collect();
    (truth, rough)
}

/// The map step on an exact isometry: the target is the source blob with its vertices
/// permuted and a misplaced boundary. The map carries the source's parts back, so the strip
/// is corrected and at least 99 % of the area agrees with the truth; the report says the map
/// was kept. With `min_agreement = 1` the same map is rejected and the rough labels come back
/// unchanged, bit for bit; bad options are errors.
#[test]
fn map_step_corrects_a_misplaced_boundary_on_an_isometric_copy() {
    use common::features::{blob, permutation, permute_mesh};
    use coseg::maps::MapShape;
    use coseg::propagate::{MapStepOptions, map_step};
    use coseg::spectral::{SpectrumOptions, laplace_beltrami_spectrum};
    let mesh = blob(3);
    let n = mesh.vertex_count();
    let perm = permutation(n, 5);
    let copy = permute_mesh(&mesh, &perm);
    let (truth, _) = blob_parts(&mesh);
    let (truth_copy, rough) = blob_parts(&copy);
    let mut so = SpectrumOptions::default();
    so.eigenpairs = 40;
    let (sa, sb) = (
        laplace_beltrami_spectrum(&mesh, &so).unwrap(),
        laplace_beltrami_spectrum(&copy, &so).unwrap(),
    );
    let source = MapShape {
        spectrum: &sa,
        positions: mesh.positions(),
        labels: &truth,
        descriptors: None,
    };
    let target = MapShape {
        spectrum: &sb,
        positions: copy.positions(),
        labels: &rough,
        descriptors: None,
    };
    let areas = copy.vertex_areas();
    let accuracy = |l: &[i32]| {
        vertex_label_agreement(&copy, &truth_copy, l)
            .unwrap()
            .accuracy
    };
    let before = accuracy(&rough);
    assert!(before < 0.95, "the strip must matter: {before}");
    let o = MapStepOptions::default();
    let (labels, report) = map_step(&source, &target, &areas, 7, &o).unwrap();
    assert!(report.applied && report.source == 7, "{report:?}");
    assert!(
        (report.agreement - before).abs() < 0.02,
        "{report:?} vs {before}"
    );
    let after = accuracy(&labels);
    assert!(
        after >= 0.99,
        "after the map step {after} (before {before})"
    );
    // Deterministic.
    assert_eq!(map_step(&source, &target, &areas, 7, &o).unwrap().0, labels);
    let mut strict = MapStepOptions::default();
    strict.min_agreement = 1.0;
    let (kept, report) = map_step(&source, &target, &areas, 7, &strict).unwrap();
    assert!(!report.applied);
    assert_eq!(kept, rough);
    strict.min_agreement = 1.5;
    assert!(map_step(&source, &target, &areas, 7, &strict).is_err());
    assert!(map_step(&source, &target, &areas[1..], 7, &o).is_err());
}

/// `coseg propagate --map-step` end to end, the real binary on a folder of the blob and two
/// permuted copies (exact isometries; the propagation alone already labels them well, so this
/// checks the plumbing, and the test above the map itself): every copy's map is kept and
/// recorded in `summary.json` with its source, the labels reach ≥ 99 % of the truth, and
/// without the flag the summary has no map-step field (the default output is unchanged).
#[test]
fn coseg_propagate_map_step_on_isometric_copies() {
    use common::features::labelled_blob_and_copies;
    let dir = tempfile::tempdir().unwrap();
    let (shapes, _, copies) = labelled_blob_and_copies(dir.path(), |m| blob_parts(m).0);
    let copies: Vec<_> = copies
        .into_iter()
        .enumerate()
        .map(|(k, copy)| {
            let truth_copy = blob_parts(&copy).0;
            (format!("c{}", k + 1), copy, truth_copy)
        })
        .collect();
    let run = |out: &std::path::Path, map: bool| {
        let mut extra = vec!["--eigenpairs", "40", "--no-pictures"];
        if map {
            extra.push("--map-step");
        }
        let (labels, cache) = (dir.path().join("a.labels.txt"), dir.path().join("cache"));
        let r = propagate_cli(&shapes, &labels, out, &cache, &extra);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        serde_json::from_str::<serde_json::Value>(
            &std::fs::read_to_string(out.join("summary.json")).unwrap(),
        )
        .unwrap()
    };
    let with = dir.path().join("with");
    let summary = run(&with, true);
    assert_eq!(summary["map_step"]["min_agreement"], serde_json::json!(0.8));
    for (name, copy, truth_copy) in &copies {
        let shape = summary["shapes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["name"] == serde_json::json!(name))
            .unwrap();
        assert_eq!(
            shape["map_step"]["applied"],
            serde_json::json!(true),
            "{shape}"
        );
        assert_eq!(shape["map_source"], serde_json::json!("a"));
        let got = read_labels(with.join(format!("{name}.labels.txt"))).unwrap();
        let acc = vertex_label_agreement(copy, truth_copy, &got)
            .unwrap()
            .accuracy;
        assert!(acc >= 0.99, "{name}: {acc}");
    }
    let without = run(&dir.path().join("without"), false);
    assert!(without.get("map_step").is_none());
    assert!(without["shapes"][1].get("map_step").is_none());
}

/// With `RouteOptions::chosen_features` the band affinity reads the feature families the
/// collection chose: on the shipped chairs, whose labels set the left legs apart from the
/// right ones, the intrinsic family alone cannot tell a leg from its mirror image, while the
/// extrinsic family in the collection frame (chosen from the data, no `--features` or `--up`
/// given) can. The affinity route alone, from `chairs_00`, per-vertex accuracy over the five
/// other chairs (their own eight labels): measured 0.814 with the chosen families (418
/// columns) and 0.438 without (300), by this test in the release profile.
#[test]
fn affinity_route_reads_the_families_the_collection_chose() {
    use coseg::propagate::{PropagateCollectionOptions, Route, RouteOptions, propagate_collection};
    let dir = collections_dir().join("chairs");
    let cache = std::env::temp_dir().join(format!("coseg-chosen-families-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&cache);
    let affinity = |chosen: bool| {
        let mut routes = RouteOptions::default();
        // The affinity route is what is compared: the others are left out to keep it quick.
        routes.rigid = false;
        routes.map = false;
        routes.chosen_features = chosen;
        let mut options = PropagateCollectionOptions::default();
        options.routes = routes;
        options.cache_dir = Some(cache.clone());
        let out = propagate_collection(&dir, &[dir.join("chairs_00.labels.txt")], &options)
            .expect("propagates");
        let features = out.graph.node(0).bands.features;
        let (_, labels) = out
            .fusion
            .routes
            .iter()
            .find(|(r, _)| *r == Route::Affinity)
            .expect("the affinity route");
        let mut sum = 0.0;
        for i in 1..6 {
            let name = format!("chairs_0{i}");
            let mesh = read_mesh(dir.join(format!("{name}.obj"))).unwrap();
            let truth = read_labels(dir.join(format!("{name}.labels.txt"))).unwrap();
            let k = (0..out.graph.node_count())
                .find(|&k| out.graph.node(k).name == name)
                .expect("a node per chair");
            sum += vertex_label_agreement(&mesh, &truth, &labels.labels[k])
                .unwrap()
                .accuracy;
        }
        (features, sum / 5.0)
    };
    let (with_features, with) = affinity(true);
    let (without_features, without) = affinity(false);
    println!(
        "affinity route from chairs_00: {with:.4} with the chosen families ({with_features} columns), {without:.4} without ({without_features})"
    );
    assert!(
        with_features > without_features,
        "the chosen families add the extrinsic columns"
    );
    assert!(with > without + 0.05, "{with} against {without}");
    let _ = std::fs::remove_dir_all(&cache);
}
