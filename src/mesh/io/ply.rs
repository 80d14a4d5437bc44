//! PLY reader (ASCII, binary little- and big-endian, via ply-rs-bw) and binary little-endian
//! writer.
//!
//! Read: element `vertex` with scalar `x`, `y`, `z` of any numeric type (float or double
//! usually; other vertex properties ignored) and element `face` with a list property
//! `vertex_indices` or `vertex_index` of any integer type (char, uchar, short, ushort, int,
//! uint), polygons fan-triangulated; other elements (edges, materials…) are ignored, except
//! `tristrips`, which is unsupported.

use super::{PlyVertexProperty, RawMesh, header_error, out_of_range, parse_error, truncated};
use crate::mesh::{IN_MEMORY, MeshError, TriMesh};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{DefaultElement, Header, Property, PropertyType, ScalarType};
use std::io::{ErrorKind, Write};

/// Parses a PLY file held in memory.
pub(super) fn parse(bytes: &[u8]) -> Result<RawMesh, MeshError> {
    let parser = Parser::<DefaultElement>::new();
    let mut reader = Reader::new(bytes);
    let header = parser.read_header(&mut reader).map_err(|e| {
        if e.kind() == ErrorKind::UnexpectedEof {
            truncated(format!("the file ends inside the PLY header ({e})"))
        } else {
            header_error(format!("wrong header: {}", one_line(&e.to_string())))
        }
    })?;
    let index_name = check_header(&header)?;
    let payload = parser.read_payload(&mut reader, &header).map_err(|e| {
        if e.kind() == ErrorKind::UnexpectedEof {
            truncated(one_line(&e.to_string()))
        } else {
            parse_error(None, one_line(&e.to_string()))
        }
    })?;
    let empty = Vec::new();
    let vertices = payload.get("vertex").unwrap_or(&empty);
    let mut positions = Vec::with_capacity(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        let mut p = [0.0; 3];
        for (k, name) in ["x", "y", "z"].iter().enumerate() {
            p[k] = v
                .get(*name)
                .and_then(scalar_f64)
                .ok_or_else(|| parse_error(None, format!("vertex {i} has no numeric `{name}`")))?;
        }
        positions.push(p);
    }
    let nv = positions.len();
    let face_elems = payload.get("face").unwrap_or(&empty);
    let mut faces = Vec::with_capacity(face_elems.len());
    let mut poly: Vec<u32> = Vec::new();
    for (fi, f) in face_elems.iter().enumerate() {
        let list = f
            .get(index_name)
            .and_then(list_i64)
            .ok_or_else(|| parse_error(None, format!("face {fi} has no `{index_name}` list")))?;
        if list.len() < 3 {
            return Err(parse_error(
                None,
                format!(
                    "face {fi} has {} vertices, at least 3 are needed",
                    list.len()
                ),
            ));
        }
        poly.clear();
        for i in list {
            if i < 0 {
                return Err(parse_error(
                    None,
                    format!("face {fi} has a negative vertex index {i}"),
                ));
            }
            if i as u64 >= nv as u64 {
                return Err(out_of_range(faces.len(), i as u64, nv));
            }
            poly.push(i as u32);
        }
        super::fan(&poly, &mut faces);
    }
    Ok(RawMesh {
        positions,
        faces,
        warnings: Vec::new(),
    })
}

/// Checks that the header declares what coseg reads; returns the name of the face index list.
fn check_header(header: &Header) -> Result<&'static str, MeshError> {
    if header.elements.contains_key("tristrips") && !header.elements.contains_key("face") {
        return Err(header_error(
            "unsupported element `tristrips`: coseg reads faces from a `face` element",
        ));
    }
    let vertex = header
        .elements
        .get("vertex")
        .ok_or_else(|| header_error("unsupported PLY: no `vertex` element"))?;
    for name in ["x", "y", "z"] {
        match vertex.properties.get(name).map(|p| &p.data_type) {
            Some(PropertyType::Scalar(_)) => {}
            Some(PropertyType::List(..)) => {
                return Err(header_error(format!(
                    "unsupported property: vertex `{name}` is a list"
                )));
            }
            None => {
                return Err(header_error(format!(
                    "unsupported PLY: the `vertex` element has no `{name}` property"
                )));
            }
        }
    }
    let face = header.elements.get("face").ok_or_else(|| {
        header_error("unsupported PLY: no `face` element (point clouds are not read)")
    })?;
    for name in ["vertex_indices", "vertex_index"] {
        match face.properties.get(name).map(|p| &p.data_type) {
            Some(PropertyType::List(_, ScalarType::Float | ScalarType::Double)) => {
                return Err(header_error(format!(
                    "unsupported property: face `{name}` is a list of floating-point numbers"
                )));
            }
            Some(PropertyType::List(..)) => return Ok(name),
            Some(PropertyType::Scalar(_)) => {
                return Err(header_error(format!(
                    "unsupported property: face `{name}` is a scalar, not a list"
                )));
            }
            None => {}
        }
    }
    Err(header_error(
        "unsupported PLY: the `face` element has no `vertex_indices` or `vertex_index` list",
    ))
}

