//! Co-segmentation modes scored against human or generated part labels (docs/PARTS.md).
//!
//! ```text
//! cargo run --release --example eval_parts -- FOLDER [--cache DIR] [--refine-rounds N]
//!     [--features F --up AXIS [--normals N]] [--starts N] [--keep-sizes TOL] [--detail]
//!     [--parts-from adaptive|geometry [--snap-band W]] [--all-cuts [--dump-tree FILE]] MODE...
//! ```
//! `--features`/`--up`/`--normals` select the feature families as `coseg segment` does (e.g.
//! `--features spectral,extrinsic --up y --normals 16`), `--starts` its several starts, `--keep-sizes TOL`
//! the size-aware refinement (`RefineSizes::Keep`, `coseg segment --refine-sizes keep:TOL`;
//! without it the free best response), `--parts-from` where `parts:N` takes its finest parts
//! (`coseg segment --parts-from`; with `geometry`, `@max=R` is the number of regions and
//! `--snap-band W` the band of the boundary snapping, `coseg segment --snap-band`).
//! `--detail` prints, for families, each shape's own purity / coverage, the pooled area table
//! (region × grouped part, % of a shape) and the best any grouping of the regions could score;
//! for the part modes the same for the leaves, the merge tree and, when regions were split into
//! their pieces, each leaf's region of origin.
//! `--all-cuts` (families, mode `default`): the part tree is grown once and scored at every cut
//! from 2 to 8 parts (each cut is `coseg segment --parts N` on that tree), with its merge
//! costs, so that rules choosing the count can be compared offline on the same trees;
//! `--dump-tree FILE` adds the tree's merges (with the mirror pairs and copies that link
//! leaves) and, per shape, each leaf's area share, log thickness and ground-truth composition
//! and each pair of leaves' boundary length and concave length, as one JSON line appended to
//! FILE (read by `scripts/count_rules.py`).
//! `--features auto` chooses the families from the data (`coseg segment` without
//! `--features`); the mode `default` is the bare `coseg segment` (parts from geometry, their
//! number chosen from the part tree).
//! `FOLDER` is either a COSEG-style set (`shapes/N.off` and `gt/N.seg`, one label per face) or a
//! shipped family (`collections/<family>`, per-vertex labels and a manifest). Each `MODE` is
//! `fixed:R` (`cosegment`, R equal-area regions, today's `coseg segment --regions R`), `auto`
//! (`coseg segment --parts auto`) or `parts:N` (`--parts N`), optionally followed by
//! `@max=M` (the upper bound, `--regions M`). COSEG sets: the area-weighted share of faces whose region id maps to their
//! label under the best one-to-one matching of ids to labels over the whole set (each shape
//! scaled to unit area; a face's id is the majority id of its corners). Families: purity and
//! coverage of the grouped parts (`coseg::evaluate`).

use coseg::evaluate::{GroundTruth, ShapeParts, part_coverage, part_purity};
use coseg::graph::{Cosegmentation, LoadedCollection, load_collection};
use coseg::parts::{AdaptiveOptions, PartsFrom, SegmentCollectionOptions, segment_collection};
use coseg::pipeline::ShapePipelineOptions;
use std::path::{Path, PathBuf};
use std::time::Instant;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// Best one-to-one matching of region ids to labels: `conf[id][label]` is the area of faces with
/// that id and label; returns the largest matched total (brute force over injective maps).
fn best_matching(conf: &[Vec<f64>]) -> f64 {
    fn go(conf: &[Vec<f64>], label: usize, used: &mut Vec<bool>) -> f64 {
        let labels = conf.first().map_or(0, Vec::len);
        if label == labels {
            return 0.0;
        }
        let mut best = go(conf, label + 1, used);
        for id in 0..conf.len() {
            if !used[id] {
                used[id] = true;
                best = best.max(conf[id][label] + go(conf, label + 1, used));
                used[id] = false;
            }
        }
        best
    }
    go(conf, 0, &mut vec![false; conf.len()])
}

