//! Correspondence ratio (paper §7.2) on TOSCA within-class pairs, identity ground truth.
//!
//! ```text
//! cargo run --release --example eval_tosca -- /work/shared/data/tosca [--cache DIR]
//!     [--shapes 4] [--seed 0] [--map-weight β] [--nearest] [--classes cat,dog,horse,david] [--configs all|NAME,NAME] [--bands K]
//!     [--area-bands] [--eigenpairs k] [--laplacian cotan|intrinsic-delaunay] [--hks n] [--wks n] [--curvature n]
//!     [--features LIST] [--up AXIS|pca] [--directions N] [--normals N] [--family-weights W]
//! ```
//! For every class, the first `--shapes` files `<class><i>.off` in increasing `i` are taken and
//! every unordered pair is segmented; the table gives the mean ratio per class and overall for
//! each configuration (Algorithm 2 at a 10 % area cutoff, Algorithm 3), plus the time spent in
//! the stable-region algorithm (per-shape data are cached and excluded).
//!
//! `--features`, `--up`, `--directions`, `--normals`, `--family-weights` are `coseg pair`'s
//! flags (docs/FEATURES.md), translated by the same library call
//! (`ShapePipelineOptions::set_families`); every configuration then runs on the affinity
//! weighted by the families' shares (`stable::pair_affinity`), as `coseg pair` does.
//!
//! `--nearest` reads the map step's last point map by nearest neighbours (ZoomOut as
//! published) instead of the default one-to-one assignment.
//!
//! The `*-oracle-*` configurations are diagnostics, not methods: they replace the map step's
//! map by ZoomOut started from the ground truth, to measure what a perfect start of the map
//! would buy.

use coseg::bands::BandWeighting;
use coseg::features::ExtrinsicOptions;
use coseg::maps::MapGuidedOptions;
use coseg::maps::{FinalMatch, ZoomOutOptions, zoomout};
use coseg::maps::{MapPreset, MapStep, ShapeGeometry};
use coseg::mesh::{TriMesh, read_mesh};
use coseg::pipeline::{ShapeData, ShapePipelineOptions, load_or_compute};
use coseg::spectral::HeatSmoother;
use coseg::stable::{
    Algorithm, AreaReference, Init, PairShape, RefineOptions, SegmentPairOptions,
    StableRegionsOptions, TSearch, VertexMap, correspondence_stats, pair_affinity,
    point_map_refinement, refine_regions, segment_pair, stable_regions_with,
};
use std::path::PathBuf;
use std::time::Instant;

/// What runs after the algorithm.
#[derive(Clone, Copy)]
enum Post {
    None,
    /// [`refine_regions`] with default options.
    Refine,
    /// [`segment_pair`] with default refinement and map step (what `coseg pair` runs).
    RefineMap,
    /// The same with [`MapGuidedOptions::near_isometric`] (`coseg pair --map-preset
    /// near-isometric`).
    RefineMapIsometric,
    /// The same with the preset `coseg::maps::map_preset` picks for the pair (`coseg pair`'s default).
    RefineMapAuto,
    /// Diagnostic, not a method: [`refine_regions`], then [`point_map_refinement`] with
    /// weight `β` and a ZoomOut map started from the ground truth (what the map step would
    /// give if its map were as good as ZoomOut can make it).
    RefineOracleMap(f64),
}

/// One shape of a class with its cached data.
struct Shape {
    name: String,
    mesh: TriMesh,
    areas: Vec<f64>,
    data: ShapeData,
    refine_smoother: HeatSmoother,
    map_smoother: HeatSmoother,
}

impl Shape {
    fn pair_shape(&self) -> PairShape<'_> {
        PairShape {
            mesh: &self.mesh,
            spectrum: &self.data.spectrum,
            bands: &self.data.bands,
            descriptors: Some(&self.data.descriptors.values),
        }
    }

    fn geometry(&self) -> ShapeGeometry<'_> {
        ShapeGeometry {
            spectrum: &self.data.spectrum,
            positions: self.mesh.positions(),
            descriptors: Some(&self.data.descriptors.values),
        }
    }
}

