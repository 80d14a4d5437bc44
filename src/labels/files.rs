//! Label files: reading, matching to meshes by stem, writing; part names.

use super::{LabelError, faces_to_vertices};
use crate::mesh::{TriMesh, write_atomic};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Label files matched to meshes, `(mesh index, file)` by mesh index, and warnings.
pub type MatchedLabels = (Vec<(usize, PathBuf)>, Vec<String>);

/// Part names: `label → name`, carried into outputs.
pub type PartNames = BTreeMap<i32, String>;

/// What a label file annotates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LabelKind {
    /// One label per vertex, in vertex order (`.labels.txt` and any non-`.seg` file).
    Vertex,
    /// One label per face, in face order (`.seg`).
    Face,
}

impl LabelKind {
    /// `Face` for a `.seg` file (any case), `Vertex` otherwise.
    ///
    /// ```
    /// use coseg::labels::LabelKind;
    /// assert_eq!(LabelKind::of_path("gt/1.SEG".as_ref()), LabelKind::Face);
    /// assert_eq!(LabelKind::of_path("a.labels.txt".as_ref()), LabelKind::Vertex);
    /// ```
    pub fn of_path(path: &Path) -> Self {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("seg") => LabelKind::Face,
            _ => LabelKind::Vertex,
        }
    }
}

/// One shape's annotation as read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeLabels {
    /// The file read.
    pub path: PathBuf,
    /// Per-vertex or per-face file.
    pub kind: LabelKind,
    /// The labels as in the file (length = vertex or face count, by `kind`).
    pub file_labels: Vec<i32>,
    /// Per-vertex labels (the file's, or converted from faces by [`faces_to_vertices`]);
    /// negative values normalised to `-1`.
    pub vertex_labels: Vec<i32>,
}

/// Reads a label file: one integer per line (blank lines skipped, surrounding spaces ignored);
/// the kind comes from the extension ([`LabelKind::of_path`]). Errors name the file and the
/// 1-based line. The bytes are parsed by [`parse_label_file`].
///
/// ```
/// let p = std::env::temp_dir().join(format!("coseg-doc-seg-{}.seg", std::process::id()));
/// std::fs::write(&p, "1\n2\n\n3\n").unwrap();
/// let (kind, l) = coseg::labels::read_label_file(&p).unwrap();
/// assert_eq!((kind, l), (coseg::labels::LabelKind::Face, vec![1, 2, 3]));
/// # std::fs::remove_file(&p).unwrap();
/// ```
pub fn read_label_file(path: &Path) -> Result<(LabelKind, Vec<i32>), LabelError> {
    let data = std::fs::read(path).map_err(|source| {
        LabelError::Io(crate::FileError {
            path: path.display().to_string(),
            source,
        })
    })?;
    parse_label_file(&data, path)
}

/// Parses the bytes of a label file named `path` (used for the kind, by its extension, and in
/// errors; nothing is read from disk): one integer in `i32` per line, lines split at `\n` with
/// an optional `\r` before it, blank lines skipped, surrounding spaces ignored. A line that is
/// not UTF-8 or not an integer in range is a [`LabelError::BadLabel`] naming the file and the
/// 1-based line (its text shortened to 40 characters). This is the entry point of the
/// `read_label_file` fuzz target: any bytes give labels or such an error, never a panic.
///
/// ```
/// use coseg::labels::{LabelKind, parse_label_file};
/// let (kind, l) = parse_label_file(b" 3\r\n\n-1\n", "a.seg".as_ref()).unwrap();
/// assert_eq!((kind, l), (LabelKind::Face, vec![3, -1]));
/// let e = parse_label_file(b"1\n2.5\n", "a.labels.txt".as_ref()).unwrap_err();
/// assert_eq!(e.to_string(), "a.labels.txt:2: \"2.5\" is not an integer label");
/// ```
pub fn parse_label_file(data: &[u8], path: &Path) -> Result<(LabelKind, Vec<i32>), LabelError> {
    let bad = |line: usize, text: &str| LabelError::BadLabel {
        path: path.display().to_string(),
        line,
        text: text.chars().take(40).collect(),
    };
    let mut labels = Vec::new();
    // `split` yields one empty piece after a final `\n`, which the blank-line rule skips.
    for (i, line) in data.split(|&b| b == b'\n').enumerate() {
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        let t = std::str::from_utf8(line)
            .map_err(|_| bad(i + 1, &String::from_utf8_lossy(line)))?
            .trim();
        if t.is_empty() {
            continue;
        }
        let v: i32 = t.parse().map_err(|_| bad(i + 1, t))?;
        labels.push(v);
    }
    Ok((LabelKind::of_path(path), labels))
}

