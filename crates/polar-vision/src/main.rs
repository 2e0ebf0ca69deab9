//! `polar-vision`: command-line front end of the polarization vision pipeline; each
//! subcommand validates its arguments before any work and reports a typed error.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use polar_vision::{eval, run, stokes};

/// Polarization vision tools for division-of-focal-plane cameras (Sony IMX250MZR layout:
/// super-pixel row 0 = [90°, 45°], row 1 = [135°, 0°]).
#[derive(Debug, Parser)]
#[command(name = "polar-vision", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
enum Command {
    /// Raw mosaic (or sample directory) -> Stokes S0..S2, DoLP, AoLP and pictures.
    Stokes(stokes::StokesArgs),
    /// One sample through the analysis tasks (shape, transparency, material, dehazing),
    /// with metrics where it has ground truth.
    Run(run::RunArgs),
    /// Every sample of a dataset through `run`: metrics.json and summary.md.
    Eval(eval::EvalArgs),
    /// Joins the outputs of `eval --shard K/N` runs into one report.
    EvalMerge(eval::MergeArgs),
}

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Command::Stokes(args) => stokes::run(&args).map(|()| true),
        Command::Run(args) => run::run(&args),
        Command::Eval(args) => eval::eval(&args),
        Command::EvalMerge(args) => eval::merge(&args),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(2),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
