//! `polar-vision stokes`: raw mosaic -> Stokes, DoLP, AoLP and pictures.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use polar_image::Gray;
use polar_io::files::vision;
use polar_io::{ExrCompression, LINEAR_STOKES_CHANNELS, Y_CHANNEL};
use polar_sensor::StokesPlanes;
use polar_sensor::picture::{aolp_hsv, colormap, quantile};
use rayon::prelude::*;

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
    /// Which files to write, comma-separated: stokes, dolp, aolp, pictures (aolp.png,
    /// dolp.png, s0.png), mask. Default: all.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = Output::ALL)]
    pub outputs: Vec<Output>,
}

/// Refuses an output folder that would overwrite the input: the input sample directory
/// itself or a folder inside it, or the folder of an input file.
pub fn check_out_apart(input: &Path, out: &Path) -> Result<(), CliError> {
    let (base, inside_too) = if input.is_dir() {
        (input.to_owned(), true)
    } else {
        let parent = input.parent().filter(|p| !p.as_os_str().is_empty());
        (parent.unwrap_or(Path::new(".")).to_owned(), false)
    };
    let Ok(base) = base.canonicalize() else {
        return Ok(());
    };
    let out_abs = absolute_existing_prefix(out);
    let clash = if inside_too {
        out_abs.starts_with(&base)
    } else {
        out_abs == base
    };
    if clash {
        return Err(CliError::OutDir {
            path: out.to_owned(),
            reason: format!(
                "it is {} the input {}; its files would be overwritten",
                if out_abs == base {
                    "the folder of"
                } else {
                    "inside"
                },
                input.display()
            ),
        });
    }
    Ok(())
}

/// `path` made absolute through its longest existing ancestor (the rest appended as is).
fn absolute_existing_prefix(path: &Path) -> PathBuf {
    let mut rest = Vec::new();
    let mut p = path.to_owned();
    loop {
        if let Ok(c) = p.canonicalize() {
            return rest.iter().rev().fold(c, |acc, part| acc.join(part));
        }
        match (p.file_name().map(|n| n.to_owned()), p.parent()) {
            (Some(name), Some(parent)) => {
                rest.push(name);
                p = if parent.as_os_str().is_empty() {
                    PathBuf::from(".")
                } else {
                    parent.to_owned()
                };
            }
            _ => return path.to_owned(),
        }
    }
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
    check_out_apart(&args.input, &args.out)?;
    prepare_out(&args.out)?;
    let start = Instant::now();
    let (obs, warnings) = read_observation(&file, &args.read)?;
    warnings.iter().for_each(|w| eprintln!("warning: {w}"));
    let mask = matches!(file, InputFile::Raw(_)).then_some(&obs.flags);
    let computed = start.elapsed();
    write_outputs(&args.out, &obs.planes, mask, &args.outputs)?;
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

/// The output files of the front end, selectable with `--outputs`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Output {
    /// stokes.exr: S0, S1, S2.
    Stokes,
    /// dolp.exr.
    Dolp,
    /// aolp.exr.
    Aolp,
    /// aolp.png, dolp.png, s0.png.
    Pictures,
    /// mask.png (raw input only).
    Mask,
}

impl Output {
    /// Every output: the default.
    pub const ALL: [Output; 5] = [
        Output::Stokes,
        Output::Dolp,
        Output::Aolp,
        Output::Pictures,
        Output::Mask,
    ];
}

type Job<'a> = Box<dyn FnOnce() -> Result<(), polar_io::Error> + Send + 'a>;

/// Writes the selected output files into `out`, encoding them in parallel. EXR files use
/// RLE compression (lossless; float noise does not deflate much, and ZIP costs several
/// times the time of the whole computation).
pub fn write_outputs(
    out: &Path,
    planes: &StokesPlanes,
    mask: Option<&Gray<u8>>,
    outputs: &[Output],
) -> Result<(), CliError> {
    let want = |o: Output| outputs.contains(&o);
    let rle = ExrCompression::Rle;
    let mut jobs: Vec<Job<'_>> = Vec::new();
    if want(Output::Stokes) {
        jobs.push(Box::new(move || {
            let s = [&planes.s0, &planes.s1, &planes.s2];
            polar_io::write_exr_planes3(out.join(vision::STOKES), s, LINEAR_STOKES_CHANNELS, rle)
        }));
    }
    if want(Output::Dolp) {
        jobs.push(Box::new(move || {
            polar_io::write_exr_with(out.join(vision::DOLP), &planes.dolp, Y_CHANNEL, rle)
        }));
    }
    if want(Output::Aolp) {
        jobs.push(Box::new(move || {
            polar_io::write_exr_with(out.join(vision::AOLP), &planes.aolp, Y_CHANNEL, rle)
        }));
    }
    if want(Output::Pictures) {
        jobs.push(Box::new(move || {
            let hsv = aolp_hsv(&planes.aolp, &planes.dolp);
            polar_io::write_rgb8_png(out.join("aolp.png"), &hsv)
        }));
        jobs.push(Box::new(move || {
            polar_io::write_rgb8_png(out.join("dolp.png"), &colormap(&planes.dolp, 0.0, 1.0))
        }));
        jobs.push(Box::new(move || {
            let s0_max = quantile(&planes.s0, 0.995).unwrap_or(1.0);
            polar_io::write_rgb8_png(out.join("s0.png"), &colormap(&planes.s0, 0.0, s0_max))
        }));
    }
    if let Some(mask) = mask.filter(|_| want(Output::Mask)) {
        jobs.push(Box::new(move || {
            polar_io::write_gray8_png(out.join("mask.png"), mask)
        }));
    }
    jobs.into_par_iter()
        .map(|job| job())
        .collect::<Result<(), _>>()?;
    Ok(())
}
