//! One point of the scaling study (issue #19, `docs/SCALING.md`), printed as one CSV line;
//! `scripts/scaling_study.sh` runs every point in its own process.
//!
//! ```text
//! RAYON_NUM_THREADS=1 cargo run --release --example scaling_study -- wx VERTICES FEATURES [--repeats R]
//! RAYON_NUM_THREADS=1 cargo run --release --example scaling_study -- alg2 VERTICES FEATURES [--repeats R]
//! cargo run --release --example scaling_study -- refine IN.obj N OUT.obj
//! cargo run --release --example scaling_study -- header
//! ```
//! `wx`: one `W·x` (the band-affinity apply, f64 `x` on every vertex of A) between two seeded
//! synthetic band tables (`coseg::bands::synthetic_band_table`, 20 bands, no spectrum) of
//! `VERTICES` vertices and `FEATURES` features each; `alg2`: one Algorithm 2 (defaults: 10 %
//! area cutoff, 10 pairs, uniform areas) on the same tables. Each is run `R` times (default 20
//! for `wx`, 3 for `alg2`); the line gives the fastest and the median wall time, the CPU time
//! of the fastest run (all threads of the process, from `/proc/self/task/*/schedstat`, ns), the
//! bytes of the two tables, the resident size once the tables are built and the peak resident
//! size while the operator is built and applied (`VmHWM` after resetting it by writing 5 to
//! `/proc/self/clear_refs`, so the making of the tables does not count) and, for `alg2`, the
//! regions found and the Algorithm-1 rounds they took.
//! `refine`: writes the mesh refined by `coseg::generate::refine_mesh` (each triangle into N²)
//! to `OUT.obj` and prints the vertex counts.

use coseg::affinity::BandAffinity;
use coseg::bands::synthetic_band_table;
use coseg::generate::refine_mesh;
use coseg::mesh::{read_mesh, write_mesh};
use coseg::stable::{StableRegionsOptions, stable_pairs_fixed};
use std::time::Instant;

/// CPU time of every thread of this process so far, in seconds.
fn process_cpu() -> f64 {
    let mut ns = 0u64;
    if let Ok(tasks) = std::fs::read_dir("/proc/self/task") {
        for t in tasks.flatten() {
            if let Ok(s) = std::fs::read_to_string(t.path().join("schedstat")) {
                ns += s
                    .split_whitespace()
                    .next()
                    .and_then(|x| x.parse::<u64>().ok())
                    .unwrap_or(0);
            }
        }
    }
    ns as f64 * 1e-9
}

/// A `kB` field of `/proc/self/status` (`VmRSS`, `VmHWM`).
fn status_kb(field: &str) -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with(field))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|x| x.parse().ok())
        })
        .unwrap_or(0)
}

/// Runs `f` `repeats` times: (fastest wall s, median wall s, CPU s of the fastest run).
fn timed(repeats: usize, mut f: impl FnMut()) -> (f64, f64, f64) {
    let mut runs: Vec<(f64, f64)> = (0..repeats.max(1))
        .map(|_| {
            let (c, t) = (process_cpu(), Instant::now());
            f();
            (t.elapsed().as_secs_f64(), process_cpu() - c)
        })
        .collect();
    runs.sort_by(|a, b| a.0.total_cmp(&b.0));
    (runs[0].0, runs[runs.len() / 2].0, runs[0].1)
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize| -> anyhow::Result<&str> {
        args.get(i)
            .map(String::as_str)
            .ok_or_else(|| anyhow::anyhow!("see the usage in examples/scaling_study.rs"))
    };
    match arg(0)? {
        "header" => {
            println!(
                "kind,vertices,features,table_bytes,wall_min_s,wall_median_s,cpu_s,rss_tables_kb,hwm_kb,threads,regions,rounds"
            );
        }
        "refine" => {
            let mesh = read_mesh(arg(1)?)?;
            let fine = refine_mesh(&mesh, arg(2)?.parse()?)?;
            write_mesh(arg(3)?, &fine, &[])?;
            println!(
                "{} -> {} vertices",
                mesh.vertex_count(),
                fine.vertex_count()
            );
        }
        kind @ ("wx" | "alg2") => {
            let (vertices, features): (usize, usize) = (arg(1)?.parse()?, arg(2)?.parse()?);
            let repeats = match args.iter().position(|a| a == "--repeats") {
                Some(i) => arg(i + 1)?.parse()?,
                None if kind == "wx" => 20,
                None => 3,
            };
            let ta = synthetic_band_table(vertices, features, 20, 1)?;
            let tb = synthetic_band_table(vertices, features, 20, 2)?;
            let rss_tables = status_kb("VmRSS:");
            std::fs::write("/proc/self/clear_refs", "5")?;
            let w = BandAffinity::new(&ta, &tb)?;
            let (best, median, cpu, (regions, rounds)) = if kind == "wx" {
                let mut ws = w.workspace();
                let x: Vec<f64> = (0..vertices).map(|p| (p % 17) as f64 + 0.5).collect();
                let mut out = vec![0.0; vertices];
                let (b, m, c) = timed(repeats, || {
                    w.apply(&x, &mut out, &mut ws).expect("sizes match");
                });
                (b, m, c, (0, 0))
            } else {
                let areas = vec![1.0 / vertices as f64; vertices];
                let options = StableRegionsOptions::default();
                let mut found = (0, 0);
                let (b, m, c) = timed(repeats, || {
                    let r = stable_pairs_fixed(&w, &areas, &areas, &options).expect("runs");
                    found = (r.pairs.len(), r.pairs.iter().map(|p| p.iterations).sum());
                });
                (b, m, c, found)
            };
            println!(
                "{kind},{vertices},{features},{},{best:.6},{median:.6},{cpu:.6},{rss_tables},{},{},{regions},{rounds}",
                ta.labels.len() + tb.labels.len(),
                status_kb("VmHWM:"),
                rayon::current_num_threads()
            );
        }
        other => anyhow::bail!("unknown command {other}: see examples/scaling_study.rs"),
    }
    Ok(())
}
