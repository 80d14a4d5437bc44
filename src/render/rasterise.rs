//! [`draw_mesh`]: z-buffered, orthographic, flat-coloured and smoothly lit triangles.

use super::{RgbImage, ViewFrame};
use crate::mesh::TriMesh;

/// Direction toward the light in view coordinates (up-left, mostly from the viewer): a head
/// light slightly off axis shows relief that a pure head light flattens.
const LIGHT: [f64; 3] = [-0.3, 0.4, 0.866];
const AMBIENT: f64 = 0.35;

/// Draws `mesh` into the rectangle `rect = [x, y, width, height]` of `img`, seen along
/// `frame` (orthographic), scaled to fit the rectangle with a 5 % margin and centred.
///
/// `colors` has one RGB colour per vertex (length #V); each pixel takes the colour of the
/// nearest corner of its triangle, shaded by `0.35 + 0.65 |n·l|` with `n` the interpolated
/// vertex normal (two-sided, so inconsistently oriented meshes look right). Only pixels the
/// mesh covers are changed. Panics if `colors.len() != mesh.vertex_count()`.
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::render::{RgbImage, canonical_frame, draw_mesh};
/// let mesh = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let mut img = RgbImage::filled(32, 32, [0, 0, 0]);
/// draw_mesh(&mut img, [0, 0, 32, 32], &mesh, &[[255, 0, 0]; 3], &canonical_frame(&mesh));
/// assert!(img.pixels.chunks(3).any(|p| p[0] > 0));
/// ```
pub fn draw_mesh(
    img: &mut RgbImage,
    rect: [u32; 4],
    mesh: &TriMesh,
    colors: &[[u8; 3]],
    frame: &ViewFrame,
) {
    assert_eq!(colors.len(), mesh.vertex_count(), "one colour per vertex");
    let [rx, ry, rw, rh] = rect.map(f64::from);
    let view: Vec<[f64; 3]> = mesh.positions().iter().map(|&p| frame.project(p)).collect();
    let normals: Vec<[f64; 3]> = mesh
        .vertex_normals()
        .iter()
        .map(|&n| frame.axes.map(|a| a[0] * n[0] + a[1] * n[1] + a[2] * n[2]))
        .collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for f in mesh.faces() {
        for &v in f {
            let p = view[v as usize];
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    let span = [(hi[0] - lo[0]).max(1e-300), (hi[1] - lo[1]).max(1e-300)];
    let scale = (0.9 * rw / span[0]).min(0.9 * rh / span[1]);
    let (cx, cy) = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]));
    let screen: Vec<[f64; 3]> = view
        .iter()
        .map(|p| {
            [
                rx + 0.5 * rw + scale * (p[0] - cx),
                ry + 0.5 * rh - scale * (p[1] - cy),
                p[2],
            ]
        })
        .collect();
    let w = rect[2] as usize;
    let mut depth = vec![f64::NEG_INFINITY; w * rect[3] as usize];
    let ln = {
        let n = LIGHT.iter().map(|x| x * x).sum::<f64>().sqrt();
        LIGHT.map(|x| x / n)
    };
    for f in mesh.faces() {
        let [a, b, c] = f.map(|v| screen[v as usize]);
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area.abs() < 1e-12 {
            continue;
        }
        let x0 = a[0].min(b[0]).min(c[0]).floor().max(rx) as i64;
        let x1 = a[0].max(b[0]).max(c[0]).ceil().min(rx + rw - 1.0) as i64;
        let y0 = a[1].min(b[1]).min(c[1]).floor().max(ry) as i64;
        let y1 = a[1].max(b[1]).max(c[1]).ceil().min(ry + rh - 1.0) as i64;
        for py in y0..=y1 {
            for px in x0..=x1 {
                let (sx, sy) = (px as f64 + 0.5, py as f64 + 0.5);
                let l0 = ((b[0] - sx) * (c[1] - sy) - (b[1] - sy) * (c[0] - sx)) / area;
                let l1 = ((c[0] - sx) * (a[1] - sy) - (c[1] - sy) * (a[0] - sx)) / area;
                let l2 = 1.0 - l0 - l1;
                if l0 < 0.0 || l1 < 0.0 || l2 < 0.0 {
                    continue;
                }
                let z = l0 * a[2] + l1 * b[2] + l2 * c[2];
                let di = (py - ry as i64) as usize * w + (px - rx as i64) as usize;
                if di >= depth.len() || z <= depth[di] {
                    continue;
                }
                depth[di] = z;
                let [na, nb, nc] = f.map(|v| normals[v as usize]);
                let n = [0, 1, 2].map(|k| l0 * na[k] + l1 * nb[k] + l2 * nc[k]);
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                let lambert = if len > 0.0 {
                    ((n[0] * ln[0] + n[1] * ln[1] + n[2] * ln[2]) / len).abs()
                } else {
                    1.0
                };
                let shade = AMBIENT + (1.0 - AMBIENT) * lambert;
                let nearest = if l0 >= l1 && l0 >= l2 {
                    0
                } else if l1 >= l2 {
                    1
                } else {
                    2
                };
                let base = colors[f[nearest] as usize];
                img.set(
                    px,
                    py,
                    base.map(|x| (x as f64 * shade).round().min(255.0) as u8),
                );
            }
        }
    }
}
