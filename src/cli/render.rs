//! `coseg render MESH… [--labels FILE…] -o PNG`: a contact sheet of meshes coloured by label.

use anyhow::{Context, Result, bail};
use clap::Args;
use coseg::evaluate::read_labels;
use coseg::mesh::{TriMesh, read_mesh_with_report};
use coseg::render::{RenderOptions, RenderShape, collection_views_or_own, render_sheet, write_png};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Meshes (.obj, .off, .ply), drawn in the order given.
    #[arg(required = true)]
    meshes: Vec<PathBuf>,
    /// Per-vertex label files (one integer per line), one per mesh in the same order.
    /// Without it, `X.regions.ply` takes its labels from `X.regions.txt` beside it when that
    /// exists, and other meshes are drawn grey.
    #[arg(long, num_args = 1..)]
    labels: Vec<PathBuf>,
    /// Output PNG file.
    #[arg(short, long, visible_alias = "out")]
    output: PathBuf,
    /// Side of each shape's square cell, pixels.
    #[arg(long, default_value_t = RenderOptions::default().cell_size)]
    cell_size: u32,
    /// Cells per row (default: about the square root of the number of meshes).
    #[arg(long)]
    columns: Option<usize>,
    /// Part names for the legend, in label order (`--part-names head torso legs`).
    #[arg(long, num_args = 1..)]
    part_names: Vec<String>,
}

/// `X.regions.txt` beside `X.regions.ply`, if present.
fn sibling_labels(mesh: &Path) -> Option<PathBuf> {
    let name = mesh.file_name()?.to_str()?;
    let stem = name.strip_suffix(".regions.ply")?;
    let txt = mesh.with_file_name(format!("{stem}.regions.txt"));
    txt.is_file().then_some(txt)
}

fn display_name(mesh: &Path) -> String {
    let name = mesh
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let stem = name.strip_suffix(".regions.ply").unwrap_or(&name);
    Path::new(stem)
        .file_stem()
        .map_or_else(|| stem.to_string(), |s| s.to_string_lossy().into_owned())
}

pub fn run(args: RenderArgs) -> Result<ExitCode> {
    if !args.labels.is_empty() && args.labels.len() != args.meshes.len() {
        bail!(
            "--labels: {} files for {} meshes (give one per mesh, in the same order)",
            args.labels.len(),
            args.meshes.len()
        );
    }
    let (mut names, mut meshes, mut all_labels) = (Vec::new(), Vec::<TriMesh>::new(), Vec::new());
    for (i, path) in args.meshes.iter().enumerate() {
        let (mesh, report) = read_mesh_with_report(path)?;
        for w in &report.warnings {
            super::warn(format_args!("{}: {w}", path.display()));
        }
        let label_file = args.labels.get(i).cloned().or_else(|| sibling_labels(path));
        let labels = match label_file {
            Some(file) => {
                let l = read_labels(&file)?;
                if l.len() != mesh.vertex_count() {
                    bail!(
                        "{}: {} labels for {} ({} vertices)",
                        file.display(),
                        l.len(),
                        path.display(),
                        mesh.vertex_count()
                    );
                }
                l
            }
            None => vec![-1; mesh.vertex_count()],
        };
        names.push(display_name(path));
        meshes.push(mesh);
        all_labels.push(labels);
    }
    // One view for every shape drawn: the collection's own frame.
    let (views, warning) = collection_views_or_own(&meshes, None);
    if let Some(w) = warning {
        super::warn(format_args!("{w}"));
    }
    let shapes: Vec<RenderShape> = names
        .iter()
        .zip(&meshes)
        .zip(&all_labels)
        .zip(views)
        .map(|(((name, mesh), labels), view)| RenderShape {
            name,
            mesh,
            labels,
            confidence: None,
            view: Some(view),
        })
        .collect();
    let mut options = RenderOptions::default();
    options.cell_size = args.cell_size;
    options.columns = args.columns;
    let names = (!args.part_names.is_empty()).then_some(args.part_names.as_slice());
    let sheet = render_sheet(&shapes, names, &options)?;
    write_png(&args.output, &sheet).with_context(|| "writing the picture")?;
    if !super::quiet() {
        println!(
            "{} meshes -> {} ({}x{} pixels)",
            shapes.len(),
            args.output.display(),
            sheet.width,
            sheet.height
        );
    }
    Ok(ExitCode::SUCCESS)
}
