//! Any bytes given to the Obj reader: an error or a valid mesh, never a panic, a hang or a
//! huge allocation; a mesh it returns satisfies `TriMesh`'s invariants and writes back.
#![no_main]

use coseg::mesh::{MeshFormat, read_mesh_from_bytes};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = read_mesh_from_bytes(data, MeshFormat::Obj) {
        let d = mesh.vertex_count();
        assert!(mesh.faces().iter().flatten().all(|&i| (i as usize) < d));
        assert!(mesh.positions().iter().flatten().all(|c| c.is_finite()));
        let _ = mesh.report();
    }
});
