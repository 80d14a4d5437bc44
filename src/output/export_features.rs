use super::OutputError;
use crate::bands::BandTable;
use crate::features::Descriptors;
use crate::mesh::write_atomic;
use crate::spectral::Spectrum;
use std::io::Write;
use std::path::{Path, PathBuf};

/// File format of [`export_features`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum ExportFormat {
    /// NumPy `.npy` (little-endian, C order). Default.
    #[default]
    Npy,
    /// Comma-separated text with a header row; floats in shortest round-trip form.
    Csv,
}

/// Options of [`export_features`].
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct ExportOptions {
    /// File format (default `.npy`).
    pub format: ExportFormat,
}

/// Writes a shape's descriptors and band table (and, if given, the spectrum they came from)
/// into `dir` (created if missing), for use outside coseg. Files (`.npy` or `.csv`):
/// - `descriptors`: `d × N` `f64`, one row per vertex, columns in table order;
/// - `bands`: `d × N` `u8` band labels (`0..K`);
/// - `features.json`: column names, families and scales (`t` or `e`), WKS `σ`, `K`;
/// - with a spectrum: `eigenvalues` (`k`), `eigenvectors` (`d × k`), `vertex_areas` (`d`),
///   all of the unit-area mesh (eigenvectors M-orthonormal for `vertex_areas`).
///
/// Every file is written atomically (temporary file and rename). Returns the paths written.
///
/// ```no_run
/// # fn f(d: &coseg::features::Descriptors, b: &coseg::bands::BandTable) {
/// use coseg::output::{export_features, ExportOptions};
/// export_features(std::path::Path::new("out"), d, b, None, &ExportOptions::default()).unwrap();
/// # }
/// ```
pub fn export_features(
    dir: &Path,
    descriptors: &Descriptors,
    bands: &BandTable,
    spectrum: Option<&Spectrum>,
    options: &ExportOptions,
) -> Result<Vec<PathBuf>, OutputError> {
    let d = descriptors.vertices;
    let n = descriptors.feature_count();
    if bands.vertices != d || bands.features != n {
        return Err(OutputError::Inconsistent(format!(
            "descriptors are {d} vertices × {n} features, bands {} × {}",
            bands.vertices, bands.features
        )));
    }
    std::fs::create_dir_all(dir).map_err(|source| {
        OutputError::Io(crate::FileError {
            path: dir.display().to_string(),
            source,
        })
    })?;
    let names = descriptors.names();
    let mut written = Vec::new();
    let mut put = |name: &str, bytes: Vec<u8>| -> Result<(), OutputError> {
        let path = dir.join(name);
        write_atomic(&path, |w| w.write_all(&bytes)).map_err(|source| {
            OutputError::Io(crate::FileError {
                path: path.display().to_string(),
                source,
            })
        })?;
        written.push(path);
        Ok(())
    };
    let rows = vertex_major(d, n, |f| descriptors.feature(f));
    match options.format {
        ExportFormat::Npy => {
            put("descriptors.npy", npy(&rows, &[d, n])?)?;
            put("bands.npy", npy(&bands.labels, &[d, n])?)?;
        }
        ExportFormat::Csv => {
            put("descriptors.csv", csv(&rows, n, &names))?;
            put("bands.csv", csv(&bands.labels, n, &names))?;
        }
    }
    let meta = features_meta(descriptors, bands, &names);
    put(
        "features.json",
        serde_json::to_vec_pretty(&meta).expect("plain JSON values serialise"),
    )?;
    if let Some(s) = spectrum {
        let (k, sd) = (s.len(), s.vertex_count());
        let vecs = vertex_major(sd, k, |i| s.eigenvector(i));
        match options.format {
            ExportFormat::Npy => {
                put("eigenvalues.npy", npy(&s.eigenvalues, &[k])?)?;
                put("eigenvectors.npy", npy(&vecs, &[sd, k])?)?;
                put("vertex_areas.npy", npy(&s.vertex_areas, &[sd])?)?;
            }
            ExportFormat::Csv => {
                let ev: Vec<String> = (0..k).map(|i| format!("phi_{i:03}")).collect();
                put(
                    "eigenvalues.csv",
                    csv(&s.eigenvalues, 1, &["lambda".to_string()]),
                )?;
                put("eigenvectors.csv", csv(&vecs, k, &ev))?;
                put(
                    "vertex_areas.csv",
                    csv(&s.vertex_areas, 1, &["area".to_string()]),
                )?;
            }
        }
    }
    Ok(written)
}

/// The contents of `features.json`; apart from [`export_features`] because it is a long literal
/// of its own that says what the columns of the other files are.
fn features_meta(
    descriptors: &Descriptors,
    bands: &BandTable,
    names: &[String],
) -> serde_json::Value {
    let (d, n) = (descriptors.vertices, descriptors.feature_count());
    serde_json::json!({
        "vertices": d,
        "features": n,
        "bands": bands.bands,
        "names": names,
        "kinds": descriptors
            .kinds()
            .iter()
            .map(|k| k.family().to_string())
            .chain(descriptors.extra_names.iter().map(|n| extra_family(n)))
            .collect::<Vec<_>>(),
        "scales": descriptors
            .kinds()
            .iter()
            .map(|k| Some(k.scale()))
            .chain(descriptors.extra_names.iter().map(|_| None))
            .collect::<Vec<_>>(),
        "hks_times": descriptors.hks_times,
        "wks_energies": descriptors.wks_energies,
        "wks_sigma": descriptors.wks_sigma,
        "curvature_times": descriptors.curvature_times,
    })
}

fn npy<T: npyz::AutoSerialize + Copy>(data: &[T], shape: &[usize]) -> Result<Vec<u8>, OutputError> {
    use npyz::WriterBuilder;
    let mut buf = Vec::new();
    let io = |source| {
        OutputError::Io(crate::FileError {
            path: "<npy buffer>".into(),
            source,
        })
    };
    let shape: Vec<u64> = shape.iter().map(|&s| s as u64).collect();
    let mut w = npyz::WriteOptions::new()
        .default_dtype()
        .shape(&shape)
        .writer(&mut buf)
        .begin_nd()
        .map_err(io)?;
    w.extend(data.iter().copied()).map_err(io)?;
    w.finish().map_err(io)?;
    Ok(buf)
}

fn csv<T: std::fmt::Display>(data: &[T], cols: usize, names: &[String]) -> Vec<u8> {
    use std::fmt::Write;
    let mut s = names.join(",");
    s.push('\n');
    for row in data.chunks(cols.max(1)) {
        for (i, x) in row.iter().enumerate() {
            if i > 0 {
                s.push(',');
            }
            write!(s, "{x}").expect("writing to a String cannot fail");
        }
        s.push('\n');
    }
    s.into_bytes()
}

/// The family of an extra column from its name: `ext`, `sdf` or `user`.
fn extra_family(name: &str) -> String {
    name.split(['_', ':']).next().unwrap_or(name).to_string()
}

/// The vertex-major copy (`vertices × columns`, row by row) of `columns` per-vertex columns.
fn vertex_major<'a>(
    vertices: usize,
    columns: usize,
    column: impl Fn(usize) -> &'a [f64],
) -> Vec<f64> {
    let mut rows = vec![0.0; vertices * columns];
    for c in 0..columns {
        for (v, &x) in column(c).iter().enumerate() {
            rows[v * columns + c] = x;
        }
    }
    rows
}
