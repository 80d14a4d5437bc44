//! Analytic test shapes: icospheres, grids, and helpers to combine meshes.
#![allow(dead_code)]

use coseg::mesh::TriMesh;
use std::collections::HashMap;

/// A mesh as plain parts: positions and triangles.
pub type Parts = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Vertices and faces of an icosphere: a regular icosahedron subdivided `subdivisions` times
/// (each triangle into four), every vertex projected onto the sphere of radius `radius`
/// centred at the origin. `10·4^s + 2` vertices, `20·4^s` faces, counter-clockwise (outward).
pub fn icosphere_parts(subdivisions: u32, radius: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut pos: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let normalise = |p: [f64; 3]| {
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [p[0] / r, p[1] / r, p[2] / r]
    };
    for p in pos.iter_mut() {
        *p = normalise(*p);
    }
    for _ in 0..subdivisions {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(faces.len() * 4);
        let mut midpoint = |a: u32, b: u32, pos: &mut Vec<[f64; 3]>| -> u32 {
            let key = (a.min(b), a.max(b));
            *mid.entry(key).or_insert_with(|| {
                let (pa, pb) = (pos[a as usize], pos[b as usize]);
                pos.push(normalise([pa[0] + pb[0], pa[1] + pb[1], pa[2] + pb[2]]));
                (pos.len() - 1) as u32
            })
        };
        for &[a, b, c] in &faces {
            let ab = midpoint(a, b, &mut pos);
            let bc = midpoint(b, c, &mut pos);
            let ca = midpoint(c, a, &mut pos);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    for p in pos.iter_mut() {
        *p = [p[0] * radius, p[1] * radius, p[2] * radius];
    }
    (pos, faces)
}

/// The icosphere of [`icosphere_parts`] as a mesh.
pub fn icosphere(subdivisions: u32, radius: f64) -> TriMesh {
    let (p, f) = icosphere_parts(subdivisions, radius);
    TriMesh::new(p, f).unwrap()
}

/// A flat `nx × ny`-cell grid over `[0, w] × [0, h]` (z = 0), two triangles per cell,
/// alternating diagonals. Has a boundary.
pub fn grid_parts(nx: usize, ny: usize, w: f64, h: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut pos = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            pos.push([w * i as f64 / nx as f64, h * j as f64 / ny as f64, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut faces = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                faces.push([a, b, c]);
                faces.push([a, c, d]);
            } else {
                faces.push([a, b, d]);
                faces.push([b, c, d]);
            }
        }
    }
    (pos, faces)
}

/// The grid of [`grid_parts`] as a mesh.
pub fn grid(nx: usize, ny: usize, w: f64, h: f64) -> TriMesh {
    let (p, f) = grid_parts(nx, ny, w, h);
    TriMesh::new(p, f).unwrap()
}

/// Concatenates meshes given as parts, translating part `i` by `offsets[i]`.
pub fn union_parts(parts: &[Parts], offsets: &[[f64; 3]]) -> Parts {
    let mut pos = Vec::new();
    let mut faces = Vec::new();
    for ((p, f), o) in parts.iter().zip(offsets) {
        let base = pos.len() as u32;
        pos.extend(p.iter().map(|q| [q[0] + o[0], q[1] + o[1], q[2] + o[2]]));
        faces.extend(f.iter().map(|t| [t[0] + base, t[1] + base, t[2] + base]));
    }
    (pos, faces)
}

/// Deterministically jitters every vertex by up to `amount` in each coordinate (breaks
/// symmetries so eigenvalues become simple).
pub fn jitter(pos: &mut [[f64; 3]], amount: f64, seed: u64) {
    let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    for p in pos.iter_mut() {
        for c in p.iter_mut() {
            *c += amount * next();
        }
    }
}
