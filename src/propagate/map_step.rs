//! [`map_step`]: a propagated labelling sharpened by a point map to its source, for
//! near-isometric collections.

use crate::maps::{MapError, MapShape, PointMapOptions, region_point_map};

/// Options of [`map_step`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct MapStepOptions {
    /// The point map (functional map fitted to the corresponding parts, then ZoomOut; defaults
    /// as [`region_point_map`]'s).
    pub point_map: PointMapOptions,
    /// Smallest area-weighted agreement, in `[0, 1]`, between the map's labels and the
    /// propagated ones for the map's labels to be kept (default 0.8). The map step is a
    /// boundary refinement: a map that changes more than a fifth of the surface is a different
    /// correspondence (typically an intrinsic symmetry flip), not a sharper one, and is
    /// rejected. Measured on TOSCA and FAUST (docs/PROPAGATION.md, "Map step"): kept maps
    /// agree on 81–96 %, rejected ones (flips, other people's bodies) on 61–78 %; the
    /// agreement does not separate every harmful map (three of 77 kept lowered their target).
    pub min_agreement: f64,
}

impl Default for MapStepOptions {
    fn default() -> Self {
        MapStepOptions {
            point_map: PointMapOptions::default(),
            min_agreement: 0.8,
        }
    }
}

impl MapStepOptions {
    /// Checks `min_agreement`.
    pub fn validate(&self) -> Result<(), MapError> {
        if !(0.0..=1.0).contains(&self.min_agreement) {
            return Err(MapError::InvalidOption(format!(
                "map step: min_agreement = {} must be in [0, 1]",
                self.min_agreement
            )));
        }
        Ok(())
    }
}

/// What [`map_step`] did to one shape.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MapStepReport {
    /// Index of the source the map goes to.
    pub source: usize,
    /// Area-weighted share of the target on which the map's label equals the propagated one
    /// (over the vertices the map sends to a labelled source vertex).
    pub agreement: f64,
    /// Whether the map's labels were kept (`agreement ≥ min_agreement`).
    pub applied: bool,
}

/// Re-labels a target through a point map to a labelled source, the near-isometric
/// refinement of a propagation (the propagation's analogue of `coseg pair`'s map step).
///
/// The point map `T` (for every target vertex `q`, a source vertex `T(q)`) is fitted by
/// [`region_point_map`] to the parts as they correspond: the source's annotation and the
/// target's propagated labels, part `r` to part `r`. Each target vertex then takes the source
/// label at `T(q)` (its propagated label where that is `-1`). The result is kept only when
/// it agrees with the propagated labels on at least `min_agreement` of the target's area;
/// otherwise the propagated labels are returned unchanged. Parts are transferred point by
/// point, so their boundaries are the source's, carried by a map that is accurate on
/// near-isometric shapes; on non-isometric ones (man-made collections) the map, and so this
/// step, is not meaningful.
///
/// Inputs: `source` and `target` with `labels` of length `#V` of each (the source's
/// annotation, the target's propagated labels), `target_areas` (`#V_target`, any positive
/// scale), `source_index` (reported). Output: the target's labels (`#V_target`) and the report.
///
/// See also: [`region_point_map`], [`crate::stable::map_guided_refinement`] (the pair's map
/// step). Known issue: an intrinsic symmetry (left and right) is a second map as good as the
/// first; only the agreement test guards against it.
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::spectral::{laplace_beltrami_spectrum, SpectrumOptions};
/// use coseg::maps::MapShape;
/// use coseg::propagate::{map_step, MapStepOptions};
/// // A strip of 8 × 2 squares; the source's parts are its left and right halves, the
/// // target (the same strip) has a rough propagated labelling with one vertex wrong.
/// let (nx, ny) = (9u32, 3u32);
/// let pos: Vec<[f64; 3]> = (0..nx * ny).map(|i| [(i % nx) as f64, (i / nx) as f64, 0.0]).collect();
/// let mut faces = Vec::new();
/// for y in 0..ny - 1 { for x in 0..nx - 1 {
///     let v = y * nx + x;
///     faces.push([v, v + 1, v + nx + 1]);
///     faces.push([v, v + nx + 1, v + nx]);
/// }}
/// let mesh = TriMesh::new(pos.clone(), faces).unwrap();
/// let mut so = SpectrumOptions::default();
/// so.eigenpairs = 12;
/// let spectrum = laplace_beltrami_spectrum(&mesh, &so).unwrap();
/// let truth: Vec<i32> = (0..nx * ny).map(|i| i32::from(i % nx >= 4)).collect();
/// let mut rough = truth.clone();
/// rough[4] = 0;
/// let source = MapShape { spectrum: &spectrum, positions: &pos, labels: &truth, descriptors: None };
/// let target = MapShape { spectrum: &spectrum, positions: &pos, labels: &rough, descriptors: None };
/// let mut o = MapStepOptions::default();
/// (o.point_map.zoomout.initial_size, o.point_map.zoomout.final_size, o.point_map.zoomout.step) = (4, 12, 4);
/// let (labels, report) = map_step(&source, &target, &vec![1.0; pos.len()], 0, &o).unwrap();
/// assert!(report.applied && report.agreement > 0.9);
/// assert_eq!(labels, truth);
/// ```
pub fn map_step(
    source: &MapShape<'_>,
    target: &MapShape<'_>,
    target_areas: &[f64],
    source_index: usize,
    options: &MapStepOptions,
) -> Result<(Vec<i32>, MapStepReport), MapError> {
    map_step_with_map(source, target, target_areas, source_index, options)
        .map(|(labels, report, _)| (labels, report))
}

