//! `polar-vision stokes`: raw mosaic -> Stokes, DoLP, AoLP and pictures.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use polar_image::{Gray, quantile};
use polar_io::files::vision;
use polar_io::{ExrCompression, LINEAR_STOKES_CHANNELS, Y_CHANNEL};
use polar_sensor::StokesPlanes;
use polar_sensor::picture::{aolp_hsv_into, colormap_into};
use rayon::prelude::*;

use crate::error::CliError;
use crate::input::{InputArgs, InputFile, read_observation, resolve};
use crate::out_dir;

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
    /// Output directory: new, empty, or an earlier output of polar-vision, which is
    /// replaced as a whole once every file is written.
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

/// Runs the subcommand.
pub fn run(args: &StokesArgs) -> Result<(), CliError> {
    let file = resolve(&args.input, None)?;
    out_dir::check(&args.input, &args.out)?;
    let start = Instant::now();
    let (obs, warnings) = read_observation(&file, &args.read)?;
    warnings.iter().for_each(|w| eprintln!("warning: {w}"));
    let mask = matches!(file, InputFile::Raw(_)).then_some(&obs.flags);
    let computed = start.elapsed();
    let staged = out_dir::stage(&args.out)?;
    write_outputs(staged.path(), &obs.planes, mask, &args.outputs)?;
    out_dir::commit(staged)?;
    let (w, h) = obs.size();
    // A Stokes EXR is read as it is: --demosaic does not apply to it.
    let source = match &file {
        InputFile::Raw(_) => format!("demosaic {}", args.read.demosaic),
        InputFile::Stokes(_) => "Stokes EXR, not demosaiced".into(),
    };
    eprintln!(
        "{w}x{h} ({source}) in {:.1} ms, outputs in {:.1} ms -> {}",
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
            polar_io::write_exr_plane(out.join(vision::DOLP), &planes.dolp, Y_CHANNEL[0], rle)
        }));
    }
    if want(Output::Aolp) {
        jobs.push(Box::new(move || {
            polar_io::write_exr_plane(out.join(vision::AOLP), &planes.aolp, Y_CHANNEL[0], rle)
        }));
    }
    if want(Output::Pictures) {
        let size = planes.s0.size();
        jobs.push(Box::new(move || {
            polar_io::write_rgb8_png_rows(out.join(vision::AOLP_PICTURE), size, |y, bytes| {
                let (px, k) = pixel_rows(size.0, y, bytes);
                aolp_hsv_into(
                    &planes.aolp.as_slice()[k.clone()],
                    &planes.dolp.as_slice()[k],
                    px,
                );
            })
        }));
        jobs.push(Box::new(move || {
            polar_io::write_rgb8_png_rows(out.join(vision::DOLP_PICTURE), size, |y, bytes| {
                let (px, k) = pixel_rows(size.0, y, bytes);
                colormap_into(&planes.dolp.as_slice()[k], 0.0, 1.0, px);
            })
        }));
        jobs.push(Box::new(move || {
            let s0 = planes.s0.as_slice();
            let s0_max = quantile(s0.iter().copied(), 0.995).unwrap_or(1.0);
            polar_io::write_rgb8_png_rows(out.join(vision::S0_PICTURE), size, |y, bytes| {
                let (px, k) = pixel_rows(size.0, y, bytes);
                colormap_into(&s0[k], 0.0, s0_max, px);
            })
        }));
    }
    if let Some(mask) = mask.filter(|_| want(Output::Mask)) {
        jobs.push(Box::new(move || {
            polar_io::write_gray8_png(out.join(vision::MASK), mask)
        }));
    }
    jobs.into_par_iter()
        .map(|job| job())
        .collect::<Result<(), _>>()?;
    Ok(())
}

/// A block of RGB rows from row `y` on, as pixels, and the plane indices they show.
fn pixel_rows(width: usize, y: usize, bytes: &mut [u8]) -> (&mut [[u8; 3]], Range<usize>) {
    let pixels = bytes.as_chunks_mut::<3>().0;
    let first = y * width;
    let len = pixels.len();
    (pixels, first..first + len)
}
