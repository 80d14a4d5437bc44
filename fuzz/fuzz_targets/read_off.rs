//! Any bytes given to the Off reader: an error or a valid mesh, never a panic, a hang or a
//! huge allocation; a mesh it returns satisfies `TriMesh`'s invariants and writes back.
#![no_main]

use coseg::mesh::MeshFormat;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| coseg_fuzz::read_mesh_checked(data, MeshFormat::Off));
