//! Speed of the alignment stage (run on a shared machine: report it as such).
//!
//! ```text
//! # Every mesh registered onto the first one (each a moved copy of itself with --self).
//! cargo run --release --example bench_align -- pairs [--self] MESH...
//! ```

use coseg::align::{RegisterOptions, register_pair};
use coseg::mesh::read_mesh;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let own = args.iter().any(|a| a == "--self");
    let files: Vec<&String> = args[1..].iter().filter(|a| !a.starts_with("--")).collect();
    let meshes = files.iter().map(read_mesh).collect::<Result<Vec<_>, _>>()?;
    let o = RegisterOptions::default();
    let mut total = 0.0;
    let mut worst = 0.0f64;
    for (f, m) in files.iter().zip(&meshes) {
        let source = if own { m } else { &meshes[0] };
        let t = Instant::now();
        let r = register_pair(source, m, &o)?;
        let s = t.elapsed().as_secs_f64();
        total += s;
        worst = worst.max(s);
        println!(
            "{f}\t{} vertices\t{s:.3} s\tangle to the given frame {:.1}°\tresidual {:.4}\tinliers {:.3}\trunner-up {}",
            m.vertex_count(),
            r.transform
                .rotation_angle_to(&coseg::align::Similarity::identity()),
            r.residual,
            r.inlier_share,
            r.runner_up
                .map(|c| format!("{:.4} at {:.0}°", c.residual, c.angle_to_best))
                .unwrap_or_else(|| "-".into())
        );
    }
    println!(
        "{} pairs: mean {:.3} s, worst {worst:.3} s",
        meshes.len(),
        total / meshes.len() as f64
    );
    Ok(())
}
