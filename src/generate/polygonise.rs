//! From a [`Model`] to a labelled, checked triangle mesh: sampling, marching tetrahedra,
//! relaxation onto the surface, labelling, rounding.

use super::marching_tetrahedra::{ScalarGrid, marching_tetrahedra};
use super::sdf::{Model, V3, add, dot, len, round_to, scale, sub};
use crate::mesh::{TriMesh, connected_components, edges};

/// Decimal places kept in vertex coordinates (the written file holds exactly these values).
pub(crate) const DECIMALS_PER_UNIT: f64 = 1e5;

/// Why a model did not give a valid mesh at a given resolution.
#[derive(Debug)]
pub(crate) enum PolygoniseFailure {
    /// Number of connected components found (≠ 1).
    Components(usize),
    /// Some edge is not shared by exactly two triangles, or the mesh is empty/invalid.
    NotManifold(String),
}

/// Samples `model` on a grid of spacing `cell`, polygonises, relaxes and labels it.
pub(crate) fn polygonise(
    model: &Model,
    cell: f64,
    relax_iterations: usize,
) -> Result<(TriMesh, Vec<u32>), PolygoniseFailure> {
    let (lo, hi) = model.bounds();
    let margin = 2.0 * cell;
    let origin = [lo[0] - margin, lo[1] - margin, lo[2] - margin];
    let dims: [usize; 3] =
        std::array::from_fn(|d| ((hi[d] - lo[d] + 2.0 * margin) / cell).ceil() as usize + 2);
    let grid = ScalarGrid::sample(origin, cell, dims, |p| model.eval(p));
    let (mut positions, faces) = marching_tetrahedra(&grid);
    if faces.is_empty() {
        return Err(PolygoniseFailure::NotManifold("empty surface".into()));
    }
    relax(&mut positions, &faces, model, cell, relax_iterations);
    for p in positions.iter_mut() {
        *p = p.map(|x| round_to(x, DECIMALS_PER_UNIT));
    }
    let labels: Vec<u32> = positions.iter().map(|&p| model.label(p)).collect();
    let mesh = TriMesh::new(positions, faces)
        .map_err(|e| PolygoniseFailure::NotManifold(e.to_string()))?;
    let (_, counts) = edges(&mesh);
    if let Some(c) = counts.iter().find(|&&c| c != 2) {
        return Err(PolygoniseFailure::NotManifold(format!(
            "an edge has {c} faces"
        )));
    }
    let comps = connected_components(&mesh);
    if comps.count != 1 {
        return Err(PolygoniseFailure::Components(comps.count));
    }
    Ok((mesh, labels))
}

/// Moves the point `x` onto the zero level of `model` by Newton steps along the numerical
/// gradient.
fn project(model: &Model, mut x: V3, cell: f64) -> V3 {
    let e = 1e-3 * cell;
    for _ in 0..4 {
        let f = model.eval(x);
        let g = [
            (model.eval(add(x, [e, 0.0, 0.0])) - model.eval(sub(x, [e, 0.0, 0.0]))) / (2.0 * e),
            (model.eval(add(x, [0.0, e, 0.0])) - model.eval(sub(x, [0.0, e, 0.0]))) / (2.0 * e),
            (model.eval(add(x, [0.0, 0.0, e])) - model.eval(sub(x, [0.0, 0.0, e]))) / (2.0 * e),
        ];
        let gg = dot(g, g);
        if gg < 1e-12 {
            break;
        }
        x = sub(x, scale(g, f / gg));
    }
    x
}

fn tri_normal(p: &[V3], f: [u32; 3]) -> V3 {
    let (a, b, c) = (p[f[0] as usize], p[f[1] as usize], p[f[2] as usize]);
    let u = sub(b, a);
    let v = sub(c, a);
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

/// Gauss–Seidel relaxation in vertex order: each vertex moves to its neighbours' centroid
/// projected back onto the surface, unless that turns an incident triangle over (or nearly
/// degenerates it) or moves the vertex more than half a cell. Improves the marching
/// tetrahedra slivers; deterministic.
fn relax(positions: &mut [V3], faces: &[[u32; 3]], model: &Model, cell: f64, iterations: usize) {
    let n = positions.len();
    let mut nbrs: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut vf: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (fi, f) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            nbrs[a as usize].push(b);
            nbrs[b as usize].push(a);
            vf[a as usize].push(fi as u32);
        }
    }
    for l in nbrs.iter_mut() {
        l.sort_unstable();
        l.dedup();
    }
    let min_area2 = (1e-4 * cell * cell).powi(2);
    for _ in 0..iterations {
        for v in 0..n {
            let old = positions[v];
            let mut c = [0.0; 3];
            for &u in &nbrs[v] {
                c = add(c, positions[u as usize]);
            }
            let c = scale(c, 1.0 / nbrs[v].len() as f64);
            let target = project(model, c, cell);
            if len(sub(target, old)) > 0.5 * cell || !target.iter().all(|x| x.is_finite()) {
                continue;
            }
            let before: Vec<V3> = vf[v]
                .iter()
                .map(|&f| tri_normal(positions, faces[f as usize]))
                .collect();
            positions[v] = target;
            let ok = vf[v].iter().zip(&before).all(|(&f, nb)| {
                let na = tri_normal(positions, faces[f as usize]);
                dot(na, na) > min_area2 && dot(na, *nb) > 0.0
            });
            if !ok {
                positions[v] = old;
            }
        }
    }
}