fn coseg_accuracy(loaded: &LoadedCollection, seg: &Cosegmentation, gt: &Path) -> Res<f64> {
    let ids = seg.tuples.len();
    let mut labels_of: Vec<Vec<usize>> = Vec::new();
    let mut max_label = 0;
    for (i, name) in seg.names.iter().enumerate() {
        let path = gt.join(format!("{name}.seg"));
        let text =
            std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let l: Vec<usize> = text
            .split_whitespace()
            .map(|t| t.parse::<usize>().map(|x| x.saturating_sub(1)))
            .collect::<Result<_, _>>()?;
        if l.len() != loaded.meshes[i].face_count() {
            return Err(format!(
                "{}: {} labels for {} faces",
                path.display(),
                l.len(),
                loaded.meshes[i].face_count()
            )
            .into());
        }
        max_label = max_label.max(l.iter().copied().max().unwrap_or(0));
        labels_of.push(l);
    }
    let mut conf = vec![vec![0.0; max_label + 1]; ids];
    for (i, mesh) in loaded.meshes.iter().enumerate() {
        let region = seg.labels(i);
        let fa = mesh.face_areas();
        let total: f64 = fa.iter().sum();
        for (f, tri) in mesh.faces().iter().enumerate() {
            let r = tri.map(|v| region[v as usize]);
            let id = if r[1] == r[2] { r[1] } else { r[0] };
            if id >= 0 {
                conf[id as usize][labels_of[i][f]] += fa[f] / total;
            }
        }
    }
    Ok(best_matching(&conf) / seg.names.len() as f64)
}

fn family_scores(
    loaded: &LoadedCollection,
    seg: &Cosegmentation,
    folder: &Path,
    detail: bool,
) -> Res<(f64, f64)> {
    let truth = GroundTruth::read(folder)?;
    let mut shapes = Vec::new();
    for (i, mesh) in loaded.meshes.iter().enumerate() {
        let parts = truth.grouped_labels(&seg.names[i])?;
        shapes.push(ShapeParts::of_mesh(mesh, parts, seg.labels(i))?);
    }
    if detail {
        let per: Vec<String> = shapes
            .iter()
            .map(|s| {
                let one = std::slice::from_ref(s);
                format!(
                    "{:.0}/{:.0}",
                    100.0 * part_purity(one).unwrap_or(0.0),
                    100.0 * part_coverage(one).unwrap_or(0.0)
                )
            })
            .collect();
        eprintln!("  per shape: {}", per.join(" "));
        let parts = shapes
            .iter()
            .flat_map(|s| s.truth.iter().copied())
            .max()
            .unwrap_or(0)
            + 1;
        let ids = seg.tuples.len();
        let mut conf = vec![vec![0.0; parts]; ids];
        for s in &shapes {
            let total: f64 = s.areas.iter().sum();
            for ((&a, &t), &f) in s.areas.iter().zip(&s.truth).zip(&s.found) {
                if f >= 0 {
                    conf[f as usize][t] += a / total / shapes.len() as f64;
                }
            }
        }
        for (r, row) in conf.iter().enumerate() {
            let cells: Vec<String> = row.iter().map(|x| format!("{:5.1}", 100.0 * x)).collect();
            eprintln!("  region {r}: {}", cells.join(" "));
        }
        // Each region joined to its majority part: the best any grouping of these regions
        // can do (the bound a part tree works towards).
        let major: Vec<i32> = conf
            .iter()
            .map(|row| {
                (0..parts)
                    .max_by(|&x, &y| row[x].total_cmp(&row[y]))
                    .unwrap_or(0) as i32
            })
            .collect();
        let grouped: Vec<ShapeParts> = shapes
            .iter()
            .map(|s| {
                let f = s
                    .found
                    .iter()
                    .map(|&f| if f >= 0 { major[f as usize] } else { f });
                ShapeParts::new(s.areas.clone(), s.truth.clone(), f.collect())
            })
            .collect::<Result<_, _>>()?;
        eprintln!(
            "  best grouping of these regions: purity {:.2} % coverage {:.2} %",
            100.0 * part_purity(&grouped)?,
            100.0 * part_coverage(&grouped)?
        );
    }
    Ok((part_purity(&shapes)?, part_coverage(&shapes)?))
}

