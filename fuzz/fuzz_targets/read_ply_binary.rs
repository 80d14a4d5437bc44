//! Binary PLY bodies behind a valid header: the first byte picks the encoding and property
//! types, the next two the vertex and face counts, the rest is the binary payload. Raw bytes
//! (`read_ply`) rarely get past the header; this target spends its time in the payload reader.
#![no_main]

use coseg::mesh::MeshFormat;
use libfuzzer_sys::fuzz_target;

const COORDS: [&str; 4] = ["float", "double", "int", "uchar"];
const COUNTS: [&str; 2] = ["uchar", "int"];
const INDICES: [&str; 4] = ["int", "uint", "short", "uchar"];

fuzz_target!(|data: &[u8]| {
    let [pick, nv, nf, body @ ..] = data else {
        return;
    };
    let format = if pick & 1 == 0 {
        "binary_little_endian"
    } else {
        "binary_big_endian"
    };
    let coord = COORDS[(pick >> 1) as usize % 4];
    let count = COUNTS[(pick >> 3) as usize % 2];
    let index = INDICES[(pick >> 4) as usize % 4];
    let extra = if pick & 0x40 != 0 {
        "property uchar red\n"
    } else {
        ""
    };
    let mut bytes = format!(
        "ply\nformat {format} 1.0\nelement vertex {nv}\nproperty {coord} x\nproperty {coord} y\n\
         {extra}property {coord} z\nelement face {nf}\nproperty list {count} {index} vertex_indices\n\
         end_header\n"
    )
    .into_bytes();
    bytes.extend_from_slice(body);
    coseg_fuzz::read_mesh_checked(&bytes, MeshFormat::Ply);
});
