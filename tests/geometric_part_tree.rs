//! Tests of the geometric part tree (`parts::geometric_part_tree`: thickness and boundary
//! concavity) and of `--parts N --parts-from geometry` (`SegmentCollectionOptions::parts_from`).

mod common;

use common::graph::{coseg_of, uniform_cues};
use coseg::bands::equal_count_bands;
use coseg::cache::CacheOutcome;
use coseg::graph::{Cosegmentation, GraphError, ShapeNode};
use coseg::mesh::TriMesh;
use coseg::parts::{
    FeatureSelection, PartCues, PartsFrom, SegmentCollectionOptions, StopReason,
    geometric_part_tree, geometric_part_tree_with_cues, load_or_compute_part_cues,
    segment_collection,
};

/// A column of octagonal rings along y, ring `k` at height `0.5 k` with radius `radius(k)`,
/// capped at both ends (the caps' centres are the last two vertices), plus, when `rod` is
/// given, a separate thin rod (8 rings of radius 0.2) at x = `rod`. Returns the mesh and the
/// vertices of each ring (the caps' centres with the end rings; the rod's rings after the
/// column's).
fn column(
    rings: usize,
    radius: impl Fn(usize) -> f64,
    rod: Option<f64>,
) -> (TriMesh, Vec<Vec<u32>>) {
    let mut p = Vec::new();
    let mut f = Vec::new();
    let mut ring_vertices = Vec::new();
    let mut tube = |p: &mut Vec<[f64; 3]>, x0: f64, rings: usize, r: &dyn Fn(usize) -> f64| {
        let o = p.len() as u32;
        for k in 0..rings {
            for j in 0..8 {
                let a = j as f64 * std::f64::consts::FRAC_PI_4;
                p.push([x0 + r(k) * a.cos(), k as f64 * 0.5, r(k) * a.sin()]);
            }
            ring_vertices.push((o + 8 * k as u32..o + 8 * (k as u32 + 1)).collect::<Vec<u32>>());
        }
        let (bottom, top) = (p.len() as u32, p.len() as u32 + 1);
        p.push([x0, 0.0, 0.0]);
        p.push([x0, 0.5 * (rings - 1) as f64, 0.0]);
        for k in 0..rings as u32 - 1 {
            for j in 0..8u32 {
                let (a, b) = (o + 8 * k + j, o + 8 * k + (j + 1) % 8);
                f.push([a, a + 8, b]);
                f.push([b, a + 8, b + 8]);
            }
        }
        let last = o + 8 * (rings as u32 - 1);
        for j in 0..8u32 {
            f.push([bottom, o + j, o + (j + 1) % 8]);
            f.push([top, last + (j + 1) % 8, last + j]);
        }
        let n = ring_vertices.len();
        ring_vertices[n - rings].push(bottom);
        ring_vertices[n - 1].push(top);
    };
    tube(&mut p, 0.0, rings, &radius);
    if let Some(x) = rod {
        tube(&mut p, x, 8, &|_| 0.2);
    }
    (TriMesh::new(p, f).unwrap(), ring_vertices)
}

/// A co-segmentation of one shape per mesh whose tuple `t` is the union of `groups[t]`'s rings.
fn by_rings(meshes: &[TriMesh], rings: &[Vec<Vec<u32>>], groups: &[Vec<usize>]) -> Cosegmentation {
    let parts: Vec<Vec<Vec<u32>>> = rings
        .iter()
        .map(|r| {
            groups
                .iter()
                .map(|g| {
                    let mut v: Vec<u32> = g.iter().flat_map(|&k| r[k].clone()).collect();
                    v.sort_unstable();
                    v
                })
                .collect()
        })
        .collect();
    coseg_of(meshes, &parts)
}

/// Three stepped columns of 24 rings, thick below ring 8 (radius 0.55–0.7) and thin above
/// (0.28–0.32), so the two halves have about one area.
fn stepped() -> (Vec<TriMesh>, Vec<Vec<Vec<u32>>>) {
    [(0.6, 0.3), (0.7, 0.32), (0.55, 0.28)]
        .iter()
        .map(|&(thick, thin)| column(24, move |k| if k < 8 { thick } else { thin }, None))
        .unzip()
}

#[test]
fn geometric_part_tree_groups_touching_regions_of_one_thickness() {
    let (meshes, rings) = stepped();
    let groups: Vec<Vec<usize>> = (0..6).map(|t| (4 * t..4 * t + 4).collect()).collect();
    let coseg = by_rings(&meshes, &rings, &groups);
    let tree = geometric_part_tree(&meshes, &coseg, &[]).unwrap();
    assert_eq!(tree.leaves, 6);
    assert_eq!(tree.merges.len(), 5);
    assert_eq!(tree.cut(2), vec![vec![0, 1], vec![2, 3, 4, 5]]);
    // Each merge joins touching groups (a column's regions touch only their neighbours), and
    // the last one, across the step, is the least alike.
    for m in &tree.merges {
        assert!(m.similarity > 0.0 && m.similarity <= 1.0, "{m:?}");
    }
    let last = tree.merges.last().unwrap().similarity;
    assert!(tree.merges[..4].iter().all(|m| m.similarity > last));
    // Deterministic, also in a pool of one thread.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let one = pool.install(|| geometric_part_tree(&meshes, &coseg, &[]).unwrap());
    assert_eq!(one, tree);
}