/// The mirror pairs of the final regions, each region named by its majority true (ungrouped)
/// part pooled over the shapes: a check that the pairs are left/right copies.
fn mirror_check(
    loaded: &LoadedCollection,
    seg: &Cosegmentation,
    folder: &Path,
    up: Option<[f64; 3]>,
    likeness: coseg::parts::Likeness<'_>,
) -> Res<String> {
    let truth = GroundTruth::read(folder)?;
    let names = &truth.manifest.parts;
    let mut area = vec![vec![0.0; names.len()]; seg.tuples.len()];
    for (i, mesh) in loaded.meshes.iter().enumerate() {
        let shape = truth.shape(&seg.names[i]).ok_or("shape not in manifest")?;
        let labels = coseg::evaluate::read_labels(truth.dir.join(&shape.labels))?;
        let w = mesh.vertex_areas();
        for (v, &r) in seg.labels(i).iter().enumerate() {
            if r >= 0 && labels[v] >= 0 {
                area[r as usize][labels[v] as usize] += w[v];
            }
        }
    }
    let major = |r: usize| {
        let k = (0..names.len())
            .max_by(|&x, &y| area[r][x].total_cmp(&area[r][y]))
            .unwrap_or(0);
        format!("{r} {}", names.get(k).map_or("?", String::as_str))
    };
    let pairs = coseg::parts::mirror_pairs(&loaded.meshes, seg, up, Some(likeness));
    Ok(pairs
        .iter()
        .map(|m| {
            format!(
                "[{} | {}] {:.2} {:.2}",
                major(m.a),
                major(m.b),
                m.ratio,
                m.likeness.unwrap_or(f64::NAN)
            )
        })
        .collect::<Vec<_>>()
        .join(", "))
}

fn options(mode: &str, refine_rounds: usize, starts: usize) -> Res<SegmentCollectionOptions> {
    let mut o = if mode == "default" {
        SegmentCollectionOptions::default()
    } else {
        SegmentCollectionOptions::equal_areas(coseg::graph::CosegmentOptions::default().regions)
    };
    // Several starts are for the equal-area mode only (segment_collection refuses them with
    // --parts).
    if mode.starts_with("fixed:") {
        o.starts = starts;
    }
    if let Some(r) = o.refine.as_mut() {
        r.max_rounds = refine_rounds;
    }
    if refine_rounds == 0 {
        o.refine = None;
    }
    let (mode, max) = match mode.split_once("@max=") {
        Some((m, x)) => (m, Some(x.parse::<usize>()?)),
        None => (mode, None),
    };
    if let Some(r) = mode.strip_prefix("fixed:") {
        o.cosegment.regions = r.parse()?;
    } else if mode != "default" {
        let mut a = AdaptiveOptions::default();
        if let Some(k) = mode.strip_prefix("parts:") {
            a.parts = Some(k.parse()?);
            a.max_parts = a.max_parts.max(k.parse()?);
        } else if mode != "auto" {
            return Err(format!("unknown mode {mode:?}").into());
        }
        if let Some(m) = max {
            a.max_parts = m;
        }
        o.parts = Some(a);
    }
    Ok(o)
}

