//! Flags that set the per-shape pipeline (spectrum, descriptors, bands), shared by subcommands.

use clap::Args;
use coseg::bands::BandWeighting;
use coseg::pipeline::ShapePipelineOptions;

#[derive(Debug, Args)]
pub struct PipelineArgs {
    /// Number of Laplace–Beltrami eigenpairs.
    #[arg(long, default_value_t = 200)]
    eigenpairs: usize,
    /// Number of HKS features.
    #[arg(long, default_value_t = 100)]
    hks: usize,
    /// Number of WKS features.
    #[arg(long, default_value_t = 100)]
    wks: usize,
    /// Number of multiscale mean-curvature features.
    #[arg(long, default_value_t = 100)]
    curvature: usize,
    /// Number of bands K.
    #[arg(long, default_value_t = 20)]
    bands: usize,
    /// Cut bands by equal area instead of equal vertex count.
    #[arg(long)]
    area_bands: bool,
}

impl PipelineArgs {
    /// The library options these flags select (library defaults for everything else).
    pub fn options(&self) -> ShapePipelineOptions {
        let mut opts = ShapePipelineOptions::default();
        opts.spectrum.eigenpairs = self.eigenpairs;
        opts.descriptors.hks_count = self.hks;
        opts.descriptors.wks_count = self.wks;
        opts.descriptors.curvature_count = self.curvature;
        opts.bands.bands = self.bands;
        if self.area_bands {
            opts.bands.weighting = BandWeighting::Area;
        }
        opts
    }
}
