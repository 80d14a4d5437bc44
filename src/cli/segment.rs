use anyhow::{Context, Result, bail};
use clap::Args;
use coseg::cache::{CacheOutcome, ShapePipelineOptions};
use coseg::graph::{
    CosegmentOptions, Cosegmentation, GraphKind, GraphOptions, LoadedCollection, ShapeGraph,
    cosegment, load_collection,
};
use coseg::mesh::{PlyVertexProperty, write_mesh};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, Args)]
pub struct SegmentArgs {
    /// Folder of meshes (.obj, .off, .ply); every mesh file directly in it is used.
    folder: PathBuf,
    /// Output folder: `<name>.regions.txt`, `<name>.ply` (coloured) per shape, `summary.json`.
    #[arg(short, long)]
    out: PathBuf,
    /// Per-shape cache folder (default: `<OUT>/.cache`).
    #[arg(long)]
    cache: Option<PathBuf>,
    /// Regions per shape, the last being the leftovers.
    #[arg(long, default_value_t = CosegmentOptions::default().regions)]
    regions: usize,
    /// Area of each region as a fraction of its shape (default: 1 / regions).
    #[arg(long)]
    area_fraction: Option<f64>,
    /// Start each region from a seeded random half of the root shape instead of its most
    /// distinctive vertex.
    #[arg(long)]
    seed: Option<u64>,
    /// Collections up to this size use a complete shape graph; larger ones a nearest-neighbour
    /// graph.
    #[arg(long, default_value_t = GraphOptions::default().complete_limit)]
    complete_limit: usize,
    /// Neighbours per shape of the nearest-neighbour graph.
    #[arg(long, default_value_t = GraphOptions::default().neighbours)]
    neighbours: usize,
}

