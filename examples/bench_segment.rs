//! Benchmark of `coseg segment`'s work on a collection: cold (spectra computed) and warm (per-shape
//! data read from the cache), with the per-stage split.
//!
//! ```text
//! cargo run --release --example bench_segment -- [--cache DIR] [--regions K] [--refine-rounds N] MESH...
//! ```
//! Without `--regions`: the bare `coseg segment` (parts from geometry, their number and the
//! feature families chosen from the data); `--regions K`: K equal-area regions.
//! Cold: every shape's spectrum, descriptors and bands are computed (shapes in parallel) and
//! written to an emptied cache folder (default `/tmp/coseg-bench-cache`); then
//! [`segment_collection`] runs with `coseg segment`'s defaults (graph, co-segmentation, heat
//! smoothers, refinement). Warm: the same from the cache's compact bands entries (as
//! `load_collection` reads them). Mesh reading is reported apart.

use coseg::cache::{CacheOutcome, bands_path, cache_path};
use coseg::graph::ShapeNode;
use coseg::mesh::read_mesh;
use coseg::parts::{SegmentCollectionOptions, SegmentTimes, segment_collection};
use coseg::pipeline::{
    ShapeBands, ShapePipelineOptions, encode_bands_entry, encode_shape_entry as encode_entry,
    load_or_compute_bands, shape_data_from_spectrum, shape_key,
};
use coseg::spectral::laplace_beltrami_spectrum;
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut cache = PathBuf::from("/tmp/coseg-bench-cache");
    let mut seg_opts = SegmentCollectionOptions::default();
    let mut files = Vec::new();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--cache" => cache = PathBuf::from(args.next().ok_or("--cache DIR")?),
            "--regions" => {
                let refine = seg_opts.refine;
                seg_opts = SegmentCollectionOptions::equal_areas(
                    args.next().ok_or("--regions K")?.parse()?,
                );
                seg_opts.refine = refine;
            }
            "--refine-rounds" => {
                let rounds: usize = args.next().ok_or("--refine-rounds N")?.parse()?;
                seg_opts.refine = (rounds > 0).then_some({
                    let mut opts = SegmentCollectionOptions::default()
                        .refine
                        .unwrap_or_default();
                    opts.max_rounds = rounds;
                    opts
                });
            }
            _ => files.push(PathBuf::from(a)),
        }
    }
    let opts = ShapePipelineOptions::default();
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
            // Both entries, as `load_collection` writes them on a cold run.
            let key = shape_key(m, &opts);
            std::fs::write(cache_path(&cache, &key), encode_entry(&data))
                .map_err(|e| e.to_string())?;
            std::fs::write(
                bands_path(&cache, &key),
                encode_bands_entry(&ShapeBands::of(&data)),
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
    let cold_run = segment_collection(nodes, &meshes, &seg_opts)?;
    let ct = cold_run.times;
    println!(
        "cold: per-shape work {t_shapes:.2} s wall on {} threads (summed over shapes: spectrum {t_spec:.2} s, descriptors+bands {t_feat:.2} s, cache write {t_write:.2} s), {}; total {:.2} s (+ read {read:.2} s)",
        rayon::current_num_threads(),
        stages(&ct),
        t_shapes + total(&ct)
    );

    // Warm: shapes in parallel, as `load_collection` does.
    let t = Instant::now();
    let nodes: Vec<ShapeNode> = meshes
        .par_iter()
        .zip(&files)
        .map(|(m, f)| -> Result<ShapeNode, String> {
            let r = load_or_compute_bands(m, &opts, &cache).map_err(|e| e.to_string())?;
            if r.outcome != CacheOutcome::Hit || !r.warnings.is_empty() {
                return Err(format!("{}: cache miss on the warm run", f.display()));
            }
            let name = f.file_stem().unwrap().to_string_lossy().into_owned();
            ShapeNode::new(name, r.data.bands, &r.data.vertex_areas).map_err(|e| e.to_string())
        })
        .collect::<Result<_, _>>()?;
    let t_load = t.elapsed().as_secs_f64();
    let warm = segment_collection(nodes, &meshes, &seg_opts)?;
    let wt = warm.times;
    let seg = &warm.segmentation;
    println!(
        "warm: cache load {t_load:.2} s, {} ({} sweeps, converged {}); total {:.2} s (+ read {read:.2} s)",
        stages(&wt),
        seg.tuples[0].sweeps,
        seg.tuples[0].converged,
        t_load + total(&wt)
    );
    println!(
        "{} regions, identical cold/warm output: {}",
        seg.tuples.len(),
        *seg == cold_run.segmentation
    );
    Ok(())
}

fn stages(t: &SegmentTimes) -> String {
    format!(
        "feature choice {:.2} s, graph {:.2} s, co-segmentation {:.2} s (part cues {:.2} s), smoothers {:.2} s, refinement {:.2} s",
        t.features.unwrap_or_default().as_secs_f64(),
        t.graph.as_secs_f64(),
        t.cosegment.as_secs_f64(),
        t.part_cues.unwrap_or_default().as_secs_f64(),
        t.smoothers.as_secs_f64(),
        t.refine.as_secs_f64()
    )
}

fn total(t: &SegmentTimes) -> f64 {
    (t.features.unwrap_or_default()
        + t.graph
        + t.part_cues.unwrap_or_default()
        + t.cosegment
        + t.smoothers
        + t.refine)
        .as_secs_f64()
}
