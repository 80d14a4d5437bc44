//! Replays the library's fusion of the routes (`coseg::propagate::fuse_routes_with`, as
//! `fuse_propagation` calls it) on the routes' labels that `COSEG_DUMP=DIR eval_propagate …`
//! wrote, and scores it against the dumped ground truth: a fusion rule is measured on every
//! dumped collection in seconds, without running the routes again.
//!
//! ```text
//! COSEG_DUMP=/tmp/dumps/goblets target/release/examples/eval_propagate labelled collections/goblets --triples 0
//! cargo run --release --example replay_fusion -- [--per-target] /tmp/dumps/goblets [DIR…]
//! ```
//! Per dump folder, every run (`run-<sources>.json`): the mean accuracy over its targets of
//! each route, of the fusion as dumped (the harness's score) and of the fusion replayed by
//! this build of the library; then each folder's means over its runs, and the mean over the
//! folders. Scores are area-weighted per vertex (`coseg::evaluate::label_agreement` on the
//! dumped vertex areas), so on the COSEG chairs, which the harness scores per face, the
//! dumped and replayed columns differ by that alone; elsewhere a replay of the dumping
//! build's fusion reproduces the harness's figures. With `REPLAY_ROUND_TRIP` set, the fusion
//! reads the parts route's round trip on the sources (`RouteOptions::round_trip`, from the
//! dumped part ids and the sources' truth). `--per-target`: every target's route
//! scores, weights and replayed score.

use coseg::evaluate::label_agreement;
use coseg::propagate::{RoundTrip, Route, RouteLabels, fuse_routes_with};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// One dumped shape: its name, vertex areas and per-vertex ground truth.
struct Shape {
    name: String,
    areas: Vec<f64>,
    truth: Vec<i32>,
}

/// The means of one run: per route, the dumped fusion and the replayed fusion.
struct RunMeans {
    routes: Vec<(String, f64)>,
    dumped: f64,
    replayed: f64,
}

fn vec_f64(v: &Value) -> Vec<f64> {
    v.as_array()
        .map(|a| a.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect())
        .unwrap_or_default()
}

fn vec_i32(v: &Value) -> Vec<i32> {
    v.as_array()
        .map(|a| a.iter().map(|x| x.as_i64().unwrap_or(-1) as i32).collect())
        .unwrap_or_default()
}

fn score(shape: &Shape, labels: &[i32]) -> f64 {
    label_agreement(&shape.areas, &shape.truth, labels).map_or(f64::NAN, |a| a.accuracy)
}

fn route_of(name: &str) -> Option<Route> {
    [Route::Affinity, Route::Parts, Route::Rigid]
        .into_iter()
        .find(|r| r.name() == name)
}

