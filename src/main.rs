//! The `coseg` command line: parses arguments, calls the library, reports.

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {}", cli::error_message(&err));
            ExitCode::from(cli::EXIT_FAILURE)
        }
    }
}
