//! Marching tetrahedra: the zero level set of a sampled scalar field as a triangle mesh.

use std::collections::HashMap;

/// A scalar field sampled on a regular grid.
///
/// `values[i + dims[0] * (j + dims[1] * k)]` is the field at
/// `origin + cell · (i, j, k)`; the inside of the surface is where the value is `< 0`
/// (a value of exactly 0 counts as outside).
#[derive(Debug, Clone)]
pub struct ScalarGrid {
    /// Position of grid point (0, 0, 0).
    pub origin: [f64; 3],
    /// Spacing between grid points (same on every axis, > 0).
    pub cell: f64,
    /// Number of grid points along x, y and z (each ≥ 2).
    pub dims: [usize; 3],
    /// Field values, x fastest, then y, then z (length `dims[0]·dims[1]·dims[2]`).
    pub values: Vec<f64>,
}

impl ScalarGrid {
    /// Samples `f` at every grid point (x fastest, sequential, so deterministic).
    pub fn sample(
        origin: [f64; 3],
        cell: f64,
        dims: [usize; 3],
        f: impl Fn([f64; 3]) -> f64,
    ) -> Self {
        let mut values = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    values.push(f([
                        origin[0] + cell * i as f64,
                        origin[1] + cell * j as f64,
                        origin[2] + cell * k as f64,
                    ]));
                }
            }
        }
        ScalarGrid {
            origin,
            cell,
            dims,
            values,
        }
    }
}

/// Offsets of the 8 cube corners (bit 0 = x, bit 1 = y, bit 2 = z).
const CORNER: [[i32; 3]; 8] = [
    [0, 0, 0],
    [1, 0, 0],
    [0, 1, 0],
    [1, 1, 0],
    [0, 0, 1],
    [1, 0, 1],
    [0, 1, 1],
    [1, 1, 1],
];

/// Kuhn (Freudenthal) split of the cube into 6 tetrahedra around the diagonal 0–7: one per
/// axis order. Every cube is split the same way, so the faces of neighbouring cubes match.
const TETS: [[usize; 4]; 6] = [
    [0, 1, 3, 7], // x, y, z
    [0, 1, 5, 7], // x, z, y
    [0, 2, 3, 7], // y, x, z
    [0, 2, 6, 7], // y, z, x
    [0, 4, 5, 7], // z, x, y
    [0, 4, 6, 7], // z, y, x
];

/// Interpolation parameters along an edge are kept in `[T_MIN, 1 − T_MIN]` so that no two
/// output vertices coincide (this moves a vertex by at most `T_MIN · cell`).
const T_MIN: f64 = 0.02;

/// Polygonises the surface `value = 0` of `grid` with marching tetrahedra.
///
/// Returns `(positions, faces)`. Faces are counter-clockwise seen from outside (the normal by
/// the right-hand rule points towards increasing values). One vertex is made per grid edge
/// crossing the surface, so, provided the negative region does not touch the grid's outer
/// layer, the result is a closed 2-manifold: every edge is shared by exactly two triangles
/// with opposite directions. Output order follows the grid (x fastest), so it is deterministic.
///
/// ```
/// use coseg::generate::{marching_tetrahedra, ScalarGrid};
/// let grid = ScalarGrid::sample([-1.5; 3], 0.25, [13; 3], |p| {
///     (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 1.0
/// });
/// let (positions, faces) = marching_tetrahedra(&grid);
/// assert!(!faces.is_empty());
/// // Every vertex lies close to the unit sphere.
/// assert!(positions.iter().all(|p| ((p[0]*p[0] + p[1]*p[1] + p[2]*p[2]).sqrt() - 1.0).abs() < 0.05));
/// ```
pub fn marching_tetrahedra(grid: &ScalarGrid) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let [nx, ny, nz] = grid.dims;
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    if nx < 2 || ny < 2 || nz < 2 || grid.values.len() != nx * ny * nz {
        return (positions, faces);
    }
    let index = |i: usize, j: usize, k: usize| i + nx * (j + ny * k);
    // Grid edge (lower point index, higher point index) → output vertex.
    let mut edge_vertex: HashMap<(usize, usize), u32> = HashMap::new();

    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let ids: [usize; 8] = std::array::from_fn(|c| {
                    let o = CORNER[c];
                    index(i + o[0] as usize, j + o[1] as usize, k + o[2] as usize)
                });
                let inside: [bool; 8] = std::array::from_fn(|c| grid.values[ids[c]] < 0.0);
                if inside.iter().all(|&b| b) || inside.iter().all(|&b| !b) {
                    continue;
                }
                for tet in &TETS {
                    let n_in = tet.iter().filter(|&&c| inside[c]).count();
                    if n_in == 0 || n_in == 4 {
                        continue;
                    }
                    let vertex = |a: usize, b: usize| -> u32 {
                        let (ga, gb) = (ids[a], ids[b]);
                        let key = (ga.min(gb), ga.max(gb));
                        *edge_vertex.entry(key).or_insert_with(|| {
                            let (lo, hi) = if ga < gb { (a, b) } else { (b, a) };
                            let (fl, fh) = (grid.values[ids[lo]], grid.values[ids[hi]]);
                            let t = (fl / (fl - fh)).clamp(T_MIN, 1.0 - T_MIN);
                            let (ol, oh) = (CORNER[lo], CORNER[hi]);
                            let base = [i as f64, j as f64, k as f64];
                            let p = std::array::from_fn(|d| {
                                let x = base[d] + ol[d] as f64 + t * (oh[d] - ol[d]) as f64;
                                grid.origin[d] + grid.cell * x
                            });
                            positions.push(p);
                            (positions.len() - 1) as u32
                        })
                    };
                    tet_faces(tet, &inside, n_in, vertex, &mut faces);
                }
            }
        }
    }
    (positions, faces)
}

