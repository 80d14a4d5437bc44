//! An output folder's files and a cache folder's entries, read back to compare runs byte for
//! byte.

use super::cli::text;
use std::path::{Path, PathBuf};

/// The files of `dir` (not its folders) by name, `summary.json` without its
/// `collection_stage` field (the last one, written only when the part tree was read from the
/// cache and re-cut).
pub fn output_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            let mut bytes = std::fs::read(&p).unwrap();
            if name == "summary.json" {
                let t = text(&bytes).replace(",\n  \"collection_stage\": \"recut\"\n}", "\n}");
                bytes = t.into_bytes();
            }
            (name, bytes)
        })
        .collect();
    out.sort();
    out
}

/// Asserts that two [`output_files`] lists hold the same names and bytes (`what` names the
/// comparison in the failure).
pub fn same_files(a: &[(String, Vec<u8>)], b: &[(String, Vec<u8>)], what: &str) {
    assert_eq!(
        a.iter().map(|f| &f.0).collect::<Vec<_>>(),
        b.iter().map(|f| &f.0).collect::<Vec<_>>(),
        "{what}"
    );
    for ((name, x), (_, y)) in a.iter().zip(b) {
        assert!(x == y, "{what}: {name} differs");
    }
}

/// The entries of `cache` with extension `ext`, sorted, with their bytes.
pub fn cache_entries(cache: &Path, ext: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out: Vec<(PathBuf, Vec<u8>)> = std::fs::read_dir(cache)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == ext))
        .map(|p| {
            let b = std::fs::read(&p).unwrap();
            (p, b)
        })
        .collect();
    out.sort();
    out
}
