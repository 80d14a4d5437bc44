//! Wavefront OBJ reader and writer (positions and faces).
//!
//! Our own parser rather than `tobj`: tobj 4 builds one mesh per `o`/`g` object and, for each,
//! copies the positions its faces use in order of first use (`add_vertex` /
//! `add_vertex_multi_index` in tobj's `lib.rs`), which reorders vertices, splits them per object
//! and drops unreferenced ones. Labels and ground-truth maps index the file's vertices, so coseg
//! needs the file's `v` records exactly, in order.
//!
//! Read: `v x y z [w | r g b]` (extra values ignored); `f` with `i`, `i/t`, `i//n` or `i/t/n`
//! corners, 1-based or negative (relative) position indices, polygons fan-triangulated, faces of
//! every object and group concatenated in file order; `\` line continuations; `#` comments.
//! Ignored: texture coordinates, normals, lines, points, groups, materials, smoothing and any
//! other statement.

use super::text::{TokenLines, position, short};
use super::{RawMesh, fan, out_of_range, parse_error};
use crate::mesh::{MeshError, TriMesh};
use std::io::Write;

/// Parses an OBJ file held in memory.
pub(super) fn parse(bytes: &[u8]) -> Result<RawMesh, MeshError> {
    let mut lines = TokenLines::new(bytes);
    let mut positions: Vec<[f64; 3]> = Vec::new();
    // Faces as signed 1-based indices resolved now (negative ones are relative to the vertices
    // read so far); range-checked at the end since a face may name a later vertex.
    let mut polys: Vec<Vec<i64>> = Vec::new();
    let mut joined = String::new();
    while let Some(raw) = lines.next_raw()? {
        let line = lines.line();
        let mut text = raw.split('#').next().unwrap_or("");
        // Line continuation: a trailing backslash joins the next line.
        if text.trim_end().ends_with('\\') {
            joined.clear();
            let mut cur = text;
            loop {
                let t = cur.trim_end();
                match t.strip_suffix('\\') {
                    Some(head) => {
                        joined.push_str(head);
                        joined.push(' ');
                        match lines.next_raw()? {
                            Some(next) => cur = next.split('#').next().unwrap_or(""),
                            None => break,
                        }
                    }
                    None => {
                        joined.push_str(cur);
                        break;
                    }
                }
            }
            text = &joined;
        }
        let mut toks = text.split_ascii_whitespace();
        let Some(kw) = toks.next() else { continue };
        match kw {
            "v" => {
                let t: Vec<&str> = toks.take(3).collect();
                positions.push(position(&t, line, None)?);
            }
            "f" | "fo" => {
                polys.push(read_face(toks, line, positions.len())?);
            }
            _ => {}
        }
    }
    let faces = triangulate(&polys, positions.len())?;
    Ok(RawMesh {
        positions,
        faces,
        warnings: Vec::new(),
    })
}

/// The corners of one `f` line as 0-based indices (`read`: the vertices read so far, which
/// negative indices are relative to); not yet range-checked, since a face may name a later
/// vertex.
fn read_face<'a>(
    toks: impl Iterator<Item = &'a str>,
    line: usize,
    read: usize,
) -> Result<Vec<i64>, MeshError> {
    let mut poly = Vec::new();
    for corner in toks {
        let v = corner.split('/').next().unwrap_or("");
        let i: i64 = v.parse().map_err(|_| {
            parse_error(
                Some(line),
                format!("invalid face corner `{}`", short(corner)),
            )
        })?;
        let resolved = match i {
            0 => {
                return Err(parse_error(
                    Some(line),
                    "vertex index 0 (OBJ indices start at 1)",
                ));
            }
            i if i < 0 => {
                let r = read as i64 + i;
                if r < 0 {
                    return Err(parse_error(
                        Some(line),
                        format!(
                            "relative vertex index {i} points before the first vertex ({} read so far)",
                            read
                        ),
                    ));
                }
                r
            }
            i => i - 1,
        };
        poly.push(resolved);
    }
    if poly.len() < 3 {
        return Err(parse_error(
            Some(line),
            format!("face has {} vertices, at least 3 are needed", poly.len()),
        ));
    }
    Ok(poly)
}

/// Range-checks the faces' indices against the `nv` vertices and fan-triangulates them.
fn triangulate(polys: &[Vec<i64>], nv: usize) -> Result<Vec<[u32; 3]>, MeshError> {
    let mut faces = Vec::with_capacity(polys.len());
    let mut poly32: Vec<u32> = Vec::new();
    for poly in polys {
        poly32.clear();
        for &i in poly {
            // i >= 0 here.
            if i as u64 >= nv as u64 {
                return Err(out_of_range(faces.len(), i as u64, nv));
            }
            poly32.push(i as u32);
        }
        fan(&poly32, &mut faces);
    }
    Ok(faces)
}

/// Writes `mesh` as OBJ (`v` and `f` records, 1-based), coordinates in shortest round-trip
/// decimal.
pub(super) fn write<W: Write>(w: &mut W, mesh: &TriMesh) -> std::io::Result<()> {
    writeln!(w, "# written by coseg")?;
    for p in mesh.positions() {
        writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
    }
    for f in mesh.faces() {
        writeln!(w, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1)?;
    }
    Ok(())
}
