//! Quality of label propagation against ground truth (docs/PROPAGATION.md has the tables).
//!
//! ```text
//! # COSEG chairs: every chair as the one source, then seeded random triples of sources.
//! cargo run --release --example eval_propagate -- chairs ../shared/data/coseg_chairs [--triples 10] [--seed 0]
//! # Near-isometric classes (identity ground truth): a part decomposition of the first shape
//! # (K farthest-point Voronoi cells, --parts K, or with --parts-from features K clusters of
//! # its own band table, its segmentation in feature space) carried to the others.
//! # With --map-step: then the library's map step (coseg propagate --map-step) on every target.
//! cargo run --release --example eval_propagate -- identity [--parts 6] [--map-step] MESH...
//! # Timing (warm cache): propagate from the first mesh, update adding the second.
//! cargo run --release --example eval_propagate -- bench [--seg DIR] [--reps 3] MESH...
//! # A shipped collection (per-vertex `<stem>.labels.txt` beside the meshes), as `chairs`.
//! cargo run --release --example eval_propagate -- labelled collections/goblets
//! ```
//! Common options: `--sources A,B` (chairs: only these single sources), `--triple A,B,C` (only
//! this set of sources), `--per-target` (accuracy, confusion and label counts of every target
//! on stderr), `--cache DIR` (default /tmp/coseg-eval-cache), `--routes all|affinity` (the
//! library's default fusion of every route, or the band affinity alone; with `all` each route
//! alone is printed beside the fusion), `--snap-band B`, `--affine true|false` (the rigid
//! route's affine relaxation), `--nonrigid true|false` (its non-rigid step), `--classifier
//! true|false` (the classifier refinement, off by default; `--round-trip true|false` the
//! parts route's round trip in the fusion, off by default; with it on the fused labels before
//! it are printed as "fused before classifier"), `--size-prior A`,
//! `--network-weight W`, `--similarity-power P`, `--smoothing-time T`, `--neighbours K`, `--complete-limit N`,
//! `--part-score affinity|geometric`, `--area-weighted true|false`, `--refit-rounds N`,
//! `--refit-weight B`, `--update-relays true|false`;
//! the per-shape pipeline as `coseg propagate` takes it: `--features spectral,extrinsic,sdf`,
//! `--up y|pca|…`, `--directions N`, `--normals N` (extrinsic normal columns), `--family-weights extrinsic=2`, `--bands K`,
//! `--area-bands`, `--eigenpairs N`, `--laplacian cotan|intrinsic-delaunay`. Chairs only: `--gt-swap STEMS:A=B` exchanges labels `A`
//! and `B` of the ground truth of the listed shapes (annotations and scoring alike), e.g.
//! `--gt-swap 101,102,103,109,110:1=3` (docs/PROPAGATION.md: those five files label the back
//! 3 and the legs 1, the other seventeen the reverse).
//! `--route rigid`: instead of `coseg propagate`, the rigid baseline on the same sources and
//! targets: each target registered onto a source by `coseg::align::register_pair` (similarity,
//! any pose) and every target vertex given the label of the nearest source surface point
//! (`coseg::align::nearest_point_vertex_labels`, from the per-vertex annotation); from several
//! sources, each target from its best-registered source (lowest residual).
//! `labelled` scores grouped parts (the manifest's `part_groups`, as `coseg::evaluate` does).
//! With the environment variable `COSEG_DIAG` set, every run prints on stderr, per target,
//! each route's accuracy and its weight in the fusion, the fused accuracy and the area shares
//! of the routes' agreement patterns (all three agree, only affinity and parts, only affinity
//! and rigid, only parts and rigid, none), and with several sources each route's held-out
//! accuracy on the sources. With `COSEG_DUMP=DIR`, every run writes every route's labels and
//! confidences on every target and the held-out runs to `DIR/run-<sources>.json` (the shapes'
//! areas and per-vertex ground truth to `DIR/shapes.json`), for replaying fusion rules offline
//! (`examples/replay_fusion.rs` replays the library's fusion on them); each run also gets the
//! co-segmentation's part ids of every shape and whether the parts read the intrinsic family
//! alone, and with `COSEG_DUMP_POSES` set each target gets every source's registration
//! candidates (residual, angle, the labels carried by the similarity and by its affine
//! relaxation; a registration and an affine fit per pose, so off by default).
//! Accuracy is area-weighted: per face against `.seg` files for the chairs, per vertex for
//! the identity sets; the source shapes are left out of every mean.

use coseg::align::{RegisterOptions, Registration, nearest_point_vertex_labels, register_pair};
use coseg::bands::BandWeighting;
use coseg::evaluate::{face_label_agreement, vertex_label_agreement};
use coseg::features::{parse_alignment, parse_families, parse_family_weights};
use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
use coseg::labels::{faces_to_vertices, read_label_file};
use coseg::mesh::{TriMesh, read_mesh};
use coseg::pipeline::{ShapePipelineOptions, load_or_compute_bands};
use coseg::propagate::{
    CollectionParts, PartScore, PropagateOptions, RouteOptions, fuse_propagation, propagate_labels,
};
use coseg::spectral::HeatSmoother;
use rand::SeedableRng;
use rand::seq::SliceRandom;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

struct Set {
    names: Vec<String>,
    meshes: Vec<TriMesh>,
    graph: ShapeGraph,
    smoothers: Option<Vec<HeatSmoother>>,
    /// `--route rigid`: registrations `(source, target)` computed so far.
    rigid: Option<Mutex<HashMap<(usize, usize), Registration>>>,
    /// The routes fused with the band affinity (`--routes affinity`: none) and the
    /// collection's co-segmentations, made once per number of parts.
    routes: RouteOptions,
    parts: Mutex<CollectionParts>,
    /// Per route (and "fused"), the mean accuracy of every run, in run order.
    route_log: Mutex<BTreeMap<String, Vec<(usize, f64)>>>,
    /// `COSEG_DUMP`: registrations `(source, target)` of every candidate pose, computed so far.
    dump_regs: Mutex<HashMap<(usize, usize), Registration>>,
    /// The per-shape pipeline and cache the shapes were loaded with (the map route reads the
    /// spectra from them).
    pipeline: ShapePipelineOptions,
    cache: PathBuf,
}

