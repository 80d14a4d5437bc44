//! Load a mesh, check it, and look at its Laplace–Beltrami spectrum.
//!
//! ```sh
//! cargo run --release --example 01_inspect_mesh -- collections/quadrupeds/quadrupeds_00.obj
//! ```
//!
//! Readers keep the file's vertex order, so per-vertex labels and ground-truth maps stay valid.
//! Conditions the method survives (several components, boundaries, degenerate triangles…) come
//! back as warnings in a report rather than errors.

use coseg::mesh::{connected_components, read_mesh_with_report};
use coseg::spectral::{SpectrumOptions, laplace_beltrami_spectrum};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "collections/quadrupeds/quadrupeds_00.obj".to_string());
    let (mesh, report) = read_mesh_with_report(&path)?;
    println!(
        "{path}: {} vertices, {} triangles, area {:.4}, {} component(s)",
        mesh.vertex_count(),
        mesh.face_count(),
        mesh.total_area(),
        connected_components(&mesh).count
    );
    for warning in &report.warnings {
        println!("  warning: {warning}");
    }

    // The spectrum is that of the mesh scaled to unit area, so eigenvalues are comparable
    // across shapes whatever the units of the file.
    let spectrum = laplace_beltrami_spectrum(&mesh, &{
        let mut opts = SpectrumOptions::default();
        opts.eigenpairs = 20;
        opts
    })?;
    println!("first eigenvalues (unit-area surface):");
    for (i, lambda) in spectrum.eigenvalues.iter().enumerate() {
        println!("  λ{i:<2} = {lambda:.4}");
    }
    Ok(())
}
