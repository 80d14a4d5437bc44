//! Speed of the alignment stage (run on a shared machine: report it as such).
//!
//! ```text
//! # Every mesh registered onto the first one (each a moved copy of itself with --self).
//! cargo run --release --example bench_align -- pairs [--self] MESH...
//! # A collection aligned (align_collection), optionally every shape first moved by a seeded
//! # random similarity (rotation uniform, scale 0.5–2, translation ±10): the rotation error of
//! # each shape against the collection's common frame (the rotation of recovered ∘ true that most shapes share, within 5°).
//! cargo run --release --example bench_align -- collection [--move SEED] [--neighbours K] MESH...
//! ```

use coseg::align::{AlignOptions, RegisterOptions, Similarity, align_collection, register_pair};
use coseg::mesh::read_mesh;
use std::time::Instant;

// The seeded motion the tests give shapes (one definition for both).
#[path = "../tests/common/motion.rs"]
mod motion;
use motion::{net_motions, random_similarity};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("collection") {
        return collection(&args[1..]);
    }
    let own = args.iter().any(|a| a == "--self");
    let files: Vec<&String> = args[1..].iter().filter(|a| !a.starts_with("--")).collect();
    let meshes = files.iter().map(read_mesh).collect::<Result<Vec<_>, _>>()?;
    let o = RegisterOptions::default();
    let mut total = 0.0;
    let mut worst = 0.0f64;
    for (f, m) in files.iter().zip(&meshes) {
        let source = if own { m } else { &meshes[0] };
        let t = Instant::now();
        let r = register_pair(source, m, &o)?;
        let s = t.elapsed().as_secs_f64();
        total += s;
        worst = worst.max(s);
        println!(
            "{f}\t{} vertices\t{s:.3} s\tangle to the given frame {:.1}°\tresidual {:.4}\tinliers {:.3}\trunner-up {}",
            m.vertex_count(),
            r.transform
                .rotation_angle_to(&coseg::align::Similarity::identity()),
            r.residual,
            r.inlier_share,
            r.runner_up
                .map(|c| format!("{:.4} at {:.0}°", c.residual, c.angle_to_best))
                .unwrap_or_else(|| "-".into())
        );
    }
    println!(
        "{} pairs: mean {:.3} s, worst {worst:.3} s",
        meshes.len(),
        total / meshes.len() as f64
    );
    Ok(())
}

