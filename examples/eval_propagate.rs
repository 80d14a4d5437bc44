//! Quality of label propagation against ground truth (docs/PROPAGATION.md has the tables).
//!
//! ```text
//! # COSEG chairs: every chair as the one source, then seeded random triples of sources.
//! cargo run --release --example eval_propagate -- chairs ../shared/data/coseg_chairs [--triples 10] [--seed 0]
//! # Near-isometric classes (identity ground truth): a part decomposition of the first shape
//! # (K farthest-point Voronoi cells, --parts K) carried to the others.
//! cargo run --release --example eval_propagate -- identity [--parts 6] MESH...
//! ```
//! Common options: `--sources A,B` (chairs: only these single sources), `--cache DIR` (default /tmp/coseg-eval-cache), `--size-prior A`,
//! `--network-weight W`, `--smoothing-time T`, `--neighbours K`, `--complete-limit N`.
//! Accuracy is area-weighted: per face against `.seg` files for the chairs, per vertex for
//! the identity sets; the source shapes are left out of every mean.

use coseg::evaluate::{face_label_agreement, vertex_label_agreement};
use coseg::graph::{GraphOptions, ShapeGraph, ShapeNode};
use coseg::labels::{faces_to_vertices, read_label_file};
use coseg::mesh::{TriMesh, read_mesh};
use coseg::pipeline::{ShapePipelineOptions, load_or_compute_bands};
use coseg::propagate::{PropagateOptions, propagate_labels};
use coseg::spectral::HeatSmoother;
use rand::SeedableRng;
use rand::seq::SliceRandom;
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

struct Set {
    names: Vec<String>,
    meshes: Vec<TriMesh>,
    graph: ShapeGraph,
    smoothers: Option<Vec<HeatSmoother>>,
}

fn load(
    files: &[PathBuf],
    cache: &std::path::Path,
    graph: &GraphOptions,
    time: f64,
) -> Result<Set, Box<dyn std::error::Error>> {
    let t = Instant::now();
    let loaded: Vec<(String, TriMesh, ShapeNode)> = files
        .par_iter()
        .map(|f| {
            let mesh = read_mesh(f).map_err(|e| e.to_string())?;
            let b = load_or_compute_bands(&mesh, &ShapePipelineOptions::default(), cache)
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
    let graph = ShapeGraph::build(nodes, graph)?;
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
    let ann: Vec<Option<Vec<i32>>> = (0..n)
        .map(|i| sources.contains(&i).then(|| annotation(i)))
        .collect();
    let p = propagate_labels(&set.graph, set.smoothers.as_deref(), &ann, options)?;
    Ok((0..n)
        .filter(|i| !sources.contains(i))
        .map(|i| (i, score(i, &p.labels[i])))
        .collect())
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
    let mut only: Option<Vec<String>> = None;
    let mut rest = Vec::new();
    while let Some(a) = args.next() {
        let mut val = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--cache" => cache = PathBuf::from(val()?),
            "--size-prior" => options.size_prior = val()?.parse()?,
            "--network-weight" => options.network_weight = val()?.parse()?,
            "--smoothing-time" => options.smoothing_time = val()?.parse()?,
            "--max-sweeps" => options.max_sweeps = val()?.parse()?,
            "--neighbours" => graph.neighbours = val()?.parse()?,
            "--complete-limit" => graph.complete_limit = val()?.parse()?,
            "--triples" => triples = val()?.parse()?,
            "--seed" => seed = val()?.parse()?,
            "--parts" => parts = val()?.parse()?,
            "--sources" => only = Some(val()?.split(',').map(str::to_string).collect()),
            _ => rest.push(PathBuf::from(a)),
        }
    }
    eprintln!("options: {options:?}, graph: {graph:?}");
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
            let set = load(&files, &cache, &graph, options.smoothing_time)?;
            let gt: Vec<Vec<i32>> = set
                .names
                .iter()
                .map(|n| Ok(read_label_file(&dir.join("gt").join(format!("{n}.seg")))?.1))
                .collect::<Result<_, Box<dyn std::error::Error>>>()?;
            let ann = |i: usize| faces_to_vertices(&set.meshes[i], &gt[i]).unwrap();
            let score = |i: usize, l: &[i32]| {
                face_label_agreement(&set.meshes[i], &gt[i], l)
                    .unwrap()
                    .accuracy
            };
            chairs(&set, &ann, &score, &options, triples, seed, only.as_deref())
        }
        "identity" => {
            let set = load(&rest, &cache, &graph, options.smoothing_time)?;
            let truth = voronoi_parts(&set.meshes[0], parts);
            let ann = |_: usize| truth.clone();
            let score = |i: usize, l: &[i32]| {
                vertex_label_agreement(&set.meshes[i], &truth, l)
                    .unwrap()
                    .accuracy
            };
            let t = Instant::now();
            let r = run(&set, &[0], &ann, &score, &options)?;
            let (w, wv) = worst(&r);
            println!(
                "| source {} ({parts} parts) | {} targets | mean {:.1} % | worst {} {:.1} % | {:.2} s |",
                set.names[0],
                r.len(),
                100.0 * mean(&r),
                set.names[w],
                100.0 * wv,
                t.elapsed().as_secs_f64()
            );
            Ok(())
        }
        _ => Err(format!("unknown mode {mode}").into()),
    }
}

fn chairs(
    set: &Set,
    ann: &dyn Fn(usize) -> Vec<i32>,
    score: &dyn Fn(usize, &[i32]) -> f64,
    options: &PropagateOptions,
    triples: usize,
    seed: u64,
    only: Option<&[String]>,
) -> Result<(), Box<dyn std::error::Error>> {
    let n = set.names.len();
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
    incremental(set, ann, score, options)?;
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
        1,
        Some(ann(1)),
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
