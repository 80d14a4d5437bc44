//! OFF (Object File Format, ASCII) reader and writer.
//!
//! Accepted: `#` comments anywhere, blank lines, CRLF line ends; the header keyword with any
//! combination of the `ST`, `C`, `N` prefixes (`OFF`, `COFF`, `NOFF`, `CNOFF`, `STOFF`, …);
//! the counts `V F [E]` on the header line or the next non-blank line (the edge count is
//! ignored); one vertex per line (`x y z` then anything — normals, colours, texture coordinates —
//! ignored); one face per line (`n i0 … in-1` then anything — a colour — ignored), 0-based
//! indices, polygons fan-triangulated. Data after the declared records is skipped with a
//! warning ([`MeshWarning::IgnoredData`]). Rejected: the `4OFF`/`nOFF` dimension prefixes and
//! `OFF BINARY`, records fewer than the header declares (truncated file).

use super::text::{TokenLines, position, short};
use super::{RawMesh, capacity_hint, fan, header_error, out_of_range, parse_error, truncated};
use crate::mesh::{MeshError, MeshWarning, TriMesh};
use std::io::Write;

/// Parses an OFF file held in memory.
pub(super) fn parse(bytes: &[u8]) -> Result<RawMesh, MeshError> {
    let mut lines = TokenLines::new(bytes);
    let (nv, nf) = read_header(&mut lines)?;
    let positions = read_vertices(&mut lines, nv, nf, bytes.len())?;
    let faces = read_faces(&mut lines, nv, nf, bytes.len())?;
    let mut warnings = Vec::new();
    // Other readers ignore what follows the declared elements (exporters pad files, or append
    // edges); the mesh is complete, so this is a warning. Invalid UTF-8 there is ignored too.
    if let Ok(Some((l, _))) = lines.next_tokens() {
        warnings.push(MeshWarning::IgnoredData {
            message: format!(
                "data from line {l} on, after the {nv} vertices and {nf} faces the header declares"
            ),
        });
    }
    Ok(RawMesh {
        positions,
        faces,
        warnings,
    })
}

/// Reads the header keyword and the counts `V F [E]` (on the header line or the next one);
/// returns the vertex and face counts.
fn read_header(lines: &mut TokenLines<'_>) -> Result<(usize, usize), MeshError> {
    let Some((hline, htoks)) = lines.next_tokens()? else {
        return Err(MeshError::Empty {
            path: crate::mesh::IN_MEMORY.to_string(),
            vertices: 0,
            faces: 0,
        });
    };
    check_keyword(htoks[0], hline)?;
    let mut counts: Vec<&str> = htoks[1..].to_vec();
    if counts.first() == Some(&"BINARY") {
        return Err(header_error(format!(
            "line {hline}: unsupported encoding: binary OFF (only ASCII OFF is read)"
        )));
    }
    let mut cline = hline;
    if counts.is_empty() {
        match lines.next_tokens()? {
            Some((l, t)) => {
                cline = l;
                counts = t;
            }
            None => {
                return Err(truncated(format!(
                    "the file ends at line {} after the `{}` keyword, before the vertex and face counts",
                    lines.line(),
                    htoks[0]
                )));
            }
        }
    }
    if counts.len() < 2 {
        return Err(header_error(format!(
            "line {cline}: wrong header: expected the counts `vertices faces edges`, found `{}`",
            short(&counts.join(" "))
        )));
    }
    let count = |tok: &str, what: &str| -> Result<usize, MeshError> {
        tok.parse::<usize>().map_err(|_| {
            header_error(format!(
                "line {cline}: wrong header: invalid {what} count `{}`",
                short(tok)
            ))
        })
    };
    let nv = count(counts[0], "vertex")?;
    let nf = count(counts[1], "face")?;
    if let Some(ne) = counts.get(2) {
        count(ne, "edge")?;
    }
    Ok((nv, nf))
}

