//! `coseg eval RESULT_DIR --truth DIR`: scores a result folder against ground truth.

use anyhow::{Context, Result, bail};
use clap::Args;
use coseg::evaluate::{matched_scores, read_labels};
use coseg::mesh::read_mesh;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct EvalArgs {
    /// Folder written by `coseg segment` or `pair` (`<name>.regions.txt`, `<name>.regions.ply`).
    result: PathBuf,
    /// Ground-truth folder: `<name>.labels.txt` (one label per vertex) or `<name>.seg` (one
    /// label per face, turned into vertex labels by majority of the incident faces).
    #[arg(long)]
    truth: PathBuf,
    /// Correspondence ratio of a two-shape result: `identity` (same triangulation) or a file
    /// with one index into the second shape per vertex of the first (negative = none).
    #[arg(long)]
    map: Option<String>,
    /// Also write the scores as JSON to this file.
    #[arg(long)]
    json: Option<PathBuf>,
}

/// Vertex labels from face labels: each vertex takes the most frequent label of its faces
/// (smallest on ties), `-1` for a vertex in no face.
fn vertex_labels_from_faces(faces: &[[u32; 3]], face_labels: &[i32], vertices: usize) -> Vec<i32> {
    let mut votes: Vec<std::collections::BTreeMap<i32, usize>> = vec![Default::default(); vertices];
    for (f, &l) in faces.iter().zip(face_labels) {
        for &v in f {
            *votes[v as usize].entry(l).or_default() += 1;
        }
    }
    votes
        .iter()
        .map(|m| {
            m.iter()
                .rev()
                .max_by_key(|(_, c)| **c)
                .map_or(-1, |(l, _)| *l)
        })
        .collect()
}

fn truth_for(truth: &Path, result: &Path, name: &str, vertices: usize) -> Result<Vec<i32>> {
    let per_vertex = truth.join(format!("{name}.labels.txt"));
    if per_vertex.is_file() {
        return Ok(read_labels(&per_vertex)?);
    }
    let seg = truth.join(format!("{name}.seg"));
    if seg.is_file() {
        let mesh_path = result.join(format!("{name}.regions.ply"));
        let mesh = read_mesh(&mesh_path)
            .with_context(|| format!("{}: faces needed for the per-face labels", seg.display()))?;
        let labels = read_labels(&seg)?;
        if labels.len() != mesh.face_count() {
            bail!(
                "{}: {} labels for {} faces",
                seg.display(),
                labels.len(),
                mesh.face_count()
            );
        }
        return Ok(vertex_labels_from_faces(mesh.faces(), &labels, vertices));
    }
    bail!(
        "{name}: no ground truth ({} or {})",
        per_vertex.display(),
        seg.display()
    )
}

/// `Cor = |{p : found_a[p] ≥ 0, L(p) exists, found_b[L(p)] = found_a[p]}| / |{p : L(p) exists}|`.
fn correspondence_ratio(a: &[i32], b: &[i32], map: &str) -> Result<f64> {
    let image: Vec<Option<usize>> = if map == "identity" {
        (0..a.len()).map(|p| (p < b.len()).then_some(p)).collect()
    } else {
        let raw = read_labels(map)?;
        if raw.len() != a.len() {
            bail!("{map}: {} entries for {} vertices", raw.len(), a.len());
        }
        raw.iter()
            .map(|&q| (q >= 0 && (q as usize) < b.len()).then_some(q as usize))
            .collect()
    };
    let mapped = image.iter().filter(|q| q.is_some()).count();
    let good = a
        .iter()
        .zip(&image)
        .filter(|(r, q)| **r >= 0 && q.is_some_and(|q| b[q] == **r))
        .count();
    Ok(if mapped == 0 {
        0.0
    } else {
        good as f64 / mapped as f64
    })
}

pub fn run(args: EvalArgs) -> Result<ExitCode> {
    let mut names: Vec<String> = std::fs::read_dir(&args.result)
        .with_context(|| format!("{}", args.result.display()))?
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            e.file_name()
                .to_str()?
                .strip_suffix(".regions.txt")
                .map(str::to_string)
        })
        .collect();
    names.sort();
    if names.is_empty() {
        bail!("{}: no <name>.regions.txt files", args.result.display());
    }
    let mut shapes = Vec::new();
    for name in &names {
        let found = read_labels(args.result.join(format!("{name}.regions.txt")))?;
        let truth = truth_for(&args.truth, &args.result, name, found.len())?;
        if truth.len() != found.len() {
            bail!(
                "{name}: {} true labels for {} vertices",
                truth.len(),
                found.len()
            );
        }
        shapes.push((found, truth));
    }
    let scores = matched_scores(&shapes)?;
    let ratio = match &args.map {
        Some(map) if shapes.len() == 2 => {
            Some(correspondence_ratio(&shapes[0].0, &shapes[1].0, map)?)
        }
        Some(_) => bail!(
            "--map needs a two-shape result, got {} shapes",
            shapes.len()
        ),
        None => None,
    };
    let mean_rand = scores.per_shape.iter().map(|s| s.1).sum::<f64>() / names.len() as f64;
    if !super::quiet() {
        println!("{:<24} {:>9} {:>11}", "shape", "accuracy", "rand index");
        for (name, (acc, ri)) in names.iter().zip(&scores.per_shape) {
            println!("{name:<24} {:>8.2}% {:>11.4}", 100.0 * acc, ri);
        }
        println!(
            "{:<24} {:>8.2}% {:>11.4}",
            "all",
            100.0 * scores.accuracy,
            mean_rand
        );
        println!("part IoU (region ids mapped to their majority part):");
        for (part, iou) in &scores.part_iou {
            println!("  part {part:<4} {:>6.2}%", 100.0 * iou);
        }
        println!("  mean      {:>6.2}%", 100.0 * scores.mean_iou);
        if let Some(r) = ratio {
            println!("correspondence ratio {:.2}%", 100.0 * r);
        }
    }
    if let Some(path) = &args.json {
        let json = serde_json::json!({
            "shapes": names.iter().zip(&scores.per_shape).map(|(n, (a, r))| {
                serde_json::json!({"name": n, "accuracy": a, "rand_index": r})
            }).collect::<Vec<_>>(),
            "accuracy": scores.accuracy,
            "mean_rand_index": mean_rand,
            "part_iou": scores.part_iou,
            "mean_iou": scores.mean_iou,
            "mapping": scores.mapping,
            "correspondence_ratio": ratio,
        });
        let text = serde_json::to_string_pretty(&json)?;
        coseg::mesh::write_atomic(path, |w| std::io::Write::write_all(w, text.as_bytes()))
            .with_context(|| format!("{}", path.display()))?;
    }
    Ok(ExitCode::SUCCESS)
}
