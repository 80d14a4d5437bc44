//! Fixtures for the shape-graph tests: structured band tables and vertex permutations.

use coseg::bands::{BandTable, equal_count_bands};
use coseg::graph::{Cosegmentation, RegionTuple, ShapeNode};
use coseg::mesh::TriMesh;
use coseg::parts::PartCues;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{Rng, SeedableRng};

fn uniform(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// A band table of a "shape" whose vertices sit on a closed curve: feature `k` is a smooth
/// periodic function of the position (random frequency 1–3 and phase) plus `noise` × uniform
/// noise, cut into `bands` equal-count bands. Nearby vertices share bands, so stable regions
/// are arcs.
pub fn curve_table(
    vertices: usize,
    features: usize,
    bands: usize,
    noise: f64,
    seed: u64,
) -> BandTable {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut values = vec![0.0; features * vertices];
    for k in 0..features {
        let freq = 1.0 + (rng.next_u64() % 3) as f64;
        let phase = uniform(&mut rng) * std::f64::consts::TAU;
        for v in 0..vertices {
            let x = v as f64 / vertices as f64 * std::f64::consts::TAU;
            values[k * vertices + v] = (freq * x + phase).sin() + noise * uniform(&mut rng);
        }
    }
    equal_count_bands(&values, features, vertices, bands).unwrap()
}

/// A seeded random permutation of `0..n`.
pub fn permutation(n: usize, seed: u64) -> Vec<u32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut p: Vec<u32> = (0..n as u32).collect();
    for i in (1..n).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        p.swap(i, j);
    }
    p
}

/// The table with vertex `v` moved to index `perm[v]`.
pub fn permute_table(t: &BandTable, perm: &[u32]) -> BandTable {
    let mut labels = vec![0u8; t.labels.len()];
    for (v, &p) in perm.iter().enumerate().take(t.vertices) {
        let d = p as usize;
        labels[d * t.features..(d + 1) * t.features].copy_from_slice(t.row(v));
    }
    BandTable {
        labels,
        ..t.clone()
    }
}

/// Per-vertex values moved like [`permute_table`].
pub fn permute_values<T: Copy + Default>(x: &[T], perm: &[u32]) -> Vec<T> {
    let mut out = vec![T::default(); x.len()];
    for (v, &val) in x.iter().enumerate() {
        out[perm[v] as usize] = val;
    }
    out
}

/// Seeded positive weights in `[0.5, 1.5)`.
pub fn random_weights(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| 0.5 + uniform(&mut rng)).collect()
}

/// A co-segmentation of `meshes` (one shape each, a star graph rooted at shape 0) whose tuple
/// `t` is region `parts[i][t]` on shape `i`: given regions, not found by the sweeps (area
/// fractions 0, confidence 1).
pub fn coseg_of(meshes: &[TriMesh], parts: &[Vec<Vec<u32>>]) -> Cosegmentation {
    let n = meshes.len();
    let tuples = (0..parts[0].len())
        .map(|t| RegionTuple::given(parts.iter().map(|p| p[t].clone()).collect(), vec![0.0; n]))
        .collect();
    Cosegmentation {
        names: (0..n).map(|i| format!("s{i}")).collect(),
        vertices: meshes.iter().map(TriMesh::vertex_count).collect(),
        root: 0,
        order: (0..n).collect(),
        parent: (0..n).map(|i| (i > 0).then_some(0)).collect(),
        alpha: 0.1,
        tuples,
    }
}

/// Part cues that make every geometric merge cost 0: thickness 1 and mean curvature 1 (convex)
/// at every vertex of each mesh.
pub fn uniform_cues(meshes: &[TriMesh]) -> Vec<PartCues> {
    meshes
        .iter()
        .map(|m| PartCues {
            thickness: vec![1.0; m.vertex_count()],
            mean_curvature: vec![1.0; m.vertex_count()],
        })
        .collect()
}

/// The shape graph's nodes of `meshes` through the per-shape pipeline `options`, named
/// `{prefix}0`, `{prefix}1`, …
pub fn shape_nodes(
    meshes: &[TriMesh],
    options: &coseg::pipeline::ShapePipelineOptions,
    prefix: &str,
) -> Vec<ShapeNode> {
    meshes
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let d = coseg::pipeline::compute_shape_data(m, options).unwrap();
            ShapeNode::new(format!("{prefix}{i}"), d.bands, &d.descriptors.vertex_areas).unwrap()
        })
        .collect()
}
