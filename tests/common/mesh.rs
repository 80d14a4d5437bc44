//! Mesh fixtures: small meshes and PLY byte builders.

use coseg::mesh::TriMesh;

/// A tetrahedron with outward (counter-clockwise) faces: closed, 4 vertices, 4 faces.
pub fn tetrahedron() -> TriMesh {
    TriMesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
    .unwrap()
}

/// An `n × n` grid of squares split into triangles, in the z = 0 plane, with coordinates that
/// are not exactly representable in decimal (multiples of 0.1) so round trips test precision.
pub fn grid(n: u32) -> TriMesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push([i as f64 * 0.1, j as f64 * 0.1, (i * j) as f64 * 1e-3 / 3.0]);
        }
    }
    let mut faces = Vec::new();
    let at = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            faces.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            faces.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    TriMesh::new(positions, faces).unwrap()
}

/// PLY encodings the builder below writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlyEncoding {
    /// `format ascii 1.0`
    Ascii,
    /// `format binary_little_endian 1.0`
    Little,
    /// `format binary_big_endian 1.0`
    Big,
}

/// Scalar types for the builder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlyScalar {
    UChar,
    Short,
    Int,
    UInt,
    Float,
    Double,
}

impl PlyScalar {
    fn name(self) -> &'static str {
        match self {
            PlyScalar::UChar => "uchar",
            PlyScalar::Short => "short",
            PlyScalar::Int => "int",
            PlyScalar::UInt => "uint",
            PlyScalar::Float => "float",
            PlyScalar::Double => "double",
        }
    }

    fn push(self, v: f64, enc: PlyEncoding, out: &mut Vec<u8>) {
        macro_rules! put {
            ($x:expr) => {
                match enc {
                    PlyEncoding::Ascii => out.extend_from_slice(format!("{} ", $x).as_bytes()),
                    PlyEncoding::Little => out.extend_from_slice(&$x.to_le_bytes()),
                    PlyEncoding::Big => out.extend_from_slice(&$x.to_be_bytes()),
                }
            };
        }
        match self {
            PlyScalar::UChar => put!(v as u8),
            PlyScalar::Short => put!(v as i16),
            PlyScalar::Int => put!(v as i32),
            PlyScalar::UInt => put!(v as u32),
            PlyScalar::Float => put!(v as f32),
            PlyScalar::Double => put!(v),
        }
    }
}

/// Builds a PLY file: vertices with `coord` x, y, z plus an extra `float quality` property,
/// faces as polygons with list type `list <count> <index> <index_name>`, and an extra
/// `element edge` after the faces.
pub fn ply_bytes(
    enc: PlyEncoding,
    coord: PlyScalar,
    count: PlyScalar,
    index: PlyScalar,
    index_name: &str,
    positions: &[[f64; 3]],
    polygons: &[Vec<u32>],
) -> Vec<u8> {
    let format = match enc {
        PlyEncoding::Ascii => "ascii",
        PlyEncoding::Little => "binary_little_endian",
        PlyEncoding::Big => "binary_big_endian",
    };
    let c = coord.name();
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment test fixture\nelement vertex {}\nproperty {c} x\nproperty {c} y\nproperty float quality\nproperty {c} z\nelement face {}\nproperty list {} {} {index_name}\nproperty uchar flags\nelement edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n",
        positions.len(),
        polygons.len(),
        count.name(),
        index.name()
    )
    .into_bytes();
    let eol = |out: &mut Vec<u8>| {
        if enc == PlyEncoding::Ascii {
            out.push(b'\n');
        }
    };
    for p in positions {
        coord.push(p[0], enc, &mut out);
        coord.push(p[1], enc, &mut out);
        PlyScalar::Float.push(0.5, enc, &mut out);
        coord.push(p[2], enc, &mut out);
        eol(&mut out);
    }
    for poly in polygons {
        count.push(poly.len() as f64, enc, &mut out);
        for &i in poly {
            index.push(i as f64, enc, &mut out);
        }
        PlyScalar::UChar.push(7.0, enc, &mut out);
        eol(&mut out);
    }
    PlyScalar::Int.push(0.0, enc, &mut out);
    PlyScalar::Int.push(1.0, enc, &mut out);
    eol(&mut out);
    out
}