fn collection(args: &[String]) -> Result<(), Box<dyn std::error::Error>> {
    use rand::SeedableRng;
    let mut seed = None;
    let mut files = Vec::new();
    let mut options = AlignOptions::default();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--move" => seed = Some(it.next().ok_or("--move SEED")?.parse::<u64>()?),
            "--neighbours" => options.neighbours = it.next().ok_or("--neighbours K")?.parse()?,
            _ => files.push(a.clone()),
        }
    }
    let mut meshes = files.iter().map(read_mesh).collect::<Result<Vec<_>, _>>()?;
    let mut truth = vec![Similarity::identity(); meshes.len()];
    if let Some(s) = seed {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(s);
        for (m, t) in meshes.iter_mut().zip(truth.iter_mut()) {
            *t = random_similarity(&mut rng);
            *m = m.map_positions(|p| t.apply(p))?;
        }
    }
    let vertices: usize = meshes.iter().map(|m| m.vertex_count()).sum();
    let t = Instant::now();
    let a = align_collection(&meshes, &options)?;
    let wall = t.elapsed().as_secs_f64();
    let net = net_motions(&a, &truth);
    // With an axis of revolution `a` (collection frame), rotations about it are forgiven:
    // each shape is then judged by where its net rotation takes `a` from (`netᵀ a`, the
    // file-frame axis), which a turn about `a` does not change.
    let plain_error = |x: &Similarity, c: &Similarity| match a.symmetry_axis {
        None => x.rotation_angle_to(c),
        Some(axis) => {
            let back = |s: &Similarity| -> [f64; 3] {
                std::array::from_fn(|j| (0..3).map(|i| s.rotation[i][j] * axis[i]).sum())
            };
            let (u, v) = (back(x), back(c));
            let dot: f64 = (0..3).map(|k| u[k] * v[k]).sum();
            dot.clamp(-1.0, 1.0).acos().to_degrees()
        }
    };
    // A shape's own symmetries (`T`, collection frame) are forgiven too: `T ∘ net` is as right.
    let error_of = |i: usize, c: &Similarity| {
        a.shapes[i]
            .symmetries
            .iter()
            .map(|t| {
                let turn = Similarity {
                    rotation: *t,
                    scale: 1.0,
                    translation: [0.0; 3],
                };
                plain_error(&turn.compose(&net[i]), c)
            })
            .fold(plain_error(&net[i], c), f64::min)
    };
    // The common frame: the shapes' net rotation that most others are within 5° of, refined
    // by the chordal mean of those.
    let support = |c: &Similarity| (0..net.len()).filter(|&i| error_of(i, c) <= 5.0).count();
    let seed_frame = net
        .iter()
        .max_by_key(|c| support(c))
        .copied()
        .unwrap_or_else(Similarity::identity);
    let mut m = [[0.0; 3]; 3];
    for i in (0..net.len()).filter(|&i| plain_error(&net[i], &seed_frame) <= 5.0) {
        for (row, r) in m.iter_mut().zip(&net[i].rotation) {
            for (x, y) in row.iter_mut().zip(r) {
                *x += y;
            }
        }
    }
    let mean = nearest_rotation(m);
    let mut within = 0;
    let mut up_within = 0;
    for (i, (f, sh)) in files.iter().zip(&a.shapes).enumerate() {
        let e = error_of(i, &mean);
        within += usize::from(e <= 5.0);
        // Where the shape's file +y (up in every shipped family and the COSEG chairs) lands,
        // against where the common frame puts it: the up axis alone, whatever the turn about
        // it (what a posed body can be expected to get right).
        let up_error = {
            let (u, v) = (net[i].rotation.map(|r| r[1]), mean.rotation.map(|r| r[1]));
            let dot: f64 = (0..3).map(|k| u[k] * v[k]).sum();
            dot.clamp(-1.0, 1.0).acos().to_degrees()
        };
        up_within += usize::from(up_error <= 5.0);
        println!(
            "{f}\terror {e:.1}° (own symmetries {})\tup error {up_error:.1}°\tconfidence {:.2}\tresidual {}\tambiguity {}",
            sh.symmetries.len(),
            sh.confidence,
            sh.residual.map_or("-".into(), |r| format!("{r:.4}")),
            sh.ambiguity
                .zip(sh.ambiguity_angle)
                .map_or("-".into(), |(x, g)| format!("{x:.2} at {g:.0}°"))
        );
    }
    println!(
        "{:?}: {} shapes ({vertices} vertices), {} edges, given-frame share {:.2}, up {:?}, forward {:?}, axis of revolution (forgiven) {:?}; within 5° of the common frame: {within} of {} ({:.1} %); file +y within 5° of the common frame's: {up_within}; {wall:.2} s wall ({:.3} s per shape)",
        a.case,
        meshes.len(),
        a.edges.len(),
        a.given_frame_share,
        a.up.map(|x| (x * 1000.0).round() / 1000.0),
        a.forward.map(|x| (x * 1000.0).round() / 1000.0),
        a.symmetry_axis
            .map(|v| v.map(|x| (x * 1000.0).round() / 1000.0)),
        meshes.len(),
        100.0 * within as f64 / meshes.len() as f64,
        wall / meshes.len() as f64
    );
    Ok(())
}

/// The rotation nearest to `m` (SVD projection).
fn nearest_rotation(m: [[f64; 3]; 3]) -> Similarity {
    let a = nalgebra::Matrix3::from_fn(|i, j| m[i][j]);
    let svd = a.svd(true, true);
    let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
    let d = (u * vt).determinant().signum();
    let r = u * nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, d)) * vt;
    Similarity {
        rotation: std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)])),
        scale: 1.0,
        translation: [0.0; 3],
    }
}
