//! Tests of `parts::snap_part_boundaries`: part boundaries moved onto concave creases by a
//! minimum cut in a band.

mod common;

use common::graph::coseg_of;
use coseg::graph::{Cosegmentation, GraphError};
use coseg::mesh::TriMesh;
use coseg::parts::snap_part_boundaries;

/// A column of 20 octagonal rings 0.25 apart (capped; the caps' centres are vertices 160 and
/// 161): rings below `step` have radius 1, the others 0.4, and ring `step` lies in the thick
/// part's top face (a washer), so the surface folds inwards there. `step` = 0: a smooth tube
/// of radius 0.4. `flip` winds every face inwards.
fn column(step: usize, flip: bool) -> TriMesh {
    let mut p = Vec::new();
    for k in 0..20usize {
        let r = if k < step { 1.0 } else { 0.4 };
        let y = if step == 0 || k < step {
            0.25 * k as f64
        } else {
            0.25 * (step - 1) as f64 + 0.25 * (k - step) as f64
        };
        for j in 0..8 {
            let a = j as f64 * std::f64::consts::FRAC_PI_4;
            p.push([r * a.cos(), y, r * a.sin()]);
        }
    }
    p.push([0.0, 0.0, 0.0]);
    p.push([0.0, p[152][1], 0.0]);
    let mut f = Vec::new();
    for k in 0..19u32 {
        for j in 0..8u32 {
            let (a, b) = (8 * k + j, 8 * k + (j + 1) % 8);
            f.push([a, a + 8, b]);
            f.push([b, a + 8, b + 8]);
        }
    }
    for j in 0..8u32 {
        f.push([160, j, (j + 1) % 8]);
        f.push([161, 152 + (j + 1) % 8, 152 + j]);
    }
    if flip {
        for t in &mut f {
            t.swap(1, 2);
        }
    }
    TriMesh::new(p, f).unwrap()
}

fn ring(v: u32) -> u32 {
    match v {
        160 => 0,
        161 => 19,
        _ => v / 8,
    }
}

/// The vertices of rings `lo..=hi`.
fn rings(lo: u32, hi: u32) -> Vec<u32> {
    (0..162)
        .filter(|&v| ring(v) >= lo && ring(v) <= hi)
        .collect()
}

/// One shape per mesh, each cut into the given ring ranges.
fn cut(meshes: &[TriMesh], ranges: &[(u32, u32)]) -> Cosegmentation {
    let parts: Vec<Vec<Vec<u32>>> = meshes
        .iter()
        .map(|_| ranges.iter().map(|&(lo, hi)| rings(lo, hi)).collect())
        .collect();
    coseg_of(meshes, &parts)
}

#[test]
fn the_column_has_its_fold_at_the_step() {
    // The fixture: ring 8 in the plane of ring 7 (the washer), ring 9 above it.
    let m = column(8, false);
    let p = m.positions();
    assert_eq!(p[56][1], p[64][1]);
    assert!(p[72][1] > p[64][1]);
    assert!((p[64][0] - 0.4).abs() < 1e-12 && (p[56][0] - 1.0).abs() < 1e-12);
}

#[test]
fn a_boundary_moves_onto_the_fold_from_either_side() {
    let meshes = vec![column(8, false), column(8, false)];
    for start in [5, 6, 10, 11] {
        let coseg = cut(&meshes, &[(0, start - 1), (start, 19)]);
        let snapped = snap_part_boundaries(&meshes, &coseg, 0.3).unwrap();
        for i in 0..2 {
            assert_eq!(
                snapped.tuples[1].regions[i],
                rings(9, 19),
                "boundary started at ring {start}"
            );
            assert_eq!(snapped.tuples[0].regions[i], rings(0, 8));
        }
        // A partition still, with its area fractions.
        let areas = meshes[0].vertex_areas();
        let total: f64 = areas.iter().sum();
        for t in &snapped.tuples {
            let a: f64 = t.regions[0].iter().map(|&v| areas[v as usize]).sum();
            assert!((t.area_fractions[0] - a / total).abs() < 1e-12);
        }
    }
}

#[test]
fn a_smooth_tube_keeps_its_boundary() {
    // No crease (the caps' sharp rims are convex, no crease either): every cut across the
    // tube costs the same, and the pull towards each vertex's side keeps the boundary.
    let meshes = vec![column(0, false)];
    for start in [6, 10, 13] {
        let coseg = cut(&meshes, &[(0, start - 1), (start, 19)]);
        let snapped = snap_part_boundaries(&meshes, &coseg, 0.3).unwrap();
        for (t, before) in snapped.tuples.iter().zip(&coseg.tuples) {
            assert_eq!(t.regions, before.regions, "boundary at ring {start}");
        }
    }
}

#[test]
fn a_part_within_the_band_is_left_alone() {
    // Ring 12 alone is a part: all of it lies within the band, nothing anchors it.
    let meshes = vec![column(8, false)];
    let coseg = cut(&meshes, &[(0, 11), (12, 12), (13, 19)]);
    let snapped = snap_part_boundaries(&meshes, &coseg, 0.3).unwrap();
    assert_eq!(snapped.tuples[1].regions[0], rings(12, 12));
}

#[test]
fn band_zero_is_the_identity_and_bad_input_is_refused() {
    let meshes = vec![column(8, false)];
    let coseg = cut(&meshes, &[(0, 10), (11, 19)]);
    assert_eq!(snap_part_boundaries(&meshes, &coseg, 0.0).unwrap(), coseg);
    for band in [-0.1, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            snap_part_boundaries(&meshes, &coseg, band),
            Err(GraphError::BadOption(_))
        ));
    }
    let two = vec![column(8, false), column(8, false)];
    assert!(matches!(
        snap_part_boundaries(&two, &coseg, 0.1),
        Err(GraphError::BadOption(_))
    ));
}

#[test]
fn the_result_does_not_depend_on_winding_or_threads() {
    let meshes = vec![column(8, false), column(8, true)];
    let coseg = cut(&meshes, &[(0, 10), (11, 19)]);
    let snapped = snap_part_boundaries(&meshes, &coseg, 0.3).unwrap();
    assert_eq!(snapped.tuples[1].regions[0], snapped.tuples[1].regions[1]);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    assert_eq!(
        pool.install(|| snap_part_boundaries(&meshes, &coseg, 0.3).unwrap()),
        snapped
    );
}