fn load(
    files: &[PathBuf],
    cache: &std::path::Path,
    pipeline: &ShapePipelineOptions,
    graph: &GraphOptions,
    time: f64,
    routes: &RouteOptions,
) -> Result<Set, Box<dyn std::error::Error>> {
    let t = Instant::now();
    let loaded: Vec<(String, TriMesh, ShapeNode)> = files
        .par_iter()
        .map(|f| {
            let mesh = read_mesh(f).map_err(|e| e.to_string())?;
            let b = load_or_compute_bands(&mesh, pipeline, cache)
                .map_err(|e| format!("{}: {e}", f.display()))?;
            let name = f.file_stem().unwrap().to_string_lossy().into_owned();
            let node = ShapeNode::new(name.clone(), b.data.bands, &b.data.vertex_areas)
                .map_err(|e| e.to_string())?;
            Ok::<_, String>((name, mesh, node))
        })
        .collect::<Result<_, _>>()?;
    let (mut names, mut meshes, mut nodes) = (Vec::new(), Vec::new(), Vec::new());
    for (n, m, node) in loaded {
        names.push(n);
        meshes.push(m);
        nodes.push(node);
    }
    let features = nodes.first().map_or(0, |n| n.bands.features);
    let mut parts = CollectionParts::new(nodes.clone(), pipeline, graph, Some(cache.to_path_buf()));
    let smoothers = if time > 0.0 {
        Some(
            meshes
                .par_iter()
                .map(|m| HeatSmoother::new(m, time))
                .collect::<Result<Vec<_>, _>>()?,
        )
    } else {
        None
    };
    // As `propagate_loaded`: the band affinity reads the families the collection chose.
    let chosen = match routes.parts && routes.chosen_features {
        true => parts.chosen_graph(&meshes, smoothers.as_deref())?,
        false => None,
    };
    let graph = match chosen {
        Some(g) => g,
        None => {
            let mut graph = ShapeGraph::build(nodes, graph)?;
            graph.set_feature_weights(pipeline.feature_weights(features))?;
            graph
        }
    };
    eprintln!(
        "loaded {} shapes ({:?} graph) in {:.1} s",
        names.len(),
        graph.kind(),
        t.elapsed().as_secs_f64()
    );
    Ok(Set {
        names,
        meshes,
        graph,
        smoothers,
        rigid: None,
        routes: routes.clone(),
        parts: Mutex::new(parts),
        route_log: Mutex::new(BTreeMap::new()),
        dump_regs: Mutex::new(HashMap::new()),
        pipeline: pipeline.clone(),
        cache: cache.to_path_buf(),
    })
}