#[test]
fn geometric_part_tree_merges_regions_that_do_not_touch_only_when_linked() {
    // A thick column (rings 0–7) with a thin top (rings 8–15), and a separate thin rod (rings
    // 16–23) of the thin top's thickness.
    let (meshes, rings): (Vec<TriMesh>, Vec<_>) = [0.0, 0.1, -0.1]
        .iter()
        .map(|&e| column(16, move |k| if k < 8 { 1.0 + e } else { 0.2 }, Some(4.0)))
        .unzip();
    let groups = vec![(0..8).collect(), (8..16).collect(), (16..24).collect()];
    let coseg = by_rings(&meshes, &rings, &groups);
    // Unlinked, the rod touches nothing: the column merges first whatever the thicknesses.
    let tree = geometric_part_tree(&meshes, &coseg, &[]).unwrap();
    assert_eq!(tree.cut(2), vec![vec![0, 1], vec![2]]);
    // Linked (a mirror pair), the rod joins the thin top it resembles.
    let tree = geometric_part_tree(&meshes, &coseg, &[(2, 1)]).unwrap();
    assert_eq!(tree.cut(2), vec![vec![0], vec![1, 2]]);
    // Meshes that do not match are refused.
    assert!(matches!(
        geometric_part_tree(&meshes[..2], &coseg, &[]),
        Err(GraphError::BadOption(_))
    ));
}

/// End to end through `segment_collection`: `--parts 2 --parts-from geometry --regions 6`
/// cuts the geometric part tree of six refined equal-area regions, and refuses what it cannot do.
#[test]
fn parts_from_geometry_cuts_the_tree_of_equal_area_regions() {
    let (meshes, _) = stepped();
    let nodes: Vec<ShapeNode> = meshes
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let y: Vec<f64> = m.positions().iter().map(|p| p[1]).collect();
            let t = equal_count_bands(&y, 1, y.len(), 16).unwrap();
            ShapeNode::new(format!("s{i}"), t, &m.vertex_areas()).unwrap()
        })
        .collect();
    let mut o = SegmentCollectionOptions::default();
    // The height bands as they are (not the feature families chosen from the data).
    o.features = FeatureSelection::Given;
    o.request_parts(coseg::parts::PartsRequest::Count(2), None);
    o.set_parts_from("geometry".parse().unwrap(), Some(6));
    // The tree's cut as it is: the boundary snapping is tested on its own.
    o.set_snap_band(0.0).unwrap();
    let out = segment_collection(nodes.clone(), &meshes, &o).unwrap();
    let a = out.adaptive.as_ref().unwrap();
    assert_eq!(a.stop, StopReason::EqualAreaLeaves);
    // Six regions, split into their kinds of pieces (split_disconnected_leaves): the tree
    // is over those.
    assert!(a.leaves.tuples.len() >= 6, "{}", a.leaves.tuples.len());
    assert_eq!(a.tree.leaves, a.leaves.tuples.len());
    assert_eq!(a.tree.merges.len(), a.leaves.tuples.len() - 1);
    assert_eq!(a.leaf_origin.len(), a.leaves.tuples.len());
    assert_eq!(a.leaf_origin[..6], [0, 1, 2, 3, 4, 5]);
    assert!(a.leaf_origin[6..].iter().all(|&o| o < 6));
    assert_eq!(out.segmentation.tuples.len(), 2);
    // The parts are the tree's cut of the refined equal-area leaves, with no refinement after.
    assert_eq!(out.segmentation, a.cut(2));
    // Deterministic.
    let again = segment_collection(nodes.clone(), &meshes, &o).unwrap();
    assert_eq!(again.segmentation, out.segmentation);
    // Through the cue cache: one entry per shape, the same parts bit for bit on the cold run
    // and on the warm one, and nothing to warn about.
    let dir = tempfile::tempdir().unwrap();
    let mut cached = o.clone();
    cached.cue_cache = Some(dir.path().to_path_buf());
    for _ in 0..2 {
        let run = segment_collection(nodes.clone(), &meshes, &cached).unwrap();
        assert_eq!(run.segmentation, out.segmentation);
        assert_eq!(run.adaptive.as_ref().unwrap().tree, a.tree);
        assert!(run.warnings.is_empty(), "{:?}", run.warnings);
        assert_eq!(cue_entries(dir.path()), 3);
    }
    // Without a number of parts, the tree's cut criterion chooses one and says why.
    o.request_parts(coseg::parts::PartsRequest::Auto, None);
    let auto = segment_collection(nodes.clone(), &meshes, &o).unwrap();
    let count = auto.part_count.as_ref().unwrap();
    assert!((2..=8).contains(&count.count), "{count:?}");
    assert_eq!(auto.segmentation.tuples.len(), count.count);
    assert!(out.part_count.is_none(), "a number was given");
    // Enough regions to make the parts asked for.
    o.request_parts(coseg::parts::PartsRequest::Count(8), None);
    assert!(matches!(
        segment_collection(nodes.clone(), &meshes, &o),
        Err(GraphError::BadOption(_))
    ));
    // Parts from geometry without parts (equal-area regions) are refused.
    let mut none = SegmentCollectionOptions::equal_areas(6);
    none.features = FeatureSelection::Given;
    none.parts_from = PartsFrom::Geometry {
        leaves: 6,
        band: 0.1,
    };
    assert!(matches!(
        segment_collection(nodes, &meshes, &none),
        Err(GraphError::BadOption(_))
    ));
}

