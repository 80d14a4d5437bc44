//! Fixtures for the features, bands and cache tests: icospheres, a smooth asymmetric blob, rigid
//! motions and vertex permutations.
#![allow(dead_code)]

use coseg::mesh::TriMesh;

/// Unit icosphere: an icosahedron subdivided `level` times, vertices projected on the unit
/// sphere (10·4^level + 2 vertices), counter-clockwise seen from outside.
pub fn icosphere(level: usize) -> TriMesh {
    super::shapes::icosphere(level as u32, 1.0)
}

/// A smooth, star-shaped, asymmetric blob (no symmetry, so generic simple eigenvalues and no
/// feature ties): the icosphere with radius `1 + bumps(direction)`.
pub fn blob(level: usize) -> TriMesh {
    icosphere(level)
        .map_positions(|p| {
            let r = 1.0
                + 0.35 * (2.0 * p[0] + 0.3).sin() * (1.5 * p[1] - 0.2).cos()
                + 0.25 * (3.0 * p[2] + 0.7 * p[0]).sin()
                + 0.6 * (p[0] - 0.5).max(0.0).powi(2);
            [r * p[0] * 1.3, r * p[1], r * p[2] * 0.8]
        })
        .unwrap()
}

/// A rotation (about an oblique axis), uniform scaling by `scale` and translation.
pub fn similarity(mesh: &TriMesh, scale: f64) -> TriMesh {
    let (a, b) = (0.7f64, -1.1f64);
    let (ca, sa, cb, sb) = (a.cos(), a.sin(), b.cos(), b.sin());
    mesh.map_positions(|p| {
        // Rotate about z by a, then about x by b.
        let q = [ca * p[0] - sa * p[1], sa * p[0] + ca * p[1], p[2]];
        let r = [q[0], cb * q[1] - sb * q[2], sb * q[1] + cb * q[2]];
        [scale * r[0] + 3.0, scale * r[1] - 1.5, scale * r[2] + 0.25]
    })
    .unwrap()
}

/// A fixed pseudo-random permutation of `0..n` (`perm[new] = old`), seeded.
pub fn permutation(n: usize, seed: u64) -> Vec<usize> {
    let mut p: Vec<usize> = (0..n).collect();
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    for i in (1..n).rev() {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let j = ((s >> 33) % (i as u64 + 1)) as usize;
        p.swap(i, j);
    }
    p
}

/// The mesh with its vertices reordered: new vertex `i` is old vertex `perm[i]`.
pub fn permute_mesh(mesh: &TriMesh, perm: &[usize]) -> TriMesh {
    let mut inv = vec![0u32; perm.len()];
    for (new, &old) in perm.iter().enumerate() {
        inv[old] = new as u32;
    }
    let pos = perm.iter().map(|&old| mesh.positions()[old]).collect();
    let faces = mesh
        .faces()
        .iter()
        .map(|f| [inv[f[0] as usize], inv[f[1] as usize], inv[f[2] as usize]])
        .collect();
    TriMesh::new(pos, faces).unwrap()
}

/// Ranks of `x` (0-based, ties by index).
pub fn ranks(x: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..x.len()).collect();
    order.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
    let mut r = vec![0; x.len()];
    for (i, &v) in order.iter().enumerate() {
        r[v] = i;
    }
    r
}

/// Spearman rank correlation (no tie correction).
pub fn spearman(a: &[f64], b: &[f64]) -> f64 {
    let (ra, rb) = (ranks(a), ranks(b));
    let n = a.len() as f64;
    let d2: f64 = ra
        .iter()
        .zip(&rb)
        .map(|(&x, &y)| (x as f64 - y as f64).powi(2))
        .sum();
    1.0 - 6.0 * d2 / (n * (n * n - 1.0))
}

/// A small pipeline for tests: `eigenpairs` eigenpairs, `per_kind` HKS, WKS and curvature
/// features each, 8 bands.
pub fn small_pipeline(eigenpairs: usize, per_kind: usize) -> coseg::pipeline::ShapePipelineOptions {
    let mut o = coseg::pipeline::ShapePipelineOptions::default();
    o.spectrum.eigenpairs = eigenpairs;
    o.descriptors.hks_count = per_kind;
    o.descriptors.wks_count = per_kind;
    o.descriptors.curvature_count = per_kind;
    o.bands.bands = 8;
    o
}

/// A small ZoomOut for tests: spectral sizes 6 to 40 in steps of 5, 300 samples.
pub fn small_zoomout() -> coseg::maps::ZoomOutOptions {
    let mut opts = coseg::maps::ZoomOutOptions::default();
    opts.initial_size = 6;
    opts.final_size = 40;
    opts.step = 5;
    opts.samples = 300;
    opts
}

/// The `k` smallest Laplace–Beltrami eigenpairs of `mesh` (the library's other defaults).
pub fn spectrum_of(mesh: &coseg::mesh::TriMesh, k: usize) -> coseg::spectral::Spectrum {
    coseg::spectral::laplace_beltrami_spectrum(
        mesh,
        &coseg::spectral::SpectrumOptions::with_eigenpairs(k),
    )
    .unwrap()
}

/// A labelled blob and two vertex-permuted copies of it (exact isometries), for propagation:
/// `dir/shapes/` holds `a.off` (`blob(3)`), `c1.off` and `c2.off` (permutation seeds 11 and
/// 12); `dir/a.labels.txt` holds `truth` of the blob. Returns the folder, the blob and the
/// copies.
pub fn labelled_blob_and_copies(
    dir: &std::path::Path,
    truth: impl Fn(&TriMesh) -> Vec<i32>,
) -> (std::path::PathBuf, TriMesh, Vec<TriMesh>) {
    let shapes = dir.join("shapes");
    std::fs::create_dir(&shapes).unwrap();
    let mesh = blob(3);
    coseg::mesh::write_mesh(shapes.join("a.off"), &mesh, &[]).unwrap();
    coseg::labels::write_vertex_labels(dir, "a", &truth(&mesh)).unwrap();
    let mut copies = Vec::new();
    for (k, seed) in [(1, 11u64), (2, 12)] {
        let copy = permute_mesh(&mesh, &permutation(mesh.vertex_count(), seed));
        coseg::mesh::write_mesh(shapes.join(format!("c{k}.off")), &copy, &[]).unwrap();
        copies.push(copy);
    }
    (shapes, mesh, copies)
}

/// Three parts of a mesh cut by planes across `x` (at −0.4 and 0.35): labels 0, 1, 2 per vertex,
/// the blob's slab parts of the propagation tests.
pub fn three_slabs(mesh: &TriMesh) -> Vec<i32> {
    mesh.positions()
        .iter()
        .map(|p| {
            if p[0] < -0.4 {
                0
            } else if p[0] < 0.35 {
                1
            } else {
                2
            }
        })
        .collect()
}
