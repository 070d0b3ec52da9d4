//! The `gradmesh` command: inspect, convert, refine and render gradient meshes.
//!
//! Flags are parsed in `args`; each subcommand in `commands` turns them into library calls.

mod allocator;
mod args;
mod commands;
mod output;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    allocator::tune();
    let cli = args::Cli::parse();
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(commands::Failure::Error(e)) => {
            eprintln!("gradmesh: error: {e}");
            ExitCode::FAILURE
        }
        Err(commands::Failure::Reported) => ExitCode::FAILURE,
    }
}
