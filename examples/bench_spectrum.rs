//! Benchmark of the sparse Laplace–Beltrami eigensolver (not a test).
//!
//! ```text
//! cargo run --release --example bench_spectrum -- [-k 100,200] [--repeat 3] [--threads 1] MESH...
//! ```
//! For every mesh and k: the median wall-clock seconds of `laplace_beltrami_spectrum` over the
//! repeats (mesh reading excluded), the phase breakdown of the last run, and the first and last
//! eigenvalues (to compare with `scripts/scipy_spectrum.py`).

use coseg::mesh::read_mesh;
use coseg::spectral::{SpectrumOptions, laplace_beltrami_spectrum_with_stats};
use std::time::Instant;

fn main() {
    let mut ks = vec![100usize, 200];
    let mut repeat = 3usize;
    let mut threads = SpectrumOptions::default().threads;
    let mut meshes = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "-k" => {
                ks = args
                    .next()
                    .expect("-k needs a list")
                    .split(',')
                    .map(|x| x.parse().expect("k must be an integer"))
                    .collect()
            }
            "--repeat" => {
                repeat = args
                    .next()
                    .and_then(|x| x.parse().ok())
                    .expect("--repeat N")
            }
            "--threads" => {
                threads = args
                    .next()
                    .and_then(|x| x.parse().ok())
                    .expect("--threads N")
            }
            _ => meshes.push(a),
        }
    }
    for path in &meshes {
        let mesh = match read_mesh(path) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("skipping {path}: {e}");
                continue;
            }
        };
        for &k in &ks {
            let opts = {
                let mut opts = SpectrumOptions::with_eigenpairs(k);
                opts.threads = threads;
                opts
            };
            let mut times = Vec::new();
            let mut last = None;
            for _ in 0..repeat.max(1) {
                let t = Instant::now();
                let r = laplace_beltrami_spectrum_with_stats(&mesh, &opts).expect("spectrum");
                times.push(t.elapsed().as_secs_f64());
                last = Some(r);
            }
            let (s, stats) = last.expect("at least one run");
            let mut sorted = times.clone();
            sorted.sort_by(|a, b| a.total_cmp(b));
            let runs: Vec<String> = times.iter().map(|t| format!("{t:.3}")).collect();
            println!(
                "{path}: {} vertices, k={k}, threads={threads}: median {:.3} s (runs: {})",
                mesh.vertex_count(),
                sorted[sorted.len() / 2],
                runs.join(" ")
            );
            println!(
                "  setup {:.3} s, lanczos {:.3} s, verify {:.3} s, polish {:.3} s; factor nnz {}, \
                 {} applications, {} restarts, {} attempt(s)",
                stats.seconds_setup,
                stats.seconds_lanczos,
                stats.seconds_verify,
                stats.seconds_polish,
                stats.factor_nnz,
                stats.applications,
                stats.restarts,
                stats.attempts
            );
            let first: Vec<String> = s
                .eigenvalues
                .iter()
                .take(8)
                .map(|v| format!("{v:.9e}"))
                .collect();
            println!("  first eigenvalues: {}", first.join(" "));
            println!("  last eigenvalue: {:.9e}", s.eigenvalues[k - 1]);
        }
    }
}
