//! `polar-vision`: a thin shell over [`polar_vision::cli`]. Exit code 0 on success, 2 when
//! the command completed but a task or sample failed, 1 on an error.

use std::process::ExitCode;

use clap::Parser;
use polar_vision::cli::{Cli, dispatch};

/// The allocator of the binaries (see the workspace Cargo.toml).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    match dispatch(Cli::parse()) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(2),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
