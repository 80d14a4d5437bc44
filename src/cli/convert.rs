use anyhow::Result;
use clap::Args;
use coseg::mesh::{read_mesh_with_report, write_mesh};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// Input mesh (.obj, .off, .ply).
    input: PathBuf,
    /// Output mesh (.obj, .off, .ply); the format follows the extension. Written atomically.
    output: PathBuf,
}

pub fn run(args: ConvertArgs) -> Result<ExitCode> {
    let (mesh, report) = read_mesh_with_report(&args.input)?;
    for w in &report.warnings {
        eprintln!("warning: {}: {w}", args.input.display());
    }
    write_mesh(&args.output, &mesh, &[])?;
    println!(
        "{} -> {}: {} vertices, {} faces",
        args.input.display(),
        args.output.display(),
        mesh.vertex_count(),
        mesh.face_count()
    );
    Ok(ExitCode::SUCCESS)
}
