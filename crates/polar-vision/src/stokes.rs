//! `polar-vision stokes`: raw mosaic -> Stokes, DoLP, AoLP and pictures.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use polar_image::Gray;
use polar_io::files::vision;
use polar_io::{LINEAR_STOKES_CHANNELS, Y_CHANNEL};
use polar_sensor::StokesPlanes;
use polar_sensor::picture::{aolp_hsv, colormap, quantile};

use crate::error::CliError;
use crate::input::{InputArgs, InputFile, read_observation, resolve};

/// Arguments of `polar-vision stokes`.
#[derive(Debug, Args)]
#[command(
    after_help = "Writes to --out: stokes.exr (channels S0, S1, S2, in DN), dolp.exr and aolp.exr \
(channel Y; NaN where S0 = 0), aolp.png (hue = AoLP, value = DoLP), dolp.png (DoLP 0..1 on a viridis map), \
s0.png (S0 from 0 to its 99.5th percentile on a viridis map) and mask.png (0 valid, 1 saturated, \
2 zero intensity; see polar_sensor::mask)."
)]
pub struct StokesArgs {
    /// A raw mosaic PNG (8- or 16-bit grayscale, IMX250MZR layout), or a sample directory
    /// holding raw.png (or, without raw.png, stokes.exr).
    pub input: PathBuf,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// How to read the input.
    #[command(flatten)]
    pub read: InputArgs,
}

/// Creates the output directory (or checks it is one).
pub fn prepare_out(out: &Path) -> Result<(), CliError> {
    if out.exists() && !out.is_dir() {
        return Err(CliError::OutDir {
            path: out.to_owned(),
            reason: "exists and is not a directory".into(),
        });
    }
    std::fs::create_dir_all(out).map_err(|e| CliError::OutDir {
        path: out.to_owned(),
        reason: e.to_string(),
    })
}

/// Runs the subcommand.
pub fn run(args: &StokesArgs) -> Result<(), CliError> {
    let file = resolve(&args.input, None)?;
    prepare_out(&args.out)?;
    let start = Instant::now();
    let obs = read_observation(&file, &args.read)?;
    let mask = matches!(file, InputFile::Raw(_)).then_some(&obs.flags);
    let computed = start.elapsed();
    write_outputs(&args.out, &obs.planes, mask)?;
    let (w, h) = obs.size();
    eprintln!(
        "{w}x{h} ({}) in {:.1} ms, outputs in {:.1} ms -> {}",
        args.read.demosaic,
        computed.as_secs_f64() * 1e3,
        (start.elapsed() - computed).as_secs_f64() * 1e3,
        args.out.display()
    );
    Ok(())
}

/// Writes every output file of the subcommand into `out`.
pub fn write_outputs(
    out: &Path,
    planes: &StokesPlanes,
    mask: Option<&Gray<u8>>,
) -> Result<(), CliError> {
    polar_io::write_exr(
        out.join(vision::STOKES),
        &planes.linear_stokes(),
        LINEAR_STOKES_CHANNELS,
    )?;
    polar_io::write_exr(out.join(vision::DOLP), &planes.dolp, Y_CHANNEL)?;
    polar_io::write_exr(out.join(vision::AOLP), &planes.aolp, Y_CHANNEL)?;
    polar_io::write_rgb8_png(out.join("aolp.png"), &aolp_hsv(&planes.aolp, &planes.dolp))?;
    polar_io::write_rgb8_png(out.join("dolp.png"), &colormap(&planes.dolp, 0.0, 1.0))?;
    let s0_max = quantile(&planes.s0, 0.995).unwrap_or(1.0);
    polar_io::write_rgb8_png(out.join("s0.png"), &colormap(&planes.s0, 0.0, s0_max))?;
    if let Some(mask) = mask {
        polar_io::write_gray8_png(out.join("mask.png"), mask)?;
    }
    Ok(())
}
