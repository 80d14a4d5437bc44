//! [`read_labels`]: one integer per line, as in `<name>.labels.txt` and `<name>.regions.txt`.

use super::EvaluateError;
use crate::labels::LabelError;
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
    crate::labels::read_label_file(path)
        .map(|(_, labels)| labels)
        .map_err(|e| evaluate_error(e, path))
}

/// [`read_labels`] on bytes held in memory; errors name `name`. Never panics, whatever the
/// bytes (text that is not UTF-8 is an error naming its first bad line).
///
/// ```
/// use coseg::evaluate::parse_labels;
/// assert_eq!(parse_labels(b"1\n\n 2 \r\n", "x.txt").unwrap(), vec![1, 2]);
/// assert!(parse_labels(b"1\n\xff\n", "x.txt").unwrap_err().to_string().contains("x.txt:2:"));
/// ```
pub fn parse_labels(bytes: &[u8], name: &str) -> Result<Vec<i32>, EvaluateError> {
    crate::labels::parse_label_file(bytes, Path::new(name))
        .map(|(_, labels)| labels)
        .map_err(|e| evaluate_error(e, Path::new(name)))
}

/// The label module's error (one parser of label files serves both) as this module's.
fn evaluate_error(e: LabelError, path: &Path) -> EvaluateError {
    match e {
        LabelError::Io(e) => EvaluateError::Io(e),
        e @ LabelError::BadLabel { .. } => EvaluateError::Label(e),
        e => EvaluateError::BadManifest {
            path: path.display().to_string(),
            message: e.to_string(),
        },
    }
}
