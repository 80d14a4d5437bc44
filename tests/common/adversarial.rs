//! A generated corpus of meshes that real collections contain and that break naive pipelines:
//! several components (including single triangles), non-manifold edges and vertices,
//! zero-area and needle triangles, duplicate and unreferenced vertices, inconsistent
//! orientation, coordinates at 1e-8 and 1e8 scale, meshes smaller than the eigenpair count,
//! a strip two vertices wide. Built from analytic shapes (no data folder), written in all three
//! formats.
#![allow(dead_code)]

use super::shapes::{Parts, grid_parts, icosphere_parts, jitter, union_parts};
use coseg::mesh::{TriMesh, write_mesh};
use std::path::{Path, PathBuf};

/// One adversarial mesh: a file name (its extension picks the format) and its content.
pub struct Case {
    /// File name, e.g. `components.off`.
    pub file: &'static str,
    /// What is special about it.
    pub what: &'static str,
    /// Positions and triangles.
    pub parts: Parts,
}

/// A base shape: a jittered icosphere of 162 vertices (closed, one component).
pub fn base_sphere(seed: u64) -> Parts {
    let (mut p, f) = icosphere_parts(2, 1.0);
    jitter(&mut p, 0.05, seed);
    (p, f)
}

/// [`base_sphere`] as a mesh.
pub fn sphere_mesh(seed: u64) -> TriMesh {
    let (p, f) = base_sphere(seed);
    TriMesh::new(p, f).unwrap()
}

/// Writes [`base_sphere`]`(seed)` to `path` (its extension picks the format).
pub fn write_sphere(path: &Path, seed: u64) {
    write_mesh(path, &sphere_mesh(seed), &[]).unwrap();
}

fn single_triangle(at: [f64; 3], size: f64) -> Parts {
    (
        vec![
            at,
            [at[0] + size, at[1], at[2]],
            [at[0], at[1] + size, at[2]],
        ],
        vec![[0, 1, 2]],
    )
}

fn tetrahedron(size: f64) -> Parts {
    (
        vec![
            [size, size, size],
            [size, -size, -size],
            [-size, size, -size],
            [-size, -size, size],
        ],
        vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
    )
}

/// `parts` plus three single triangles and a small tetrahedron, disjoint and apart from it:
/// five components, three of them of one triangle.
pub fn with_debris(parts: Parts, scale: f64) -> Parts {
    let s = scale;
    union_parts(
        &[
            parts,
            single_triangle([0.0, 0.0, 0.0], 0.05 * s),
            single_triangle([0.0, 0.0, 0.0], 0.02 * s),
            single_triangle([0.0, 0.0, 0.0], 0.1 * s),
            tetrahedron(0.03 * s),
        ],
        &[
            [0.0; 3],
            [3.0 * s, 0.0, 0.0],
            [0.0, 3.0 * s, 0.0],
            [0.0, 0.0, 3.0 * s],
            [-3.0 * s, -3.0 * s, 0.0],
        ],
    )
}

/// `parts` plus `count` single triangles of side `size`, each a hair (`size / 10`) off one of
/// its vertices (every `parts.len() / count`-th): disjoint pieces lying on the surface, as
/// scanned or modelled meshes have (eyes, buttons, loose patches). Farthest-point samples
/// never land on them, which is what made the map step's sampled basis singular (#21).
pub fn with_surface_debris(parts: Parts, count: usize, size: f64) -> Parts {
    let stride = (parts.0.len() / count.max(1)).max(1);
    let anchors: Vec<[f64; 3]> = parts
        .0
        .iter()
        .step_by(stride)
        .take(count)
        .copied()
        .collect();
    let mut all = vec![parts];
    let mut offsets = vec![[0.0; 3]];
    for a in anchors {
        all.push(single_triangle([0.0; 3], size));
        offsets.push([a[0] + size / 10.0, a[1] + size / 10.0, a[2] + size / 10.0]);
    }
    union_parts(&all, &offsets)
}

/// A 10 × 10 grid with a fin (a third triangle on an interior edge: non-manifold edge) and a
/// bow-tie (two extra triangles meeting the grid at one corner vertex only: non-manifold
/// vertex).
fn non_manifold() -> Parts {
    let (mut p, mut f) = grid_parts(10, 10, 1.0, 1.0);
    // Interior edge (vertices of row 5, columns 4 and 5), fin rising in z.
    let (a, b) = (5 * 11 + 4, 5 * 11 + 5);
    p.push([0.45, 0.5, 0.3]);
    f.push([a, b, (p.len() - 1) as u32]);
    // Bow-tie at corner vertex 0.
    let n = p.len() as u32;
    p.extend([[-0.2, -0.1, 0.0], [-0.1, -0.2, 0.0]]);
    f.push([0, n, n + 1]);
    (p, f)
}

/// A 10 × 10 grid with zero-area triangles (a repeated vertex and three collinear ones) and
/// needle triangles (a vertex 1e-9 off an edge), all sharing edges with the grid.
fn degenerate() -> Parts {
    let (mut p, mut f) = grid_parts(10, 10, 1.0, 1.0);
    f.push([12, 12, 13]);
    let n = p.len() as u32;
    p.push([0.15, 0.0, 0.0]); // on the edge between vertices 1 and 2: collinear
    f.push([1, n, 2]);
    p.push([0.55, 1.0 + 1e-9, 0.0]); // needle over the top edge
    f.push([115, 116, n + 1]);
    (p, f)
}