fn main() -> Res<()> {
    let mut args = std::env::args().skip(1);
    let folder = PathBuf::from(args.next().ok_or("FOLDER")?);
    let mut cache = std::env::temp_dir().join("coseg-eval-cache");
    let mut refine_rounds = SegmentCollectionOptions::default()
        .refine
        .map_or(0, |r| r.max_rounds);
    let mut modes = Vec::new();
    let (mut features, mut up, mut starts) = ("spectral".to_string(), "y".to_string(), 1);
    let mut keep: Option<f64> = None;
    let mut detail = false;
    // `--all-cuts` (with the mode `default`): the part tree grown once, then scored at every
    // cut from 2 to 8 parts, and its merge costs printed (to compare ways of choosing the
    // count on one tree).
    let mut all_cuts = false;
    // `--dump-tree FILE` (with `--all-cuts`): the tree and its leaves per shape appended to
    // FILE as one JSON line (`scripts/count_rules.py` reads it).
    let mut dump_tree_to: Option<PathBuf> = None;
    let mut normals = 0;
    let mut mirrors = false;
    let mut parts_from = None;
    let mut snap_band: Option<f64> = None;
    let mut family_weights = String::new();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--features" => features = args.next().ok_or("--features F")?,
            "--up" => up = args.next().ok_or("--up AXIS")?,
            "--normals" => normals = args.next().ok_or("--normals N")?.parse()?,
            "--starts" => starts = args.next().ok_or("--starts N")?.parse()?,
            "--detail" => detail = true,
            "--all-cuts" => all_cuts = true,
            "--dump-tree" => {
                dump_tree_to = Some(PathBuf::from(args.next().ok_or("--dump-tree FILE")?))
            }
            "--group-mirrors" => mirrors = true,
            "--parts-from" => {
                parts_from = Some(
                    args.next()
                        .ok_or("--parts-from KIND")?
                        .parse::<PartsFrom>()?,
                )
            }
            "--keep-sizes" => keep = Some(args.next().ok_or("--keep-sizes TOL")?.parse()?),
            "--cache" => cache = PathBuf::from(args.next().ok_or("--cache DIR")?),
            "--family-weights" => family_weights = args.next().ok_or("--family-weights W")?,
            "--snap-band" => snap_band = Some(args.next().ok_or("--snap-band W")?.parse()?),
            "--refine-rounds" => refine_rounds = args.next().ok_or("--refine-rounds N")?.parse()?,
            _ => modes.push(a),
        }
    }
    let coseg_set = folder.join("gt").is_dir();
    let shapes = if coseg_set {
        folder.join("shapes")
    } else {
        folder.clone()
    };
    let mut pipeline = ShapePipelineOptions::default();
    let directions = coseg::features::ExtrinsicOptions::default().directions;
    // `auto`: the families chosen from the data, as `coseg segment` without `--features`.
    let chosen = features == "auto";
    let given = if chosen {
        "spectral"
    } else {
        features.as_str()
    };
    pipeline.set_families(given, &up, directions, normals, &family_weights)?;
    let loaded = load_collection(&shapes, &pipeline, &cache, |_, _, _| {})?;
    if mirrors {
        let errors: Vec<String> = loaded
            .meshes
            .iter()
            .map(|m| {
                coseg::parts::mirror_plane(m).map_or("-".into(), |p| format!("{:.3}", p.error))
            })
            .collect();
        println!("mirror plane errors: {}", errors.join(" "));
    }
    for s in &loaded.skipped {
        eprintln!("skipped: {}", s.error);
    }
    for mode in &modes {
        let mut o = options(mode, refine_rounds, starts)?;
        if !chosen {
            o.features = coseg::parts::FeatureSelection::Given;
        }
        o.feature_weights = pipeline.feature_weights(loaded.nodes[0].bands.features);
        o.group_mirrors = mirrors;
        if let (Some(from), Some(_)) = (parts_from, &o.parts) {
            let leaves = mode
                .split_once("@max=")
                .map(|(_, m)| m.parse())
                .transpose()?;
            o.set_parts_from(from, leaves);
            if let Some(b) = snap_band {
                o.set_snap_band(b)?;
            }
        }
        o.up = pipeline.up_direction();
        o.mirror_columns = pipeline.mirror_invariant_columns(loaded.nodes[0].bands.features);
        o.cue_cache = Some(cache.clone());
        if let Some(tolerance) = keep {
            o.refine_sizes = coseg::graph::RefineSizes::Keep { tolerance };
        }
        if all_cuts && mode == "default" && !coseg_set {
            let stage = coseg::parts::part_tree(loaded.nodes.clone(), &loaded.meshes, &o)?;
            let costs: Vec<f64> = stage
                .tree
                .tree
                .merges
                .iter()
                .map(|m| -m.similarity.clamp(f64::MIN_POSITIVE, 1.0).ln())
                .collect();
            println!("  all-cuts costs {costs:?}");
            if let Some(path) = &dump_tree_to {
                let mirrors: Vec<(usize, usize)> = coseg::parts::mirror_pairs(
                    &loaded.meshes,
                    &stage.tree.leaves,
                    stage.up,
                    Some(coseg::parts::Likeness {
                        graph: &stage.graph,
                        columns: &stage.mirror_columns,
                    }),
                )
                .iter()
                .map(|m| (m.a, m.b))
                .collect();
                dump_tree(path, &folder, &loaded, &stage.tree, &cache, &mirrors)?;
            }
            for n in 2..=8.min(stage.tree.leaves.tuples.len()) {
                let mut on = o.clone();
                on.request_parts(coseg::parts::PartsRequest::Count(n), None);
                let out = coseg::parts::cut_part_tree(stage.clone(), &loaded.meshes, &on)?;
                let (p, c) = family_scores(&loaded, &out.segmentation, &folder, false)?;
                println!("  all-cuts {n}: {:.2} {:.2}", 100.0 * p, 100.0 * c);
            }
            continue;
        }
        let t = Instant::now();
        let out = segment_collection(loaded.nodes.clone(), &loaded.meshes, &o)?;
        let secs = t.elapsed().as_secs_f64();
        let seg = &out.segmentation;
        if let Some(f) = &out.features {
            println!("  {}", f.reason);
        }
        if let Some(c) = &out.part_count {
            println!(
                "  {} costs {:?}",
                c.reason,
                c.costs
                    .iter()
                    .map(|x| (100.0 * x).round() / 100.0)
                    .collect::<Vec<_>>()
            );
        }
        let sizes: Vec<String> = seg
            .tuples
            .iter()
            .map(|t| {
                let mut a = t.area_fractions.clone();
                a.sort_by(f64::total_cmp);
                format!("{:.0}", 100.0 * a[a.len() / 2])
            })
            .collect();
        let extra = out.adaptive.as_ref().map_or(String::new(), |a| {
            let pairs = coseg::parts::mirror_pairs(
                &loaded.meshes,
                &a.leaves,
                o.up,
                Some(coseg::parts::Likeness {
                    graph: &out.graph,
                    columns: &o.mirror_columns,
                }),
            );
            format!(
                " leaves {} mirror pairs {:?} stop {:?} t {:?}",
                a.leaves.tuples.len(),
                pairs
                    .iter()
                    .map(|m| (m.a, m.b, (100.0 * m.ratio).round() / 100.0))
                    .collect::<Vec<_>>(),
                a.stop,
                a.auto.iter().map(|x| x.t).collect::<Vec<_>>()
            ) + &format!(
                " leafconf {:.3} costs {:?}",
                coseg::parts::start_score(&a.leaves),
                a.tree
                    .merges
                    .iter()
                    .map(|m| (-m.similarity.ln() * 100.0).round() / 100.0)
                    .collect::<Vec<_>>()
            )
        });
        if mirrors && !coseg_set {
            let likeness = coseg::parts::Likeness {
                graph: &out.graph,
                columns: &o.mirror_columns,
            };
            println!(
                "  final mirror pairs: {}",
                mirror_check(&loaded, seg, &folder, o.up, likeness)?
            );
        }
        if let (true, false, Some(a)) = (detail, coseg_set, out.adaptive.as_ref()) {
            eprintln!("  leaves:");
            family_scores(&loaded, &a.leaves, &folder, true)?;
            eprintln!(
                "  tree: {:?}",
                a.tree
                    .merges
                    .iter()
                    .map(|m| (m.a, m.b, (100.0 * m.similarity).round() / 100.0))
                    .collect::<Vec<_>>()
            );
            if !a.leaf_origin.is_empty() {
                eprintln!("  leaf origin: {:?}", a.leaf_origin);
            }
            eprintln!("  final:");
        }
        let score = if coseg_set {
            format!(
                "accuracy {:.1} %",
                100.0 * coseg_accuracy(&loaded, seg, &folder.join("gt"))?
            )
        } else {
            let (p, c) = family_scores(&loaded, seg, &folder, detail)?;
            format!("purity {:.2} % coverage {:.2} %", 100.0 * p, 100.0 * c)
        };
        println!(
            "{mode:>12}: {score}  confidence {:.3}  parts {} (median sizes % {}){extra}  {secs:.2} s",
            coseg::parts::start_score(seg),
            seg.tuples.len(),
            sizes.join("/")
        );
    }
    Ok(())
}

