//! Latency of the studio's library calls (what `coseg studio`'s server runs per request):
//! opening a folder, a click on a patch (label + the JSON of the shape's labels the server
//! sends back), the first propagation and an incremental one after a one-shape change.
//!
//! `cargo run --release --example bench_studio -- FOLDER [CACHE]`: the shapes of FOLDER, the
//! per-shape cache CACHE (default: the system's temporary `coseg-cache`). Run it twice for
//! warm-cache figures. Shape 0 is labelled patch by patch (part = patch index mod 4), then one
//! patch of shape 1 is relabelled before the second propagation (shape 1 becomes a second source)
//! and another before the third (a correction of a source).

use coseg::studio::{Studio, StudioOptions};
use std::path::PathBuf;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let folder = PathBuf::from(args.first().expect("usage: bench_studio FOLDER [CACHE]"));
    let mut options = StudioOptions::default();
    options.propagate.cache_dir = args.get(1).map(PathBuf::from);
    let labels = tempfile::tempdir()?;
    options.labels_dir = Some(labels.path().to_path_buf());
    let t = Instant::now();
    let mut s = Studio::open(&folder, &options)?;
    println!(
        "open: {} shapes in {:.2} s",
        s.len(),
        t.elapsed().as_secs_f64()
    );
    for _ in 0..4 {
        s.add_part("part")?;
    }
    let patches = *s.patches(0)?.iter().max().unwrap_or(&0) + 1;
    let mut times = Vec::new();
    for q in 0..patches {
        let t = Instant::now();
        s.label_patch(0, q, (q % 4) as i32)?;
        let reply = serde_json::to_vec(&serde_json::json!({ "labels": s.labels(0)? }))?;
        std::hint::black_box(reply);
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    println!(
        "click on a patch (label + reply), {} clicks on {} vertices: median {:.2} ms, max {:.2} ms",
        times.len(),
        s.mesh(0)?.vertex_count(),
        times[times.len() / 2],
        times[times.len() - 1]
    );
    let t = Instant::now();
    let first = s.propagate(|_| {})?;
    println!(
        "first propagation (full: {}): {:.2} s",
        first.full,
        t.elapsed().as_secs_f64()
    );
    s.label_patch(1, 0, 1)?;
    time_propagation(&mut s, "a one-shape change")?;
    // A correction of a shape that is already a source: no new (source, target) pair, so the
    // rigid route's registrations are all kept from the runs before.
    if s.label_patch(1, 1, 3)?.changed == 0 {
        s.label_patch(1, 1, 2)?;
    }
    time_propagation(&mut s, "a correction of a source")?;
    let t = Instant::now();
    let png = s.thumbnail(0, 160)?;
    println!(
        "thumbnail 160 px: {:.1} ms ({} bytes)",
        t.elapsed().as_secs_f64() * 1e3,
        png.len()
    );
    Ok(())
}

/// Times an incremental propagation and prints it, after `change`.
fn time_propagation(s: &mut Studio, change: &str) -> anyhow::Result<()> {
    let t = Instant::now();
    let run = s.propagate(|_| {})?;
    println!(
        "propagation after {change} (full: {}, {} transports): {:.3} s",
        run.full,
        run.transports,
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
