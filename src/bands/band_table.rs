use super::{BandError, BandTable, area_weighted_bands, equal_count_bands, fixed_range_bands};
use crate::features::Descriptors;

/// How a feature's sorted order is cut into bands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum BandWeighting {
    /// Equal vertex counts (sizes differ by at most one), as in the paper. Default.
    #[default]
    Count,
    /// Equal surface area (unit-area vertex areas), up to one vertex per band: for unevenly
    /// sampled meshes.
    Area,
}

/// Options of [`band_table`].
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct BandOptions {
    /// Number of bands `K` (default 20, as in the paper; `1..=256`).
    pub bands: usize,
    /// Count or area blocks (default [`BandWeighting::Count`]).
    pub weighting: BandWeighting,
}

impl Default for BandOptions {
    fn default() -> Self {
        BandOptions {
            bands: 20,
            weighting: BandWeighting::Count,
        }
    }
}

/// The band table of a shape's descriptors: [`equal_count_bands`] or [`area_weighted_bands`]
/// (with the descriptors' unit-area vertex areas) on every feature, except the features with a
/// fixed value range ([`Descriptors::value_ranges`]: the extrinsic family's normal columns),
/// which get [`fixed_range_bands`] whatever the weighting. Deterministic; features are
/// processed in parallel.
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::dense_spectrum};
/// use coseg::features::{descriptors, DescriptorOptions};
/// use coseg::bands::{band_table, BandOptions};
/// let m = TriMesh::new(vec![[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.]], vec![[0,1,2],[0,2,3]]).unwrap();
/// let s = dense_spectrum(&m, 4).unwrap();
/// let mut opts = DescriptorOptions::default();
/// (opts.hks_count, opts.wks_count, opts.curvature_count) = (2, 2, 2);
/// let f = descriptors(&m, &s, &opts).unwrap();
/// let mut band_options = BandOptions::default();
/// band_options.bands = 2;
/// let t = band_table(&f, &band_options).unwrap();
/// assert_eq!((t.vertices, t.features, t.bands), (4, 6, 2));
/// ```
pub fn band_table(
    descriptors: &Descriptors,
    options: &BandOptions,
) -> Result<BandTable, BandError> {
    let (n, d) = (descriptors.feature_count(), descriptors.vertices);
    let mut table = match options.weighting {
        BandWeighting::Count => equal_count_bands(&descriptors.values, n, d, options.bands),
        BandWeighting::Area => area_weighted_bands(
            &descriptors.values,
            &descriptors.vertex_areas,
            n,
            d,
            options.bands,
        ),
    }?;
    for (f, range) in descriptors.value_ranges().into_iter().enumerate() {
        if let Some(range) = range {
            let column = fixed_range_bands(descriptors.feature(f), range, options.bands).map_err(
                |e| match e {
                    BandError::NaN { vertex, .. } => BandError::NaN { feature: f, vertex },
                    e => e,
                },
            )?;
            for (v, b) in column.into_iter().enumerate() {
                table.labels[v * n + f] = b;
            }
        }
    }
    Ok(table)
}