/// The one or two triangles, oriented outwards, where the surface crosses tetrahedron `tet` of a
/// cube (`n_in` of its corners `inside`, 1 to 3). Apart from [`marching_tetrahedra`] so that the
/// grid walk and the shared edge vertices read on one screen; `vertex(a, b)` is the output vertex
/// on the cube edge between corners `a` and `b`, and the order of its calls fixes the numbering.
fn tet_faces(
    tet: &[usize; 4],
    inside: &[bool; 8],
    n_in: usize,
    mut vertex: impl FnMut(usize, usize) -> u32,
    faces: &mut Vec<[u32; 3]>,
) {
    // Doubled integer corner coordinates: edge midpoints are then integers,
    // and orientation is decided exactly on the midpoint surface.
    let c2 = |c: usize| CORNER[c].map(|x| 2 * x);
    let mid = |a: usize, b: usize| {
        let (x, y) = (c2(a), c2(b));
        [(x[0] + y[0]) / 2, (x[1] + y[1]) / 2, (x[2] + y[2]) / 2]
    };
    let (ins, outs): (Vec<usize>, Vec<usize>) = tet.iter().partition(|&&c| inside[c]);
    if n_in == 1 || n_in == 3 {
        let (lone, others) = if n_in == 1 {
            (ins[0], [outs[0], outs[1], outs[2]])
        } else {
            (outs[0], [ins[0], ins[1], ins[2]])
        };
        let m = others.map(|o| mid(lone, o));
        let n = icross(isub(m[1], m[0]), isub(m[2], m[0]));
        // Direction from inside to outside.
        let l = c2(lone);
        let s = others.iter().fold([0; 3], |acc, &o| iadd(acc, c2(o)));
        let towards_others = isub(s, [3 * l[0], 3 * l[1], 3 * l[2]]);
        let outward = if n_in == 1 {
            towards_others
        } else {
            ineg(towards_others)
        };
        let v = others.map(|o| vertex(lone, o));
        if idot(n, outward) > 0 {
            faces.push([v[0], v[1], v[2]]);
        } else {
            faces.push([v[0], v[2], v[1]]);
        }
    } else {
        let (n1, n2, p1, p2) = (ins[0], ins[1], outs[0], outs[1]);
        let m = [mid(n1, p1), mid(n1, p2), mid(n2, p2), mid(n2, p1)];
        let n = icross(isub(m[1], m[0]), isub(m[2], m[0]));
        let outward = isub(iadd(c2(p1), c2(p2)), iadd(c2(n1), c2(n2)));
        let q = [
            vertex(n1, p1),
            vertex(n1, p2),
            vertex(n2, p2),
            vertex(n2, p1),
        ];
        if idot(n, outward) > 0 {
            faces.push([q[0], q[1], q[2]]);
            faces.push([q[0], q[2], q[3]]);
        } else {
            faces.push([q[0], q[2], q[1]]);
            faces.push([q[0], q[3], q[2]]);
        }
    }
}

fn isub(a: [i32; 3], b: [i32; 3]) -> [i32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn iadd(a: [i32; 3], b: [i32; 3]) -> [i32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn ineg(a: [i32; 3]) -> [i32; 3] {
    [-a[0], -a[1], -a[2]]
}
fn idot(a: [i32; 3], b: [i32; 3]) -> i32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn icross(a: [i32; 3], b: [i32; 3]) -> [i32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
