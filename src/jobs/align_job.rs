//! [`run_align`]: `coseg align FOLDER -o OUT` as a library call — every mesh of a folder put
//! in one collection frame, `transforms.json` written atomically (and the aligned meshes on
//! request).

use super::JobError;
use crate::align::{AlignError, AlignOptions, CollectionAlignment, align_collection};
use crate::mesh::{TriMesh, read_mesh, write_atomic, write_mesh};
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Options of [`run_align`]; `Default` is `coseg align`'s default.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct AlignJob {
    /// The alignment itself (default [`AlignOptions::default`]).
    pub align: AlignOptions,
    /// Also write every mesh in the collection frame as `<output>/<file name>` (default false;
    /// `--write-meshes`). A mesh whose transform is the identity (the already-aligned case) is
    /// copied byte for byte.
    pub write_meshes: bool,
    /// Folder for `transforms.json` (and the meshes), created if missing; it must differ from
    /// the input folder, so that a run never reads its own outputs. `None` (default): nothing
    /// is written.
    pub output: Option<PathBuf>,
}

/// What [`run_align`] found and wrote.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct AlignOutcome {
    /// The mesh files, in the order of [`AlignOutcome::alignment`]'s shapes.
    pub files: Vec<PathBuf>,
    /// The alignment.
    pub alignment: CollectionAlignment,
    /// Files written (`transforms.json` first).
    pub written: Vec<PathBuf>,
}

#[derive(Serialize)]
struct TransformsFile<'a> {
    format: u32,
    case: crate::align::FrameCase,
    up: [f64; 3],
    forward: [f64; 3],
    given_frame_share: f64,
    shapes: Vec<ShapeEntry<'a>>,
    edges: &'a [(usize, usize)],
    symmetry_axis: Option<[f64; 3]>,
}

#[derive(Serialize)]
struct ShapeEntry<'a> {
    name: String,
    file: String,
    #[serde(flatten)]
    alignment: &'a crate::align::ShapeAlignment,
}

/// Aligns every mesh of `folder` (`.obj`, `.off`, `.ply`, sorted by name) and, with an output
/// folder, writes `transforms.json` (format in docs/ALIGN.md), plus the aligned meshes with
/// [`AlignJob::write_meshes`].
///
/// - `folder`: the collection;
/// - returns an [`AlignOutcome`].
///
/// Errors: [`JobError::Align`]: [`AlignError::Io`] / [`AlignError::Mesh`] naming the file,
/// [`AlignError::BadOption`] when the output is `folder` or the folder holds no mesh, the
/// alignment's errors naming the file.
///
/// See also: [`align_collection`], the stage alone.
pub fn run_align(folder: &Path, job: &AlignJob) -> Result<AlignOutcome, JobError> {
    Ok(align_folder(folder, job)?)
}

fn align_folder(folder: &Path, job: &AlignJob) -> Result<AlignOutcome, AlignError> {
    let files = mesh_files(folder)?;
    if files.is_empty() {
        return Err(AlignError::BadOption(format!(
            "{}: no .obj, .off or .ply mesh",
            folder.display()
        )));
    }
    if let Some(out) = &job.output {
        std::fs::create_dir_all(out).map_err(|source| AlignError::Io {
            path: out.display().to_string(),
            source,
        })?;
        let same = |a: &Path, b: &Path| matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y);
        if same(folder, out) {
            return Err(AlignError::BadOption(format!(
                "{}: the output folder must differ from the input folder",
                out.display()
            )));
        }
    }
    let meshes: Vec<TriMesh> = files
        .par_iter()
        .map(|f| {
            read_mesh(f).map_err(|source| AlignError::Mesh {
                path: f.display().to_string(),
                source,
            })
        })
        .collect::<Result<_, _>>()?;
    let alignment = align_collection(&meshes, &job.align).map_err(|e| match e {
        AlignError::Degenerate(m) => AlignError::Degenerate(name_shape(&m, &files)),
        e => e,
    })?;
    let name = |f: &PathBuf| {
        f.file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let doc = TransformsFile {
        format: 1,
        case: alignment.case,
        up: alignment.up,
        forward: alignment.forward,
        given_frame_share: alignment.given_frame_share,
        symmetry_axis: alignment.symmetry_axis,
        shapes: files
            .iter()
            .zip(&alignment.shapes)
            .map(|(f, s)| ShapeEntry {
                name: f
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                file: name(f),
                alignment: s,
            })
            .collect(),
        edges: &alignment.edges,
    };
    let Some(out) = &job.output else {
        return Ok(AlignOutcome {
            files,
            alignment,
            written: Vec::new(),
        });
    };
    let json = serde_json::to_vec_pretty(&doc).expect("plain data serialises");
    let path = out.join("transforms.json");
    write_atomic(&path, |w| std::io::Write::write_all(w, &json)).map_err(|source| {
        AlignError::Io {
            path: path.display().to_string(),
            source,
        }
    })?;
    let mut written = vec![path];
    if job.write_meshes {
        for ((f, m), s) in files.iter().zip(&meshes).zip(&alignment.shapes) {
            let p = out.join(name(f));
            if s.transform.is_identity() {
                // Unchanged: the file's own bytes, so that aligned input stays bit for bit.
                let bytes = std::fs::read(f).map_err(|source| AlignError::Io {
                    path: f.display().to_string(),
                    source,
                })?;
                write_atomic(&p, |w| std::io::Write::write_all(w, &bytes)).map_err(|source| {
                    AlignError::Io {
                        path: p.display().to_string(),
                        source,
                    }
                })?;
            } else {
                let moved = m
                    .map_positions(|x| s.transform.apply(x))
                    .map_err(|source| AlignError::Mesh {
                        path: f.display().to_string(),
                        source,
                    })?;
                write_mesh(&p, &moved, &[]).map_err(|source| AlignError::Mesh {
                    path: p.display().to_string(),
                    source,
                })?;
            }
            written.push(p);
        }
    }
    Ok(AlignOutcome {
        files,
        alignment,
        written,
    })
}

/// `shape i: …` → `<file>: …`.
fn name_shape(message: &str, files: &[PathBuf]) -> String {
    message
        .strip_prefix("shape ")
        .and_then(|r| r.split_once(':'))
        .and_then(|(i, rest)| {
            let i: usize = i.parse().ok()?;
            Some(format!("{}:{rest}", files.get(i)?.display()))
        })
        .unwrap_or_else(|| message.to_string())
}

/// The folder's mesh files, sorted by name.
fn mesh_files(folder: &Path) -> Result<Vec<PathBuf>, AlignError> {
    let io = |source| AlignError::Io {
        path: folder.display().to_string(),
        source,
    };
    let mut files = Vec::new();
    for e in std::fs::read_dir(folder).map_err(io)? {
        let p = e.map_err(io)?.path();
        let ext = p
            .extension()
            .map(|x| x.to_string_lossy().to_ascii_lowercase());
        if p.is_file() && matches!(ext.as_deref(), Some("obj" | "off" | "ply")) {
            // coseg's own outputs beside the meshes (`<name>.regions.ply`, `<name>.labels.ply`).
            let stem = p.file_stem().map(|s| s.to_string_lossy().to_lowercase());
            if stem.is_some_and(|s| s.ends_with(".regions") || s.ends_with(".labels")) {
                continue;
            }
            files.push(p);
        }
    }
    files.sort();
    Ok(files)
}
