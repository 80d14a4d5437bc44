//! [`nearest_point_labels`]: labels carried from a source onto a registered target, each target
//! vertex taking the label of the nearest point of the source's surface (the rigid baseline of
//! label transfer).

use super::AlignError;
use super::closest_surface_points::{SurfaceIndex, SurfacePoint};
use super::similarity::Similarity;
use crate::mesh::TriMesh;
use rayon::prelude::*;

/// Per-vertex labels of `target` from per-face labels of `source`, through `transform`
/// (target onto source, as [`register_pair`](super::register_pair) returns it).
///
/// - `source`: the labelled shape (`F` faces); `source_face_labels`: `F` labels (any `i32`;
///   negative values are carried like any other);
/// - `target`: the shape to label (`V` vertices); `transform`: target points into the source's
///   frame;
/// - returns `(labels, distances)`: `V` labels, and for each target vertex the distance (in
///   source units) from its transformed position to the source surface point whose label it
///   took — a large distance marks a vertex where the shapes differ.
///
/// Errors: [`AlignError::LabelCount`] when the labels do not match the source's faces.
///
/// See also: [`nearest_point_vertex_labels`] (per-vertex source labels),
/// [`closest_surface_points`](super::closest_surface_points).
///
/// Known issues: the nearest point is Euclidean: where two parts of the source come close (a
/// chair's arm over its seat) a target vertex may take the label across the gap.
pub fn nearest_point_labels(
    source: &TriMesh,
    source_face_labels: &[i32],
    target: &TriMesh,
    transform: &Similarity,
) -> Result<(Vec<i32>, Vec<f64>), AlignError> {
    check_count(source_face_labels, source.face_count(), "face")?;
    let index = SurfaceIndex::new(source);
    Ok(nearest(&index, target, transform, |c| {
        source_face_labels[c.face]
    }))
}

/// [`nearest_point_labels`] with per-vertex source labels: each target vertex takes the label
/// of the corner of the nearest source face that carries the largest barycentric weight (the
/// source vertex nearest to the closest surface point, on its face).
///
/// - `source_vertex_labels`: one label per source vertex;
/// - returns `(labels, distances)` as [`nearest_point_labels`].
///
/// Errors: [`AlignError::LabelCount`] when the labels do not match the source's vertices.
pub fn nearest_point_vertex_labels(
    source: &TriMesh,
    source_vertex_labels: &[i32],
    target: &TriMesh,
    transform: &Similarity,
) -> Result<(Vec<i32>, Vec<f64>), AlignError> {
    nearest_point_vertex_labels_in(
        &SurfaceIndex::new(source),
        source,
        source_vertex_labels,
        target,
        transform,
    )
}

/// [`nearest_point_vertex_labels`] with the source's index given (`SurfaceIndex::new(source)`),
/// for many targets read from one source: the same result.
pub(crate) fn nearest_point_vertex_labels_in(
    index: &SurfaceIndex,
    source: &TriMesh,
    source_vertex_labels: &[i32],
    target: &TriMesh,
    transform: &Similarity,
) -> Result<(Vec<i32>, Vec<f64>), AlignError> {
    check_count(source_vertex_labels, source.vertex_count(), "vertex")?;
    let faces = source.faces();
    Ok(nearest(index, target, transform, |c| {
        source_vertex_labels[nearest_corner(faces, c)]
    }))
}

/// [`AlignError::LabelCount`] unless `labels` holds one label per source face or vertex
/// (`kind`), of which the source has `expected`.
fn check_count(labels: &[i32], expected: usize, kind: &'static str) -> Result<(), AlignError> {
    if labels.len() != expected {
        return Err(AlignError::LabelCount {
            expected,
            found: labels.len(),
            kind,
        });
    }
    Ok(())
}

/// The source vertex a closest surface point `c` reads its label from: the corner of its face
/// with the largest barycentric weight (the first of equal ones).
pub(crate) fn nearest_corner(faces: &[[u32; 3]], c: &SurfacePoint) -> usize {
    let mut k = 0;
    for i in 1..3 {
        if c.barycentric[i] > c.barycentric[k] {
            k = i;
        }
    }
    faces[c.face][k] as usize
}

/// Per target vertex (moved by `transform`), the label `label` reads off the closest point
/// of the source surface, and the distance to it.
fn nearest(
    index: &SurfaceIndex,
    target: &TriMesh,
    transform: &Similarity,
    label: impl Fn(&SurfacePoint) -> i32 + Sync,
) -> (Vec<i32>, Vec<f64>) {
    target
        .positions()
        .par_iter()
        .map(|&p| {
            let c = index.closest(transform.apply(p));
            (label(&c), c.distance)
        })
        .unzip()
}