/// The number of part-cue entries in a cache directory.
fn cue_entries(dir: &std::path::Path) -> usize {
    std::fs::read_dir(dir)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "coseg-cues")
        })
        .count()
}

#[test]
fn part_cues_are_cached_bit_for_bit_and_a_bad_entry_is_recomputed() {
    let (meshes, _) = stepped();
    let m = &meshes[0];
    let fresh = PartCues::of(m).unwrap();
    assert_eq!(fresh.thickness.len(), m.vertex_count());
    // The thick bottom is thicker than the thin top (radii 0.6 and 0.3).
    let (bottom, top) = (fresh.thickness[8 * 4], fresh.thickness[8 * 20]);
    assert!(bottom > 1.5 * top, "{bottom} {top}");
    let dir = tempfile::tempdir().unwrap();
    let first = load_or_compute_part_cues(m, dir.path()).unwrap();
    assert_eq!(first.outcome, CacheOutcome::Miss);
    assert_eq!(first.write_error, None);
    let second = load_or_compute_part_cues(m, dir.path()).unwrap();
    assert_eq!(second.outcome, CacheOutcome::Hit);
    assert_eq!(second.cues, fresh);
    let entry = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .next()
        .unwrap();
    assert!(entry.to_string_lossy().ends_with(".coseg-cues"));
    // Another mesh, another entry.
    load_or_compute_part_cues(&meshes[1], dir.path()).unwrap();
    assert_eq!(cue_entries(dir.path()), 2);
    // A damaged entry is not trusted: recomputed (the reason names the file) and replaced.
    let mut bytes = std::fs::read(&entry).unwrap();
    let n = bytes.len();
    bytes[n - 1] ^= 1;
    std::fs::write(&entry, &bytes).unwrap();
    let third = load_or_compute_part_cues(m, dir.path()).unwrap();
    match &third.outcome {
        CacheOutcome::Recomputed { reason } => {
            assert!(reason.contains(&entry.display().to_string()), "{reason}")
        }
        o => panic!("expected a recomputation, got {o:?}"),
    }
    assert_eq!(third.cues, fresh);
    assert_eq!(
        load_or_compute_part_cues(m, dir.path()).unwrap().outcome,
        CacheOutcome::Hit
    );
    // A cache that cannot be written costs a warning, not the cues.
    let file = dir.path().join("not-a-folder");
    std::fs::write(&file, b"x").unwrap();
    let r = load_or_compute_part_cues(m, &file).unwrap();
    assert_eq!(r.cues, fresh);
    assert!(r.write_error.unwrap().contains("not-a-folder"));
}

#[test]
fn geometric_part_tree_with_cues_is_the_tree_and_refuses_cues_that_do_not_fit() {
    let (meshes, rings) = stepped();
    let groups: Vec<Vec<usize>> = (0..6).map(|t| (4 * t..4 * t + 4).collect()).collect();
    let coseg = by_rings(&meshes, &rings, &groups);
    let mut cues: Vec<PartCues> = meshes.iter().map(|m| PartCues::of(m).unwrap()).collect();
    assert_eq!(
        geometric_part_tree_with_cues(&meshes, &cues, &coseg, &[]).unwrap(),
        geometric_part_tree(&meshes, &coseg, &[]).unwrap()
    );
    // The tree reads the cues it is given: a bottom as thin as the top joins it.
    let tree = |cues: &[PartCues]| geometric_part_tree_with_cues(&meshes, cues, &coseg, &[]);
    for c in &mut cues {
        c.thickness = vec![1.0; c.thickness.len()];
    }
    assert_ne!(
        tree(&cues).unwrap(),
        geometric_part_tree(&meshes, &coseg, &[]).unwrap()
    );
    cues[1].thickness.pop();
    assert!(matches!(tree(&cues), Err(GraphError::BadOption(_))));
    assert!(matches!(tree(&cues[..2]), Err(GraphError::BadOption(_))));
}

