//! Benchmark: descriptors (100 HKS + 100 WKS + 100 mean curvature) and band table (K = 20)
//! of a large mesh from an already computed spectrum, plus the time to read a cache entry
//! (decode the stored spectrum, then rebuild descriptors and bands from it).
//!
//! The spectrum is synthetic (k = 200 eigenvalues following Weyl's law, eigenvectors with
//! seeded pseudo-random entries scaled to unit M-norm): the cost of the feature stage does not
//! depend on the eigenvectors' values, and the dense oracle solver cannot handle 45k vertices.
//!
//! ```text
//! cargo run --release --example bench_features -- /work/shared/data/tosca_hires/victoria0.off [reps]
//! ```

use coseg::bands::{BandOptions, band_table};
use coseg::features::{DescriptorOptions, descriptors};
use coseg::mesh::read_mesh;
use coseg::pipeline::{
    ShapePipelineOptions, decode_shape_entry, encode_shape_entry as encode_entry,
    shape_data_from_spectrum,
};
use coseg::spectral::Spectrum;
use std::time::Instant;

/// CPU time (user + system, all threads) of this process in seconds, from /proc (Linux; 0
/// elsewhere). 10 ms resolution.
fn cpu_seconds() -> f64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    let rest = &s[s.rfind(')').map_or(0, |i| i + 2)..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let tick = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    (tick(11) + tick(12)) / 100.0
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .ok_or_else(|| anyhow::anyhow!("usage: bench_features MESH [reps]"))?;
    let reps: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(5);
    let mesh = read_mesh(&path)?;
    let d = mesh.vertex_count();
    let k = 200;
    let area = mesh.total_area();
    let vertex_areas: Vec<f64> = mesh.vertex_areas().iter().map(|a| a / area).collect();
    let mut s = 0x9e3779b97f4a7c15u64;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let eigenvalues: Vec<f64> = (0..k)
        .map(|i| 4.0 * std::f64::consts::PI * i as f64 * (1.0 + 0.1 * next()))
        .collect();
    let mut eigenvectors = Vec::with_capacity(d * k);
    for _ in 0..k {
        let col: Vec<f64> = (0..d).map(|_| next()).collect();
        let norm: f64 = col
            .iter()
            .zip(&vertex_areas)
            .map(|(x, w)| x * x * w)
            .sum::<f64>()
            .sqrt();
        eigenvectors.extend(col.iter().map(|x| x / norm));
    }
    let spectrum = Spectrum {
        eigenvalues,
        eigenvectors,
        vertex_areas,
        original_area: area,
    };
    println!(
        "{path}: {d} vertices, k = {k}, {} threads",
        rayon::current_num_threads()
    );
    let dopts = DescriptorOptions::default();
    let bopts = BandOptions::default();
    let mut t_feat = Vec::new();
    let mut t_band = Vec::new();
    let (mut c_feat, mut c_band) = (0.0, 0.0);
    for _ in 0..reps {
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let f = descriptors(&mesh, &spectrum, &dopts)?;
        let (t1, c1) = (Instant::now(), cpu_seconds());
        let b = band_table(&f, &bopts)?;
        let (t2, c2) = (Instant::now(), cpu_seconds());
        std::hint::black_box(&b);
        t_feat.push((t1 - t0).as_secs_f64());
        t_band.push((t2 - t1).as_secs_f64());
        c_feat += c1 - c0;
        c_band += c2 - c1;
    }
    println!(
        "CPU time per run (all threads): descriptors {:.3} s, bands {:.3} s",
        c_feat / reps as f64,
        c_band / reps as f64
    );
    let stats = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        (v[0], v[v.len() / 2])
    };
    let (fmin, fmed) = stats(&mut t_feat);
    let (bmin, bmed) = stats(&mut t_band);
    println!("descriptors (300 features): min {fmin:.3} s, median {fmed:.3} s");
    println!("band table (K = 20):        min {bmin:.3} s, median {bmed:.3} s");
    println!(
        "descriptors + bands:        min {:.3} s, median {:.3} s",
        fmin + bmin,
        fmed + bmed
    );
    // Reading a cache entry (the f32 spectrum) back from bytes, then rebuilding the rest.
    let options = ShapePipelineOptions::default();
    let data = shape_data_from_spectrum(&mesh, spectrum, &options)?;
    let bytes = encode_entry(&data);
    let t0 = Instant::now();
    let stored = decode_shape_entry(&bytes, &data.key, d).map_err(anyhow::Error::msg)?;
    let t_decode = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let rebuilt = stored.into_shape_data(&mesh, &options)?;
    let t_rebuild = t0.elapsed().as_secs_f64();
    assert!(rebuilt == data, "the entry does not rebuild the data");
    println!(
        "cache entry: {:.1} MB, verify + decode {t_decode:.3} s (checksum {:.3} s), rebuild {t_rebuild:.3} s",
        bytes.len() as f64 / 1e6,
        {
            let t = Instant::now();
            std::hint::black_box(blake3::hash(&bytes[84..]));
            t.elapsed().as_secs_f64()
        }
    );
    Ok(())
}