/// Replays one run; prints it and returns its means.
fn replay(
    shapes: &[Shape],
    run: &Value,
    per_target: bool,
) -> Result<RunMeans, Box<dyn std::error::Error>> {
    let n = shapes.len();
    let names: Vec<String> = serde_json::from_value(run["routes"].clone())?;
    let mut routes: Vec<RouteLabels> = names.iter().map(|_| RouteLabels::empty(n)).collect();
    let mut dumped = Vec::new();
    let mut targets = Vec::new();
    for t in run["targets"].as_array().ok_or("no targets")? {
        let i = t["shape"].as_u64().ok_or("target without shape")? as usize;
        targets.push(i);
        dumped.push(t["fused_score"].as_f64().unwrap_or(f64::NAN));
        for (r, name) in names.iter().enumerate() {
            let d = &t["routes"][name];
            routes[r].labels[i] = vec_i32(&d["labels"]);
            routes[r].confidence[i] = vec_f64(&d["conf"]);
            routes[r].shape_confidence[i] = d["shape_conf"].as_f64().unwrap_or(0.0);
            let res = d["residual"].as_f64().unwrap_or(-1.0);
            routes[r].residual[i] = if res >= 0.0 { res } else { f64::NAN };
        }
    }
    let held_out: Option<Vec<f64>> = match &run["held_out"] {
        Value::Null => None,
        h => Some(match h.get("accuracy") {
            Some(a) => vec_f64(a),
            // Dumps made before the accuracy was written: the mean of the scores.
            None => {
                let scores: Vec<Vec<f64>> = serde_json::from_value(h["scores"].clone())?;
                (0..names.len())
                    .map(|r| scores.iter().map(|s| s[r]).sum::<f64>() / scores.len().max(1) as f64)
                    .collect()
            }
        }),
    };
    let position = |route: Route| names.iter().position(|x| route_of(x) == Some(route));
    let shared = position(Route::Affinity)
        .zip(position(Route::Parts))
        .filter(|_| run["parts_intrinsic"].as_bool().unwrap_or(false));
    let refs: Vec<&RouteLabels> = routes.iter().collect();
    let areas: Vec<&[f64]> = shapes.iter().map(|s| s.areas.as_slice()).collect();
    // The parts route's round trip on the sources, as `fuse_propagation` measures it (from
    // the dumped part ids and the sources' ground truth, which is what they were given).
    let part_ids: Vec<Vec<i32>> =
        serde_json::from_value(run["part_ids"].clone()).unwrap_or_default();
    let mut tally: std::collections::BTreeMap<i32, std::collections::BTreeMap<i32, f64>> =
        Default::default();
    for s in vec_i32(&run["sources"]) {
        let s = s as usize;
        let Some(ids) = part_ids.get(s) else { continue };
        for ((&p, &g), &a) in ids.iter().zip(&shapes[s].truth).zip(&shapes[s].areas) {
            if p >= 0 && g >= 0 {
                *tally.entry(p).or_default().entry(g).or_insert(0.0) += a;
            }
        }
    }
    let total: f64 = tally.values().flat_map(|t| t.values()).sum();
    let right: f64 = tally
        .values()
        .map(|t| t.values().copied().fold(0.0, f64::max))
        .sum();
    let round_trip = match (position(Route::Parts), position(Route::Affinity)) {
        (Some(route), Some(partner)) if total > 0.0 && held_out.is_none() => Some(RoundTrip {
            route,
            partner,
            accuracy: right / total,
        }),
        _ => None,
    };
    // `RouteOptions::round_trip`, off by default: replayed with `REPLAY_ROUND_TRIP` set.
    let round_trip = round_trip.filter(|_| std::env::var_os("REPLAY_ROUND_TRIP").is_some());
    let fused = fuse_routes_with(&refs, &areas, held_out.as_deref(), shared, round_trip);
    let sources: Vec<String> = vec_i32(&run["sources"])
        .iter()
        .map(|&s| shapes[s as usize].name.clone())
        .collect();
    let mut route_sums = vec![0.0; names.len()];
    let mut replayed = 0.0;
    for &i in &targets {
        let s = score(&shapes[i], &fused.labels[i]);
        replayed += s;
        let mut line = format!("    {:>14}", shapes[i].name);
        for (r, name) in names.iter().enumerate() {
            let rs = score(&shapes[i], &routes[r].labels[i]);
            route_sums[r] += rs;
            line += &format!(" {name}={:.1}/w{:.2}", 100.0 * rs, fused.weights[i][r]);
        }
        if per_target {
            println!("{line} fused={:.1}", 100.0 * s);
        }
    }
    let k = targets.len().max(1) as f64;
    let means = RunMeans {
        routes: names
            .iter()
            .zip(&route_sums)
            .map(|(n, s)| (n.clone(), s / k))
            .collect(),
        dumped: dumped.iter().sum::<f64>() / k,
        replayed: replayed / k,
    };
    let routes_line: Vec<String> = means
        .routes
        .iter()
        .map(|(n, m)| format!("{n} {:.2}", 100.0 * m))
        .collect();
    println!(
        "  from {} (parts intrinsic: {}): {}; fused dumped {:.2}, replayed {:.2}",
        sources.join(","),
        run["parts_intrinsic"],
        routes_line.join(", "),
        100.0 * means.dumped,
        100.0 * means.replayed
    );
    Ok(means)
}

/// Replays every run of one dump folder; returns the means over its runs of the dumped and
/// the replayed fusion.
fn replay_dir(dir: &Path, per_target: bool) -> Result<(f64, f64), Box<dyn std::error::Error>> {
    let v: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("shapes.json"))?)?;
    let shapes: Vec<Shape> = v
        .as_array()
        .ok_or("shapes.json: not a list")?
        .iter()
        .map(|s| Shape {
            name: s["name"].as_str().unwrap_or("?").to_string(),
            areas: vec_f64(&s["areas"]),
            truth: vec_i32(&s["gt"]),
        })
        .collect();
    let mut runs: Vec<PathBuf> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|f| f.to_str())
                .is_some_and(|f| f.starts_with("run-") && f.ends_with(".json"))
        })
        .collect();
    runs.sort();
    println!("{}", dir.display());
    let mut all = Vec::new();
    for path in &runs {
        let run: Value = serde_json::from_str(&std::fs::read_to_string(path)?)?;
        all.push(replay(&shapes, &run, per_target)?);
    }
    let k = all.len().max(1) as f64;
    let dumped = all.iter().map(|m| m.dumped).sum::<f64>() / k;
    let replayed = all.iter().map(|m| m.replayed).sum::<f64>() / k;
    let mut line = String::new();
    if let Some(first) = all.first() {
        for (r, (name, _)) in first.routes.iter().enumerate() {
            let m = all.iter().map(|x| x.routes[r].1).sum::<f64>() / k;
            line += &format!("{name} {:.2}, ", 100.0 * m);
        }
    }
    println!(
        "  {} runs: {line}fused dumped {:.2}, replayed {:.2}",
        all.len(),
        100.0 * dumped,
        100.0 * replayed
    );
    Ok((dumped, replayed))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut per_target = false;
    let mut dirs = Vec::new();
    for a in std::env::args().skip(1) {
        match a.as_str() {
            "--per-target" => per_target = true,
            _ => dirs.push(PathBuf::from(a)),
        }
    }
    if dirs.is_empty() {
        return Err("usage: replay_fusion [--per-target] DUMP_DIR...".into());
    }
    let mut sums = (0.0, 0.0);
    for d in &dirs {
        let (a, b) = replay_dir(d, per_target)?;
        sums.0 += a;
        sums.1 += b;
    }
    let k = dirs.len() as f64;
    println!(
        "mean of {} folders: fused dumped {:.2}, replayed {:.2}",
        dirs.len(),
        100.0 * sums.0 / k,
        100.0 * sums.1 / k
    );
    Ok(())
}
