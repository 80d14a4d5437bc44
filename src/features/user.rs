//! User-supplied per-vertex features: one matrix per shape, `.npy` or CSV, for researchers
//! who bring their own descriptors (learned ones included).

use super::{FeatureColumns, FeatureError};
use std::path::{Path, PathBuf};

fn bad(path: &Path, message: impl Into<String>) -> FeatureError {
    FeatureError::UserFile {
        path: path.display().to_string(),
        message: message.into(),
    }
}

/// The feature file of shape `stem` in `dir`: `<stem>.npy`, else `<stem>.csv`; `None` when
/// neither exists.
///
/// ```
/// let dir = std::env::temp_dir();
/// assert!(coseg::features::user_feature_path(&dir, "no-such-shape-xyz").is_none());
/// ```
pub fn user_feature_path(dir: &Path, stem: &str) -> Option<PathBuf> {
    ["npy", "csv"]
        .iter()
        .map(|ext| dir.join(format!("{stem}.{ext}")))
        .find(|p| p.is_file())
}

/// Reads a user feature matrix for a mesh of `vertices` vertices.
///
/// - `.npy`: a 2-D `float64` or `float32` array of shape `(vertices, N)` (C or Fortran order),
///   or 1-D of length `vertices` (one feature). Columns are named by position:
///   `user_000`, `user_001`… (paired across shapes by position).
/// - `.csv` (or anything else): one row per vertex, `N` comma-separated numbers. If the first
///   row is not all numbers it is a header and columns are named `user:<header>` (paired
///   across shapes by header, whatever their order in each file); otherwise by position.
///
/// Values are stored as read (`f32` widened to `f64` exactly), so they round-trip bit for bit.
/// Errors name the file and the problem: wrong row count, ragged rows, a non-number, NaN.
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let p = dir.path().join("a.csv");
/// std::fs::write(&p, "height,curv\n1,0.5\n2,0.25\n3,0\n").unwrap();
/// let c = coseg::features::read_user_features(&p, 3).unwrap();
/// assert_eq!(c.names, ["user:height", "user:curv"]);
/// assert_eq!(c.column(1), &[0.5, 0.25, 0.0]);
/// assert!(coseg::features::read_user_features(&p, 4).is_err());
/// ```
pub fn read_user_features(path: &Path, vertices: usize) -> Result<FeatureColumns, FeatureError> {
    let bytes = std::fs::read(path).map_err(|e| bad(path, e.to_string()))?;
    let (names, values) = if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
    {
        read_npy(path, &bytes, vertices)?
    } else {
        read_csv(path, &bytes, vertices)?
    };
    if let Some(i) = values.iter().position(|x| !x.is_finite()) {
        return Err(bad(
            path,
            format!(
                "column {} is not finite at vertex {}",
                names[i / vertices],
                i % vertices
            ),
        ));
    }
    FeatureColumns::new(vertices, names, values).map_err(|e| bad(path, e.to_string()))
}

type Table = (Vec<String>, Vec<f64>);

fn positional(n: usize) -> Vec<String> {
    (0..n).map(|i| format!("user_{i:03}")).collect()
}

fn read_npy(path: &Path, bytes: &[u8], vertices: usize) -> Result<Table, FeatureError> {
    let open = || npyz::NpyFile::new(bytes).map_err(|e| bad(path, format!("not a .npy file: {e}")));
    let npy = open()?;
    let shape = npy.shape().to_vec();
    let fortran = npy.order() == npyz::Order::Fortran;
    let data: Vec<f64> = match npy.into_vec::<f64>() {
        Ok(v) => v,
        Err(_) => open()?
            .into_vec::<f32>()
            .map_err(|e| bad(path, format!("expected a float64 or float32 array: {e}")))?
            .into_iter()
            .map(f64::from)
            .collect(),
    };
    let (rows, cols) = match shape[..] {
        [r] => (r as usize, 1),
        [r, c] => (r as usize, c as usize),
        _ => {
            return Err(bad(
                path,
                format!("expected a 1-D or 2-D array, got shape {shape:?}"),
            ));
        }
    };
    if rows != vertices {
        return Err(bad(
            path,
            format!("{rows} rows but the mesh has {vertices} vertices"),
        ));
    }
    if cols == 0 {
        return Err(bad(path, "the array has no column"));
    }
    // Feature-major is the Fortran layout of a (vertices, N) array.
    let values = if fortran || cols == 1 {
        data
    } else {
        let mut v = vec![0.0; data.len()];
        for r in 0..rows {
            for c in 0..cols {
                v[c * rows + r] = data[r * cols + c];
            }
        }
        v
    };
    Ok((positional(cols), values))
}

fn read_csv(path: &Path, bytes: &[u8], vertices: usize) -> Result<Table, FeatureError> {
    let text = std::str::from_utf8(bytes).map_err(|_| bad(path, "not UTF-8 text"))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, first)) = lines.next() else {
        return Err(bad(path, "empty file"));
    };
    let cells = |l: &str| {
        l.split(',')
            .map(|c| c.trim().to_string())
            .collect::<Vec<_>>()
    };
    let head = cells(first);
    let is_header = head.iter().any(|c| c.parse::<f64>().is_err());
    let names = if is_header {
        head.iter().map(|h| format!("user:{h}")).collect()
    } else {
        positional(head.len())
    };
    let n = names.len();
    let mut rows: Vec<Vec<f64>> = Vec::with_capacity(vertices);
    let first_data = (!is_header).then_some((0usize, first));
    for (i, line) in first_data.into_iter().chain(lines) {
        let row = cells(line);
        if row.len() != n {
            return Err(bad(
                path,
                format!("line {}: {} values, expected {n}", i + 1, row.len()),
            ));
        }
        let parsed: Result<Vec<f64>, _> = row.iter().map(|c| c.parse::<f64>()).collect();
        rows.push(parsed.map_err(|_| bad(path, format!("line {}: not a number", i + 1)))?);
    }
    if rows.len() != vertices {
        return Err(bad(
            path,
            format!("{} rows but the mesh has {vertices} vertices", rows.len()),
        ));
    }
    let values = (0..n)
        .flat_map(|c| rows.iter().map(move |r| r[c]))
        .collect();
    Ok((names, values))
}
