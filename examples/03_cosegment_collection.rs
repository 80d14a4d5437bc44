//! Co-segment a whole shipped family and score the parts found against its ground truth.
//!
//! ```sh
//! cargo run --release --example 03_cosegment_collection -- quadrupeds   # or humanoids, goblets, chairs
//! ```
//!
//! Every shape of `collections/<family>/` is loaded through the per-shape cache; a shape graph
//! links them; `cosegment` finds region tuples (region `r` is the same part on every shape) and
//! `refine_cosegmentation` cleans their boundaries. Purity: how much of each region lies in one
//! ground-truth part. Coverage: how much of each part one region covers, on all shapes at once.

use coseg::cache::ShapePipelineOptions;
use coseg::evaluate::{GroundTruth, ShapeParts, part_coverage, part_purity};
use coseg::graph::{
    CosegmentOptions, Cosegmentation, GraphOptions, LoadedCollection, ShapeGraph, cosegment,
    load_collection, refine_cosegmentation,
};
use coseg::spectral::HeatSmoother;
use coseg::stable::RefineOptions;
use std::path::PathBuf;

fn score(
    loaded: &LoadedCollection,
    seg: &Cosegmentation,
    truth: &GroundTruth,
) -> Result<(f64, f64), Box<dyn std::error::Error>> {
    let mut shapes = Vec::new();
    for (i, mesh) in loaded.meshes.iter().enumerate() {
        let parts = truth.grouped_labels(&seg.names[i])?;
        shapes.push(ShapeParts::of_mesh(mesh, parts, seg.labels(i))?);
    }
    Ok((part_purity(&shapes)?, part_coverage(&shapes)?))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let family = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "quadrupeds".into());
    let folder = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("collections")
        .join(&family);
    let cache = std::env::temp_dir().join("coseg-example-cache");

    // Meshes → spectra, descriptors, band tables (cached: the second run skips this).
    let loaded = load_collection(
        &folder,
        &ShapePipelineOptions::default(),
        &cache,
        |_, _, _| {},
    )?;
    for skipped in &loaded.skipped {
        eprintln!("skipped: {}", skipped.error);
    }
    let graph = ShapeGraph::build(loaded.nodes.clone(), &GraphOptions::default())?;

    // Region tuples across the family, then boundary refinement over every graph edge.
    let seg = cosegment(&graph, &CosegmentOptions::default())?;
    let refine = RefineOptions::default();
    let smoothers = loaded
        .meshes
        .iter()
        .map(|m| HeatSmoother::new(m, refine.smoothing_time))
        .collect::<Result<Vec<_>, _>>()?;
    let refined = refine_cosegmentation(&graph, &seg, Some(&smoothers), &refine)?;

    println!(
        "{family}: {} shapes, {} regions, root {}",
        loaded.nodes.len(),
        refined.tuples.len(),
        refined.names[refined.root]
    );
    for (r, tuple) in refined.tuples.iter().enumerate() {
        let (lo, hi) = tuple
            .area_fractions
            .iter()
            .fold((f64::MAX, 0.0f64), |(lo, hi), &a| (lo.min(a), hi.max(a)));
        println!(
            "  region {r}: {:.1}–{:.1} % of each shape, confidence {:.2}{}",
            100.0 * lo,
            100.0 * hi,
            tuple.confidence,
            if tuple.leftover { ", leftovers" } else { "" }
        );
    }
    let truth = GroundTruth::read(&folder)?;
    println!("grouped parts: {}", truth.groups.names.join(", "));
    for (what, s) in [("co-segmentation", &seg), ("refined", &refined)] {
        let (purity, coverage) = score(&loaded, s, &truth)?;
        println!(
            "{what:>16}: purity {:.1} %, coverage {:.1} %",
            100.0 * purity,
            100.0 * coverage
        );
    }
    Ok(())
}