/// Reads `path` ([`read_label_file`]) for `mesh` (named `mesh_name` in errors), checks the
/// count against the mesh's vertices or faces, and converts per-face labels to per-vertex
/// ([`parse_shape_labels`] on the file's bytes).
///
/// ```
/// use coseg::mesh::TriMesh;
/// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let p = std::env::temp_dir().join(format!("coseg-doc-l-{}.labels.txt", std::process::id()));
/// std::fs::write(&p, "0\n0\n").unwrap();
/// let e = coseg::labels::read_shape_labels(&p, &m, "tri").unwrap_err().to_string();
/// assert!(e.contains("2 labels") && e.contains("3 vertices"), "{e}");
/// # std::fs::remove_file(&p).unwrap();
/// ```
pub fn read_shape_labels(
    path: &Path,
    mesh: &TriMesh,
    mesh_name: &str,
) -> Result<ShapeLabels, LabelError> {
    let data = std::fs::read(path).map_err(|source| {
        LabelError::Io(crate::FileError {
            path: path.display().to_string(),
            source,
        })
    })?;
    parse_shape_labels(&data, path, mesh, mesh_name)
}

/// [`read_shape_labels`] on bytes already read from `path` (named in errors, its extension
/// gives the kind): [`parse_label_file`], the count check against `mesh` (an empty file has 0
/// labels and is refused like any wrong count), per-face to per-vertex conversion, negative
/// labels normalised to `-1`. Any bytes give labels of the mesh's length or an error naming
/// `path`, never a panic (the `read_label_file` fuzz target).
///
/// ```
/// use coseg::mesh::TriMesh;
/// let m = TriMesh::new(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], vec![[0, 1, 2]]).unwrap();
/// let l = coseg::labels::parse_shape_labels(b"7\n", "t.seg".as_ref(), &m, "t").unwrap();
/// assert_eq!(l.vertex_labels, vec![7, 7, 7]);
/// let e = coseg::labels::parse_shape_labels(b"", "t.seg".as_ref(), &m, "t").unwrap_err();
/// assert_eq!(e.to_string(), "t.seg: 0 labels, but the mesh t has 1 faces");
/// ```
pub fn parse_shape_labels(
    data: &[u8],
    path: &Path,
    mesh: &TriMesh,
    mesh_name: &str,
) -> Result<ShapeLabels, LabelError> {
    let (kind, file_labels) = parse_label_file(data, path)?;
    let (what, expected) = match kind {
        LabelKind::Vertex => ("vertices", mesh.vertex_count()),
        LabelKind::Face => ("faces", mesh.face_count()),
    };
    if file_labels.len() != expected {
        return Err(LabelError::Count {
            path: path.display().to_string(),
            mesh: mesh_name.to_string(),
            what,
            expected,
            got: file_labels.len(),
        });
    }
    let mut vertex_labels = match kind {
        LabelKind::Vertex => file_labels.clone(),
        LabelKind::Face => faces_to_vertices(mesh, &file_labels)?,
    };
    vertex_labels
        .iter_mut()
        .filter(|l| **l < 0)
        .for_each(|l| *l = -1);
    Ok(ShapeLabels {
        path: path.to_path_buf(),
        kind,
        file_labels,
        vertex_labels,
    })
}

/// The mesh stem a label file belongs to: the file name without `.labels.txt`, `.seg` or
/// `.txt` (any case), else without its last extension.
///
/// ```
/// use coseg::labels::label_file_stem;
/// assert_eq!(label_file_stem("d/chair3.labels.txt".as_ref()).as_deref(), Some("chair3"));
/// assert_eq!(label_file_stem("gt/12.seg".as_ref()).as_deref(), Some("12"));
/// ```
pub fn label_file_stem(path: &Path) -> Option<String> {
    let name = path.file_name()?.to_str()?;
    let lower = name.to_ascii_lowercase();
    for suffix in [".labels.txt", ".seg", ".txt"] {
        if lower.ends_with(suffix) && lower.len() > suffix.len() {
            return Some(name[..name.len() - suffix.len()].to_string());
        }
    }
    path.file_stem()
        .and_then(|s| s.to_str())
        .map(str::to_string)
}

