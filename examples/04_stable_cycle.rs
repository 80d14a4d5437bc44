//! The cycle solver the method is named for: stable regions around a cycle of three shapes,
//! fixed points of `P_1 ∘ W_13 ∘ P_3 ∘ W_32 ∘ P_2 ∘ W_21` (docs/METHOD.md §5).
//!
//! ```sh
//! cargo run --release --example 04_stable_cycle -- \
//!     collections/quadrupeds/quadrupeds_00.obj collections/quadrupeds/quadrupeds_01.obj \
//!     collections/quadrupeds/quadrupeds_02.obj
//! ```
//!
//! As Algorithm 2 does for two shapes, region triples are extracted one after another, each
//! covering `α` = 1/R of every shape's area and removed before the next is sought; the last is
//! the leftovers. Each triple is a fixed point of the whole cycle: shape 1's region, carried to
//! 2, thresholded, carried to 3, thresholded and carried back, selects itself. `coseg segment`
//! solves the same equations over a whole shape graph by sweeps instead of one cycle
//! (`coseg::graph::cosegment`, whose module docs argue why).
//!
//! With a `manifest.json` next to the meshes (the shipped collections), each triple's majority
//! part on every shape is printed: a consistent triple names the same part three times.

use coseg::affinity::{BandAffinity, Direction};
use coseg::evaluate::GroundTruth;
use coseg::graph::{CycleShape, CycleStep, StableCycleOptions, stable_cycle};
use coseg::mesh::read_mesh;
use coseg::pipeline::{ShapePipelineOptions, compute_shape_data};
use coseg::stable::{Init, Threshold, initial_indicator};
use std::path::Path;

/// Number of regions per shape, the last being the leftovers.
const REGIONS: usize = 5;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        paths = (0..3)
            .map(|i| format!("collections/quadrupeds/quadrupeds_0{i}.obj"))
            .collect();
    }
    if paths.len() != 3 {
        return Err("give three meshes (or none for the shipped quadrupeds)".into());
    }
    let pipeline = ShapePipelineOptions::default();
    let mut data = Vec::new();
    for p in &paths {
        let mesh = read_mesh(p)?;
        data.push(compute_shape_data(&mesh, &pipeline)?);
    }
    // Unit-area vertex areas: α is a share of each shape whatever its file units.
    let areas: Vec<&[f64]> = data.iter().map(|d| &d.spectrum.vertex_areas[..]).collect();
    // W_21 carries shape 1 to 2, W_32 shape 2 to 3, W_13 shape 3 back to 1.
    let w12 = BandAffinity::new(&data[0].bands, &data[1].bands)?;
    let w23 = BandAffinity::new(&data[1].bands, &data[2].bands)?;
    let w13 = BandAffinity::new(&data[0].bands, &data[2].bands)?;
    let steps = [
        CycleStep {
            affinity: &w12,
            direction: Direction::AtoB,
        },
        CycleStep {
            affinity: &w23,
            direction: Direction::AtoB,
        },
        CycleStep {
            affinity: &w13,
            direction: Direction::BtoA,
        },
    ];
    let mut remaining: Vec<Vec<u32>> = data
        .iter()
        .map(|d| (0..d.bands.vertices as u32).collect())
        .collect();
    let alpha = 1.0 / REGIONS as f64;
    let mut triples = Vec::new();
    for r in 0..REGIONS - 1 {
        let shapes: Vec<CycleShape<'_>> = (0..3)
            .map(|i| CycleShape {
                remaining: &remaining[i],
                areas: areas[i],
                reference_area: 1.0,
                rule: Threshold::AreaFraction(alpha),
            })
            .collect();
        // Start from shape 1's most distinctive remaining vertex, as Algorithm 2 does.
        let f0 = initial_indicator(&w12, &remaining[0], Init::Extreme, 0, r);
        let c = stable_cycle(&shapes, &steps, &f0, &StableCycleOptions::default())?;
        println!(
            "triple {r}: {} rounds, {}, closing mass {:.3e}",
            c.iterations,
            if c.converged {
                "a fixed point of the cycle"
            } else {
                "best visited (not converged)"
            },
            c.objective
        );
        for (rem, region) in remaining.iter_mut().zip(&c.regions) {
            rem.retain(|v| region.binary_search(v).is_err());
        }
        triples.push(c.regions);
    }
    triples.push(remaining);

    let folder = Path::new(&paths[0]).parent().unwrap_or(Path::new("."));
    let Ok(truth) = GroundTruth::read(folder) else {
        println!("no manifest.json next to {}: no parts to compare", paths[0]);
        return Ok(());
    };
    let mut parts = Vec::new();
    for p in &paths {
        let stem = Path::new(p).file_stem().unwrap().to_string_lossy();
        parts.push(truth.grouped_labels(&stem)?);
    }
    println!("triple  majority part (share of the region's area) on shapes 1, 2, 3");
    for (r, triple) in triples.iter().enumerate() {
        let mut line = format!("{r:>6} ");
        for (i, region) in triple.iter().enumerate() {
            let mut by_part = vec![0.0; parts[i].iter().max().map_or(0, |m| m + 1)];
            for &v in region {
                by_part[parts[i][v as usize]] += areas[i][v as usize];
            }
            let total: f64 = by_part.iter().sum();
            let (best, share) = by_part
                .iter()
                .enumerate()
                .fold((0, 0.0), |b, (p, &a)| if a > b.1 { (p, a) } else { b });
            line += &format!(
                "  part {best} ({:.0} %)",
                100.0 * share / total.max(f64::MIN_POSITIVE)
            );
        }
        if r == triples.len() - 1 {
            line += "  leftovers";
        }
        println!("{line}");
    }
    Ok(())
}
