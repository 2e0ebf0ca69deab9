//! The command line: argument parsing and dispatch, in the library so that end-to-end tests
//! drive exactly what the binary does.

use std::ffi::OsString;

use clap::{Parser, Subcommand};

use crate::error::CliError;
use crate::{eval, run, stokes, train};

/// Polarization vision tools for division-of-focal-plane cameras (Sony IMX250MZR layout:
/// super-pixel row 0 = [90°, 45°], row 1 = [135°, 0°]).
#[derive(Debug, Parser)]
#[command(name = "polar-vision", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
    /// The most pixels an input image may have; larger ones are refused from their header,
    /// before any memory is allocated (a small corrupt file can claim a huge image).
    /// The default, 100 megapixels, is 20 times a 5-MP polarization sensor.
    #[arg(long, global = true, value_name = "N", default_value_t = polar_io::MAX_PIXELS,
          value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..))]
    max_pixels: usize,
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
    /// Trains a task's learned model on a labelled dataset (`train material|transparent
    /// DATASET --out MODEL`), for `run --material-model MODEL` or `--transparent-model MODEL`.
    Train(train::TrainArgs),
}

/// Runs the command line `args` (program name first); `Ok(false)` when a task or sample
/// failed but the command itself completed.
pub fn run_cli<I, T>(args: I) -> Result<bool, CliError>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = Cli::try_parse_from(args).map_err(|e| CliError::Usage(e.to_string()))?;
    dispatch(cli)
}

/// Runs a parsed command line.
pub fn dispatch(cli: Cli) -> Result<bool, CliError> {
    polar_io::set_max_pixels(cli.max_pixels);
    match cli.command {
        Command::Stokes(args) => stokes::run(&args).map(|()| true),
        Command::Run(args) => run::run(&args),
        Command::Eval(args) => eval::eval(&args),
        Command::EvalMerge(args) => eval::merge(&args),
        Command::Train(args) => train::train(&args),
    }
}
