//! `polar-vision`: command-line front end of the polarization vision pipeline.
//!
//! A thin binary over the library crates: one module per subcommand, each of which
//! validates its arguments before any work and returns a typed [`error::CliError`].

mod error;
mod stokes;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Stokes(args) => stokes::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