/// Propagates from `sources` and returns the accuracy on every other shape.
fn run(
    set: &Set,
    sources: &[usize],
    annotation: &dyn Fn(usize) -> Vec<i32>,
    score: &dyn Fn(usize, &[i32]) -> f64,
    options: &PropagateOptions,
) -> Result<Vec<(usize, f64)>, Box<dyn std::error::Error>> {
    let n = set.names.len();
    if let Some(cache) = &set.rigid {
        return rigid(set, cache, sources, annotation, score);
    }
    let ann: Vec<Option<Vec<i32>>> = (0..n)
        .map(|i| sources.contains(&i).then(|| annotation(i)))
        .collect();
    let mut p = propagate_labels(&set.graph, set.smoothers.as_deref(), &ann, options)?;
    // The library's default: the band affinity fused with the other routes, as
    // `propagate_collection` runs it; each route alone is logged beside it.
    let report = fuse_propagation(
        &set.graph,
        &set.meshes,
        &ann,
        &mut p,
        Some(&mut *set.parts.lock().unwrap()),
        set.smoothers.as_deref(),
        options,
        &set.routes,
    )?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    let targets: Vec<usize> = (0..n).filter(|i| !sources.contains(i)).collect();
    // The map route, as `propagate_loaded` runs it after the fusion.
    if set.routes.map {
        let fused: Vec<f64> = targets.iter().map(|&i| score(i, &p.labels[i])).collect();
        let (maps, warnings) = coseg::propagate::map_route(
            &set.meshes,
            &set.graph,
            &ann,
            &mut p,
            &report,
            &set.pipeline,
            Some(&set.cache),
        );
        for w in &warnings {
            eprintln!("warning: {w}");
        }
        if std::env::var_os("COSEG_DIAG").is_some() {
            for (&i, f) in targets.iter().zip(&fused) {
                if let Some(m) = &maps[i] {
                    eprintln!(
                        "diag {:>12} map route: fused {:.1} -> {:.1} (agreement {:.1} %, {})",
                        set.names[i],
                        100.0 * f,
                        100.0 * score(i, &p.labels[i]),
                        100.0 * m.agreement,
                        if m.applied { "taken" } else { "not taken" }
                    );
                }
            }
        }
    }
    if std::env::var_os("COSEG_DIAG").is_some() {
        if let Some(h) = &report.held_out {
            eprintln!("diag held-out {:?}", h);
        }
        // Per target: each route's accuracy and weight, the fusion's accuracy, and the
        // area shares of the agreement patterns of the first three routes.
        for &i in &targets {
            let mut line = format!("diag {:>12}", set.names[i]);
            for (x, (route, labels)) in report.routes.iter().enumerate() {
                if labels.votes_on(i) {
                    line += &format!(
                        " {}={:.1}/w{:.2}",
                        route.name(),
                        100.0 * score(i, &labels.labels[i]),
                        report.fused.weights[i][x]
                    );
                }
            }
            line += &format!(" fused={:.1}", 100.0 * score(i, &report.fused.labels[i]));
            if report.routes.len() == 3 && (0..3).all(|x| report.routes[x].1.votes_on(i)) {
                let a = &set.graph.node(i).areas;
                let tot: f64 = a.iter().sum();
                let mut f = [0.0; 5];
                for (v, &av) in a.iter().enumerate() {
                    let (x, y, z) = (
                        report.routes[0].1.labels[i][v],
                        report.routes[1].1.labels[i][v],
                        report.routes[2].1.labels[i][v],
                    );
                    let k = if x == y && y == z {
                        0
                    } else if x == y {
                        1
                    } else if x == z {
                        2
                    } else if y == z {
                        3
                    } else {
                        4
                    };
                    f[k] += av / tot;
                }
                line += &format!(
                    " all={:.2} AP={:.2} AR={:.2} PR={:.2} none={:.2}",
                    f[0], f[1], f[2], f[3], f[4]
                );
            }
            eprintln!("{line}");
        }
    }
    if let Some(dir) = std::env::var_os("COSEG_DUMP") {
        dump_run(
            set,
            std::path::Path::new(&dir),
            sources,
            annotation,
            score,
            &report,
            &p,
        )?;
    }
    let mut log = set.route_log.lock().unwrap();
    for (route, labels) in &report.routes {
        let r: Vec<(usize, f64)> = targets
            .iter()
            .filter(|&&i| labels.votes_on(i))
            .map(|&i| (i, score(i, &labels.labels[i])))
            .collect();
        log.entry(route.name().to_string())
            .or_default()
            .push((sources[0], mean(&r)));
    }
    let fused_unsnapped: Vec<(usize, f64)> = targets
        .iter()
        .map(|&i| (i, score(i, &report.fused.labels[i])))
        .collect();
    if let Some(c) = &report.classifier {
        let before: Vec<(usize, f64)> = targets
            .iter()
            .map(|&i| (i, score(i, &c.before[i])))
            .collect();
        log.entry("fused before classifier".into())
            .or_default()
            .push((sources[0], mean(&before)));
        if std::env::var_os("COSEG_DIAG").is_some() {
            eprintln!(
                "diag classifier held-out {:?} weight {:.2}",
                c.held_out, c.weight
            );
            for (&i, b) in targets.iter().zip(&before) {
                if let Some(s) = &c.shapes[i] {
                    eprintln!(
                        "diag {:>12} classifier: {:.1} -> {:.1} (disputed {:.1} %, changed {:.1} %)",
                        set.names[i],
                        100.0 * b.1,
                        100.0 * score(i, &report.fused.labels[i]),
                        100.0 * s.disputed,
                        100.0 * s.changed
                    );
                }
            }
        }
    }
    log.entry("fused, votes' boundaries".into())
        .or_default()
        .push((sources[0], mean(&fused_unsnapped)));
    let r: Vec<(usize, f64)> = targets
        .iter()
        .map(|&i| (i, score(i, &p.labels[i])))
        .collect();
    log.entry("fused (default)".into())
        .or_default()
        .push((sources[0], mean(&r)));
    Ok(r)
}

/// `COSEG_DUMP=DIR`: writes every route's labels and confidences on every target, the
/// held-out runs and the scores to `DIR/run-<sources>.json` (and the shapes' areas and
/// per-vertex ground truth to `DIR/shapes.json` once), for studying fusion rules offline.
fn dump_run(
    set: &Set,
    dir: &std::path::Path,
    sources: &[usize],
    annotation: &dyn Fn(usize) -> Vec<i32>,
    score: &dyn Fn(usize, &[i32]) -> f64,
    report: &coseg::propagate::FusionReport,
    p: &coseg::propagate::Propagation,
) -> Result<(), Box<dyn std::error::Error>> {
    use serde_json::json;
    std::fs::create_dir_all(dir)?;
    let shapes = dir.join("shapes.json");
    if !shapes.exists() {
        let v: Vec<_> = (0..set.names.len())
            .map(|i| {
                json!({"name": set.names[i], "areas": set.graph.node(i).areas, "gt": annotation(i)})
            })
            .collect();
        std::fs::write(&shapes, serde_json::to_string(&v)?)?;
    }
    let r3 = |c: &[f64]| -> Vec<f64> { c.iter().map(|x| (x * 1000.0).round() / 1000.0).collect() };
    // Every registration candidate costs a registration and an affine fit per pose: written
    // only when asked for, so that a dump costs no more than the run it records.
    let poses = std::env::var_os("COSEG_DUMP_POSES").is_some();
    let n = set.names.len();
    let targets: Vec<_> = (0..n)
        .filter(|i| !sources.contains(i))
        .map(|i| {
            let routes: serde_json::Map<String, serde_json::Value> = report
                .routes
                .iter()
                .map(|(r, l)| {
                    (
                        r.name().to_string(),
                        json!({
                            "labels": l.labels[i],
                            "conf": l.confidence[i],
                            "shape_conf": l.shape_confidence[i],
                            "residual": if l.residual[i].is_finite() { l.residual[i] } else { -1.0 },
                            "score": if l.votes_on(i) { score(i, &l.labels[i]) } else { -1.0 },
                        }),
                    )
                })
                .collect();
            json!({
                "shape": i,
                "candidates": if poses { candidates(set, sources, annotation, i) } else { json!([]) },
                "routes": routes,
                "fused_score": score(i, &p.labels[i]),
                "weights": report.fused.weights[i],
            })
        })
        .collect();
    let held = report.held_out_runs.as_ref().map(|h| {
        json!({
            "sources": h.sources,
            "labels": h.labels,
            "conf": h.confidence.iter().map(|c| c.iter().map(|x| r3(x)).collect::<Vec<_>>()).collect::<Vec<_>>(),
            "scores": h.scores,
            "accuracy": h.accuracy,
            "residual": h.residual.iter().map(|r| r.iter().map(|x| if x.is_finite() { *x } else { -1.0 }).collect::<Vec<_>>()).collect::<Vec<_>>(),
        })
    });
    let names: Vec<String> = report
        .routes
        .iter()
        .map(|(r, _)| r.name().to_string())
        .collect();
    let tag: Vec<String> = sources.iter().map(|s| s.to_string()).collect();
    let (parts, intrinsic): (Vec<Vec<i32>>, Option<bool>) = {
        let mut cp = set.parts.lock().unwrap();
        let parts = match cp.parts(p.parts.len(), &set.meshes) {
            Ok(seg) => (0..n).map(|i| seg.labels(i)).collect(),
            Err(_) => Vec::new(),
        };
        (parts, cp.intrinsic_only(p.parts.len()))
    };
    let v = json!({"sources": sources, "routes": names, "targets": targets, "held_out": held,
                   "part_ids": parts, "parts_intrinsic": intrinsic});
    std::fs::write(
        dir.join(format!("run-{}.json", tag.join("-"))),
        serde_json::to_string(&v)?,
    )?;
    Ok(())
}

