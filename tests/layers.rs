//! The pipeline's stages depend one way: no module of the library names (outside comments) a
//! module of a later stage. The order is the README's: mesh → align → per-shape operators and spectrum →
//! features → bands → per-shape pipeline → affinity → maps → stable → graph → propagate →
//! evaluate → output. Doc links may point forward; code may not.

use std::path::Path;

/// Earlier stages first. `vertex_sets` (sorted-set helpers), `labels` (label files) and
/// `generate` (synthetic inputs) depend only on `mesh`; `cache` only stores entries.
const ORDER: &[&str] = &[
    "vertex_sets",
    "mesh",
    "labels",
    "generate",
    "cache",
    "align",
    "spectral",
    "features",
    "bands",
    "pipeline",
    "affinity",
    "maps",
    "stable",
    "graph",
    "shape_task",
    "propagate",
    "evaluate",
    "render",
    "output",
];

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// `(module, named module, file:line)` for every `crate::x` outside comments.
fn references() -> Vec<(String, String, String)> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut refs = Vec::new();
    for f in files {
        let rel = f
            .strip_prefix(&src)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        let top = rel
            .split('/')
            .next()
            .unwrap()
            .trim_end_matches(".rs")
            .to_string();
        if matches!(top.as_str(), "cli" | "main" | "lib") {
            continue;
        }
        for (i, line) in std::fs::read_to_string(&f).unwrap().lines().enumerate() {
            if line.trim_start().starts_with("//") {
                continue;
            }
            for (at, _) in line.match_indices("crate::") {
                let name: String = line[at + 7..]
                    .chars()
                    .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                    .collect();
                if !name.is_empty() && name != top {
                    refs.push((top.clone(), name, format!("src/{rel}:{}", i + 1)));
                }
            }
        }
    }
    refs
}

#[test]
fn no_module_names_a_module_of_a_later_stage() {
    let refs = references();
    assert!(
        refs.iter().any(|(m, d, _)| m == "graph" && d == "stable"),
        "the scan found nothing: it no longer reads the sources"
    );
    let stage = |m: &str| ORDER.iter().position(|x| *x == m);
    let mut bad = Vec::new();
    for (m, d, at) in &refs {
        match (stage(m), stage(d)) {
            (Some(a), Some(b)) if b > a => bad.push(format!("{at}: {m} uses the later {d}")),
            (None, _) => bad.push(format!("{at}: module {m} has no stage in ORDER")),
            (_, None) => bad.push(format!("{at}: {d} has no stage in ORDER")),
            _ => {}
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}
