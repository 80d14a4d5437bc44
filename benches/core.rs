//! Criterion benchmarks of the kernels a pair runs, on seeded generated inputs (no data files):
//! the band-affinity product `W·x` at several sizes and feature counts, Algorithm 2, the
//! spectrum, ZoomOut and the auction of its last match.
//!
//! ```text
//! cargo bench --bench core            # all, ~1 min
//! cargo bench --bench core -- affinity
//! ```

use coseg::affinity::BandAffinity;
use coseg::bands::{BandTable, equal_count_bands};
use coseg::maps::{
    AuctionOptions, CandidateLists, ShapeGeometry, ZoomOutOptions, auction_assignment, zoomout,
};
use coseg::mesh::TriMesh;
use coseg::spectral::{SpectrumOptions, laplace_beltrami_spectrum};
use coseg::stable::{StableRegionsOptions, stable_pairs_fixed};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;

/// A deterministic stream of numbers in [0, 1) (SplitMix64).
struct Seeded(u64);

impl Seeded {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A `features × vertices` band table of smooth random features (sines of random
/// projections of points on a unit square) with 20 bands.
fn table(vertices: usize, features: usize, seed: u64) -> BandTable {
    let mut r = Seeded(seed);
    let points: Vec<(f64, f64)> = (0..vertices).map(|_| (r.next(), r.next())).collect();
    let mut values = Vec::with_capacity(vertices * features);
    for _ in 0..features {
        let (a, b, f) = (r.next() - 0.5, r.next() - 0.5, 1.0 + 6.0 * r.next());
        values.extend(points.iter().map(|&(x, y)| (f * (a * x + b * y)).sin()));
    }
    equal_count_bands(&values, features, vertices, 20).expect("finite features")
}

/// An `n × n` grid of unit squares, each cut into two triangles, gently bent.
fn grid(n: u32) -> TriMesh {
    let pos = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64, (i / n) as f64);
            [x, y, 0.1 * (x * 0.3).sin() * (y * 0.2).cos()]
        })
        .collect();
    let mut faces = Vec::new();
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let v = y * n + x;
            faces.push([v, v + 1, v + n + 1]);
            faces.push([v, v + n + 1, v + n]);
        }
    }
    TriMesh::new(pos, faces).expect("a valid grid")
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

fn algorithm_2(c: &mut Criterion) {
    let (ta, tb) = (table(5_000, 50, 3), table(5_000, 50, 4));
    let w = BandAffinity::new(&ta, &tb).expect("equal feature counts");
    let areas = vec![1.0 / 5_000.0; 5_000];
    let options = StableRegionsOptions::default();
    c.bench_function("algorithm_2/5000v_50f", |b| {
        b.iter(|| stable_pairs_fixed(&w, &areas, &areas, black_box(&options)).expect("runs"))
    });
}

fn spectrum_and_map(c: &mut Criterion) {
    let mesh = grid(50);
    let options = {
        let mut opts = SpectrumOptions::default();
        opts.eigenpairs = 40;
        opts
    };
    c.bench_function("spectrum/2500v_k40", |b| {
        b.iter(|| laplace_beltrami_spectrum(black_box(&mesh), &options).expect("solves"))
    });
    let spectrum = laplace_beltrami_spectrum(&mesh, &options).expect("solves");
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
    let mut r = Seeded(5);
    let (queries, per_query) = (20_000usize, 16usize);
    let mut targets = Vec::with_capacity(queries * per_query);
    let mut costs = Vec::with_capacity(queries * per_query);
    for q in 0..queries {
        let mut cost = r.next();
        for _ in 0..per_query {
            let t = (q as f64 + 200.0 * (r.next() - 0.5)).clamp(0.0, queries as f64 - 1.0);
            targets.push(t as u32);
            costs.push(cost);
            cost += r.next();
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

fn config() -> Criterion {
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
}

criterion_group! {
    name = benches;
    config = config();
    targets = affinity, algorithm_2, spectrum_and_map
}
criterion_main!(benches);