/// `COSEG_DUMP`: every candidate pose of the registration of target `i` onto each source,
/// with its residual and the labels it carries (similarity, and relaxed to affine as the
/// rigid route does).
fn candidates(
    set: &Set,
    sources: &[usize],
    annotation: &dyn Fn(usize) -> Vec<i32>,
    i: usize,
) -> serde_json::Value {
    use coseg::align::{Similarity, SurfaceIndex};
    use serde_json::json;
    let mut out = Vec::new();
    for &s in sources {
        let cached = set.dump_regs.lock().unwrap().get(&(s, i)).cloned();
        let reg = match cached {
            Some(r) => r,
            None => {
                match register_pair(&set.meshes[s], &set.meshes[i], &RegisterOptions::default()) {
                    Ok(r) => {
                        set.dump_regs.lock().unwrap().insert((s, i), r.clone());
                        r
                    }
                    Err(_) => continue,
                }
            }
        };
        let ann = annotation(s);
        let index = SurfaceIndex::new(&set.meshes[s]);
        let cands: Vec<serde_json::Value> = reg
            .candidates
            .par_iter()
            .map(|c| {
                let sim = nearest_point_vertex_labels(&set.meshes[s], &ann, &set.meshes[i], &c.transform)
                    .map(|x| x.0)
                    .unwrap_or_default();
                let fit = coseg::propagate::refine_affine(&set.meshes[s], &index, &set.meshes[i], &c.transform, 0.9);
                let aff = set.meshes[i]
                    .map_positions(|p| fit.map.apply(p))
                    .ok()
                    .and_then(|m| nearest_point_vertex_labels(&set.meshes[s], &ann, &m, &Similarity::identity()).ok())
                    .map(|x| x.0)
                    .unwrap_or_default();
                json!({"residual": c.residual, "angle": c.angle_to_best, "labels": sim, "affine": aff,
                       "affine_residual": fit.residual, "affine_start": fit.start_residual})
            })
            .collect();
        out.push(json!({"source": s, "inlier_share": reg.inlier_share, "candidates": cands}));
    }
    json!(out)
}

/// Prints each logged route's mean over the runs and its worst run, then clears the log.
fn print_routes(set: &Set, what: &str) {
    let mut log = set.route_log.lock().unwrap();
    for (route, runs) in log.iter() {
        let (w, wv) = worst(runs);
        println!(
            "  {what}, {route}: mean {:.2} %, worst {} ({:.1} %)",
            100.0 * mean(runs),
            set.names[w],
            100.0 * wv
        );
    }
    log.clear();
}

/// The rigid baseline: every target registered onto each source (similarity, any pose), its
/// labels from the best-registered source's nearest surface points.
fn rigid(
    set: &Set,
    cache: &Mutex<HashMap<(usize, usize), Registration>>,
    sources: &[usize],
    annotation: &dyn Fn(usize) -> Vec<i32>,
    score: &dyn Fn(usize, &[i32]) -> f64,
) -> Result<Vec<(usize, f64)>, Box<dyn std::error::Error>> {
    let n = set.names.len();
    let targets: Vec<usize> = (0..n).filter(|i| !sources.contains(i)).collect();
    let pairs: Vec<(usize, usize)> = targets
        .iter()
        .flat_map(|&t| sources.iter().map(move |&s| (s, t)))
        .filter(|k| !cache.lock().unwrap().contains_key(k))
        .collect();
    let o = RegisterOptions::default();
    let new: Vec<((usize, usize), Registration)> = pairs
        .par_iter()
        .map(|&(s, t)| {
            register_pair(&set.meshes[s], &set.meshes[t], &o)
                .map(|r| ((s, t), r))
                .map_err(|e| format!("{} onto {}: {e}", set.names[t], set.names[s]))
        })
        .collect::<Result<_, _>>()?;
    cache.lock().unwrap().extend(new);
    let regs = cache.lock().unwrap();
    let labels: Vec<Option<Vec<i32>>> = sources.iter().map(|&s| Some(annotation(s))).collect();
    targets
        .iter()
        .map(|&t| {
            let (k, s) = sources
                .iter()
                .enumerate()
                .min_by(|a, b| {
                    regs[&(*a.1, t)]
                        .residual
                        .total_cmp(&regs[&(*b.1, t)].residual)
                })
                .unwrap();
            let l = labels[k].as_ref().unwrap();
            let (lt, _) = nearest_point_vertex_labels(
                &set.meshes[*s],
                l,
                &set.meshes[t],
                &regs[&(*s, t)].transform,
            )?;
            Ok((t, score(t, &lt)))
        })
        .collect()
}

fn mean(x: &[(usize, f64)]) -> f64 {
    x.iter().map(|v| v.1).sum::<f64>() / x.len().max(1) as f64
}

fn worst(x: &[(usize, f64)]) -> (usize, f64) {
    x.iter()
        .copied()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((0, f64::NAN))
}

