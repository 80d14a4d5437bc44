//! Quality of the collection co-segmentation against the identity ground truth, and the chained
//! pairwise baseline.
//!
//! ```text
//! cargo run --release --example eval_collection -- [--cache DIR] [--regions K] [--alpha A] [--complete-limit N] MESH...
//! ```
//! Every mesh must have the same vertex count (shapes of one class whose vertex `i` corresponds
//! to vertex `i` everywhere, e.g. TOSCA's cats or FAUST). Prints, for the co-segmentation and for
//! pairwise Algorithm 2 chained along the file order (region ids carried from shape to shape by
//! area-weighted majority), the mean over all pairs of shapes of the area fraction where the two
//! shapes give a vertex the same region id.

use coseg::affinity::BandAffinity;
use coseg::graph::{
    CosegmentOptions, GraphOptions, ShapeGraph, ShapeNode, cosegment, refine_cosegmentation,
};
use coseg::mesh::read_mesh;
use coseg::parts::SegmentCollectionOptions;
use coseg::pipeline::{ShapePipelineOptions, load_or_compute};
use coseg::spectral::HeatSmoother;
use coseg::stable::RefineOptions;
use coseg::stable::{StableRegionsOptions, Threshold, refine_regions, stable_regions};
use std::path::PathBuf;
use std::time::Instant;