/// [`map_step`], also returning the point map it fitted (one source vertex per target
/// vertex) for the map route's cache.
pub(crate) fn map_step_with_map(
    source: &MapShape<'_>,
    target: &MapShape<'_>,
    target_areas: &[f64],
    source_index: usize,
    options: &MapStepOptions,
) -> Result<(Vec<i32>, MapStepReport, Vec<u32>), MapError> {
    options.validate()?;
    if target_areas.len() != target.labels.len() {
        return Err(MapError::InvalidOption(format!(
            "map step: {} areas for {} target labels",
            target_areas.len(),
            target.labels.len()
        )));
    }
    let map = region_point_map(source, target, &options.point_map)?;
    let (labels, report) = map_step_through(
        source.labels,
        target.labels,
        target_areas,
        source_index,
        &map,
        options,
    );
    Ok((labels, report, map))
}

/// [`map_step`] through a point map already fitted (`map[q]`: the source vertex of target
/// vertex `q`, as [`region_point_map`] returns it): the same labels and report. `map`,
/// `target_labels` and `target_areas` are as long; every `map[q]` indexes `source_labels`.
pub(crate) fn map_step_through(
    source_labels: &[i32],
    target_labels: &[i32],
    target_areas: &[f64],
    source_index: usize,
    map: &[u32],
    options: &MapStepOptions,
) -> (Vec<i32>, MapStepReport) {
    let mut labels = Vec::with_capacity(map.len());
    let (mut agree, mut total) = (0.0, 0.0);
    for (q, &p) in map.iter().enumerate() {
        let carried = source_labels[p as usize];
        let own = target_labels[q];
        if carried < 0 {
            labels.push(own);
            continue;
        }
        let a = target_areas[q];
        total += a;
        if carried == own {
            agree += a;
        }
        labels.push(carried);
    }
    let agreement = if total > 0.0 { agree / total } else { 0.0 };
    let applied = total > 0.0 && agreement >= options.min_agreement;
    let report = MapStepReport {
        source: source_index,
        agreement,
        applied,
    };
    if applied {
        (labels, report)
    } else {
        (target_labels.to_vec(), report)
    }
}