/// The shape's own segmentation in feature space: `k` clusters of its band-table rows
/// (k-means, L1 distance between band indices, area-weighted means, farthest-point seeds from
/// vertex 0, 20 rounds). Intrinsic features cannot tell a left leg from a right one, so these
/// parts are the kind of regions an intrinsic method can carry (a cluster may span both).
fn feature_parts(t: &coseg::bands::BandTable, areas: &[f64], k: usize) -> Vec<i32> {
    let (d, nf) = (t.vertices, t.features);
    let dist = |v: usize, c: &[f64]| -> f64 {
        t.row(v)
            .iter()
            .zip(c)
            .map(|(&b, &x)| (b as f64 - x).abs())
            .sum()
    };
    let row = |v: usize| -> Vec<f64> { t.row(v).iter().map(|&b| b as f64).collect() };
    let mut centres = vec![row(0)];
    let mut near: Vec<f64> = (0..d).map(|v| dist(v, &centres[0])).collect();
    while centres.len() < k {
        let far = (0..d).max_by(|&a, &b| near[a].total_cmp(&near[b])).unwrap();
        centres.push(row(far));
        let c = centres.last().unwrap().clone();
        for (v, n) in near.iter_mut().enumerate() {
            *n = n.min(dist(v, &c));
        }
    }
    let mut labels = vec![0i32; d];
    for _ in 0..20 {
        labels = (0..d)
            .into_par_iter()
            .map(|v| {
                (0..k)
                    .min_by(|&a, &b| dist(v, &centres[a]).total_cmp(&dist(v, &centres[b])))
                    .unwrap() as i32
            })
            .collect();
        for (c, centre) in centres.iter_mut().enumerate() {
            let mut sum = vec![0.0; nf];
            let mut mass = 0.0;
            for v in (0..d).filter(|&v| labels[v] == c as i32) {
                for (s, &b) in sum.iter_mut().zip(t.row(v)) {
                    *s += areas[v] * b as f64;
                }
                mass += areas[v];
            }
            if mass > 0.0 {
                *centre = sum.iter().map(|s| s / mass).collect();
            }
        }
    }
    labels
}

