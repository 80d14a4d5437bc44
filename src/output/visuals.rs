//! [`write_visuals`]: every picture of a result folder in one call.

use super::{OutputError, write_viewer};
use crate::render::{RenderOptions, RenderShape, write_pictures};
use std::path::{Path, PathBuf};

/// Writes the pictures of a result into `dir`: `preview.png` (contact sheet), `<name>.png`
/// per shape (see [`crate::render::write_pictures`]) and `index.html` (see [`write_viewer`]).
/// `part_names[i]` names label `i` in the legends. Returns the paths written.
///
/// This is the one call `segment`, `pair` and `propagate` make, so their pictures look alike.
///
/// ```
/// use coseg::mesh::TriMesh;
/// use coseg::output::write_visuals;
/// use coseg::render::{RenderOptions, RenderShape};
/// let mesh = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let dir = std::env::temp_dir().join(format!("coseg-doc-visuals-{}", std::process::id()));
/// let shape = RenderShape { name: "tri", mesh: &mesh, labels: &[0, 1, 1], confidence: None, view: None };
/// let names = vec!["head".to_string(), "tail".to_string()];
/// let paths = write_visuals(&dir, &[shape], Some(&names), &RenderOptions::default()).unwrap();
/// assert_eq!(paths.len(), 3);
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_visuals(
    dir: &Path,
    shapes: &[RenderShape<'_>],
    part_names: Option<&[String]>,
    options: &RenderOptions,
) -> Result<Vec<PathBuf>, OutputError> {
    let mut paths = write_pictures(dir, shapes, part_names, options)?;
    paths.push(write_viewer(dir, shapes, part_names)?);
    Ok(paths)
}
