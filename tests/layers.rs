//! The pipeline's stages depend one way: no module of the library names (outside comments) a
//! module of a later stage. The order is the README's: mesh → align → per-shape operators and
//! spectrum → features → bands → per-shape pipeline → affinity → maps → stable → graph → parts →
//! propagate → evaluate → output → jobs → studio. Doc links may point forward; code may not.
//! Within a module, no two files import each other, directly or around a longer circle.

use std::path::Path;

/// Earlier stages first. `file_error` (the I/O error every stage reports) depends on nothing.
/// `vertex_sets` (sorted-set helpers), `labels` (label files) and
/// `generate` (synthetic inputs) depend only on `mesh`; `cache` only stores entries;
/// `stage_timer` (the `COSEG_TIMINGS` profile lines) and `option_range` (the range check of
/// option values) depend on nothing and every stage may use them.
const ORDER: &[&str] = &[
    "file_error",
    "stage_timer",
    "option_range",
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
    "parts",
    "shape_task",
    "propagate",
    "evaluate",
    "render",
    "output",
    "jobs",
    "studio",
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

/// The code of `text` (comment lines dropped) up to its unit tests, whose `super::` is the
/// file itself.
fn code_lines(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            break;
        }
        if !line.trim_start().starts_with("//") {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// The first path segment of every item a `super::` path names in `code`, braces expanded:
/// `super::a::X` gives `a`, `super::{X, b::Y}` gives `X` and `b`.
fn super_names(code: &str) -> Vec<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut names = Vec::new();
    for (at, _) in code.match_indices("super::") {
        let rest = &code[at + 7..];
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 1;
            let mut item = String::new();
            for c in group.chars() {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    _ => {}
                }
                if depth == 0 || (depth == 1 && c == ',') {
                    names.push(ident(&item));
                    item.clear();
                    if depth == 0 {
                        break;
                    }
                } else {
                    item.push(c);
                }
            }
        } else {
            names.push(ident(rest));
        }
    }
    names.retain(|n| !n.is_empty() && n != "super");
    names
}

/// For each module folder: `file → files it imports`, an item re-exported by `mod.rs`
/// (`pub use file::{…}`) counting as its file.
fn file_imports() -> Vec<(String, std::collections::BTreeMap<String, Vec<String>>)> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut modules = Vec::new();
    for e in std::fs::read_dir(&src).unwrap() {
        let dir = e.unwrap().path();
        if !dir.is_dir() || !dir.join("mod.rs").exists() {
            continue;
        }
        let mut files = Vec::new();
        rust_files(&dir, &mut files);
        let stem = |p: &Path| p.file_stem().unwrap().to_string_lossy().to_string();
        let siblings: Vec<String> = files
            .iter()
            .filter(|f| f.parent() == Some(dir.as_path()))
            .map(|f| stem(f))
            .collect();
        // Items of mod.rs's `pub use file::…` lines, by the file that defines them.
        let mut owner = std::collections::BTreeMap::new();
        let root = code_lines(&std::fs::read_to_string(dir.join("mod.rs")).unwrap());
        for stmt in root.split(';') {
            let stmt = stmt.trim();
            let Some(path) = stmt
                .strip_prefix("pub use ")
                .or_else(|| stmt.strip_prefix("pub(crate) use "))
            else {
                continue;
            };
            let Some((file, items)) = path.split_once("::") else {
                continue;
            };
            if !siblings.iter().any(|s| s == file) {
                continue;
            }
            for item in items.trim_matches(|c| c == '{' || c == '}').split(',') {
                let name = item.split(" as ").last().unwrap().trim();
                if !name.is_empty() {
                    owner.insert(name.to_string(), file.to_string());
                }
            }
        }
        let mut imports = std::collections::BTreeMap::new();
        for f in files.iter().filter(|f| f.parent() == Some(dir.as_path())) {
            let name = stem(f);
            if name == "mod" {
                continue;
            }
            let code = code_lines(&std::fs::read_to_string(f).unwrap());
            let mut to: Vec<String> = super_names(&code)
                .into_iter()
                .filter_map(|n| {
                    if siblings.contains(&n) {
                        Some(n)
                    } else {
                        owner.get(&n).cloned()
                    }
                })
                .filter(|n| *n != name && n != "mod")
                .collect();
            to.sort();
            to.dedup();
            imports.insert(name, to);
        }
        modules.push((stem(&dir), imports));
    }
    modules
}

#[test]
fn no_import_circle_between_files_of_a_module() {
    let modules = file_imports();
    let parts = modules
        .iter()
        .find(|(m, _)| m == "parts")
        .expect("the parts module");
    assert!(
        parts.1["segment_collection"].contains(&"adaptive_cosegment".to_string()),
        "the scan found nothing: it no longer reads the imports"
    );
    let mut circles = Vec::new();
    for (module, imports) in &modules {
        // Depth-first search for a back edge, in file order (deterministic report).
        fn visit(
            f: &str,
            imports: &std::collections::BTreeMap<String, Vec<String>>,
            path: &mut Vec<String>,
            done: &mut std::collections::BTreeSet<String>,
            found: &mut Vec<String>,
        ) {
            if let Some(at) = path.iter().position(|p| p == f) {
                found.push(format!("{} → {f}", path[at..].join(" → ")));
                return;
            }
            if !done.insert(f.to_string()) {
                return;
            }
            path.push(f.to_string());
            for g in imports.get(f).into_iter().flatten() {
                visit(g, imports, path, done, found);
            }
            path.pop();
        }
        let mut done = std::collections::BTreeSet::new();
        let mut found = Vec::new();
        for f in imports.keys() {
            visit(f, imports, &mut Vec::new(), &mut done, &mut found);
        }
        circles.extend(found.into_iter().map(|c| format!("src/{module}: {c}")));
    }
    assert!(circles.is_empty(), "{}", circles.join("\n"));
}
