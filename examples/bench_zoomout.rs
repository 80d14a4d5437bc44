//! Speed benchmark of ZoomOut's last match: nearest neighbours against the one-to-one
//! assignment (`FinalMatch`), with and without descriptors.
//!
//! ```text
//! cargo run --release --example bench_zoomout -- A.off B.off [--cache DIR] [--repeats R]
//! ```
//! Per-shape data come from `coseg::pipeline::load_or_compute` (computed once, excluded). ZoomOut
//! starts from the identity map (shapes of one TOSCA class share their vertex order) with the
//! default sizes (10 → 150, 2,000 samples); every configuration is run `R` times (default 3)
//! and its wall times printed, with the share of vertices mapped to themselves.

use coseg::maps::{FinalMatch, ShapeGeometry, ZoomOutOptions, zoomout};
use coseg::mesh::read_mesh;
use coseg::pipeline::{ShapePipelineOptions, load_or_compute};
use std::path::PathBuf;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut files = Vec::new();
    let mut cache = PathBuf::from("/tmp/coseg-bench-cache");
    let mut repeats = 3usize;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--cache" => {
                cache = args.get(i + 1).cloned().unwrap_or_default().into();
                i += 1;
            }
            "--repeats" => {
                repeats = args.get(i + 1).cloned().unwrap_or_default().parse()?;
                i += 1;
            }
            f => files.push(PathBuf::from(f)),
        }
        i += 1;
    }
    let [a, b] = files.as_slice() else {
        anyhow::bail!("usage: bench_zoomout A.off B.off [--cache DIR] [--repeats R]");
    };
    let pipe = ShapePipelineOptions::default();
    let (ma, mb) = (read_mesh(a)?, read_mesh(b)?);
    let da = load_or_compute(&ma, &pipe, &cache)?.data;
    let db = load_or_compute(&mb, &pipe, &cache)?.data;
    let ga = ShapeGeometry {
        spectrum: &da.spectrum,
        positions: ma.positions(),
        descriptors: Some(&da.descriptors.values),
    };
    let gb = ShapeGeometry {
        spectrum: &db.spectrum,
        positions: mb.positions(),
        descriptors: Some(&db.descriptors.values),
    };
    let start: Vec<u32> = (0..mb.vertex_count() as u32).collect();
    println!(
        "{} × {} vertices, {} run(s) each",
        ma.vertex_count(),
        mb.vertex_count(),
        repeats
    );
    for descriptor_weight in [0.0, 500.0] {
        for (name, final_match) in [
            ("nearest", FinalMatch::Nearest),
            ("one-to-one", FinalMatch::default()),
        ] {
            let options = {
                let mut opts = ZoomOutOptions::default();
                opts.descriptor_weight = descriptor_weight;
                opts.final_match = final_match;
                opts
            };
            let mut seconds = Vec::new();
            let mut map = Vec::new();
            for _ in 0..repeats {
                let t = Instant::now();
                map = zoomout(ga, gb, &start, &options)?;
                seconds.push(t.elapsed().as_secs_f64());
            }
            let fixed = map.iter().zip(&start).filter(|(x, y)| x == y).count();
            println!(
                "descriptor weight {descriptor_weight:>5}, {name:>10}: {} s; identity kept on {:.1} %",
                seconds
                    .iter()
                    .map(|s| format!("{s:.3}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                100.0 * fixed as f64 / start.len() as f64
            );
        }
    }
    Ok(())
}
