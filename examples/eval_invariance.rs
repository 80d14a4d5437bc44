//! Invariance of the bare commands (docs/ALIGN.md, "Invariance of the bare commands"): bare
//! `coseg segment` and bare `coseg propagate --labels <first shape's labels>` on a shipped
//! family as shipped, with every coordinate rounded differently (× a random 1 ± 10⁻¹², no
//! motion) and with every shape moved by the seeded random similarity of
//! `tests/e2e_invariance.rs`; scored as that test scores them.
//!
//! ```text
//! cargo run --release --example eval_invariance -- collections/FAMILY [--perturb SEED]...
//!     [--move SEED]... [--work DIR] [--segment-only | --propagate-only] [--dump]
//! ```
//! Each variant's copy and outputs go to `WORK/<family>_<variant>` (default work folder
//! `/tmp/coseg-invariance`). The run goes through the library's jobs ([`run_segment`],
//! [`run_propagate`] with their defaults: the bare commands). `--dump` writes
//! `dump.json` beside each segment output: the chosen feature families, the part tree's leaves
//! (the refined, split equal-area regions) and merges, the chosen count; two variants' dumps
//! compared show the first collection stage that differs.

use coseg::evaluate::{GroundTruth, matched_scores, read_labels};
use coseg::jobs::{
    PropagateInput, PropagateJob, SegmentInput, SegmentJob, run_propagate, run_segment,
};
use coseg::mesh::{read_mesh, write_mesh};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::cell::RefCell;
use std::path::{Path, PathBuf};

#[path = "../tests/common/motion.rs"]
mod motion;
use motion::{random_similarity, unit};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// How a variant changes the shipped meshes.
#[derive(Clone, Copy)]
enum Variant {
    Shipped,
    /// Every coordinate × (1 + 10⁻¹² u), u uniform in [−1, 1), seeded.
    Perturb(u64),
    /// The seeded random similarity of the invariance test, one per shape in manifest order.
    Move(u64),
}

impl Variant {
    fn tag(self) -> String {
        match self {
            Self::Shipped => "shipped".into(),
            Self::Perturb(s) => format!("perturb{s}"),
            Self::Move(s) => format!("move{s}"),
        }
    }
}

fn copy(input: &Path, truth: &GroundTruth, variant: Variant, out: &Path) -> Res<()> {
    std::fs::create_dir_all(out)?;
    let (seed, moving) = match variant {
        Variant::Shipped => return Ok(()),
        Variant::Perturb(s) => (s, false),
        Variant::Move(s) => (s, true),
    };
    let rng = RefCell::new(ChaCha8Rng::seed_from_u64(seed));
    for s in &truth.manifest.shapes {
        let m = read_mesh(input.join(&s.mesh))?;
        let m = if moving {
            let t = random_similarity(&mut rng.borrow_mut());
            m.map_positions(|p| t.apply(p))?
        } else {
            m.map_positions(|p| {
                let mut r = rng.borrow_mut();
                p.map(|x| x * (1.0 + 1e-12 * (2.0 * unit(&mut r) - 1.0)))
            })?
        };
        write_mesh(out.join(&s.mesh), &m, &[])?;
    }
    Ok(())
}

fn segment(folder: &Path, truth: &GroundTruth, out: &Path, dump: bool) -> Res<f64> {
    let mut job = SegmentJob::default();
    job.output = Some(out.to_path_buf());
    let done = run_segment(SegmentInput::Folder(folder.to_path_buf()), &job)?;
    let shapes: Vec<(Vec<i32>, Vec<i32>)> = truth
        .manifest
        .shapes
        .iter()
        .map(|s| {
            let found = read_labels(out.join(format!("{}.regions.txt", s.name)))?;
            let parts = truth.grouped_labels(&s.name)?;
            Ok((found, parts.into_iter().map(|p| p as i32).collect()))
        })
        .collect::<Res<_>>()?;
    let accuracy = matched_scores(&shapes)?.accuracy;
    let r = &done.result;
    if dump {
        let leaves = r.adaptive.as_ref().map(|a| {
            (0..a.leaves.names.len())
                .map(|i| a.leaves.labels(i))
                .collect::<Vec<_>>()
        });
        let pairs = r.adaptive.as_ref().map(|a| {
            let likeness = coseg::parts::Likeness {
                graph: &r.graph,
                columns: &r.mirror_columns,
            };
            coseg::parts::mirror_pairs(&done.meshes, &a.leaves, r.up, Some(likeness))
        });
        let planes: Vec<_> = done.meshes.iter().map(coseg::parts::mirror_plane).collect();
        let cues: Vec<_> = done
            .meshes
            .iter()
            .map(|m| {
                let c = coseg::parts::PartCues::of(m).expect("cues");
                (c.thickness, c.mean_curvature)
            })
            .collect();
        let faces: Vec<_> = done.meshes.iter().map(|m| m.faces().to_vec()).collect();
        let j = serde_json::json!({
            "cues": cues,
            "faces": faces,
            "mirror_pairs": pairs,
            "mirror_planes": planes,
            "features": r.features,
            "part_count": r.part_count,
            "tree": r.adaptive.as_ref().map(|a| &a.tree),
            "leaf_origin": r.adaptive.as_ref().map(|a| &a.leaf_origin),
            "leaf_copies": r.adaptive.as_ref().map(|a| &a.leaf_copies),
            "leaves": leaves,
            "names": r.segmentation.names,
        });
        std::fs::write(out.join("dump.json"), serde_json::to_string(&j)?)?;
    }
    println!(
        "    segment: {} parts, features {}, {:.1} %",
        r.segmentation.tuples.len(),
        r.features
            .as_ref()
            .map_or("given".to_string(), |f| format!("{:?}", f.chosen)),
        100.0 * accuracy
    );
    Ok(accuracy)
}

