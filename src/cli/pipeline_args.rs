//! Flags that set the per-shape pipeline (spectrum, descriptors, bands), shared by subcommands.

use clap::Args;
use coseg::bands::BandWeighting;
use coseg::pipeline::{FamilyFlags, ShapePipelineOptions};
use coseg::spectral::LaplacianKind;

#[derive(Debug, Args)]
pub struct PipelineArgs {
    /// Number of Laplace–Beltrami eigenpairs.
    #[arg(long, default_value_t = ShapePipelineOptions::default().spectrum.eigenpairs)]
    eigenpairs: usize,
    /// Number of HKS features.
    #[arg(long, default_value_t = ShapePipelineOptions::default().descriptors.hks_count)]
    hks: usize,
    /// Number of WKS features.
    #[arg(long, default_value_t = ShapePipelineOptions::default().descriptors.wks_count)]
    wks: usize,
    /// Number of multiscale mean-curvature features.
    #[arg(long, default_value_t = ShapePipelineOptions::default().descriptors.curvature_count)]
    curvature: usize,
    /// Number of bands K.
    #[arg(long, default_value_t = ShapePipelineOptions::default().bands.bands)]
    bands: usize,
    /// Cut bands by equal area instead of equal vertex count.
    #[arg(long)]
    area_bands: bool,
    /// Feature families, comma-separated: spectral, extrinsic, sdf, user:DIR (DIR holds
    /// <mesh stem>.npy or .csv per shape). See docs/FEATURES.md. Default: `coseg segment`
    /// chooses spectral or spectral,extrinsic (in the collection frame it aligns) from the data
    /// (docs/PARTS.md); the other commands use spectral.
    #[arg(long)]
    features: Option<String>,
    /// Frame of the extrinsic family: the collection's up axis (x, y, z, -x, …) when it is
    /// already aligned, or pca. [default: y]
    #[arg(long)]
    up: Option<String>,
    /// Number of height directions of the extrinsic family.
    #[arg(long, default_value_t = FamilyFlags::default().directions)]
    directions: usize,
    /// Number of normal columns of the extrinsic family (|normal · direction|; 0 = none).
    #[arg(long, default_value_t = FamilyFlags::default().normals)]
    normals: usize,
    /// Triangulation of the spectral family's Laplacian: cotan (the mesh's triangles) or
    /// intrinsic-delaunay (edges flipped intrinsically until every cotangent weight is
    /// non-negative; for CAD exports and poor triangulations). See docs/FEATURES.md.
    #[arg(long, default_value_t = ShapePipelineOptions::default().spectrum.laplacian)]
    laplacian: LaplacianKind,
    /// Family weights in the affinity, e.g. spectral=1,extrinsic=2,normals=1 (a family's total
    /// share; default 1 each; `normals` = the extrinsic family's `--normals` columns, weighted
    /// as a family of their own). Used by `coseg segment`, `coseg propagate` and `coseg pair` (all its
    /// stages).
    #[arg(long)]
    family_weights: Option<String>,
}

impl PipelineArgs {
    /// Whether `--features` was given (otherwise `coseg segment` chooses the families).
    pub fn features_given(&self) -> bool {
        self.features.is_some()
    }

    /// The library options these flags select (library defaults for everything else).
    pub fn options(&self) -> anyhow::Result<ShapePipelineOptions> {
        let mut opts = ShapePipelineOptions::default();
        opts.spectrum.eigenpairs = self.eigenpairs;
        opts.spectrum.laplacian = self.laplacian;
        opts.descriptors.hks_count = self.hks;
        opts.descriptors.wks_count = self.wks;
        opts.descriptors.curvature_count = self.curvature;
        opts.bands.bands = self.bands;
        if self.area_bands {
            opts.bands.weighting = BandWeighting::Area;
        }
        let mut flags = FamilyFlags::default();
        if let Some(f) = &self.features {
            flags.features = f.clone();
        }
        if let Some(u) = &self.up {
            flags.up = u.clone();
        }
        flags.directions = self.directions;
        flags.normals = self.normals;
        if let Some(w) = &self.family_weights {
            flags.family_weights = w.clone();
        }
        opts.set_family_flags(&flags)?;
        Ok(opts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Debug, Parser)]
    struct Wrapper {
        #[command(flatten)]
        pipeline: PipelineArgs,
    }

    /// The flags' defaults are the library's: no flag given selects `ShapePipelineOptions::default()`.
    #[test]
    fn default_flags_select_the_library_defaults() {
        let w = Wrapper::try_parse_from(["coseg"]).unwrap();
        assert_eq!(
            w.pipeline.options().unwrap(),
            ShapePipelineOptions::default()
        );
    }
}