fn agreement(labels: &[Vec<i32>], areas: &[Vec<f64>]) -> (f64, f64) {
    let n = labels.len();
    let (mut sum, mut count, mut worst) = (0.0, 0usize, 1.0f64);
    for i in 0..n {
        for j in i + 1..n {
            let mut agree = 0.0;
            let mut total = 0.0;
            for v in 0..labels[i].len() {
                let w = 0.5 * (areas[i][v] + areas[j][v]);
                total += w;
                if labels[i][v] == labels[j][v] {
                    agree += w;
                }
            }
            let f = agree / total;
            sum += f;
            worst = worst.min(f);
            count += 1;
        }
    }
    (sum / count as f64, worst)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut cache = PathBuf::from("/tmp/coseg-eval-cache");
    let mut regions = CosegmentOptions::default().regions;
    let mut alpha: Option<f64> = None;
    let mut graph_opts = GraphOptions::default();
    let mut files = Vec::new();
    let mut refine = SegmentCollectionOptions::default()
        .refine
        .unwrap_or_default();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--cache" => cache = PathBuf::from(args.next().ok_or("--cache DIR")?),
            "--regions" => regions = args.next().ok_or("--regions K")?.parse()?,
            "--complete-limit" => {
                graph_opts.complete_limit = args.next().ok_or("--complete-limit N")?.parse()?
            }
            "--refine-rounds" => {
                refine.max_rounds = args.next().ok_or("--refine-rounds N")?.parse()?
            }
            "--smoothing-time" => {
                refine.smoothing_time = args.next().ok_or("--smoothing-time T")?.parse()?
            }
            "--alpha" => alpha = Some(args.next().ok_or("--alpha A")?.parse()?),
            _ => files.push(PathBuf::from(a)),
        }
    }
    if files.len() < 2 {
        return Err("need at least two meshes".into());
    }
    let opts = ShapePipelineOptions::default();
    let t = Instant::now();
    let mut nodes = Vec::new();
    let mut smoothers = Vec::new();
    let mut pair_smoothers = Vec::new();
    for f in &files {
        let mesh = read_mesh(f)?;
        smoothers.push(HeatSmoother::new(&mesh, refine.smoothing_time.max(1e-9))?);
        pair_smoothers.push(HeatSmoother::new(
            &mesh,
            RefineOptions::default().smoothing_time,
        )?);
        let data = load_or_compute(&mesh, &opts, &cache)?.data;
        let name = f.file_stem().unwrap().to_string_lossy().into_owned();
        nodes.push(ShapeNode::new(
            name,
            data.bands,
            &data.descriptors.vertex_areas,
        )?);
    }
    let d = nodes[0].bands.vertices;
    if nodes.iter().any(|n| n.bands.vertices != d) {
        return Err("identity ground truth needs equal vertex counts".into());
    }
    eprintln!("per-shape data: {:.2} s", t.elapsed().as_secs_f64());
    let areas: Vec<Vec<f64>> = nodes.iter().map(|n| n.areas.clone()).collect();

    let t = Instant::now();
    let graph = ShapeGraph::build(nodes.clone(), &graph_opts)?;
    let co = {
        let mut opts = CosegmentOptions::default();
        opts.regions = regions;
        opts.area_fraction = alpha;
        opts
    };
    let seg = cosegment(&graph, &co)?;
    let seg_time = t.elapsed().as_secs_f64();
    let labels: Vec<Vec<i32>> = (0..nodes.len()).map(|i| seg.labels(i)).collect();
    let (mean, worst) = agreement(&labels, &areas);
    println!(
        "shapes {}  regions {}  alpha {:.3}  graph {:?} ({} edges)  root {}",
        nodes.len(),
        seg.tuples.len(),
        seg.alpha,
        graph.kind(),
        graph.edge_count(),
        seg.names[seg.root]
    );
    for (r, t) in seg.tuples.iter().enumerate() {
        println!(
            "  region {r}: converged {} sweeps {} confidence {:.3} cycle-consistency {:?} leftover {}",
            t.converged,
            t.sweeps,
            t.confidence,
            t.cycle_consistency.map(|c| (c * 1000.0).round() / 1000.0),
            t.leftover
        );
    }
    println!(
        "co-segmentation: mean pairwise area agreement {:.2} % (worst pair {:.2} %), {:.2} s",
        100.0 * mean,
        100.0 * worst,
        seg_time
    );

    let t = Instant::now();
    let refined = refine_cosegmentation(&graph, &seg, Some(&smoothers), &refine)?;
    let rlabels: Vec<Vec<i32>> = (0..nodes.len()).map(|i| refined.labels(i)).collect();
    let (rmean, rworst) = agreement(&rlabels, &areas);
    println!(
        "refined co-segmentation ({} sweeps, converged {}): mean pairwise area agreement {:.2} % (worst pair {:.2} %), {:.2} s",
        refined.tuples[0].sweeps,
        refined.tuples[0].converged,
        100.0 * rmean,
        100.0 * rworst,
        t.elapsed().as_secs_f64()
    );
    for (r, t) in refined.tuples.iter().enumerate() {
        println!(
            "  region {r}: confidence {:.3} area fractions {:?}",
            t.confidence,
            t.area_fractions
                .iter()
                .map(|a| (a * 1000.0).round() / 1000.0)
                .collect::<Vec<_>>()
        );
    }

    // Baseline: pairwise Algorithm 2 along the chain 0-1-2-…, ids carried by majority.
    let t = Instant::now();
    let a = seg.alpha;
    let so = {
        let mut opts = StableRegionsOptions::default();
        opts.pairs = regions;
        opts.p = Threshold::AreaFraction(a);
        opts.q = Threshold::AreaFraction(a);
        opts
    };
    // Each pair as `coseg pair` gives it by default (Algorithm 2, then its refinement), and raw.
    let pair_refine = RefineOptions::default();
    let mut chain: Vec<Vec<i32>> = Vec::new();
    let mut chain_refined: Vec<Vec<i32>> = Vec::new();
    for i in 0..nodes.len() - 1 {
        let pr = stable_regions(
            &nodes[i].bands,
            &nodes[i + 1].bands,
            &areas[i],
            &areas[i + 1],
            &so,
        )?;
        let w = BandAffinity::new(&nodes[i].bands, &nodes[i + 1].bands)?;
        let prr = refine_regions(
            &w,
            &pr,
            &areas[i],
            &areas[i + 1],
            Some(&pair_smoothers[i]),
            Some(&pair_smoothers[i + 1]),
            &pair_refine,
        )?;
        carry(&mut chain, &pr, &areas[i], d);
        carry(&mut chain_refined, &prr, &areas[i], d);
    }
    for (name, labels) in [
        ("chained pairwise Algorithm 2", &chain),
        (
            "chained pairwise Algorithm 2 + pair refinement",
            &chain_refined,
        ),
    ] {
        let (cmean, cworst) = agreement(labels, &areas);
        println!(
            "{name}: mean pairwise area agreement {:.2} % (worst pair {:.2} %)",
            100.0 * cmean,
            100.0 * cworst,
        );
    }
    println!("chains: {:.2} s", t.elapsed().as_secs_f64());
    Ok(())
}

/// Appends the next shape's labels to `chain`: each region of the pair takes the id on the
/// chain's last shape that covers most of its area there (the first pair starts the chain).
fn carry(
    chain: &mut Vec<Vec<i32>>,
    pr: &coseg::stable::StableRegions,
    areas_prev: &[f64],
    d: usize,
) {
    if chain.is_empty() {
        chain.push(pr.labels_a());
    }
    let prev = chain.last().expect("started").clone();
    let mut next = vec![-1; d];
    for p in &pr.pairs {
        let mut votes = std::collections::BTreeMap::new();
        for &v in &p.region_a {
            *votes.entry(prev[v as usize]).or_insert(0.0) += areas_prev[v as usize];
        }
        let id = votes
            .iter()
            .max_by(|x, y| x.1.total_cmp(y.1).then(y.0.cmp(x.0)))
            .map_or(-1, |(k, _)| *k);
        for &v in &p.region_b {
            next[v as usize] = id;
        }
    }
    chain.push(next);
}
