//! Criterion benchmarks of the kernels a pair and a collection run, on seeded generated inputs
//! (no data files; `coseg::generate`'s synthetic band tables, grid and shape families): the
//! band-affinity product `W·x` at several sizes and feature counts, Algorithms 1, 2 and 3, the
//! stable cycle over 3 shapes, the co-segmentation sweep of a generated collection, the
//! spectrum, the descriptors (HKS, WKS, curvature), ZoomOut, the clustered candidate search of
//! the last match and its auction, and a warm `coseg propagate` (every route, the cache filled
//! by a first run).
//!
//! ```text
//! cargo bench --bench core            # all, ~3 min
//! cargo bench --bench core -- affinity
//! ```

use coseg::affinity::{BandAffinity, Direction};
use coseg::bands::{BandTable, synthetic_band_table};
use coseg::features::{DescriptorOptions, descriptors};
use coseg::generate::{
    Family, GenerateOptions, SplitMix64, generate_family, grid_mesh, smooth_features,
    write_collection,
};
use coseg::graph::{
    CosegmentOptions, CycleShape, CycleStep, GraphOptions, ShapeGraph, ShapeNode,
    StableCycleOptions, cosegment, stable_cycle,
};
use coseg::maps::{
    AuctionOptions, CandidateLists, ShapeGeometry, ZoomOutOptions, auction_assignment,
    nearest_candidates, zoomout,
};
use coseg::pipeline::{ShapePipelineOptions, compute_shape_data};
use coseg::propagate::{PropagateCollectionOptions, propagate_collection};
use coseg::spectral::{SpectrumOptions, laplace_beltrami_spectrum};
use coseg::stable::{
    Algorithm, Remaining, StablePairOptions, StableRegionsOptions, Threshold, stable_pair,
    stable_pairs_auto, stable_pairs_fixed,
};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::Mat;
use std::hint::black_box;
use std::time::Duration;

/// The synthetic `features × vertices` band table of the benchmarks (20 bands).
fn table(vertices: usize, features: usize, seed: u64) -> BandTable {
    synthetic_band_table(vertices, features, 20, seed).expect("finite features")
}

fn affinity(c: &mut Criterion) {
    let mut g = c.benchmark_group("affinity_apply");
    for &(vertices, features) in &[(2_000, 10), (2_000, 100), (20_000, 10), (20_000, 100)] {
        let (ta, tb) = (table(vertices, features, 1), table(vertices, features, 2));
        let w = BandAffinity::new(&ta, &tb).expect("equal feature counts");
        let mut ws = w.workspace();
        let x: Vec<f64> = (0..vertices).map(|i| (i % 7) as f64).collect();
        let mut out = vec![0.0; vertices];
        g.bench_function(
            BenchmarkId::from_parameter(format!("{vertices}v_{features}f")),
            |bch| {
                bch.iter(|| {
                    w.apply(black_box(&x), &mut out, &mut ws)
                        .expect("sizes match")
                })
            },
        );
    }
    g.finish();
}

/// Algorithms 1, 2 and 3 between two synthetic 5,000-vertex shapes with 50 features, and the
/// stable cycle through a third.
fn pair_algorithms(c: &mut Criterion) {
    let n = 5_000;
    let (ta, tb, tc) = (table(n, 50, 3), table(n, 50, 4), table(n, 50, 6));
    let w = BandAffinity::new(&ta, &tb).expect("equal feature counts");
    let areas = vec![1.0 / n as f64; n];
    let all: Vec<u32> = (0..n as u32).collect();
    let remaining = Remaining {
        vertices_a: &all,
        vertices_b: &all,
        areas_a: &areas,
        areas_b: &areas,
        reference_area_a: 1.0,
        reference_area_b: 1.0,
    };
    // Algorithm 1 from the first 10 % of A (α = 0.1 on both sides).
    let f0: Vec<u32> = (0..n as u32 / 10).collect();
    let options = StablePairOptions::default();
    c.bench_function("algorithm_1/5000v_50f", |b| {
        b.iter(|| stable_pair(&w, &remaining, black_box(&f0), &options).expect("runs"))
    });
    let options = StableRegionsOptions::default();
    c.bench_function("algorithm_2/5000v_50f", |b| {
        b.iter(|| stable_pairs_fixed(&w, &areas, &areas, black_box(&options)).expect("runs"))
    });
    let options = {
        let mut opts = StableRegionsOptions::default();
        opts.algorithm = Algorithm::Auto;
        opts
    };
    c.bench_function("algorithm_3/5000v_50f", |b| {
        b.iter(|| stable_pairs_auto(&w, &areas, &areas, black_box(&options)).expect("runs"))
    });
    // The cycle A → B → C → A with α = 0.1 on every shape.
    let (wbc, wca) = (
        BandAffinity::new(&tb, &tc).expect("equal feature counts"),
        BandAffinity::new(&tc, &ta).expect("equal feature counts"),
    );
    let shape = CycleShape {
        remaining: &all,
        areas: &areas,
        reference_area: 1.0,
        rule: Threshold::AreaFraction(0.1),
    };
    let steps = [&w, &wbc, &wca].map(|affinity| CycleStep {
        affinity,
        direction: Direction::AtoB,
    });
    let options = StableCycleOptions::default();
    c.bench_function("stable_cycle/3x5000v_50f", |b| {
        b.iter(|| stable_cycle(&[shape; 3], &steps, black_box(&f0), &options).expect("runs"))
    });
}

