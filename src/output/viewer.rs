//! [`write_viewer`]: `OUT/index.html`, one self-contained interactive 3D view of every shape.
//!
//! The page needs no network: the meshes are embedded as base64 of little-endian arrays
//! (positions `f32`, already in each shape's view ([`RenderShape::frame`]: the collection's shared view where
//! the job gave one, else the shape's canonical view) and scaled to unit radius;
//! triangle indices `u32`; colours `u8` RGB from [`region_colors`]) in a JSON block, and
//! about 150 lines of our own WebGL 1 code draw them. Drag rotates, the wheel zooms, the list
//! picks a shape; the legend names the parts and each shape shows its confidence. The page
//! writes its state into `#status` (`ok: N shapes` or `error: …`) so tests can read it.

use super::{OutputError, region_colors};
use crate::mesh::write_atomic;
use crate::render::{RenderShape, labels_present};
use std::io::Write;
use std::path::{Path, PathBuf};

const TEMPLATE: &str = include_str!("viewer.html");
/// The page's WebGL helpers (`shader`, `normals`), shared with the studio page of `coseg studio`.
const GL_FUNCTIONS: &str = include_str!("gl_functions.js");
/// The page's shaded program (`prog`) and its attribute and uniform locations (`loc`) for the
/// context `gl`, shared with the studio page.
const GL_PROGRAM: &str = include_str!("gl_program.js");

fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ABC[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// The JSON data block of the page: shapes (name, confidence, base64 arrays) and parts.
fn page_data(shapes: &[RenderShape<'_>], part_names: Option<&[String]>) -> serde_json::Value {
    let labels = labels_present(shapes);
    let parts: Vec<serde_json::Value> = labels
        .iter()
        .zip(region_colors(&labels))
        .map(|(&l, c)| {
            let name = (l >= 0)
                .then(|| part_names.and_then(|n| n.get(l as usize)).cloned())
                .flatten();
            serde_json::json!({"id": l, "name": name, "color": c})
        })
        .collect();
    let shapes: Vec<serde_json::Value> = shapes
        .iter()
        .map(|s| {
            let frame = s.frame();
            let view: Vec<[f64; 3]> = s
                .mesh
                .positions()
                .iter()
                .map(|&p| frame.project(p))
                .collect();
            let radius = view
                .iter()
                .map(|p| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt())
                .fold(0.0f64, f64::max)
                .max(1e-300);
            let pos: Vec<u8> = view
                .iter()
                .flat_map(|p| p.map(|x| ((x / radius) as f32).to_le_bytes()))
                .flatten()
                .collect();
            let idx: Vec<u8> = s
                .mesh
                .faces()
                .iter()
                .flat_map(|f| f.map(u32::to_le_bytes))
                .flatten()
                .collect();
            let col: Vec<u8> = region_colors(s.labels).into_iter().flatten().collect();
            serde_json::json!({
                "name": s.name,
                "confidence": s.confidence,
                "vertices": s.mesh.vertex_count(),
                "faces": s.mesh.face_count(),
                "positions": base64(&pos),
                "indices": base64(&idx),
                "colors": base64(&col),
            })
        })
        .collect();
    serde_json::json!({"shapes": shapes, "parts": parts})
}

/// Writes `dir/index.html` (atomically; `dir` created if missing) showing `shapes`, coloured
/// by label, with a legend naming label `i` `part_names[i]` when given. Returns its path.
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::output::write_viewer;
/// use coseg::render::RenderShape;
/// let mesh = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let dir = std::env::temp_dir().join(format!("coseg-doc-viewer-{}", std::process::id()));
/// let shape = RenderShape { name: "tri", mesh: &mesh, labels: &[0, 1, 1], confidence: Some(0.5), view: None };
/// let path = write_viewer(&dir, &[shape], None).unwrap();
/// let html = std::fs::read_to_string(&path).unwrap();
/// assert!(html.contains("\"name\":\"tri\"") && !html.contains("http"));
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_viewer(
    dir: &Path,
    shapes: &[RenderShape<'_>],
    part_names: Option<&[String]>,
) -> Result<PathBuf, OutputError> {
    for s in shapes {
        if s.labels.len() != s.mesh.vertex_count() {
            return Err(OutputError::Length {
                name: s.name.to_string(),
                ids: s.labels.len(),
                vertices: s.mesh.vertex_count(),
            });
        }
    }
    let data = page_data(shapes, part_names);
    // `</` inside a script block would end it: JSON allows escaping the slash.
    let json = serde_json::to_string(&data)
        .map_err(|e| OutputError::Json(e.to_string()))?
        .replace("</", "<\\/");
    let html = TEMPLATE
        .replace("__GL_FUNCTIONS__\n", GL_FUNCTIONS)
        .replace("__GL_PROGRAM__\n", GL_PROGRAM)
        .replace("__COSEG_DATA__", &json);
    std::fs::create_dir_all(dir).map_err(|source| {
        OutputError::Io(crate::FileError {
            path: dir.display().to_string(),
            source,
        })
    })?;
    let path = dir.join("index.html");
    write_atomic(&path, |w| w.write_all(html.as_bytes())).map_err(|source| {
        OutputError::Io(crate::FileError {
            path: path.display().to_string(),
            source,
        })
    })?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::base64;

    #[test]
    fn base64_matches_rfc4648_vectors() {
        for (input, want) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(input.as_bytes()), want, "{input}");
        }
    }
}