fn propagate(input: &Path, folder: &Path, truth: &GroundTruth, out: &Path, dump: bool) -> Res<f64> {
    let source = &truth.manifest.shapes[0];
    let labels = input.join(format!("{}.labels.txt", source.name));
    let mut job = PropagateJob::default();
    job.output = Some(out.to_path_buf());
    let done = run_propagate(
        PropagateInput::Folder {
            folder: folder.to_path_buf(),
            labels: vec![labels],
        },
        &job,
    )?;
    if dump {
        let f = &done.result.fusion;
        let routes: Vec<_> = f
            .routes
            .iter()
            .map(|(r, l)| (r.name(), &l.labels, &l.shape_confidence))
            .collect();
        let j = serde_json::json!({
            "routes": routes,
            "fused": f.fused.labels,
            "weights": f.fused.weights,
            "final": done.result.propagation.labels,
        });
        std::fs::write(out.join("dump.json"), serde_json::to_string(&j)?)?;
    }
    let (mut right, mut all) = (0usize, 0usize);
    for s in &truth.manifest.shapes[1..] {
        let found = read_labels(out.join(format!("{}.labels.txt", s.name)))?;
        let expected = read_labels(input.join(format!("{}.labels.txt", s.name)))?;
        right += found.iter().zip(&expected).filter(|(a, b)| a == b).count();
        all += expected.len();
    }
    let a = right as f64 / all as f64;
    println!("    propagate: {:.1} %", 100.0 * a);
    Ok(a)
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut input = None;
    let mut variants = vec![Variant::Shipped];
    let mut work = PathBuf::from("/tmp/coseg-invariance");
    let (mut do_segment, mut do_propagate, mut dump) = (true, true, false);
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--perturb" => variants.push(Variant::Perturb(value()?.parse()?)),
            "--move" => variants.push(Variant::Move(value()?.parse()?)),
            "--work" => work = PathBuf::from(value()?),
            "--segment-only" => do_propagate = false,
            "--propagate-only" => do_segment = false,
            "--dump" => dump = true,
            _ => input = Some(PathBuf::from(a)),
        }
    }
    let input = input.ok_or("give a shipped family's folder")?;
    let truth = GroundTruth::read(&input)?;
    let family = input
        .file_name()
        .map_or("family".into(), |f| f.to_string_lossy().to_string());
    let mut rows = Vec::new();
    for v in variants {
        let base = work.join(format!("{family}_{}", v.tag()));
        if base.exists() {
            std::fs::remove_dir_all(&base)?;
        }
        let folder = match v {
            Variant::Shipped => input.clone(),
            _ => base.join("meshes"),
        };
        copy(&input, &truth, v, &folder)?;
        println!("{family} {}:", v.tag());
        let s = if do_segment {
            Some(segment(&folder, &truth, &base.join("segment"), dump)?)
        } else {
            None
        };
        let p = if do_propagate {
            Some(propagate(
                &input,
                &folder,
                &truth,
                &base.join("propagate"),
                dump,
            )?)
        } else {
            None
        };
        rows.push((v.tag(), s, p));
    }
    let pct = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{:.1} %", 100.0 * x));
    println!("| {family} | segment | propagate |\n|---|---|---|");
    for (tag, s, p) in rows {
        println!("| {tag} | {} | {} |", pct(s), pct(p));
    }
    Ok(())
}