/// Farthest-point Voronoi cells (Euclidean) of `k` seeds from vertex 0.
fn voronoi_parts(mesh: &TriMesh, k: usize) -> Vec<i32> {
    let p = mesh.positions();
    let d2 = |a: [f64; 3], b: [f64; 3]| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>();
    let mut seeds = vec![0usize];
    let mut dist: Vec<f64> = p.iter().map(|&x| d2(x, p[0])).collect();
    while seeds.len() < k {
        let (far, _) = dist
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap();
        seeds.push(far);
        for (v, d) in dist.iter_mut().enumerate() {
            *d = d.min(d2(p[v], p[far]));
        }
    }
    p.iter()
        .map(|&x| {
            (0..k)
                .min_by(|&a, &b| d2(x, p[seeds[a]]).total_cmp(&d2(x, p[seeds[b]])))
                .unwrap() as i32
        })
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mode = args.next().ok_or("mode: chairs DIR | identity MESH...")?;
    let mut cache = PathBuf::from("/tmp/coseg-eval-cache");
    let mut options = PropagateOptions::default();
    let mut graph = GraphOptions::default();
    let (mut triples, mut seed, mut parts) = (10usize, 0u64, 6usize);
    let mut triple: Option<String> = None;
    let mut only: Option<Vec<String>> = None;
    let mut per_target = false;
    let mut rest = Vec::new();
    let (mut features, mut up, mut weights) =
        ("spectral".to_string(), "y".to_string(), String::new());
    let mut pipeline = ShapePipelineOptions::default();
    let mut directions = None;
    let mut normals = 0usize;
    let mut parts_from = "voronoi".to_string();
    let mut map_step = false;
    let mut route_rigid = false;
    let mut swaps: Vec<(Vec<String>, i32, i32)> = Vec::new();
    let (mut seg, mut reps): (Option<PathBuf>, usize) = (None, 3);
    let mut routes = RouteOptions::default();
    while let Some(a) = args.next() {
        let mut val = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--cache" => cache = PathBuf::from(val()?),
            "--size-prior" => options.size_prior = val()?.parse()?,
            "--network-weight" => options.network_weight = val()?.parse()?,
            "--similarity-power" => options.similarity_power = val()?.parse()?,
            "--smoothing-time" => options.smoothing_time = val()?.parse()?,
            "--max-sweeps" => options.max_sweeps = val()?.parse()?,
            "--part-score" => {
                options.part_score = match val()?.as_str() {
                    "affinity" => PartScore::Affinity,
                    "geometric" => PartScore::Geometric,
                    o => return Err(format!("--part-score {o}: affinity or geometric").into()),
                }
            }
            "--area-weighted" => options.area_weighted = val()?.parse()?,
            "--refit-rounds" => options.refit_rounds = val()?.parse()?,
            "--refit-weight" => options.refit_weight = val()?.parse()?,
            "--update-relays" => options.update_relays = val()?.parse()?,
            "--neighbours" => graph.neighbours = val()?.parse()?,
            "--complete-limit" => graph.complete_limit = val()?.parse()?,
            "--triples" => triples = val()?.parse()?,
            "--seed" => seed = val()?.parse()?,
            "--parts" => parts = val()?.parse()?,
            "--parts-from" => parts_from = val()?,
            "--map-step" => map_step = true,
            "--route" => {
                route_rigid = match val()?.as_str() {
                    "rigid" => true,
                    "coseg" => false,
                    o => return Err(format!("--route {o}: coseg or rigid").into()),
                }
            }
            "--seg" => seg = Some(PathBuf::from(val()?)),
            "--reps" => reps = val()?.parse()?,
            "--per-target" => per_target = true,
            "--routes" => {
                routes = match val()?.as_str() {
                    "affinity" => RouteOptions::affinity_only(),
                    "all" => RouteOptions::default(),
                    o => return Err(format!("--routes {o}: all or affinity").into()),
                }
            }
            "--snap-band" => routes.snap_band = val()?.parse()?,
            "--affine" => routes.affine = val()?.parse()?,
            "--classifier" => routes.classifier = val()?.parse()?,
            "--round-trip" => routes.round_trip = val()?.parse()?,
            "--chosen-features" => routes.chosen_features = val()?.parse()?,
            "--nonrigid" => routes.nonrigid = val()?.parse()?,
            "--triple" => triple = Some(val()?),
            "--sources" => only = Some(val()?.split(',').map(str::to_string).collect()),
            "--features" => features = val()?,
            "--up" => up = val()?,
            "--family-weights" => weights = val()?,
            "--directions" => directions = Some(val()?.parse()?),
            "--normals" => normals = val()?.parse()?,
            "--bands" => pipeline.bands.bands = val()?.parse()?,
            "--eigenpairs" => pipeline.spectrum.eigenpairs = val()?.parse()?,
            "--laplacian" => pipeline.spectrum.laplacian = val()?.parse()?,
            "--area-bands" => pipeline.bands.weighting = BandWeighting::Area,
            "--gt-swap" => {
                let v = val()?;
                let (stems, pair) = v.split_once(':').ok_or("--gt-swap STEMS:A=B")?;
                let (a, b) = pair.split_once('=').ok_or("--gt-swap STEMS:A=B")?;
                swaps.push((
                    stems.split(',').map(str::to_string).collect(),
                    a.parse()?,
                    b.parse()?,
                ));
            }
            _ => rest.push(PathBuf::from(a)),
        }
    }
    let (spectral, mut families) = parse_families(&features, parse_alignment(&up)?)?;
    if let Some(e) = families.extrinsic.as_mut() {
        if let Some(n) = directions {
            e.directions = n;
        }
        e.normal_directions = normals;
    }
    parse_family_weights(&weights, &mut families.weights)?;
    pipeline.families = families;
    if !spectral {
        pipeline.descriptors.hks_count = 0;
        pipeline.descriptors.wks_count = 0;
        pipeline.descriptors.curvature_count = 0;
    }
    eprintln!(
        "options: {options:?}, graph: {graph:?}, features {features} (up {up}, weights {weights:?})"
    );
    let load_files = |files: &[PathBuf]| {
        load(
            files,
            &cache,
            &pipeline,
            &graph,
            options.smoothing_time,
            &routes,
        )
    };
    // The collection with the rigid route's registrations kept when it is fused.
    let load_set = |files: &[PathBuf]| -> Result<Set, Box<dyn std::error::Error>> {
        let mut set = load_files(files)?;
        if route_rigid {
            set.rigid = Some(Mutex::default());
        }
        Ok(set)
    };
    // Both labelled data sets are scored alike: single sources, then triples, as the flags say.
    let score_sources =
        |set: &Set, ann: &dyn Fn(usize) -> Vec<i32>, score: &dyn Fn(usize, &[i32]) -> f64| {
            chairs(
                set,
                ann,
                score,
                &options,
                (triples, seed, triple.as_deref()),
                only.as_deref(),
            )
        };
    match mode.as_str() {
        "chairs" => {
            let dir = rest.first().ok_or("chairs DIR")?;
            let mut files: Vec<PathBuf> = std::fs::read_dir(dir.join("shapes"))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .collect();
            files.sort_by_key(|f| {
                f.file_stem()
                    .and_then(|s| s.to_str())
                    .and_then(|s| s.parse::<u64>().ok())
                    .unwrap_or(u64::MAX)
            });
            let set = load_set(&files)?;
            let mut gt: Vec<Vec<i32>> = set
                .names
                .iter()
                .map(|n| Ok(read_label_file(&dir.join("gt").join(format!("{n}.seg")))?.1))
                .collect::<Result<_, Box<dyn std::error::Error>>>()?;
            for (stems, a, b) in &swaps {
                for (name, g) in set.names.iter().zip(gt.iter_mut()) {
                    if stems.contains(name) {
                        for l in g.iter_mut() {
                            *l = if *l == *a {
                                *b
                            } else if *l == *b {
                                *a
                            } else {
                                *l
                            };
                        }
                    }
                }
            }
            let ann = |i: usize| faces_to_vertices(&set.meshes[i], &gt[i]).unwrap();
            let score = |i: usize, l: &[i32]| {
                let a = face_label_agreement(&set.meshes[i], &gt[i], l).unwrap();
                if per_target {
                    let rows: Vec<String> = a
                        .confusion
                        .iter()
                        .zip(&a.labels)
                        .map(|(r, t)| {
                            let c: Vec<String> = r.iter().map(|x| format!("{:.2}", x)).collect();
                            format!("{t}: {}", c.join(" "))
                        })
                        .collect();
                    let mut h = std::collections::BTreeMap::new();
                    for &x in l {
                        *h.entry(x).or_insert(0usize) += 1;
                    }
                    eprintln!(
                        "  target {} {:.1} % [{}] {h:?}",
                        set.names[i],
                        100.0 * a.accuracy,
                        rows.join(" | ")
                    );
                }
                a.accuracy
            };
            score_sources(&set, &ann, &score)
        }
        "labelled" => {
            // A shipped collection: meshes and `<stem>.labels.txt` (per vertex) in one folder.
            let dir = rest.first().ok_or("labelled DIR")?;
            let files = coseg::graph::mesh_files(dir)?;
            let set = load_set(&files)?;
            let groups = part_groups(dir)?;
            let gt: Vec<Vec<i32>> = set
                .names
                .iter()
                .map(|n| {
                    let raw = read_label_file(&dir.join(format!("{n}.labels.txt")))?.1;
                    Ok(match &groups {
                        Some(g) => g.apply(&raw)?.into_iter().map(|x| x as i32).collect(),
                        None => raw,
                    })
                })
                .collect::<Result<_, Box<dyn std::error::Error>>>()?;
            let ann = |i: usize| gt[i].clone();
            let score = |i: usize, l: &[i32]| {
                vertex_label_agreement(&set.meshes[i], &gt[i], l)
                    .unwrap()
                    .accuracy
            };
            score_sources(&set, &ann, &score)
        }
        "bench" => {
            // Timing, warm cache: MESH... (the first two are labelled), `--seg DIR` for face
            // labels by stem (else 6 farthest-point parts of each labelled shape), `--reps N`.
            let t = Instant::now();
            let set = load_files(&rest)?;
            let t_load = t.elapsed().as_secs_f64();
            let ann = |i: usize| -> Vec<i32> {
                match &seg {
                    Some(dir) => {
                        let f = read_label_file(&dir.join(format!("{}.seg", set.names[i])))
                            .unwrap()
                            .1;
                        faces_to_vertices(&set.meshes[i], &f).unwrap()
                    }
                    None => voronoi_parts(&set.meshes[i], parts),
                }
            };
            bench(&set, &ann, &options, reps, t_load)
        }
        "identity" => {
            let set = load_set(&rest)?;
            let truth = match parts_from.as_str() {
                "voronoi" => voronoi_parts(&set.meshes[0], parts),
                "features" => {
                    feature_parts(&set.graph.node(0).bands, &set.graph.node(0).areas, parts)
                }
                o => return Err(format!("--parts-from {o}: voronoi or features").into()),
            };
            let ann = |_: usize| truth.clone();
            let score = |i: usize, l: &[i32]| {
                vertex_label_agreement(&set.meshes[i], &truth, l)
                    .unwrap()
                    .accuracy
            };
            let t = Instant::now();
            let r = if map_step {
                // The library's map step on the propagation from the source (shape 0), as
                // `coseg propagate --map-step` runs it.
                let n = set.names.len();
                let annv: Vec<Option<Vec<i32>>> =
                    (0..n).map(|i| (i == 0).then(|| truth.clone())).collect();
                let mut p =
                    propagate_labels(&set.graph, set.smoothers.as_deref(), &annv, &options)?;
                let before = p.labels.clone();
                let (reports, warnings) = coseg::propagate::map_step_collection(
                    &set.meshes,
                    &set.graph,
                    &annv,
                    &mut p,
                    &pipeline,
                    &cache,
                    &coseg::propagate::MapStepOptions::default(),
                );
                for w in warnings.iter().filter(|w| !w.contains("rejected")) {
                    eprintln!("warning: {w}");
                }
                let mut out = Vec::new();
                for (i, rep) in reports.iter().enumerate() {
                    let Some(rep) = rep else { continue };
                    let after = score(i, &p.labels[i]);
                    println!(
                        "  {}: {:.1} % -> {:.1} % (agreement {:.1} %, {})",
                        set.names[i],
                        100.0 * score(i, &before[i]),
                        100.0 * after,
                        100.0 * rep.agreement,
                        if rep.applied { "kept" } else { "rejected" }
                    );
                    out.push((i, after));
                }
                out
            } else {
                run(&set, &[0], &ann, &score, &options)?
            };
            let (w, wv) = worst(&r);
            println!(
                "| source {} ({parts} {parts_from} parts) | {} targets | mean {:.1} % | worst {} {:.1} % | {:.2} s |",
                set.names[0],
                r.len(),
                100.0 * mean(&r),
                set.names[w],
                100.0 * wv,
                t.elapsed().as_secs_f64()
            );
            print_routes(&set, "one source");
            Ok(())
        }
        _ => Err(format!("unknown mode {mode}").into()),
    }
}