/// `parts` with, on `count` of its faces (every `faces / count`-th), a vertex a third of the
/// way along the face's first edge `ab` and the "zero-area" triangle `(a, p, b)` over that
/// edge: collinear in exact arithmetic, a hair off in floating point, so its cotangents are
/// rounding noise. Each of those faces is also repeated (a duplicated triangle) and a
/// triangle with a repeated vertex `(a, a, b)` added. Meshes like this (a benchmark mesh with
/// 20 zero-area triangles) were dropped: `eigensolver failed: Cholesky of L − σM
/// (σ = −10): NonPositivePivot` (issue #42).
pub fn with_collinear_slivers(parts: Parts, count: usize) -> Parts {
    let (mut p, mut f) = parts;
    let stride = (f.len() / count.max(1)).max(1);
    let chosen: Vec<[u32; 3]> = f.iter().step_by(stride).take(count).copied().collect();
    for [a, b, c] in chosen {
        let (pa, pb) = (p[a as usize], p[b as usize]);
        p.push([0, 1, 2].map(|k| pa[k] + (pb[k] - pa[k]) / 3.0));
        let v = (p.len() - 1) as u32;
        f.extend([[a, v, b], [a, b, c], [a, a, b]]);
    }
    (p, f)
}

/// An icosphere where every vertex on one meridian side is stored twice (faces on the two
/// sides use different copies, so the surface is cut open along a seam), plus unreferenced
/// vertices.
fn duplicates() -> Parts {
    let (mut p, mut f) = base_sphere(3);
    let original = p.len();
    let mut copy_of = vec![u32::MAX; original];
    for t in f.iter_mut() {
        let centroid_x = t.iter().map(|&i| p[i as usize][0]).sum::<f64>();
        if centroid_x > 0.0 {
            continue;
        }
        for i in t.iter_mut() {
            if p[*i as usize][0] >= 0.0 {
                let orig = *i as usize;
                if copy_of[orig] == u32::MAX {
                    copy_of[orig] = p.len() as u32;
                    p.push(p[orig]);
                }
                *i = copy_of[orig];
            }
        }
    }
    // Unreferenced vertices, one exactly on a used one, one far away.
    p.push(p[0]);
    p.push([10.0, 10.0, 10.0]);
    p.push([0.0, 0.0, 0.0]);
    (p, f)
}

/// An icosphere with every third face reversed (inconsistent orientation).
fn flipped() -> Parts {
    let (p, mut f) = base_sphere(4);
    for t in f.iter_mut().step_by(3) {
        t.swap(1, 2);
    }
    (p, f)
}

fn scaled(parts: Parts, s: f64) -> Parts {
    let (p, f) = parts;
    (
        p.into_iter()
            .map(|q| [q[0] * s, q[1] * s, q[2] * s])
            .collect(),
        f,
    )
}

/// A strip two vertices wide and 40 long (one row of quads): every vertex on the boundary.
fn strip() -> Parts {
    grid_parts(39, 1, 4.0, 0.1)
}

/// The corpus. Every mesh is valid for [`TriMesh::new`] (the readers' invalid inputs are
/// covered by `tests/data/malformed` and the fuzz targets).
pub fn corpus() -> Vec<Case> {
    vec![
        Case {
            file: "components.off",
            what: "5 components: a sphere, 3 single triangles, a tetrahedron",
            parts: with_debris(base_sphere(1), 1.0),
        },
        Case {
            file: "surface_debris.ply",
            what: "a sphere with 12 single triangles lying on it, unconnected",
            parts: with_surface_debris(base_sphere(7), 12, 0.02),
        },
        Case {
            file: "non_manifold.obj",
            what: "a non-manifold edge (fin) and vertex (bow-tie)",
            parts: non_manifold(),
        },
        Case {
            file: "degenerate.ply",
            what: "zero-area and needle triangles",
            parts: degenerate(),
        },
        Case {
            file: "collinear_slivers.off",
            what: "20 triangles collinear up to rounding, duplicated triangles (642 + 20 vertices: \
                   the sparse eigensolver)",
            parts: {
                let (mut p, f) = icosphere_parts(3, 1.0);
                jitter(&mut p, 0.01, 11);
                with_collinear_slivers((p, f), 20)
            },
        },
        Case {
            file: "duplicates.off",
            what: "duplicate vertices along a seam, unreferenced vertices",
            parts: duplicates(),
        },
        Case {
            file: "flipped.obj",
            what: "inconsistent orientation (every third face reversed)",
            parts: flipped(),
        },
        Case {
            file: "tiny_scale.off",
            what: "coordinates at 1e-8",
            parts: scaled(base_sphere(5), 1e-8),
        },
        Case {
            file: "huge_scale.ply",
            what: "coordinates at 1e8",
            parts: scaled(base_sphere(6), 1e8),
        },
        Case {
            file: "tetrahedron.off",
            what: "4 vertices, fewer than the eigenpairs asked for",
            parts: tetrahedron(1.0),
        },
        Case {
            file: "one_triangle.obj",
            what: "a single triangle (3 vertices)",
            parts: single_triangle([0.0; 3], 1.0),
        },
        Case {
            file: "strip.off",
            what: "a strip two vertices wide",
            parts: strip(),
        },
    ]
}

/// Writes `case` into `dir`; returns its path.
pub fn write_case(dir: &Path, case: &Case) -> PathBuf {
    let path = dir.join(case.file);
    let mesh = TriMesh::new(case.parts.0.clone(), case.parts.1.clone())
        .unwrap_or_else(|e| panic!("{}: {e}", case.file));
    write_mesh(&path, &mesh, &[]).unwrap();
    path
}
