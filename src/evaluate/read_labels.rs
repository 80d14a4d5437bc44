//! [`read_labels`]: one integer per line, as in `<name>.labels.txt` and `<name>.regions.txt`.

use super::EvaluateError;
use std::path::Path;

/// Reads a per-vertex label file: one integer per line, in vertex order (blank lines are
/// skipped, surrounding spaces ignored). Reads both the ground truth of `collections/`
/// (`<name>.labels.txt`, part indices) and the output of `coseg pair` / `coseg segment`
/// (`<name>.regions.txt`, region ids, `-1` = none). Errors name the file and the 1-based line.
///
/// ```
/// let path = std::env::temp_dir().join(format!("coseg-doc-labels-{}.txt", std::process::id()));
/// std::fs::write(&path, "0\n3\n-1\n").unwrap();
/// assert_eq!(coseg::evaluate::read_labels(&path).unwrap(), vec![0, 3, -1]);
/// std::fs::write(&path, "0\nleg\n").unwrap();
/// let e = coseg::evaluate::read_labels(&path).unwrap_err().to_string();
/// assert!(e.contains(":2:") && e.contains("leg"), "{e}");
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn read_labels(path: impl AsRef<Path>) -> Result<Vec<i32>, EvaluateError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|source| EvaluateError::Io {
        path: path.display().to_string(),
        source,
    })?;
    let mut labels = Vec::with_capacity(text.len() / 2);
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        labels.push(t.parse().map_err(|_| EvaluateError::BadLabel {
            path: path.display().to_string(),
            line: i + 1,
            text: t.to_string(),
        })?);
    }
    Ok(labels)
}
