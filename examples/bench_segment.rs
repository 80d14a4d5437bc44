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
use coseg::graph::{CosegmentOptions, GraphOptions, ShapeGraph, ShapeNode, cosegment};
use coseg::mesh::read_mesh;
use coseg::spectral::laplace_beltrami_spectrum;
use std::path::PathBuf;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut cache = PathBuf::from("/tmp/coseg-bench-cache");
    let mut regions = CosegmentOptions::default().regions;
    let mut files = Vec::new();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--cache" => cache = PathBuf::from(args.next().ok_or("--cache DIR")?),
            "--regions" => regions = args.next().ok_or("--regions K")?.parse()?,
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
    let (mut t_spec, mut t_feat, mut t_write) = (0.0, 0.0, 0.0);
    let mut nodes = Vec::new();
    for (m, f) in meshes.iter().zip(&files) {
        let t = Instant::now();
        let s = laplace_beltrami_spectrum(m, &opts.spectrum)?;
        t_spec += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let data = shape_data_from_spectrum(m, s, &opts)?;
        t_feat += t.elapsed().as_secs_f64();
        let t = Instant::now();
        std::fs::write(
            cache_path(&cache, &shape_key(m, &opts)),
            encode_entry(&data),
        )?;
        t_write += t.elapsed().as_secs_f64();
        let name = f.file_stem().unwrap().to_string_lossy().into_owned();
        nodes.push(ShapeNode::new(
            name,
            data.bands,
            &data.descriptors.vertex_areas,
        )?);
    }
    let t = Instant::now();
    let graph = ShapeGraph::build(nodes, &GraphOptions::default())?;
    let t_graph = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let seg_cold = cosegment(&graph, &co)?;
    let t_seg = t.elapsed().as_secs_f64();
    println!(
        "cold: spectrum {t_spec:.2} s, descriptors+bands {t_feat:.2} s, cache write {t_write:.2} s, graph {t_graph:.2} s, co-segmentation {t_seg:.2} s; total {:.2} s (+ read {read:.2} s)",
        t_spec + t_feat + t_write + t_graph + t_seg
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
    println!(
        "warm: cache load {t_load:.2} s, graph {t_graph:.2} s, co-segmentation {t_seg:.2} s; total {:.2} s (+ read {read:.2} s)",
        t_load + t_graph + t_seg
    );
    let sweeps: usize = seg.tuples.iter().map(|t| t.sweeps).sum();
    println!(
        "{} regions, {} sweeps in all, identical cold/warm output: {}",
        seg.tuples.len(),
        sweeps,
        seg == seg_cold
    );
    Ok(())
}
