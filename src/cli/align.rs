//! `coseg align FOLDER -o OUT`: every mesh of a folder in one collection frame.

use anyhow::Result;
use clap::Args;
use coseg::align::{AlignOptions, FrameCase};
use coseg::jobs::{AlignJob, run_align};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Args)]
pub struct AlignArgs {
    /// Folder of meshes (.obj, .off, .ply).
    folder: PathBuf,
    /// Output folder (must differ from FOLDER): transforms.json, and the aligned meshes with
    /// --write-meshes.
    #[arg(short, long)]
    output: PathBuf,
    /// Also write every mesh in the collection frame, under its own file name.
    #[arg(long)]
    write_meshes: bool,
    /// Registration-graph neighbours per shape.
    #[arg(long, default_value_t = AlignOptions::default().neighbours)]
    neighbours: usize,
}

/// The job `coseg align` runs with these flags (the flags translated, nothing else).
fn align_job(args: &AlignArgs) -> AlignJob {
    let mut job = AlignJob::default();
    job.write_meshes = args.write_meshes;
    job.align.neighbours = args.neighbours;
    job.output = Some(args.output.clone());
    job
}

pub fn run(args: AlignArgs) -> Result<ExitCode> {
    let r = run_align(&args.folder, &align_job(&args))?;
    let a = &r.alignment;
    let case = match a.case {
        FrameCase::AlreadyAligned => "already aligned: the given frames agree, kept unchanged",
        FrameCase::Synchronised => "aligned by registration and synchronisation",
        FrameCase::Single => "one shape: its own frame",
    };
    if !super::quiet() {
        println!(
            "{} shapes, {} registrations: {case} ({:.0} % of the registrations keep the given frame)",
            r.files.len(),
            a.edges.len(),
            100.0 * a.given_frame_share
        );
        println!("up {:?}, forward {:?}", a.up, a.forward);
        for (f, s) in r.files.iter().zip(&a.shapes) {
            let name = f.file_name().unwrap_or_default().to_string_lossy();
            let amb = match (s.ambiguity, s.ambiguity_angle) {
                (Some(x), Some(g)) if x > 0.9 => format!(
                    ", ambiguous: a pose {g:.0}° away fits {:.0} % as well",
                    100.0 * x
                ),
                _ => String::new(),
            };
            println!("  {name}: confidence {:.2}{amb}", s.confidence);
        }
        for w in &r.written {
            println!("wrote {}", w.display());
        }
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bare command runs the job's default: the CLI chooses no default of its own.
    #[test]
    fn the_bare_command_runs_the_default_job() {
        let args: AlignArgs = super::super::parse_args(&["coseg", "shapes", "-o", "out"]);
        let mut want = AlignJob::default();
        want.output = Some(PathBuf::from("out"));
        assert_eq!(align_job(&args), want);
    }
}
