use super::surface_operators::{half_cotangents, weighted_vertex_areas};
use crate::mesh::TriMesh;

/// Lumped (barycentric) mass matrix `M` as its diagonal: `ω_j` = a third of the area of every
/// triangle at vertex `j`. Length `d`, non-negative, sums to the mesh's total area (squared file
/// units). Triangles that the Laplacian treats as zero-area (collinear up to rounding, see
/// [`super::unresolved_triangles`]) carry no mass either, so the mass is the one the spectrum
/// uses ([`super::SurfaceOperators::vertex_areas`]).
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::lumped_mass};
/// let mesh = TriMesh::new(vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]).unwrap();
/// let m = lumped_mass(&mesh);
/// assert!((m.iter().sum::<f64>() - 0.5).abs() < 1e-12);
/// ```
pub fn lumped_mass(mesh: &TriMesh) -> Vec<f64> {
    weighted_vertex_areas(mesh, mesh.faces(), &half_cotangents(mesh))
}
