use crate::mesh::TriMesh;

/// Lumped (barycentric) mass matrix `M` as its diagonal: `ω_j` = a third of the area of every
/// triangle at vertex `j`. Length `d`, non-negative, sums to the mesh's total area (squared file
/// units).
///
/// ```
/// use coseg::{mesh::TriMesh, spectral::lumped_mass};
/// let mesh = TriMesh::new(vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]).unwrap();
/// let m = lumped_mass(&mesh);
/// assert!((m.iter().sum::<f64>() - 0.5).abs() < 1e-12);
/// ```
pub fn lumped_mass(mesh: &TriMesh) -> Vec<f64> {
    mesh.vertex_areas()
}
