use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use coseg::cache::CacheOutcome;
use coseg::mesh::read_mesh_with_report;
use coseg::output::{ExportFormat, ExportOptions, export_features};
use coseg::pipeline::{compute_shape_data, load_or_compute};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Clone, Copy, ValueEnum)]
enum Format {
    Npy,
    Csv,
}

#[derive(Debug, Args)]
pub struct FeaturesArgs {
    /// Mesh file (.obj, .off, .ply).
    mesh: PathBuf,
    /// Output directory (created if missing).
    #[arg(short, long)]
    output: PathBuf,
    /// File format of the tables. [default: npy]
    #[arg(long, value_enum)]
    format: Option<Format>,
    /// Also write the unit-area spectrum (eigenvalues, eigenvectors, vertex areas).
    #[arg(long)]
    spectrum: bool,
    #[command(flatten)]
    pipeline: super::pipeline_args::PipelineArgs,
    /// Per-shape cache directory (read if valid, written otherwise).
    #[arg(long)]
    cache: Option<PathBuf>,
}

pub fn run(args: FeaturesArgs) -> Result<ExitCode> {
    let (mesh, report) = read_mesh_with_report(&args.mesh)?;
    for w in &report.warnings {
        eprintln!("warning: {}: {w}", args.mesh.display());
    }
    let mut opts = args.pipeline.options()?;
    let spectrum_warnings = [
        coseg::pipeline::small_mesh_warning(&mesh, &opts),
        coseg::pipeline::unresolved_triangles_warning(&mesh),
    ];
    for w in spectrum_warnings.into_iter().flatten() {
        eprintln!("warning: {}: {w}", args.mesh.display());
    }
    // User features are per shape: resolve the folder to this mesh's file.
    opts.families = opts.families.for_shape(&args.mesh)?;
    let data = match &args.cache {
        Some(dir) => {
            let r = load_or_compute(&mesh, &opts, dir)
                .with_context(|| format!("{}", args.mesh.display()))?;
            match &r.outcome {
                CacheOutcome::Hit => eprintln!("cache hit: {}", r.path.display()),
                CacheOutcome::Miss => eprintln!("cache miss: wrote {}", r.path.display()),
                CacheOutcome::Recomputed { reason } => eprintln!("warning: {reason}"),
            }
            if let Some(e) = &r.write_error {
                eprintln!("warning: {e}");
            }
            r.data
        }
        None => {
            compute_shape_data(&mesh, &opts).with_context(|| format!("{}", args.mesh.display()))?
        }
    };
    let format = match args.format {
        Some(Format::Npy) => ExportFormat::Npy,
        Some(Format::Csv) => ExportFormat::Csv,
        None => ExportFormat::default(),
    };
    let written = export_features(
        &args.output,
        &data.descriptors,
        &data.bands,
        args.spectrum.then_some(&data.spectrum),
        &{
            let mut opts = ExportOptions::default();
            opts.format = format;
            opts
        },
    )?;
    println!(
        "{}: {} vertices, {} features, {} bands -> {} files in {}",
        args.mesh.display(),
        data.vertices,
        data.descriptors.feature_count(),
        data.bands.bands,
        written.len(),
        args.output.display()
    );
    Ok(ExitCode::SUCCESS)
}