/// ply-rs-bw's messages span several lines and start with `Line N:`; make them one line, with
/// the line number in our lower-case style.
fn one_line(message: &str) -> String {
    let flat = message
        .split(['\n', '\t'])
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect::<Vec<_>>()
        .join(" ");
    match flat.strip_prefix("Line ") {
        Some(rest) => format!("line {rest}"),
        None => flat,
    }
}

fn scalar_f64(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => v as f64,
        Property::UChar(v) => v as f64,
        Property::Short(v) => v as f64,
        Property::UShort(v) => v as f64,
        Property::Int(v) => v as f64,
        Property::UInt(v) => v as f64,
        Property::Float(v) => v as f64,
        Property::Double(v) => v,
        _ => return None,
    })
}

fn list_i64(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
        _ => return None,
    })
}

/// Checks the properties a writer was given: one value per vertex, valid distinct names.
pub(super) fn check_properties(
    mesh: &TriMesh,
    properties: &[PlyVertexProperty],
) -> Result<(), MeshError> {
    let err = |message: String| MeshError::Property {
        path: IN_MEMORY.to_string(),
        message,
    };
    let d = mesh.vertex_count();
    let mut names: Vec<&str> = vec!["x", "y", "z"];
    for p in properties {
        let (new, len): (Vec<&str>, usize) = match p {
            PlyVertexProperty::Color(c) => (vec!["red", "green", "blue"], c.len()),
            PlyVertexProperty::Int(n, v) => (vec![n.as_str()], v.len()),
            PlyVertexProperty::Float(n, v) => (vec![n.as_str()], v.len()),
        };
        if len != d {
            return Err(err(format!(
                "vertex property `{}` has {len} values for {d} vertices",
                new[0]
            )));
        }
        for n in new {
            let mut chars = n.chars();
            let valid = chars
                .next()
                .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
                && chars.all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
            if !valid {
                return Err(err(format!(
                    "invalid PLY property name `{n}` (a letter or `_`, then letters, digits, `_`, `-`)"
                )));
            }
            if names.contains(&n) {
                return Err(err(format!("vertex property `{n}` is given twice")));
            }
            names.push(n);
        }
    }
    Ok(())
}

/// Writes `mesh` as binary little-endian PLY: `double` x, y, z, then `properties` in order
/// (colour as uchar `red green blue`, ints as `int`, floats as `float`); faces as
/// `list uchar int vertex_indices` (`uint` beyond `i32::MAX` vertices). Properties must have
/// passed [`check_properties`].
pub(super) fn write<W: Write>(
    w: &mut W,
    mesh: &TriMesh,
    properties: &[PlyVertexProperty],
) -> std::io::Result<()> {
    writeln!(w, "ply")?;
    writeln!(w, "format binary_little_endian 1.0")?;
    writeln!(w, "comment written by coseg")?;
    writeln!(w, "element vertex {}", mesh.vertex_count())?;
    for c in ["x", "y", "z"] {
        writeln!(w, "property double {c}")?;
    }
    for p in properties {
        match p {
            PlyVertexProperty::Color(_) => {
                for c in ["red", "green", "blue"] {
                    writeln!(w, "property uchar {c}")?;
                }
            }
            PlyVertexProperty::Int(n, _) => writeln!(w, "property int {n}")?,
            PlyVertexProperty::Float(n, _) => writeln!(w, "property float {n}")?,
        }
    }
    let wide = mesh.vertex_count() > i32::MAX as usize;
    writeln!(w, "element face {}", mesh.face_count())?;
    writeln!(
        w,
        "property list uchar {} vertex_indices",
        if wide { "uint" } else { "int" }
    )?;
    writeln!(w, "end_header")?;
    let mut rec: Vec<u8> = Vec::with_capacity(64);
    for (i, p) in mesh.positions().iter().enumerate() {
        rec.clear();
        for c in p {
            rec.extend_from_slice(&c.to_le_bytes());
        }
        for prop in properties {
            match prop {
                PlyVertexProperty::Color(c) => rec.extend_from_slice(&c[i]),
                PlyVertexProperty::Int(_, v) => rec.extend_from_slice(&v[i].to_le_bytes()),
                PlyVertexProperty::Float(_, v) => rec.extend_from_slice(&v[i].to_le_bytes()),
            }
        }
        w.write_all(&rec)?;
    }
    for f in mesh.faces() {
        rec.clear();
        rec.push(3);
        for &i in f {
            rec.extend_from_slice(&i.to_le_bytes());
        }
        w.write_all(&rec)?;
    }
    Ok(())
}
