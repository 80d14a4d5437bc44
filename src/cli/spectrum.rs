use anyhow::{Context, Result};
use clap::Args;
use coseg::mesh::read_mesh;
use coseg::spectral::{
    SpectrumOptions, available_eigenpairs, laplace_beltrami_spectrum_with_stats,
};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct SpectrumArgs {
    /// Mesh file (.obj, .off, .ply).
    mesh: PathBuf,
    /// Number of eigenpairs.
    #[arg(short = 'k', long, default_value_t = SpectrumOptions::default().eigenpairs)]
    eigenpairs: usize,
    /// Print a JSON object (eigenvalues, vertex count, original area, solver statistics).
    #[arg(long)]
    json: bool,
    /// Shift σ < 0 of the shift-invert operator (unit-area scale).
    #[arg(long, default_value_t = SpectrumOptions::default().shift, allow_hyphen_values = true)]
    shift: f64,
    /// Relative residual tolerance of the Lanczos iteration.
    #[arg(long, default_value_t = SpectrumOptions::default().tolerance)]
    tolerance: f64,
    /// Block size of the block Lanczos iteration.
    #[arg(long, default_value_t = SpectrumOptions::default().block_size)]
    block_size: usize,
    /// Seed of the Lanczos start block.
    #[arg(long, default_value_t = SpectrumOptions::default().seed)]
    seed: u64,
    /// Threads for the solver (0 = all of `--threads`, 1 = sequential).
    #[arg(long, default_value_t = SpectrumOptions::default().threads)]
    solver_threads: usize,
    /// Maximum Krylov basis size (default: about twice the eigenpairs computed).
    #[arg(long)]
    basis_size: Option<usize>,
    /// Triangulation of the Laplacian: cotan (the mesh's triangles) or intrinsic-delaunay.
    #[arg(long, default_value_t = SpectrumOptions::default().laplacian)]
    laplacian: coseg::spectral::LaplacianKind,
    /// Print solver statistics (timings, factor size) to stderr.
    #[arg(long)]
    stats: bool,
}

pub fn run(args: SpectrumArgs) -> Result<ExitCode> {
    let mesh = read_mesh(&args.mesh)?;
    let options = {
        let mut opts = SpectrumOptions::default();
        opts.eigenpairs = args.eigenpairs;
        opts.shift = args.shift;
        opts.tolerance = args.tolerance;
        opts.block_size = args.block_size;
        opts.seed = args.seed;
        opts.threads = args.solver_threads;
        opts.basis_size = args.basis_size;
        opts.laplacian = args.laplacian;
        opts
    };
    let pipeline = {
        let mut opts = coseg::pipeline::ShapePipelineOptions::default();
        opts.spectrum = options.clone();
        opts
    };
    let spectrum_warnings = [
        coseg::pipeline::small_mesh_warning(&mesh, &pipeline),
        coseg::pipeline::unresolved_triangles_warning(&mesh),
    ];
    for w in spectrum_warnings.into_iter().flatten() {
        eprintln!("warning: {}: {w}", args.mesh.display());
    }
    let mut options = options;
    options.eigenpairs = options.eigenpairs.min(available_eigenpairs(&mesh));
    let (spectrum, stats) = laplace_beltrami_spectrum_with_stats(&mesh, &options)
        .with_context(|| format!("{}: spectrum", args.mesh.display()))?;
    if args.json {
        let out = serde_json::json!({
            "mesh": args.mesh.display().to_string(),
            "vertices": mesh.vertex_count(),
            "original_area": spectrum.original_area,
            "normalisation": "unit total area",
            "eigenvalues": spectrum.eigenvalues,
            "stats": stats,
        });
        println!("{out}");
    } else {
        for (i, l) in spectrum.eigenvalues.iter().enumerate() {
            println!("{i}\t{l:.12e}");
        }
    }
    if args.stats {
        eprintln!("{stats:?}");
    }
    Ok(ExitCode::SUCCESS)
}
