use anyhow::{Result, bail};
use clap::Args;
use coseg::generate::{Family, GenerateOptions, generate_family, write_collection};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct GenerateArgs {
    /// Family: quadrupeds, humanoids, goblets, chairs, or `all` (one sub-directory each).
    family: String,
    /// Output directory (for `all`: the parent of the family directories).
    #[arg(short, long)]
    output: PathBuf,
    /// Seed of the parameter stream (the shipped collections use the default).
    #[arg(long, default_value_t = GenerateOptions::default().seed)]
    seed: u64,
    /// Number of shapes per family.
    #[arg(long, default_value_t = GenerateOptions::default().count)]
    count: usize,
}

pub fn run(args: GenerateArgs) -> Result<ExitCode> {
    let options = {
        let mut opts = GenerateOptions::default();
        opts.seed = args.seed;
        opts.count = args.count;
        opts
    };
    let targets: Vec<(Family, PathBuf)> = if args.family == "all" {
        Family::ALL
            .into_iter()
            .map(|f| (f, args.output.join(f.name())))
            .collect()
    } else if let Some(f) = Family::from_name(&args.family) {
        vec![(f, args.output.clone())]
    } else {
        let names: Vec<&str> = Family::ALL.iter().map(|f| f.name()).collect();
        bail!(
            "unknown family {:?} (expected one of {}, or all)",
            args.family,
            names.join(", ")
        );
    };
    for (family, dir) in targets {
        let collection = generate_family(family, &options)?;
        write_collection(&collection, &options, &dir)?;
        let vs: Vec<usize> = collection
            .shapes
            .iter()
            .map(|s| s.mesh.vertex_count())
            .collect();
        println!(
            "{family}: {} shapes ({}–{} vertices) in {}",
            vs.len(),
            vs.iter().min().unwrap_or(&0),
            vs.iter().max().unwrap_or(&0),
            dir.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