/// Appends one JSON line describing the part tree and its leaves per shape (for offline
/// studies of the count rule): merges, and per shape each leaf's area share, log thickness
/// and truth composition, and each touching pair's boundary length and concave length. The
/// thickness, the boundary (each interior edge seen from both of its faces) and the concave
/// test are those of `parts::geometric_part_tree`, so that a rule tried on these lines
/// reads what the tree reads.
fn dump_tree(
    path: &Path,
    folder: &Path,
    loaded: &LoadedCollection,
    tree: &coseg::parts::AdaptiveCosegmentation,
    cache: &Path,
    mirrors: &[(usize, usize)],
) -> Res<()> {
    use std::io::Write;
    let leaves = &tree.leaves;
    let l = leaves.tuples.len();
    let truth = GroundTruth::read(folder)?;
    let mut shapes = Vec::new();
    for (i, mesh) in loaded.meshes.iter().enumerate() {
        let cues = coseg::parts::load_or_compute_part_cues(mesh, cache)?.cues;
        let labels = leaves.labels(i);
        let gt = truth.grouped_labels(&leaves.names[i])?;
        let parts = ShapeParts::of_mesh(mesh, gt, labels.clone())?;
        let w = mesh.vertex_areas();
        let total: f64 = w.iter().sum();
        let mut area = vec![0.0; l];
        let mut lnt = vec![0.0; l];
        for (v, &x) in labels.iter().enumerate() {
            if x >= 0 {
                area[x as usize] += w[v];
                lnt[x as usize] += w[v] * cues.thickness[v].max(f64::MIN_POSITIVE).ln();
            }
        }
        let nt = parts.truth.iter().copied().max().unwrap_or(0) + 1;
        let mut comp = vec![vec![0.0; nt]; l];
        let ptotal: f64 = parts.areas.iter().sum();
        for ((&a, &t), &f) in parts.areas.iter().zip(&parts.truth).zip(&parts.found) {
            if f >= 0 {
                comp[f as usize][t] += a / ptotal;
            }
        }
        let h = &cues.mean_curvature;
        let flat = coseg::features::mean_curvature_resolution(mesh);
        let p = mesh.positions();
        let mut bd = std::collections::BTreeMap::new();
        for f in mesh.faces() {
            for k in 0..3 {
                let (u, v) = (f[k] as usize, f[(k + 1) % 3] as usize);
                let (x, y) = (labels[u], labels[v]);
                if x < 0 || y < 0 || x == y {
                    continue;
                }
                let d = p[u]
                    .iter()
                    .zip(&p[v])
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum::<f64>()
                    .sqrt();
                let c = if h[u] + h[v] < -(flat[u] + flat[v]) {
                    d
                } else {
                    0.0
                };
                let e = bd.entry((x.min(y), x.max(y))).or_insert((0.0, 0.0));
                e.0 += d;
                e.1 += c;
            }
        }
        let bd: Vec<(i32, i32, f64, f64)> = bd
            .into_iter()
            .map(|((a, b), (d, c))| (a, b, d, c))
            .collect();
        shapes.push(serde_json::json!({
            "area": area.iter().map(|a| a / total).collect::<Vec<_>>(),
            "lnt": lnt.iter().zip(&area).map(|(s, a)| if *a > 0.0 { s / a } else { f64::NAN }).map(|x| if x.is_finite() { Some(x) } else { None }).collect::<Vec<_>>(),
            "comp": comp,
            "bd": bd,
            "sqrt_area": total.sqrt(),
        }));
    }
    let merges: Vec<(usize, usize, f64)> = tree
        .tree
        .merges
        .iter()
        .map(|m| (m.a, m.b, -m.similarity.clamp(f64::MIN_POSITIVE, 1.0).ln()))
        .collect();
    let line = serde_json::json!({
        "folder": folder.display().to_string(),
        "leaves": l,
        "merges": merges,
        "copies": tree.leaf_copies,
        "mirrors": mirrors,
        "shapes": shapes,
    });
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)?;
    writeln!(f, "{line}")?;
    Ok(())
}
