//! Benchmark of `coseg segment`'s work on a collection: cold (spectra computed) and warm (per-shape
//! data read from the cache), with the per-stage split.
//!
//! ```text
//! cargo run --release --example bench_segment -- [--cache DIR] [--regions K] MESH...
//! ```
//! Cold: every shape's spectrum, descriptors and bands are computed and written to an emptied
//! cache folder (default `/tmp/coseg-bench-cache`); then the graph is built and co-segmented.
//! Warm: the same from the cache.

use coseg::cache::{
    CacheOutcome, ShapePipelineOptions, cache_path, encode_entry, load_or_compute,
    shape_data_from_spectrum, shape_key,
};
use coseg::graph::{
    CosegmentOptions, GraphOptions, ShapeGraph, ShapeNode, cosegment, refine_cosegmentation,
};
use coseg::mesh::read_mesh;
use coseg::spectral::{HeatSmoother, laplace_beltrami_spectrum};
use coseg::stable::RefineOptions;
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut cache = PathBuf::from("/tmp/coseg-bench-cache");
    let mut regions = CosegmentOptions::default().regions;
    let mut files = Vec::new();
    let mut refine = RefineOptions::default();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--cache" => cache = PathBuf::from(args.next().ok_or("--cache DIR")?),
            "--regions" => regions = args.next().ok_or("--regions K")?.parse()?,
            "--refine-rounds" => {
                refine.max_rounds = args.next().ok_or("--refine-rounds N")?.parse()?
            }
            _ => files.push(PathBuf::from(a)),
        }
    }
    let opts = ShapePipelineOptions::default();
    let co = CosegmentOptions {
        regions,
        ..Default::default()
    };
    let t = Instant::now();
    let meshes: Vec<_> = files.iter().map(read_mesh).collect::<Result<_, _>>()?;
    let read = t.elapsed().as_secs_f64();
    let verts: Vec<usize> = meshes.iter().map(|m| m.vertex_count()).collect();
    println!(
        "{} shapes, {}–{} vertices, read {:.2} s",
        meshes.len(),
        verts.iter().min().unwrap_or(&0),
        verts.iter().max().unwrap_or(&0),
        read
    );

    // Cold.
    let _ = std::fs::remove_dir_all(&cache);
    std::fs::create_dir_all(&cache)?;
    // Shapes in parallel, one per rayon thread, as `load_collection` does.
    let t_shapes = Instant::now();
    type Cold = (f64, f64, f64, ShapeNode);
    let cold: Vec<Cold> = meshes
        .par_iter()
        .zip(&files)
        .map(|(m, f)| -> Result<Cold, String> {
            let t = Instant::now();
            let s = laplace_beltrami_spectrum(m, &opts.spectrum).map_err(|e| e.to_string())?;
            let spec = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let data = shape_data_from_spectrum(m, s, &opts).map_err(|e| e.to_string())?;
            let feat = t.elapsed().as_secs_f64();
            let t = Instant::now();
            std::fs::write(
                cache_path(&cache, &shape_key(m, &opts)),
                encode_entry(&data),
            )
            .map_err(|e| e.to_string())?;
            let write = t.elapsed().as_secs_f64();
            let name = f.file_stem().unwrap().to_string_lossy().into_owned();
            let node = ShapeNode::new(name, data.bands, &data.descriptors.vertex_areas)
                .map_err(|e| e.to_string())?;
            Ok((spec, feat, write, node))
        })
        .collect::<Result<_, _>>()?;
    let t_shapes = t_shapes.elapsed().as_secs_f64();
    let (t_spec, t_feat, t_write) = cold
        .iter()
        .fold((0.0, 0.0, 0.0), |a, c| (a.0 + c.0, a.1 + c.1, a.2 + c.2));
    let nodes: Vec<ShapeNode> = cold.into_iter().map(|c| c.3).collect();
    let t = Instant::now();
    let graph = ShapeGraph::build(nodes, &GraphOptions::default())?;
    let t_graph = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let seg_cold = cosegment(&graph, &co)?;
    let t_seg = t.elapsed().as_secs_f64();
    let (seg_cold, t_smooth, t_refine) = refined(&graph, &seg_cold, &meshes, &refine)?;
    println!(
        "cold: per-shape work {t_shapes:.2} s wall on {} threads (summed over shapes: spectrum {t_spec:.2} s, descriptors+bands {t_feat:.2} s, cache write {t_write:.2} s), graph {t_graph:.2} s, co-segmentation {t_seg:.2} s, smoothers {t_smooth:.2} s, refinement {t_refine:.2} s; total {:.2} s (+ read {read:.2} s)",
        rayon::current_num_threads(),
        t_shapes + t_graph + t_seg + t_smooth + t_refine
    );

    // Warm.
    let t = Instant::now();
    let mut nodes = Vec::new();
    for (m, f) in meshes.iter().zip(&files) {
        let r = load_or_compute(m, &opts, &cache)?;
        if r.outcome != CacheOutcome::Hit {
            return Err(format!("{}: cache miss on the warm run", f.display()).into());
        }
        let name = f.file_stem().unwrap().to_string_lossy().into_owned();
        nodes.push(ShapeNode::new(
            name,
            r.data.bands,
            &r.data.descriptors.vertex_areas,
        )?);
    }
    let t_load = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let graph = ShapeGraph::build(nodes, &GraphOptions::default())?;
    let t_graph = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let seg = cosegment(&graph, &co)?;
    let t_seg = t.elapsed().as_secs_f64();
    let (seg, t_smooth, t_refine) = refined(&graph, &seg, &meshes, &refine)?;
    println!(
        "warm: cache load {t_load:.2} s, graph {t_graph:.2} s, co-segmentation {t_seg:.2} s, smoothers {t_smooth:.2} s, refinement {t_refine:.2} s ({} sweeps, converged {}); total {:.2} s (+ read {read:.2} s)",
        seg.tuples[0].sweeps,
        seg.tuples[0].converged,
        t_load + t_graph + t_seg + t_smooth + t_refine
    );
    let sweeps: usize = seg_unrefined_sweeps(&seg);
    println!(
        "{} regions, {} sweeps in all, identical cold/warm output: {}",
        seg.tuples.len(),
        sweeps,
        seg == seg_cold
    );
    Ok(())
}

/// The refinement step of `coseg segment` (skipped when `max_rounds` is 0): heat smoothers,
/// then [`refine_cosegmentation`]. Returns the result and the two stage times.
fn refined(
    graph: &ShapeGraph,
    seg: &coseg::graph::Cosegmentation,
    meshes: &[coseg::mesh::TriMesh],
    refine: &RefineOptions,
) -> Result<(coseg::graph::Cosegmentation, f64, f64), Box<dyn std::error::Error>> {
    if refine.max_rounds == 0 {
        return Ok((seg.clone(), 0.0, 0.0));
    }
    let t = Instant::now();
    let smoothers: Vec<HeatSmoother> = meshes
        .iter()
        .map(|m| HeatSmoother::new(m, refine.smoothing_time))
        .collect::<Result<_, _>>()?;
    let t_smooth = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let out = refine_cosegmentation(graph, seg, Some(&smoothers), refine)?;
    Ok((out, t_smooth, t.elapsed().as_secs_f64()))
}

fn seg_unrefined_sweeps(seg: &coseg::graph::Cosegmentation) -> usize {
    seg.tuples.iter().map(|t| t.sweeps).sum()
}
