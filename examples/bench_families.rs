//! Per-shape cost of each feature family on the meshes given on the command line:
//! spectral (spectrum + descriptors), extrinsic (100 directions, PCA frame), sdf (30 rays), and
//! the spectral family's intrinsic Delaunay option (the flips and operators alone, with the
//! number of flips, and the whole spectrum on it).
//! Median of `--reps` runs (default 3) for the extrinsic, sdf and flip columns, one for the
//! spectra.
//!
//!     cargo run --release --example bench_families -- MESH... [--reps N]

use coseg::features::{
    Alignment, DescriptorOptions, ExtrinsicOptions, SdfOptions, descriptors, extrinsic_features,
    shape_diameter,
};
use coseg::mesh::read_mesh;
use coseg::spectral::{
    LaplacianKind, SpectrumOptions, SurfaceOperators, laplace_beltrami_spectrum,
};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let reps = args
        .iter()
        .position(|a| a == "--reps")
        .and_then(|i| args.get(i + 1))
        .map_or(Ok(3), |s| s.parse())?;
    let meshes: Vec<&String> = args
        .iter()
        .enumerate()
        .filter(|(i, a)| !a.starts_with("--") && (*i == 0 || args[i - 1] != "--reps"))
        .map(|(_, a)| a)
        .collect();
    println!(
        "| mesh | vertices | spectrum (s) | descriptors (s) | extrinsic (s) | sdf (s) | intrinsic Delaunay operators (s) | flips | spectrum on it (s) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for path in meshes {
        let m = read_mesh(path)?;
        let t = Instant::now();
        let s = laplace_beltrami_spectrum(&m, &SpectrumOptions::default())?;
        let spectrum = t.elapsed().as_secs_f64();
        let t = Instant::now();
        descriptors(&m, &s, &DescriptorOptions::default())?;
        let desc = t.elapsed().as_secs_f64();
        let mut eo = ExtrinsicOptions::default();
        eo.alignment = Alignment::Pca;
        let ext = median(
            (0..reps)
                .map(|_| {
                    let t = Instant::now();
                    extrinsic_features(&m, &eo).map(|_| t.elapsed().as_secs_f64())
                })
                .collect::<Result<_, _>>()?,
        );
        let sdf = median(
            (0..reps)
                .map(|_| {
                    let t = Instant::now();
                    shape_diameter(&m, &SdfOptions::default()).map(|_| t.elapsed().as_secs_f64())
                })
                .collect::<Result<_, _>>()?,
        );
        let idt = median(
            (0..reps)
                .map(|_| {
                    let t = Instant::now();
                    SurfaceOperators::with_laplacian(&m, LaplacianKind::IntrinsicDelaunay);
                    t.elapsed().as_secs_f64()
                })
                .collect(),
        );
        let flips = coseg::spectral::IntrinsicDelaunay::new(&m).flips();
        let mut so = SpectrumOptions::default();
        so.laplacian = LaplacianKind::IntrinsicDelaunay;
        let t = Instant::now();
        laplace_beltrami_spectrum(&m, &so)?;
        let spectrum_idt = t.elapsed().as_secs_f64();
        println!(
            "| {path} | {} | {spectrum:.2} | {desc:.2} | {ext:.3} | {sdf:.2} | {idt:.3} | {flips} | {spectrum_idt:.2} |",
            m.vertex_count()
        );
    }
    Ok(())
}