pub fn run(args: SegmentArgs) -> Result<ExitCode> {
    let cache = args
        .cache
        .clone()
        .unwrap_or_else(|| args.out.join(".cache"));
    let pipeline = ShapePipelineOptions::default();
    let t0 = Instant::now();
    let bar = if std::io::stderr().is_terminal() {
        let b = ProgressBar::new(0);
        b.set_style(
            ProgressStyle::with_template("{bar:30} {pos}/{len} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        Some(b)
    } else {
        None
    };
    let loaded = load_collection(&args.folder, &pipeline, &cache, |i, total, path| {
        if let Some(b) = &bar {
            b.set_length(total as u64);
            b.set_position(i as u64);
            b.set_message(path.display().to_string());
        }
    })
    .with_context(|| format!("reading {}", args.folder.display()))?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    for s in &loaded.skipped {
        eprintln!("error: {} (skipped)", s.error);
    }
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    let total_files = loaded.nodes.len() + loaded.skipped.len();
    if total_files == 0 {
        bail!(
            "{}: no mesh files (.obj, .off, .ply)",
            args.folder.display()
        );
    }
    if loaded.nodes.len() < 2 {
        bail!(
            "{}: co-segmentation needs at least 2 readable shapes, got {}",
            args.folder.display(),
            loaded.nodes.len()
        );
    }
    let t_graph = Instant::now();
    let graph_opts = GraphOptions {
        complete_limit: args.complete_limit,
        neighbours: args.neighbours,
        ..Default::default()
    };
    let graph = ShapeGraph::build(loaded.nodes.clone(), &graph_opts)?;
    let graph_time = t_graph.elapsed();
    let t_seg = Instant::now();
    let opts = CosegmentOptions {
        regions: args.regions,
        area_fraction: args.area_fraction,
        seed: args.seed,
        ..Default::default()
    };
    let seg = cosegment(&graph, &opts)?;
    let seg_time = t_seg.elapsed();
    let t_write = Instant::now();
    write_results(&args.out, &loaded, &graph, &seg)?;
    let write_time = t_write.elapsed();
    let hits = loaded
        .outcomes
        .iter()
        .filter(|o| **o == CacheOutcome::Hit)
        .count();
    println!(
        "{} shapes co-segmented into {} regions; results in {}",
        loaded.nodes.len(),
        seg.tuples.len(),
        args.out.display()
    );
    println!(
        "time: read {:.2} s, per-shape data {:.2} s ({hits} cached), graph {:.2} s, co-segmentation {:.2} s, write {:.2} s, total {:.2} s",
        loaded.read_time.as_secs_f64(),
        loaded.shape_time.as_secs_f64(),
        graph_time.as_secs_f64(),
        seg_time.as_secs_f64(),
        write_time.as_secs_f64(),
        t0.elapsed().as_secs_f64()
    );
    Ok(super::exit_code(loaded.skipped.len(), total_files))
}

/// A distinct colour per region id (golden-ratio hues; id `-1` grey).
fn colour(id: i32) -> [u8; 3] {
    if id < 0 {
        return [128, 128, 128];
    }
    let h = (id as f64 * 0.618_033_988_749_895).fract() * 6.0;
    let (s, v) = (0.65, 0.95);
    let c = v * s;
    let x = c * (1.0 - ((h % 2.0) - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    [r, g, b].map(|u| ((u + m) * 255.0).round() as u8)
}

/// Writes `<name>.regions.txt` (one region id per line, vertex order of the input file),
/// `<name>.ply` (coloured, with an int `region` property) and `summary.json`. Kept in one place
/// to switch to the shared writers of `coseg::output` once they exist.
fn write_results(
    out: &Path,
    loaded: &LoadedCollection,
    graph: &ShapeGraph,
    seg: &Cosegmentation,
) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut shapes = Vec::new();
    for (i, name) in seg.names.iter().enumerate() {
        let labels = seg.labels(i);
        let mut text = String::with_capacity(labels.len() * 3);
        for l in &labels {
            text.push_str(&l.to_string());
            text.push('\n');
        }
        let regions_file = out.join(format!("{name}.regions.txt"));
        std::fs::write(&regions_file, text)
            .with_context(|| format!("writing {}", regions_file.display()))?;
        let ply = out.join(format!("{name}.ply"));
        write_mesh(
            &ply,
            &loaded.meshes[i],
            &[
                PlyVertexProperty::Color(labels.iter().map(|&l| colour(l)).collect()),
                PlyVertexProperty::Int("region".into(), labels.clone()),
            ],
        )?;
        shapes.push(serde_json::json!({
            "name": name,
            "input": loaded.paths[i].display().to_string(),
            "vertices": seg.vertices[i],
            "regions_file": regions_file.display().to_string(),
            "mesh_file": ply.display().to_string(),
            "region_area_fractions": seg.tuples.iter().map(|t| t.area_fractions[i]).collect::<Vec<_>>(),
        }));
    }
    let regions: Vec<_> = seg
        .tuples
        .iter()
        .enumerate()
        .map(|(r, t)| {
            serde_json::json!({
                "id": r,
                "leftover": t.leftover,
                "confidence": t.confidence,
                "cycle_consistency": t.cycle_consistency,
                "converged": t.converged,
                "sweeps": t.sweeps,
                "objective": t.objective,
            })
        })
        .collect();
    let kind = match graph.kind() {
        GraphKind::Complete => "complete".to_string(),
        GraphKind::Nearest(k) => format!("nearest-{k}"),
    };
    let summary = serde_json::json!({
        "command": "segment",
        "shapes": shapes,
        "regions": regions,
        "area_fraction": seg.alpha,
        "root": seg.names[seg.root],
        "graph": {
            "kind": kind,
            "edges": graph.edges().iter().map(|(i, j, e)| serde_json::json!({
                "a": seg.names[*i], "b": seg.names[*j], "weight": e.weight, "distance": e.distance
            })).collect::<Vec<_>>(),
        },
        "skipped": loaded.skipped.iter().map(|s| serde_json::json!({
            "path": s.path.display().to_string(), "error": s.error
        })).collect::<Vec<_>>(),
    });
    let path = out.join("summary.json");
    std::fs::write(&path, serde_json::to_string_pretty(&summary)? + "\n")
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}
