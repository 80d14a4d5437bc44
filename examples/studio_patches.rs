//! Patches of `coseg studio` ([`coseg::studio::crease_patches`]) against ground-truth parts:
//! per shape, the number of patches and their purity (share of vertices whose patch's
//! majority part is their own part: the best a labelling by patch clicks alone can reach).
//!
//! `cargo run --release --example studio_patches -- collections/chairs [TARGET]` (each mesh's
//! `<stem>.labels.txt` beside it is the truth).

use coseg::labels::read_shape_labels;
use coseg::mesh::read_mesh;
use coseg::studio::{PatchOptions, crease_patches};
use std::collections::BTreeMap;
use std::path::PathBuf;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let folder = PathBuf::from(args.first().map_or("collections/chairs", String::as_str));
    let mut options = PatchOptions::default();
    if let Some(t) = args.get(1) {
        options.target_patches = t.parse()?;
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .is_some_and(|x| x == "obj" || x == "off" || x == "ply")
        })
        .collect();
    files.sort();
    println!("| shape | vertices | patches | purity | ms |");
    println!("|---|---|---|---|---|");
    let mut worst = 1.0f64;
    for f in files {
        let stem = f.file_stem().unwrap().to_string_lossy().to_string();
        let truth = folder.join(format!("{stem}.labels.txt"));
        if !truth.is_file() {
            continue;
        }
        let mesh = read_mesh(&f)?;
        let gt = read_shape_labels(&truth, &mesh, &stem)?.vertex_labels;
        let t0 = std::time::Instant::now();
        let patches = crease_patches(&mesh, &options)?;
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        let mut counts: BTreeMap<u32, BTreeMap<i32, usize>> = BTreeMap::new();
        for (&p, &g) in patches.iter().zip(&gt) {
            *counts.entry(p).or_default().entry(g).or_default() += 1;
        }
        let pure: usize = counts.values().map(|c| c.values().max().unwrap()).sum();
        let purity = pure as f64 / gt.len() as f64;
        worst = worst.min(purity);
        println!(
            "| {stem} | {} | {} | {:.3} | {ms:.1} |",
            mesh.vertex_count(),
            counts.len(),
            purity
        );
    }
    println!("worst purity {worst:.3}");
    Ok(())
}