/// `(name, options, post-processing)`.
fn configs() -> Vec<(&'static str, StableRegionsOptions, Post)> {
    // `o` with `change` made.
    let with = |o: &StableRegionsOptions, change: &dyn Fn(&mut StableRegionsOptions)| {
        let mut o = o.clone();
        change(&mut o);
        o
    };
    // Explicit inits: the configurations do not depend on the library's default.
    let base = with(&StableRegionsOptions::default(), &|o| {
        o.init = Init::Extreme
    });
    let auto = with(&base, &|o| o.algorithm = Algorithm::Auto);
    let base_random = with(&base, &|o| o.init = Init::Random);
    let auto_random = with(&auto, &|o| o.init = Init::Random);
    let remaining = with(&base, &|o| o.area_reference = AreaReference::Remaining);
    let linear = with(&auto, &|o| o.t_search = TSearch::Linear);
    let linear_cold = with(&auto_random, &|o| {
        o.t_search = TSearch::Linear;
        o.warm_start = false;
    });
    vec![
        ("alg2-extreme", base, Post::None),
        ("alg2-random", base_random.clone(), Post::None),
        ("alg2-extreme-remaining", remaining, Post::None),
        ("alg3-extreme", auto, Post::None),
        ("alg3-random", auto_random.clone(), Post::None),
        ("alg3-extreme-linear", linear, Post::None),
        ("alg3-random-linear-cold", linear_cold, Post::None),
        ("alg2-random-refined", base_random.clone(), Post::Refine),
        ("alg3-random-refined", auto_random.clone(), Post::Refine),
        ("alg2-random-mapped", base_random.clone(), Post::RefineMap),
        (
            "alg2-random-mapped-iso",
            base_random.clone(),
            Post::RefineMapIsometric,
        ),
        (
            "alg3-random-mapped-iso",
            auto_random.clone(),
            Post::RefineMapIsometric,
        ),
        (
            "alg2-random-mapped-auto",
            base_random.clone(),
            Post::RefineMapAuto,
        ),
        (
            "alg3-random-mapped-auto",
            auto_random.clone(),
            Post::RefineMapAuto,
        ),
        (
            "alg2-random-oracle-map",
            base_random.clone(),
            Post::RefineOracleMap(MapGuidedOptions::default().map_weight),
        ),
        (
            "alg2-random-oracle-transfer",
            base_random,
            Post::RefineOracleMap(1e6),
        ),
        ("alg3-random-mapped", auto_random, Post::RefineMap),
    ]
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut dir = None;
    let mut cache = PathBuf::from("/tmp/coseg-eval-cache");
    let mut shapes = 4usize;
    let mut seed = 0u64;
    let mut map_step = MapGuidedOptions::default();
    let mut nearest = false;
    let mut classes = vec![
        "cat".to_string(),
        "dog".into(),
        "horse".into(),
        "david".into(),
    ];
    let mut which = "all".to_string();
    let mut pipe = ShapePipelineOptions::default();
    // `coseg pair`'s family flags and their defaults.
    let (mut features, mut up, mut family_weights) =
        ("spectral".to_string(), "y".to_string(), String::new());
    let (mut directions, mut normals) = (ExtrinsicOptions::default().directions, 0usize);
    let mut args = args.iter();
    while let Some(arg) = args.next() {
        // The flag's value: the next argument.
        let mut value = || args.next().cloned().unwrap_or_default();
        match arg.as_str() {
            "--cache" => cache = value().into(),
            "--map-weight" => map_step.map_weight = value().parse()?,
            "--nearest" => nearest = true,
            "--seed" => seed = value().parse()?,
            "--shapes" => shapes = value().parse()?,
            "--classes" => classes = value().split(',').map(String::from).collect(),
            "--configs" => which = value(),
            "--bands" => pipe.bands.bands = value().parse()?,
            "--eigenpairs" => pipe.spectrum.eigenpairs = value().parse()?,
            "--laplacian" => {
                pipe.spectrum.laplacian = value().parse().map_err(anyhow::Error::msg)?
            }
            "--hks" => pipe.descriptors.hks_count = value().parse()?,
            "--wks" => pipe.descriptors.wks_count = value().parse()?,
            "--curvature" => pipe.descriptors.curvature_count = value().parse()?,
            "--area-bands" => pipe.bands.weighting = BandWeighting::Area,
            "--features" => features = value(),
            "--up" => up = value(),
            "--directions" => directions = value().parse()?,
            "--normals" => normals = value().parse()?,
            "--family-weights" => family_weights = value(),
            d => dir = Some(PathBuf::from(d)),
        }
    }
    pipe.set_families(&features, &up, directions, normals, &family_weights)?;
    let dir = dir.ok_or_else(|| anyhow::anyhow!("usage: eval_tosca DATA_DIR [options]"))?;
    let configs: Vec<_> = configs()
        .into_iter()
        .filter(|(n, _, _)| which == "all" || which.split(',').any(|w| w == *n))
        .map(|(n, o, p)| {
            (
                n,
                {
                    let mut opts = o;
                    opts.seed = seed;
                    opts
                },
                p,
            )
        })
        .collect();
    println!("pipeline: {pipe:?}");
    // Per class: the first `shapes` indices present.
    let mut results = vec![vec![Vec::new(); classes.len()]; configs.len()];
    let mut times = vec![0.0; configs.len()];
    let mut stable_only = vec![Vec::new(); configs.len()];
    let mut coverage = vec![Vec::new(); configs.len()];
    for (ci, class) in classes.iter().enumerate() {
        let mut idx: Vec<u32> = std::fs::read_dir(&dir)?
            .filter_map(|e| e.ok())
            .filter_map(|e| {
                let n = e.file_name().to_string_lossy().into_owned();
                n.strip_prefix(class.as_str())?
                    .strip_suffix(".off")?
                    .parse()
                    .ok()
            })
            .collect();
        idx.sort_unstable();
        idx.truncate(shapes);
        let mut data = Vec::new();
        for &k in &idx {
            let path = dir.join(format!("{class}{k}.off"));
            let mesh = read_mesh(&path)?;
            let t = Instant::now();
            let d = load_or_compute(&mesh, &pipe, &cache)?;
            eprintln!(
                "{}: {} vertices, data in {:.1} s ({:?})",
                path.display(),
                mesh.vertex_count(),
                t.elapsed().as_secs_f64(),
                d.outcome
            );
            data.push(Shape {
                name: format!("{class}{k}"),
                areas: mesh.vertex_areas(),
                refine_smoother: HeatSmoother::new(&mesh, RefineOptions::default().smoothing_time)?,
                map_smoother: HeatSmoother::new(&mesh, MapGuidedOptions::default().smoothing_time)?,
                mesh,
                data: d.data,
            });
        }
        for a in 0..data.len() {
            for b in a + 1..data.len() {
                let (sa, sb) = (&data[a], &data[b]);
                let mut line = format!("{:>8} x {:<8}", sa.name, sb.name);
                for (k, (_, opts, post)) in configs.iter().enumerate() {
                    let t = Instant::now();
                    let (ba, bb) = (&sa.data.bands, &sb.data.bands);
                    // The families' shares, as `coseg pair` weighs them (`None`: one family).
                    let weights = pipe.feature_weights(ba.features);
                    let w = pair_affinity(ba, bb, weights.as_deref())?;
                    let stable = || stable_regions_with(&w, &sa.areas, &sb.areas, opts);
                    let refined = || -> anyhow::Result<_> {
                        Ok(refine_regions(
                            &w,
                            &stable()?,
                            &sa.areas,
                            &sb.areas,
                            Some(&sa.refine_smoother),
                            Some(&sb.refine_smoother),
                            &RefineOptions::default(),
                        )?)
                    };
                    // What `coseg pair` runs (its smoothers' set-up is timed too).
                    let whole_stage = |mut map_guided: MapGuidedOptions| -> anyhow::Result<_> {
                        if nearest {
                            map_guided.point_map.zoomout.final_match = FinalMatch::Nearest;
                        }
                        let options = {
                            let mut o2 = SegmentPairOptions::default();
                            o2.regions = opts.clone();
                            o2.map_step = MapStep::Options(map_guided);
                            o2.feature_weights = weights.clone();
                            o2
                        };
                        Ok(segment_pair(sa.pair_shape(), sb.pair_shape(), &options)?.regions)
                    };
                    let r = match post {
                        Post::None => stable()?,
                        Post::Refine => refined()?,
                        Post::RefineMap => whole_stage(map_step.clone())?,
                        Post::RefineMapIsometric => {
                            whole_stage(MapGuidedOptions::near_isometric())?
                        }
                        Post::RefineMapAuto => {
                            // The library's default map step, resolved here so that
                            // `--nearest` can change it.
                            let resolved =
                                MapStep::default().resolve(&sa.data.spectrum, &sb.data.spectrum)?;
                            let choice = resolved.preset.expect("the default map step runs");
                            if choice.preset != MapPreset::NearIsometric {
                                println!(
                                    "  {} x {}: general preset (discrepancy {:.4})",
                                    sa.name, sb.name, choice.discrepancy
                                );
                            }
                            whole_stage(resolved.options.expect("the default map step runs"))?
                        }
                        Post::RefineOracleMap(weight) => {
                            let refined = refined()?;
                            // Within a class the identity is the ground truth.
                            let truth: Vec<u32> = (0..sb.areas.len() as u32).collect();
                            let map = zoomout(
                                sa.geometry(),
                                sb.geometry(),
                                &truth,
                                &ZoomOutOptions::default(),
                            )?;
                            point_map_refinement(
                                &w,
                                &refined,
                                &map,
                                &sa.areas,
                                &sb.areas,
                                Some(&sb.map_smoother),
                                *weight,
                            )?
                        }
                    };
                    times[k] += t.elapsed().as_secs_f64();
                    let st = correspondence_stats(&r, &VertexMap::Identity)?;
                    results[k][ci].push(st.ratio);
                    stable_only[k].push(st.ratio_without_leftover);
                    coverage[k].push(st.coverage);
                    line += &format!(" {:>6.2}", 100.0 * st.ratio);
                }
                println!("{line}");
            }
        }
    }
    println!(
        "\nmean correspondence ratio (%) per class, identity ground truth; then the ratio over"
    );
    println!("non-leftover regions only and their coverage (% of vertices):");
    print!("{:<26}", "config");
    for c in &classes {
        print!(" {c:>7}");
    }
    println!(
        " {:>7} {:>8} {:>14} {:>9}",
        "mean", "time s", "w/o leftover", "coverage"
    );
    for (k, (name, _, _)) in configs.iter().enumerate() {
        print!("{name:<26}");
        let mut all = Vec::new();
        for r in &results[k] {
            print!(
                " {:>7.2}",
                100.0 * r.iter().sum::<f64>() / r.len().max(1) as f64
            );
            all.extend(r);
        }
        let mean = |v: &[f64]| 100.0 * v.iter().sum::<f64>() / v.len().max(1) as f64;
        println!(
            " {:>7.2} {:>8.2} {:>14.2} {:>9.2}",
            mean(&all),
            times[k],
            mean(&stable_only[k]),
            mean(&coverage[k])
        );
    }
    Ok(())
}