/// The co-segmentation sweep (`cosegment`, 6 regions) of 4 generated quadrupeds (per-shape data
/// with 40 eigenpairs, computed once outside the timing).
fn cosegmentation(c: &mut Criterion) {
    let collection = generate_family(Family::Quadrupeds, &{
        let mut opts = GenerateOptions::default();
        opts.count = 4;
        opts
    })
    .expect("generates");
    let mut pipeline = ShapePipelineOptions::default();
    pipeline.spectrum.eigenpairs = 40;
    let nodes: Vec<ShapeNode> = collection
        .shapes
        .iter()
        .map(|s| {
            let data = compute_shape_data(&s.mesh, &pipeline).expect("per-shape data");
            ShapeNode::new(s.name.clone(), data.bands, &s.mesh.vertex_areas()).expect("a node")
        })
        .collect();
    let vertices: usize = nodes.iter().map(|n| n.bands.vertices).sum();
    let graph = ShapeGraph::build(nodes, &GraphOptions::default()).expect("a graph");
    let options = CosegmentOptions::default();
    c.bench_function(&format!("cosegment/4_quadrupeds_{vertices}v"), |b| {
        b.iter(|| cosegment(&graph, black_box(&options)).expect("runs"))
    });
}

/// The last match's clustered candidate search (`nearest_candidates`, used from 8,192 base rows):
/// 10,000 query rows against 10,000 base rows of 60 smooth columns, 64 candidates each.
fn candidate_search(c: &mut Criterion) {
    let (rows, columns) = (10_000, 60);
    // Both row sets sample the same smooth functions at different random points.
    let values = smooth_features(2 * rows, columns, 7);
    let half =
        |offset: usize| Mat::from_fn(rows, columns, |i, j| values[j * 2 * rows + offset + i]);
    let (base, query) = (half(0), half(rows));
    c.bench_function("nearest_candidates/10000x10000_60d_64c", |b| {
        b.iter(|| nearest_candidates(base.as_ref(), black_box(query.as_ref()), 64))
    });
}

fn spectrum_and_map(c: &mut Criterion) {
    let mesh = grid_mesh(50).expect("a valid grid");
    let options = {
        let mut opts = SpectrumOptions::default();
        opts.eigenpairs = 40;
        opts
    };
    c.bench_function("spectrum/2500v_k40", |b| {
        b.iter(|| laplace_beltrami_spectrum(black_box(&mesh), &options).expect("solves"))
    });
    let spectrum = laplace_beltrami_spectrum(&mesh, &options).expect("solves");
    let features = DescriptorOptions::default();
    c.bench_function("descriptors/2500v_k40_300f", |b| {
        b.iter(|| descriptors(&mesh, black_box(&spectrum), &features).expect("computes"))
    });
    let shape = ShapeGeometry {
        spectrum: &spectrum,
        positions: mesh.positions(),
        descriptors: None,
    };
    let start: Vec<u32> = (0..mesh.vertex_count() as u32).rev().collect();
    let zo = {
        let mut opts = ZoomOutOptions::default();
        opts.final_size = 40;
        opts.samples = 500;
        opts
    };
    c.bench_function("zoomout/2500v_k10to40", |b| {
        b.iter(|| zoomout(shape, shape, black_box(&start), &zo).expect("runs"))
    });
    // The auction alone on candidate lists like ZoomOut's: 20,000 queries, 16 candidates.
    let mut r = SplitMix64(5);
    let (queries, per_query) = (20_000usize, 16usize);
    let mut targets = Vec::with_capacity(queries * per_query);
    let mut costs = Vec::with_capacity(queries * per_query);
    for q in 0..queries {
        let mut cost = r.next_f64();
        for _ in 0..per_query {
            let t = (q as f64 + 200.0 * (r.next_f64() - 0.5)).clamp(0.0, queries as f64 - 1.0);
            targets.push(t as u32);
            costs.push(cost);
            cost += r.next_f64();
        }
    }
    let lists = CandidateLists {
        per_query,
        targets,
        costs,
    };
    c.bench_function("auction/20000q_16c", |b| {
        b.iter(|| auction_assignment(black_box(&lists), queries, &AuctionOptions::default()))
    });
}

/// Bare `propagate_collection` (every route fused) on 6 generated chairs from one labelled
/// chair, warm: a first run outside the timing fills the cache folder (per-shape entries, the
/// part tree, the rigid route's pairs and the map route's point maps), each timed run reads it.
fn warm_propagate(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let mut options = GenerateOptions::default();
    options.count = 6;
    let collection = generate_family(Family::Chairs, &options).expect("generates");
    let shapes = dir.path().join("chairs");
    write_collection(&collection, &options, &shapes).expect("writes");
    let labels = [shapes.join(format!("{}.labels.txt", collection.shapes[0].name))];
    let mut o = PropagateCollectionOptions::default();
    o.cache_dir = Some(dir.path().join("cache"));
    propagate_collection(&shapes, &labels, &o).expect("cold run");
    c.bench_function("propagate/warm_6_chairs", |b| {
        b.iter(|| propagate_collection(&shapes, black_box(&labels), &o).expect("warm run"))
    });
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
}

criterion_group! {
    name = benches;
    config = config();
    targets = affinity, pair_algorithms, cosegmentation, spectrum_and_map, candidate_search,
        warm_propagate
}
criterion_main!(benches);
