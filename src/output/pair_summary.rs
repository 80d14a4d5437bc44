//! [`PairSummary`]: the `summary.json` of a two-shape stable-region run.

use crate::maps::MapGuidedOptions;
use crate::maps::PresetChoice;
use crate::stable::{
    RefineOptions, SegmentPairOptions, SegmentedPair, StableRegions, StableRegionsOptions,
    StageFallback,
};
use serde::Serialize;

/// One shape of a pair run.
#[derive(Debug, Clone, Serialize)]
pub struct ShapeSummary {
    /// Output name (file stem).
    pub name: String,
    /// Input mesh file.
    pub file: String,
    /// Vertex count.
    pub vertices: usize,
    /// Surface area in the mesh's units.
    pub area: f64,
}

/// One region pair's statistics.
#[derive(Debug, Clone, Serialize)]
pub struct RegionSummary {
    /// Region id (line value in the `.regions.txt` files).
    pub id: usize,
    /// Vertices of the region on A and on B.
    pub vertices: [usize; 2],
    /// Area fractions of the region on A and on B (of each shape's total area).
    pub area_fractions: [f64; 2],
    /// `Σ W` over the pair.
    pub objective: f64,
    /// Algorithm 1 rounds of the final run.
    pub iterations: usize,
    /// Whether the final run reached a fixed point.
    pub converged: bool,
    /// The leftover pair.
    pub leftover: bool,
    /// Algorithm 3's `t` (absent for Algorithm 2).
    pub t: Option<f64>,
    /// Algorithm 3's `α` (absent for Algorithm 2).
    pub alpha: Option<f64>,
}

/// Contents of `summary.json` for `coseg pair`.
#[derive(Debug, Clone, Serialize)]
pub struct PairSummary {
    /// Always `"pair"`.
    pub command: &'static str,
    /// Version of coseg that wrote the file.
    pub version: &'static str,
    /// The two shapes, A then B.
    pub shapes: [ShapeSummary; 2],
    /// The options used.
    pub options: StableRegionsOptions,
    /// The boundary refinement applied after the algorithm, if any (then `iterations` and
    /// `converged` of every region report the refinement's rounds).
    pub refine: Option<RefineOptions>,
    /// The map-guided refinement of B's regions applied last, if any (see
    /// [`map_guided_refinement`](crate::stable::map_guided_refinement)).
    pub map_guided: Option<MapGuidedOptions>,
    /// Which preset the map step's options came from and the pair's eigenvalue discrepancy
    /// (see [`map_preset`](crate::maps::map_preset)), when the step ran.
    pub map_preset: Option<PresetChoice>,
    /// The requested optional stages (`refine`, `map_guided`) that could not run on these
    /// shapes and left the previous stage's regions, each with the reason; empty when every
    /// requested stage ran (see [`segment_pair`](crate::stable::segment_pair)).
    pub fallbacks: Vec<StageFallback>,
    /// Per-region statistics, in region-id order.
    pub regions: Vec<RegionSummary>,
    /// Correspondence ratio against the given ground truth, if any (fraction in `[0, 1]`).
    pub correspondence_ratio: Option<f64>,
    /// Seconds spent in the stable-region algorithm (excluding per-shape data). Not written
    /// to `summary.json`, so that the same inputs give the same file byte for byte (the CLI
    /// prints it instead).
    #[serde(skip)]
    pub seconds: f64,
}

impl PairSummary {
    /// Builds the summary of `regions` between `shapes`.
    ///
    /// ```
    /// use coseg::output::{PairSummary, ShapeSummary};
    /// use coseg::stable::{StableRegions, StableRegionsOptions};
    /// let s = |n: &str| ShapeSummary { name: n.into(), file: format!("{n}.off"), vertices: 0, area: 1.0 };
    /// let r = StableRegions { vertices_a: 0, vertices_b: 0, pairs: vec![] };
    /// let sum = PairSummary::new([s("a"), s("b")], &r, &StableRegionsOptions::default(), None, 0.5);
    /// assert!(serde_json::to_string(&sum).unwrap().contains("\"regions\":[]"));
    /// ```
    pub fn new(
        shapes: [ShapeSummary; 2],
        regions: &StableRegions,
        options: &StableRegionsOptions,
        correspondence_ratio: Option<f64>,
        seconds: f64,
    ) -> Self {
        let regions = regions
            .pairs
            .iter()
            .enumerate()
            .map(|(id, p)| RegionSummary {
                id,
                vertices: [p.region_a.len(), p.region_b.len()],
                area_fractions: [p.area_fraction_a, p.area_fraction_b],
                objective: p.objective,
                iterations: p.iterations,
                converged: p.converged,
                leftover: p.leftover,
                t: p.auto.map(|a| a.t),
                alpha: p.auto.map(|a| a.alpha),
            })
            .collect();
        Self {
            command: "pair",
            version: env!("CARGO_PKG_VERSION"),
            shapes,
            options: options.clone(),
            refine: None,
            map_guided: None,
            map_preset: None,
            fallbacks: Vec::new(),
            regions,
            correspondence_ratio,
            seconds,
        }
    }

    /// The summary of a [`segment_pair`](crate::stable::segment_pair) run, `pair`, with
    /// `options` (what `coseg pair` writes): [`PairSummary::new`] on the pair's regions with its
    /// refinement, map step, preset and fallbacks recorded.
    pub fn of_pair(
        shapes: [ShapeSummary; 2],
        pair: &SegmentedPair,
        options: &SegmentPairOptions,
        correspondence_ratio: Option<f64>,
        seconds: f64,
    ) -> Self {
        Self {
            refine: options.refine.clone(),
            map_guided: pair.map_guided.clone(),
            map_preset: pair.map_preset,
            fallbacks: pair.fallbacks.clone(),
            ..Self::new(
                shapes,
                &pair.regions,
                &options.regions,
                correspondence_ratio,
                seconds,
            )
        }
    }
}
