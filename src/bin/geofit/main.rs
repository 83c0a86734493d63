//! The `geofit` command line: how batch users and benchmarks drive the core.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod info;

#[derive(Parser)]
#[command(
    name = "geofit",
    version,
    about = "Fit smooth surfaces and curves to 3D scans"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Describe a point or mesh file.
    Info(info::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Info(args) => info::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("geofit: {}", message.replace('\n', " "));
            ExitCode::FAILURE
        }
    }
}