/// Regression (`leaves never on one shape together`, commit e19446f): complete linkage took the
/// thickness distance of two leaves that are never present on one shape together as infinite,
/// so any group holding both could never merge with anything at a finite cost (on generated
/// chairs, the feet of every leg stayed a part of their own). Pairs that are never together
/// now say nothing; the others decide.
#[test]
fn leaves_never_on_one_shape_together_do_not_block_a_merge() {
    // Two strips of 10 columns; leaf 0 is the left half on both, the right half is leaf 1 on
    // shape 0 and leaf 2 on shape 1: leaves 1 and 2 are never together.
    let strip = || {
        let mut p = Vec::new();
        for c in 0..=10 {
            p.push([c as f64, 0.0, 0.0]);
            p.push([c as f64, 1.0, 0.0]);
        }
        let f = (0..10u32)
            .flat_map(|c| {
                [
                    [2 * c, 2 * c + 2, 2 * c + 1],
                    [2 * c + 1, 2 * c + 2, 2 * c + 3],
                ]
            })
            .collect();
        TriMesh::new(p, f).unwrap()
    };
    let meshes = vec![strip(), strip()];
    let left: Vec<u32> = (0..10).collect();
    let right: Vec<u32> = (10..22).collect();
    let coseg = coseg_of(
        &meshes,
        &[
            vec![left.clone(), right.clone(), vec![]],
            vec![left, vec![], right],
        ],
    );
    let cues = uniform_cues(&meshes);
    let tree = geometric_part_tree_with_cues(&meshes, &cues, &coseg, &[]).unwrap();
    // Uniform thickness, convex boundaries: every merge costs 0. Before the fix the second
    // merge ({0, 1} with 2, which touch through 0) cost infinity (similarity 0).
    assert_eq!(tree.merges.len(), 2);
    assert!(tree.merges.iter().all(|m| m.similarity == 1.0), "{tree:?}");
}

/// Regression (`a flat boundary's concavity came from rounding`, shipped chairs): two regions
/// meeting on a flat stretch (a chair's seat) have `H = 0` along their boundary when the
/// stretch is axis-aligned, and `±10⁻⁹` once each coordinate is scaled by a random `1 ± 10⁻¹²`
/// (or rotated): half of the boundary counted as concave, the merge cost jumped from 0 to about
/// 0.5, and bare `coseg segment` on the shipped chairs cut 7 or 3 parts instead of 6 (82.9 % →
/// 80.1 % / 67.4 %). The concave test now asks for a curvature beyond what the coordinates
/// resolve (`features::mean_curvature_resolution`).
#[test]
fn a_flat_boundary_is_not_concave_whatever_way_rounding_tips_its_sign() {
    use common::motion::unit;
    use rand::SeedableRng;
    // A flat 9 × 9 grid in z = 0.5; leaf 0 is the left half (x < 4), leaf 1 the rest.
    let grid = |perturb: Option<u64>| {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(perturb.unwrap_or(0));
        let mut p = Vec::new();
        for y in 0..9 {
            for x in 0..9 {
                let q = [0.1 * x as f64, 0.1 * y as f64 + 0.05 * x as f64, 0.5];
                p.push(q.map(|c| match perturb {
                    Some(_) => c * (1.0 + 1e-12 * (2.0 * unit(&mut rng) - 1.0)),
                    None => c,
                }));
            }
        }
        let mut f = Vec::new();
        for y in 0..8u32 {
            for x in 0..8u32 {
                let v = 9 * y + x;
                f.push([v, v + 1, v + 10]);
                f.push([v, v + 10, v + 9]);
            }
        }
        TriMesh::new(p, f).unwrap()
    };
    let left: Vec<u32> = (0..81).filter(|v| v % 9 < 4).collect();
    let right: Vec<u32> = (0..81).filter(|v| v % 9 >= 4).collect();
    for perturb in [None, Some(1), Some(2), Some(3), Some(4), Some(5)] {
        let meshes = vec![grid(perturb)];
        let coseg = coseg_of(&meshes, &[vec![left.clone(), right.clone()]]);
        let cues: Vec<PartCues> = meshes
            .iter()
            .map(|m| PartCues {
                thickness: vec![1.0; m.vertex_count()],
                mean_curvature: coseg::features::mean_curvature(m),
            })
            .collect();
        let tree = geometric_part_tree_with_cues(&meshes, &cues, &coseg, &[]).unwrap();
        assert_eq!(tree.merges[0].similarity, 1.0, "perturbation {perturb:?}");
    }
}
