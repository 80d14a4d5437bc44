//! What the mesh-reader fuzz targets assert, kept once: a reader given any bytes returns an
//! error or a valid mesh, never a panic, a hang or a huge allocation.

use coseg::mesh::{MeshFormat, read_mesh_from_bytes};

/// Reads `bytes` as `format`; a mesh it returns must satisfy `TriMesh`'s invariants (face
/// indices in range, finite coordinates) and describe itself without panicking.
pub fn read_mesh_checked(bytes: &[u8], format: MeshFormat) {
    if let Ok(mesh) = read_mesh_from_bytes(bytes, format) {
        let d = mesh.vertex_count();
        assert!(mesh.faces().iter().flatten().all(|&i| (i as usize) < d));
        assert!(mesh.positions().iter().flatten().all(|c| c.is_finite()));
        let _ = mesh.report();
    }
}
