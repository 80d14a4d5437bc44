//! Two shapes and their stable regions, scored against the ground-truth parts.
//!
//! ```sh
//! cargo run --release --example 02_stable_pair -- \
//!     collections/quadrupeds/quadrupeds_01.obj collections/quadrupeds/quadrupeds_03.obj
//! ```
//!
//! A stable region pair is a region on each shape that selects the other through the band
//! affinity (Algorithm 1 of the paper); Algorithm 2 extracts them one after another at 10 % of
//! each shape's area, the last pair being the leftovers. `coseg pair` then refines the region
//! boundaries, and last re-assigns B's vertices by band affinity plus a point map fitted to the
//! region pairs (the paper's §7.3 in reverse); every step is shown, with purity and coverage against the shipped parts
//! (left/right legs merged: an intrinsic method cannot tell mirror images apart).

use coseg::affinity::BandAffinity;
use coseg::evaluate::{GroundTruth, ShapeParts, part_coverage, part_purity};
use coseg::maps::ShapeGeometry;
use coseg::mesh::read_mesh;
use coseg::pipeline::{ShapePipelineOptions, compute_shape_data};
use coseg::spectral::HeatSmoother;
use coseg::stable::{
    PairShape, RefineOptions, SegmentPairOptions, StableRegions, StableRegionsOptions,
    map_guided_refinement, refine_regions, segment_pair, stable_regions,
};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let a = args
        .next()
        .unwrap_or_else(|| "collections/quadrupeds/quadrupeds_01.obj".into());
    let b = args
        .next()
        .unwrap_or_else(|| "collections/quadrupeds/quadrupeds_03.obj".into());

    // Per-shape work: spectrum, descriptors and band tables (`coseg` caches these on disk).
    let (mesh_a, mesh_b) = (read_mesh(&a)?, read_mesh(&b)?);
    let pipeline = ShapePipelineOptions::default();
    let (data_a, data_b) = (
        compute_shape_data(&mesh_a, &pipeline)?,
        compute_shape_data(&mesh_b, &pipeline)?,
    );
    let (areas_a, areas_b) = (mesh_a.vertex_areas(), mesh_b.vertex_areas());

    // One call: Algorithm 2 between the two band tables.
    let options = StableRegionsOptions::default();
    let regions = stable_regions(&data_a.bands, &data_b.bands, &areas_a, &areas_b, &options)?;

    // Boundary refinement, as `coseg pair` does by default.
    let refine = RefineOptions::default();
    let smoother_a = HeatSmoother::new(&mesh_a, refine.smoothing_time)?;
    let smoother_b = HeatSmoother::new(&mesh_b, refine.smoothing_time)?;
    let w = BandAffinity::new(&data_a.bands, &data_b.bands)?;
    let refined = refine_regions(
        &w,
        &regions,
        &areas_a,
        &areas_b,
        Some(&smoother_a),
        Some(&smoother_b),
        &refine,
    )?;

    // Last, as `coseg pair` does by default: B's regions re-assigned with a point map read from
    // a functional map fitted to the region pairs (smoothed more lightly than the refinement).
    // Its options depend on how near-isometric the pair is, which the spectra tell: the
    // library's default `MapStep::Auto` resolves them.
    let resolved = SegmentPairOptions::default()
        .map_step
        .resolve(&data_a.spectrum, &data_b.spectrum)?;
    let choice = resolved.preset.expect("the default map step runs");
    println!(
        "map step preset {:?} (eigenvalue discrepancy {:.4})",
        choice.preset, choice.discrepancy
    );
    let map_step = resolved.options.expect("the default map step runs");
    let map_smoother_b = HeatSmoother::new(&mesh_b, map_step.smoothing_time)?;
    let mapped = map_guided_refinement(
        &w,
        &refined,
        ShapeGeometry {
            spectrum: &data_a.spectrum,
            positions: mesh_a.positions(),
            descriptors: Some(&data_a.descriptors.values),
        },
        ShapeGeometry {
            spectrum: &data_b.spectrum,
            positions: mesh_b.positions(),
            descriptors: Some(&data_b.descriptors.values),
        },
        Some(&map_smoother_b),
        &map_step,
    )?;

    // The same three stages in one call, as `coseg pair` runs them.
    let one_call = segment_pair(
        PairShape {
            mesh: &mesh_a,
            spectrum: &data_a.spectrum,
            bands: &data_a.bands,
            descriptors: Some(&data_a.descriptors.values),
        },
        PairShape {
            mesh: &mesh_b,
            spectrum: &data_b.spectrum,
            bands: &data_b.bands,
            descriptors: Some(&data_b.descriptors.values),
        },
        &SegmentPairOptions::default(),
    )?;
    assert_eq!(one_call.regions, mapped);

    println!("region  area on A  area on B  (after refinement and the map step)");
    for (id, pair) in mapped.pairs.iter().enumerate() {
        println!(
            "{id:>6}  {:>8.1} %  {:>8.1} %{}",
            100.0 * pair.area_fraction_a,
            100.0 * pair.area_fraction_b,
            if pair.leftover { "  leftovers" } else { "" }
        );
    }

    // Ground truth: the manifest next to the meshes, if they come from `collections/`.
    let folder = Path::new(&a).parent().unwrap_or(Path::new("."));
    let Ok(truth) = GroundTruth::read(folder) else {
        println!("no manifest.json next to {a}: no ground truth to score against");
        return Ok(());
    };
    let stem = |p: &str| {
        Path::new(p)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned()
    };
    let (truth_a, truth_b) = (
        truth.grouped_labels(&stem(&a))?,
        truth.grouped_labels(&stem(&b))?,
    );
    let score = |r: &StableRegions| -> Result<(f64, f64), Box<dyn std::error::Error>> {
        let shapes = [
            ShapeParts::new(areas_a.clone(), truth_a.clone(), r.labels_a())?,
            ShapeParts::new(areas_b.clone(), truth_b.clone(), r.labels_b())?,
        ];
        Ok((part_purity(&shapes)?, part_coverage(&shapes)?))
    };
    println!("grouped parts: {}", truth.groups.names.join(", "));
    for (what, r) in [
        ("Algorithm 2", &regions),
        ("refined", &refined),
        ("map step", &mapped),
    ] {
        let (purity, coverage) = score(r)?;
        println!(
            "{what:>12}: purity {:.1} %, coverage {:.1} %",
            100.0 * purity,
            100.0 * coverage
        );
    }
    Ok(())
}