/// Reads the `nv` vertex lines (`len`: the file's byte length, for the capacity hint).
fn read_vertices(
    lines: &mut TokenLines<'_>,
    nv: usize,
    nf: usize,
    len: usize,
) -> Result<Vec<[f64; 3]>, MeshError> {
    let mut positions = Vec::with_capacity(capacity_hint(nv, len, 6));
    for i in 0..nv {
        let Some((l, t)) = lines.next_tokens()? else {
            return Err(truncated(format!(
                "the header declares {nv} vertices and {nf} faces, but the file ends at line {} after {i} vertices",
                lines.line()
            )));
        };
        positions.push(position(&t, l, Some(i))?);
    }
    Ok(positions)
}

/// Reads the `nf` face lines, checking indices against `nv` and fan-triangulating polygons
/// (`len`: the file's byte length, for the capacity hint).
fn read_faces(
    lines: &mut TokenLines<'_>,
    nv: usize,
    nf: usize,
    len: usize,
) -> Result<Vec<[u32; 3]>, MeshError> {
    let mut faces = Vec::with_capacity(capacity_hint(nf, len, 8));
    let mut poly: Vec<u32> = Vec::new();
    for fi in 0..nf {
        let Some((l, t)) = lines.next_tokens()? else {
            return Err(truncated(format!(
                "the header declares {nf} faces, but the file ends at line {} after {fi} faces",
                lines.line()
            )));
        };
        let n: usize = t[0].parse().map_err(|_| {
            parse_error(
                Some(l),
                format!("invalid face vertex count `{}`", short(t[0])),
            )
        })?;
        if n < 3 {
            return Err(parse_error(
                Some(l),
                format!("face {fi} has {n} vertices, at least 3 are needed"),
            ));
        }
        if t.len() - 1 < n {
            return Err(parse_error(
                Some(l),
                format!("face {fi} declares {n} vertices but lists {}", t.len() - 1),
            ));
        }
        poly.clear();
        for tok in &t[1..=n] {
            let idx: u64 = tok.parse().map_err(|_| {
                parse_error(Some(l), format!("invalid vertex index `{}`", short(tok)))
            })?;
            if idx >= nv as u64 {
                return Err(out_of_range(faces.len(), idx, nv));
            }
            poly.push(idx as u32);
        }
        fan(&poly, &mut faces);
    }
    Ok(faces)
}

/// Checks the header keyword: `[ST][C][N]OFF`; `4OFF`/`nOFF` (other dimensions) are unsupported.
fn check_keyword(kw: &str, line: usize) -> Result<(), MeshError> {
    let Some(prefix) = kw.strip_suffix("OFF") else {
        return Err(header_error(format!(
            "line {line}: wrong header: expected `OFF` (or COFF, NOFF, CNOFF…), found `{}`",
            short(kw)
        )));
    };
    let prefix = prefix.strip_prefix("ST").unwrap_or(prefix);
    let prefix = prefix.strip_prefix('C').unwrap_or(prefix);
    let prefix = prefix.strip_prefix('N').unwrap_or(prefix);
    if prefix.is_empty() {
        Ok(())
    } else if prefix.contains('4') || prefix.contains('n') {
        Err(header_error(format!(
            "line {line}: unsupported OFF variant `{}`: only 3-D vertices are read",
            short(kw)
        )))
    } else {
        Err(header_error(format!(
            "line {line}: wrong header: unknown OFF variant `{}`",
            short(kw)
        )))
    }
}

/// Writes `mesh` as ASCII OFF, coordinates in shortest round-trip decimal.
pub(super) fn write<W: Write>(w: &mut W, mesh: &TriMesh) -> std::io::Result<()> {
    writeln!(w, "OFF")?;
    writeln!(w, "{} {} 0", mesh.vertex_count(), mesh.face_count())?;
    for p in mesh.positions() {
        writeln!(w, "{} {} {}", p[0], p[1], p[2])?;
    }
    for f in mesh.faces() {
        writeln!(w, "3 {} {} {}", f[0], f[1], f[2])?;
    }
    Ok(())
}
