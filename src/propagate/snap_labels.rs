//! [`snap_labels`]: the boundaries between propagated labels moved onto concave creases.

use super::PropagateError;
use crate::graph::{Cosegmentation, RegionTuple};
use crate::mesh::TriMesh;
use crate::parts::snap_part_boundaries;

/// Moves the boundaries between the labels of each shape onto the surface's concave creases,
/// within `band × √(shape area)` of where they are, by the minimum cut of
/// [`snap_part_boundaries`] (where two parts meet the surface folds inwards; a vote leaves its
/// boundaries where the votes happened to cross).
///
/// Inputs: `meshes` (#shapes), `labels` (per shape, per vertex; an empty vector leaves the
/// shape out and comes back empty), `band` (≥ 0; 0 returns the labels unchanged). Output:
/// the labels with moved boundaries (`-1` vertices are a part of their own and stay where
/// the cut puts them).
///
/// Errors: [`PropagateError::BadOption`] when a label vector does not fit its mesh or the
/// band is negative or not finite.
///
/// See also: [`crate::parts::snap_part_boundaries`], [`super::fuse_routes`].
pub fn snap_labels(
    meshes: &[TriMesh],
    labels: &[Vec<i32>],
    band: f64,
) -> Result<Vec<Vec<i32>>, PropagateError> {
    if meshes.len() != labels.len() {
        return Err(PropagateError::BadOption(format!(
            "{} label vectors for {} meshes",
            labels.len(),
            meshes.len()
        )));
    }
    let used: Vec<usize> = (0..meshes.len())
        .filter(|&i| !labels[i].is_empty())
        .collect();
    for &i in &used {
        if labels[i].len() != meshes[i].vertex_count() {
            return Err(PropagateError::BadOption(format!(
                "shape {i}: {} labels for {} vertices",
                labels[i].len(),
                meshes[i].vertex_count()
            )));
        }
    }
    if band == 0.0 || used.is_empty() {
        return Ok(labels.to_vec());
    }
    let mut values: Vec<i32> = used
        .iter()
        .flat_map(|&i| labels[i].iter().copied())
        .collect();
    values.sort_unstable();
    values.dedup();
    let sub: Vec<TriMesh> = used.iter().map(|&i| meshes[i].clone()).collect();
    let tuples: Vec<RegionTuple> = values
        .iter()
        .map(|&l| {
            let regions: Vec<Vec<u32>> = used
                .iter()
                .map(|&i| {
                    (0..labels[i].len() as u32)
                        .filter(|&v| labels[i][v as usize] == l)
                        .collect()
                })
                .collect();
            RegionTuple {
                area_fractions: vec![0.0; used.len()],
                regions,
                sweeps: 0,
                converged: true,
                cycled: false,
                objective: 0.0,
                confidence: 0.0,
                cycle_consistency: None,
                leftover: false,
            }
        })
        .collect();
    let coseg = Cosegmentation {
        names: used.iter().map(|i| i.to_string()).collect(),
        vertices: used.iter().map(|&i| labels[i].len()).collect(),
        root: 0,
        order: (0..used.len()).collect(),
        parent: (0..used.len()).map(|k| (k > 0).then_some(0)).collect(),
        alpha: 0.0,
        tuples,
    };
    let snapped = snap_part_boundaries(&sub, &coseg, band)?;
    let mut out = labels.to_vec();
    for (k, &i) in used.iter().enumerate() {
        out[i] = snapped
            .labels(k)
            .iter()
            .map(|&r| if r >= 0 { values[r as usize] } else { -1 })
            .collect();
    }
    Ok(out)
}
