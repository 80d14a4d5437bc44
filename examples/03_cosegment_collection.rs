//! Co-segment a whole shipped family and score the parts found against its ground truth.
//!
//! ```sh
//! cargo run --release --example 03_cosegment_collection -- quadrupeds   # or humanoids, goblets, chairs
//! ```
//!
//! Every shape of `collections/<family>/` is loaded through the per-shape cache;
//! `segment_collection` links them in a shape graph, finds region tuples with `cosegment`
//! (region `r` is the same part on every shape) and cleans their boundaries with
//! `refine_cosegmentation`, exactly as `coseg segment` does. Purity: how much of each region lies in one
//! ground-truth part. Coverage: how much of each part one region covers, on all shapes at once.

use coseg::evaluate::{GroundTruth, ShapeParts, part_coverage, part_purity};
use coseg::graph::{Cosegmentation, LoadedCollection, load_collection};
use coseg::parts::{SegmentCollectionOptions, segment_collection};
use coseg::pipeline::ShapePipelineOptions;
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

    // Region tuples across the family, then boundary refinement over every graph edge (the
    // defaults); and, for comparison, the raw tuples.
    let options = SegmentCollectionOptions::equal_areas(6);
    let refined = segment_collection(loaded.nodes.clone(), &loaded.meshes, &options)?.segmentation;
    let raw = {
        let mut opts = options;
        opts.refine = None;
        opts
    };
    let seg = segment_collection(loaded.nodes.clone(), &loaded.meshes, &raw)?.segmentation;

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
