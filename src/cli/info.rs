use anyhow::Result;
use clap::Args;
use coseg::mesh::read_mesh_with_report;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Mesh files (.obj, .off, .ply).
    #[arg(required = true)]
    meshes: Vec<PathBuf>,
}

pub fn run(args: InfoArgs) -> Result<ExitCode> {
    let mut failed = 0usize;
    for path in &args.meshes {
        match read_mesh_with_report(path) {
            Ok((mesh, report)) => {
                println!(
                    "{}: {} vertices, {} faces, area {:.6}",
                    path.display(),
                    mesh.vertex_count(),
                    mesh.face_count(),
                    mesh.total_area()
                );
                for w in &report.warnings {
                    eprintln!("warning: {}: {w}", path.display());
                }
            }
            Err(e) => {
                eprintln!("error: {e}");
                failed += 1;
            }
        }
    }
    Ok(super::exit_code(failed, args.meshes.len()))
}
