//! [`aligned_extrinsic_bands`]: the extrinsic family's band columns of every shape, measured
//! in the collection frame that [`crate::align::align_collection`] found.

use crate::align::{CollectionAlignment, FrameCase};
use crate::bands::{
    BandOptions, BandTable, BandWeighting, area_weighted_bands, equal_count_bands,
    fixed_range_bands,
};
use crate::features::{
    Alignment, Axis, ExtrinsicOptions, FeatureColumns, extrinsic_features, fixed_value_range,
};
use crate::mesh::TriMesh;
use rayon::prelude::*;

/// The extrinsic band columns (heights, distances, normal columns) of every shape in the
/// collection frame of `alignment`.
///
/// Inputs: `meshes` (#shapes, in the order `alignment` was computed on), `alignment` (from
/// [`crate::align::align_collection`] on those meshes), `extrinsic` (the family's columns; its
/// [`ExtrinsicOptions::alignment`] is ignored: the frame is the collection's), `bands` (the
/// per-shape pipeline's band options), `reverse` (the frame's up axis reversed: the
/// alignment's up rule reads the side a shape's mass leans to, which can be either; the
/// caller compares both).
///
/// Output: one [`BandTable`] per shape (#V_i vertices × the family's column count), the normal
/// columns cut by value ([`fixed_range_bands`]), the others by rank as `bands` says; the
/// frame's up axis in file coordinates when the files were already aligned (`None` when the
/// shapes were moved into a synchronised frame: each shape's up is then its own).
///
/// The frame:
/// - [`FrameCase::Synchronised`]: each shape is moved by its transform into the collection
///   frame, whose up axis is `+y`;
/// - [`FrameCase::AlreadyAligned`] and [`FrameCase::Single`]: the files' frame, with up the
///   positive file axis closest to the alignment's up direction (reversed with `reverse`) —
///   files whose frames already agree are almost always written with a positive axis up, and
///   the third-moment rule of the alignment can tilt away from that axis or reverse it on
///   shapes of uneven mass (docs/ALIGN.md).
///
/// Errors: a message naming the shape index when a shape's columns cannot be computed (the
/// caller falls back to the intrinsic family with a warning).
///
/// See also: [`super::choose_features`], which decides whether these columns are used.
pub fn aligned_extrinsic_bands(
    meshes: &[TriMesh],
    alignment: &CollectionAlignment,
    extrinsic: &ExtrinsicOptions,
    bands: &BandOptions,
    reverse: bool,
) -> Result<(Vec<BandTable>, Option<[f64; 3]>), String> {
    if alignment.shapes.len() != meshes.len() {
        return Err(format!(
            "an alignment of {} shapes for {} meshes",
            alignment.shapes.len(),
            meshes.len()
        ));
    }
    let moved = alignment.case == FrameCase::Synchronised;
    let mut axis = if moved {
        Axis {
            index: 1,
            positive: true,
        }
    } else {
        // Files whose frames agree are written with a positive axis up (the convention of
        // `--up`); the alignment's up only says which axis.
        Axis {
            positive: true,
            ..nearest_axis(alignment.up)
        }
    };
    axis.positive ^= reverse;
    let mut options = extrinsic.clone();
    options.alignment = Alignment::Up(axis);
    let tables = meshes
        .par_iter()
        .zip(&alignment.shapes)
        .enumerate()
        .map(|(i, (mesh, shape))| {
            let fail = |e: String| format!("shape {i}: extrinsic features: {e}");
            let columns = if moved {
                let positions = shape.transform.apply_all(mesh.positions());
                let m = TriMesh::new(positions, mesh.faces().to_vec())
                    .map_err(|e| fail(e.to_string()))?;
                extrinsic_features(&m, &options)
            } else {
                extrinsic_features(mesh, &options)
            }
            .map_err(|e| fail(e.to_string()))?;
            band_columns(&columns, &mesh.vertex_areas(), bands).map_err(fail)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let up = (!moved).then(|| {
        let mut u = [0.0; 3];
        u[axis.index] = if axis.positive { 1.0 } else { -1.0 };
        u
    });
    Ok((tables, up))
}

/// The signed coordinate axis closest to the direction `u`.
fn nearest_axis(u: [f64; 3]) -> Axis {
    let index = (0..3)
        .max_by(|&a, &b| u[a].abs().total_cmp(&u[b].abs()))
        .unwrap_or(1);
    Axis {
        index,
        positive: u[index] >= 0.0,
    }
}

/// The band table of `columns` as the per-shape pipeline cuts them (rank bands by count or
/// area, fixed-range columns by value).
fn band_columns(
    columns: &FeatureColumns,
    areas: &[f64],
    options: &BandOptions,
) -> Result<BandTable, String> {
    let (n, d) = (columns.len(), columns.vertices);
    let mut table = match options.weighting {
        BandWeighting::Count => equal_count_bands(&columns.values, n, d, options.bands),
        BandWeighting::Area => area_weighted_bands(&columns.values, areas, n, d, options.bands),
    }
    .map_err(|e| e.to_string())?;
    for (f, name) in columns.names.iter().enumerate() {
        if let Some(range) = fixed_value_range(name) {
            let column = fixed_range_bands(columns.column(f), range, options.bands)
                .map_err(|e| e.to_string())?;
            for (v, b) in column.into_iter().enumerate() {
                table.labels[v * n + f] = b;
            }
        }
    }
    Ok(table)
}

/// `a`'s columns followed by `b`'s, vertex by vertex (both of one shape and one band count).
pub(crate) fn concat_tables(a: &BandTable, b: &BandTable) -> BandTable {
    let features = a.features + b.features;
    let mut labels = Vec::with_capacity(a.vertices * features);
    for v in 0..a.vertices {
        labels.extend_from_slice(a.row(v));
        labels.extend_from_slice(b.row(v));
    }
    BandTable {
        features,
        vertices: a.vertices,
        bands: a.bands,
        labels,
    }
}