fn is_label_file(path: &Path) -> bool {
    let lower = path
        .file_name()
        .and_then(|n| n.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    path.is_file() && (lower.ends_with(".seg") || lower.ends_with(".txt"))
}

/// Pairs label files with meshes by stem ([`label_file_stem`] against `stems`, the meshes'
/// file stems). Each entry of `inputs` is a file (it must match a mesh) or a folder (its
/// `.seg` and `.txt` files that match a mesh are taken; others are ignored, except
/// `<stem>.regions.txt` outputs, which are never labels). Returns `(mesh index, file)` sorted by
/// mesh index, and warnings (folders with no match). Two files for one mesh are an error (a
/// folder's `<stem>.labels.txt` and `<stem>.seg` included), naming both.
///
/// ```
/// let dir = std::env::temp_dir().join(format!("coseg-doc-match-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// std::fs::write(dir.join("b.seg"), "1\n").unwrap();
/// std::fs::write(dir.join("notes.md"), "x").unwrap();
/// let stems = vec!["a".to_string(), "b".to_string()];
/// let (m, _) = coseg::labels::match_label_files(&[dir.clone()], &stems).unwrap();
/// assert_eq!(m, vec![(1, dir.join("b.seg"))]);
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn match_label_files(
    inputs: &[PathBuf],
    stems: &[String],
) -> Result<MatchedLabels, LabelError> {
    let index: BTreeMap<&str, usize> = stems
        .iter()
        .enumerate()
        .map(|(i, s)| (s.as_str(), i))
        .collect();
    let mut found: BTreeMap<usize, PathBuf> = BTreeMap::new();
    let mut warnings = Vec::new();
    let add = |found: &mut BTreeMap<usize, PathBuf>, i: usize, path: PathBuf| match found.get(&i) {
        Some(prev) if prev != &path => Err(LabelError::Match {
            path: path.display().to_string(),
            message: format!(
                "a second label file for mesh {} (the first is {})",
                stems[i],
                prev.display()
            ),
        }),
        _ => {
            found.insert(i, path);
            Ok(())
        }
    };
    for input in inputs {
        if input.is_dir() {
            let mut files: Vec<PathBuf> = std::fs::read_dir(input)
                .map_err(|source| {
                    LabelError::Io(crate::FileError {
                        path: input.display().to_string(),
                        source,
                    })
                })?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| is_label_file(p))
                .filter(|p| {
                    !p.to_string_lossy()
                        .to_ascii_lowercase()
                        .ends_with(".regions.txt")
                })
                .collect();
            files.sort();
            let before = found.len();
            for f in files {
                if let Some(&i) = label_file_stem(&f).as_deref().and_then(|s| index.get(s)) {
                    add(&mut found, i, f)?;
                }
            }
            if found.len() == before {
                warnings.push(format!(
                    "{}: no label file (<stem>.seg or <stem>.labels.txt) matches a mesh",
                    input.display()
                ));
            }
        } else if input.is_file() {
            let stem = label_file_stem(input).unwrap_or_default();
            let i = *index.get(stem.as_str()).ok_or_else(|| LabelError::Match {
                path: input.display().to_string(),
                message: format!("no mesh has the stem {stem:?}"),
            })?;
            add(&mut found, i, input.clone())?;
        } else {
            return Err(LabelError::Io(crate::FileError {
                path: input.display().to_string(),
                source: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file or folder"),
            }));
        }
    }
    Ok((found.into_iter().collect(), warnings))
}

/// Reads part names: a JSON object whose keys are integer labels, values names
/// (`{"1": "back", "2": "seat"}`).
///
/// ```
/// let p = std::env::temp_dir().join(format!("coseg-doc-names-{}.json", std::process::id()));
/// std::fs::write(&p, r#"{"1": "back", "3": "legs"}"#).unwrap();
/// let n = coseg::labels::read_part_names(&p).unwrap();
/// assert_eq!(n[&3], "legs");
/// # std::fs::remove_file(&p).unwrap();
/// ```
pub fn read_part_names(path: &Path) -> Result<PartNames, LabelError> {
    let bad = |message: String| LabelError::BadNames {
        path: path.display().to_string(),
        message,
    };
    let text = std::fs::read_to_string(path).map_err(|source| {
        LabelError::Io(crate::FileError {
            path: path.display().to_string(),
            source,
        })
    })?;
    let raw: BTreeMap<String, String> = serde_json::from_str(&text)
        .map_err(|e| bad(format!("expected a JSON object {{label: name}}: {e}")))?;
    raw.into_iter()
        .map(|(k, v)| {
            k.trim()
                .parse::<i32>()
                .map(|l| (l, v))
                .map_err(|_| bad(format!("key {k:?} is not an integer label")))
        })
        .collect()
}

fn write_lines(path: &Path, labels: &[i32]) -> Result<(), LabelError> {
    write_atomic(path, |w| {
        for l in labels {
            writeln!(w, "{l}")?;
        }
        Ok(())
    })
    .map_err(|source| {
        LabelError::Io(crate::FileError {
            path: path.display().to_string(),
            source,
        })
    })
}

/// Writes `dir/<name>.labels.txt` (one label per vertex) atomically; returns its path.
///
/// ```
/// let dir = std::env::temp_dir();
/// let name = format!("coseg-doc-w-{}", std::process::id());
/// let p = coseg::labels::write_vertex_labels(&dir, &name, &[2, -1]).unwrap();
/// assert_eq!(std::fs::read_to_string(&p).unwrap(), "2\n-1\n");
/// # std::fs::remove_file(&p).unwrap();
/// ```
pub fn write_vertex_labels(dir: &Path, name: &str, labels: &[i32]) -> Result<PathBuf, LabelError> {
    let path = dir.join(format!("{name}.labels.txt"));
    write_lines(&path, labels)?;
    Ok(path)
}

/// Writes `dir/<name>.seg` (one label per face) atomically; returns its path.
pub fn write_face_labels(dir: &Path, name: &str, labels: &[i32]) -> Result<PathBuf, LabelError> {
    let path = dir.join(format!("{name}.seg"));
    write_lines(&path, labels)?;
    Ok(path)
}