/// The manifest's part groups (`manifest.json`: `parts`, `part_groups`), if the folder has one.
fn part_groups(
    dir: &std::path::Path,
) -> Result<Option<coseg::evaluate::PartGroups>, Box<dyn std::error::Error>> {
    let Ok(text) = std::fs::read_to_string(dir.join("manifest.json")) else {
        return Ok(None);
    };
    let m: serde_json::Value = serde_json::from_str(&text)?;
    let parts: Vec<String> = serde_json::from_value(m["parts"].clone())?;
    let groups: std::collections::BTreeMap<String, Vec<String>> =
        serde_json::from_value(m["part_groups"].clone()).unwrap_or_default();
    Ok(Some(coseg::evaluate::group_parts(&parts, &groups)?))
}

fn chairs(
    set: &Set,
    ann: &dyn Fn(usize) -> Vec<i32>,
    score: &dyn Fn(usize, &[i32]) -> f64,
    options: &PropagateOptions,
    (triples, seed, triple): (usize, u64, Option<&str>),
    only: Option<&[String]>,
) -> Result<(), Box<dyn std::error::Error>> {
    let n = set.names.len();
    if let Some(t) = triple {
        let src: Vec<usize> = t
            .split(',')
            .map(|s| {
                set.names
                    .iter()
                    .position(|x| x == s)
                    .ok_or(format!("--triple: no shape {s}"))
            })
            .collect::<Result<_, _>>()?;
        let r = run(set, &src, ann, score, options)?;
        println!("triple {t}: {:.2} %", 100.0 * mean(&r));
        return Ok(());
    }
    println!("| source | mean accuracy | worst target | seconds |\n|---|---|---|---|");
    let mut means = Vec::new();
    for s in 0..n {
        if only.is_some_and(|o| !o.contains(&set.names[s])) {
            continue;
        }
        let t = Instant::now();
        let r = run(set, &[s], ann, score, options)?;
        let (w, wv) = worst(&r);
        means.push((s, mean(&r)));
        println!(
            "| {} | {:.1} % | {} ({:.1} %) | {:.2} |",
            set.names[s],
            100.0 * mean(&r),
            set.names[w],
            100.0 * wv,
            t.elapsed().as_secs_f64()
        );
    }
    let (ws, wsv) = worst(&means);
    println!(
        "\none source: mean {:.2} %, worst source {} ({:.1} %)",
        100.0 * mean(&means),
        set.names[ws],
        100.0 * wsv
    );
    print_routes(set, "one source");
    if set.rigid.is_some() {
        println!("\nincremental: not run (rigid route)");
    } else if let Err(e) = incremental(set, ann, score, options) {
        println!("\nincremental: not run ({e})");
    }
    if triples == 0 {
        return Ok(());
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    println!("\n| sources | mean accuracy | worst target |\n|---|---|---|");
    let mut tmeans = Vec::new();
    for _ in 0..triples {
        let mut idx: Vec<usize> = (0..n).collect();
        idx.shuffle(&mut rng);
        let mut src = idx[..3].to_vec();
        src.sort_unstable();
        let r = run(set, &src, ann, score, options)?;
        let (w, wv) = worst(&r);
        tmeans.push((src[0], mean(&r)));
        let names: Vec<&str> = src.iter().map(|&s| set.names[s].as_str()).collect();
        println!(
            "| {} | {:.1} % | {} ({:.1} %) |",
            names.join(", "),
            100.0 * mean(&r),
            set.names[w],
            100.0 * wv
        );
    }
    let (_, wt) = worst(&tmeans);
    println!(
        "\nthree sources ({triples} triples, seed {seed}): mean {:.2} %, worst triple {:.1} %",
        100.0 * mean(&tmeans),
        100.0 * wt
    );
    print_routes(set, "three sources (worst: the triple's first source)");
    Ok(())
}

/// Cost of `Propagation::update`: propagate from the second shape, then add the third as a
/// source, against a fresh run from both (the new source must not bring a new part).
fn incremental(
    set: &Set,
    ann: &dyn Fn(usize) -> Vec<i32>,
    score: &dyn Fn(usize, &[i32]) -> f64,
    options: &PropagateOptions,
) -> Result<(), Box<dyn std::error::Error>> {
    let n = set.names.len();
    let first: Vec<Option<Vec<i32>>> = (0..n).map(|i| (i == 1).then(|| ann(1))).collect();
    let t = Instant::now();
    let mut p = propagate_labels(&set.graph, set.smoothers.as_deref(), &first, options)?;
    let t_first = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let stats = p.update(
        &set.graph,
        set.smoothers.as_deref(),
        2,
        Some(ann(2)),
        options,
    )?;
    let t_update = t.elapsed().as_secs_f64();
    let others: Vec<usize> = (0..n).filter(|&i| i != 1 && i != 2).collect();
    let acc =
        |l: &[Vec<i32>]| others.iter().map(|&i| score(i, &l[i])).sum::<f64>() / others.len() as f64;
    let both: Vec<Option<Vec<i32>>> = (0..n).map(|i| (i == 1 || i == 2).then(|| ann(i))).collect();
    let t = Instant::now();
    let fresh = propagate_labels(&set.graph, set.smoothers.as_deref(), &both, options)?;
    let t_fresh = t.elapsed().as_secs_f64();
    println!(
        "\nincremental: from {} {:.2} s; adding {} by update {:.2} s ({} shape updates, {} transports), accuracy {:.1} %; fresh run from both {:.2} s, accuracy {:.1} %",
        set.names[1],
        t_first,
        set.names[2],
        t_update,
        stats.shape_updates,
        stats.transports,
        100.0 * acc(&p.labels),
        t_fresh,
        100.0 * acc(&fresh.labels)
    );
    Ok(())
}

/// `bench` mode: a full propagation from shape 0 (median of `reps`), then
/// [`coseg::propagate::Propagation::update`] adding shape 1 as a second source, then an update
/// correcting 1 % of shape 1's vertices; walls in seconds.
fn bench(
    set: &Set,
    ann: &dyn Fn(usize) -> Vec<i32>,
    options: &PropagateOptions,
    reps: usize,
    t_load: f64,
) -> Result<(), Box<dyn std::error::Error>> {
    let n = set.names.len();
    if n < 2 {
        return Err("bench needs two shapes or more".into());
    }
    let vertices: usize = set.meshes.iter().map(|m| m.vertex_count()).sum();
    let first: Vec<Option<Vec<i32>>> = (0..n).map(|i| (i == 0).then(|| ann(0))).collect();
    let mut walls = Vec::new();
    let mut p = None;
    for _ in 0..reps.max(1) {
        let t = Instant::now();
        let r = propagate_labels(&set.graph, set.smoothers.as_deref(), &first, options)?;
        walls.push(t.elapsed().as_secs_f64());
        p = Some(r);
    }
    let mut p = p.unwrap();
    walls.sort_by(f64::total_cmp);
    let sweeps = p.sweeps;
    let a1 = ann(1);
    let t = Instant::now();
    let add = p.update(
        &set.graph,
        set.smoothers.as_deref(),
        1,
        Some(a1.clone()),
        options,
    )?;
    let t_add = t.elapsed().as_secs_f64();
    let mut fixed = a1;
    let step = 100;
    for (v, f) in fixed.iter_mut().enumerate().step_by(step) {
        *f = p.parts[(v / step) % p.parts.len()];
    }
    let t = Instant::now();
    let fix = p.update(
        &set.graph,
        set.smoothers.as_deref(),
        1,
        Some(fixed),
        options,
    )?;
    let t_fix = t.elapsed().as_secs_f64();
    println!(
        "| {n} shapes, {vertices} vertices | load (warm cache) {t_load:.2} s | propagate from 1 source: median {:.2} s (min {:.2}, max {:.2}, {} reps, {sweeps} sweeps) | update adding a source {t_add:.3} s ({} shape updates, {} transports) | update correcting 1 % of it {t_fix:.3} s ({} shape updates, {} transports) |",
        walls[walls.len() / 2],
        walls[0],
        walls[walls.len() - 1],
        walls.len(),
        add.shape_updates,
        add.transports,
        fix.shape_updates,
        fix.transports
    );
    Ok(())
}
