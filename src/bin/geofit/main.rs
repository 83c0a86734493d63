//! The `geofit` command line: how batch users and benchmarks drive the core.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// `println!` that survives a closed pipe (see [`output::write_line`]).
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::output::write_line(format_args!($($arg)*))
    };
}

mod export_samples;
mod fit;
mod info;
mod output;
mod reconstruct;
mod simplify;
mod subdiv;

#[derive(Parser)]
#[command(
    name = "geofit",
    version,
    about = "Fit smooth surfaces and curves to 3D scans"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Threads for the parallel parts of a fit (foot points, surface → data distances);
    /// default: every core, or GEOFIT_THREADS. Results are the same on any number.
    #[arg(long, global = true, value_parser = clap::value_parser!(u16).range(1..))]
    threads: Option<u16>,
}

// Parsed once per process: the size of the `fit` variant (it carries the B-spline options too)
// costs nothing worth boxing for.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
enum Command {
    /// Describe a point or mesh file.
    Info(info::Args),
    /// Write reference curves and surfaces as IGES and STEP with sampled points (for
    /// interoperability tests).
    ExportSamples(export_samples::Args),
    /// Simplify a mesh by quadric error metrics to a target vertex count (the initial control
    /// mesh of a fit), timed, with its distance to the input.
    Simplify(simplify::Args),
    /// Build a manifold mesh from bare points (range grid, Delaunay or implicit surface),
    /// timed, with the points' distance to it.
    Reconstruct(reconstruct::Args),
    /// Refine a control mesh with a subdivision scheme (optionally to limit positions).
    Subdiv(subdiv::Args),
    /// Fit a subdivision surface, a B-spline surface or a B-spline / Chaikin curve to a scan
    /// (geometric iteration, least squares or knot placement), and export it.
    Fit(fit::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Some(n) = cli.threads {
        geofit::fit::set_max_threads(usize::from(n));
    }
    let result = match cli.command {
        Command::Info(args) => info::run(args),
        Command::ExportSamples(args) => export_samples::run(args),
        Command::Simplify(args) => simplify::run(args),
        Command::Reconstruct(args) => reconstruct::run(args),
        Command::Subdiv(args) => subdiv::run(args),
        Command::Fit(args) => fit::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("geofit: {}", message.replace('\n', " "));
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// clap's own definition checks (`debug_assert`) run only with debug assertions, and the
    /// tests run in release; so check here what flattening the scheme options can break: no
    /// subcommand has two arguments with the same id, long flag or short flag.
    #[test]
    fn no_subcommand_repeats_a_flag() {
        use clap::CommandFactory;
        use std::collections::HashSet;
        let cli = Cli::command();
        cli.clone().debug_assert();
        for sub in cli.get_subcommands() {
            let (mut ids, mut longs, mut shorts) = (HashSet::new(), HashSet::new(), HashSet::new());
            for arg in sub.get_arguments() {
                let name = sub.get_name();
                assert!(
                    ids.insert(arg.get_id().clone()),
                    "{name}: id {} twice",
                    arg.get_id()
                );
                if let Some(long) = arg.get_long() {
                    assert!(longs.insert(long), "{name}: --{long} twice");
                }
                if let Some(short) = arg.get_short() {
                    assert!(shorts.insert(short), "{name}: -{short} twice");
                }
            }
        }
    }
}
