//! `polar-vision stokes`: raw mosaic -> Stokes, DoLP, AoLP and pictures.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use polar_image::Gray;
use polar_io::{GrayPng, LINEAR_STOKES_CHANNELS, Y_CHANNEL};
use polar_sensor::mask::{count_saturated, validity_mask};
use polar_sensor::picture::{aolp_hsv, colormap, quantile};
use polar_sensor::{DemosaicMethod, StokesPlanes, stokes_planes};

use crate::error::CliError;

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
    /// Demosaicing method (error table and speed: README "Demosaicing error"):
    ///   residual    the default: edge-aware residual interpolation (Ahmed et al. 2017,
    ///               Morimatsu et al. 2020); lowest error on edges and fine texture; 2-4x
    ///               bilinear's demosaicing time (bilinear's fused SIMD path is faster still)
    ///   bilinear    polanalyser's COLOR_PolarMono, bit-exact; the fastest full-resolution
    ///               method: to match polanalyser/OpenCV, or when speed matters most
    ///   newton      Newton polynomial (Li et al. 2019): for comparison; beats bilinear on
    ///               fine texture, loses at polarization edges; the slowest
    ///   superpixel  half resolution, no interpolation: quick looks
    #[arg(verbatim_doc_comment)]
    #[arg(long, value_name = "NAME", default_value = "residual", value_parser = parse_method)]
    pub demosaic: DemosaicMethod,
    /// Significant bits of the sensor data (8, 10, 12 or 16). Default: the PNG's
    /// sample depth. Use 10 or 12 for such sensors stored in 16-bit PNGs, with --align.
    #[arg(long, value_name = "BITS", value_parser = clap::builder::PossibleValuesParser::new(["8", "10", "12", "16"]))]
    pub bit_depth: Option<String>,
    /// Where fewer-bit data sit in a 16-bit PNG: `right` (values 0..2^bits-1) or `left`
    /// (shifted up, low bits zero). Outputs are in DN of the --bit-depth data either way.
    #[arg(long, value_enum, default_value_t = Align::Right)]
    pub align: Align,
}

/// Alignment of fewer-bit data in wider PNG samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Align {
    /// Most significant bits used; the low bits are zero.
    Left,
    /// Least significant bits used; values are at most `2^bits − 1`.
    Right,
}

fn parse_method(s: &str) -> Result<DemosaicMethod, String> {
    s.parse()
        .map_err(|e: polar_sensor::SensorError| e.to_string())
}

/// What the input path holds.
enum Input {
    /// A raw mosaic PNG.
    Raw(PathBuf),
    /// A Stokes EXR (sample directory without raw.png).
    Stokes(PathBuf),
}

/// Resolves the input path before any work.
fn resolve_input(path: &Path) -> Result<Input, CliError> {
    if path.is_dir() {
        let (raw, stokes) = (path.join("raw.png"), path.join("stokes.exr"));
        return if raw.is_file() {
            Ok(Input::Raw(raw))
        } else if stokes.is_file() {
            Ok(Input::Stokes(stokes))
        } else {
            Err(CliError::Input(path.to_owned()))
        };
    }
    if !path.exists() {
        return Err(polar_io::Error::NotFound {
            path: path.to_owned(),
        }
        .into());
    }
    Ok(Input::Raw(path.to_owned()))
}

/// Creates the output directory (or checks it is one).
fn prepare_out(out: &Path) -> Result<(), CliError> {
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
    let bits: Option<u8> = args
        .bit_depth
        .as_deref()
        .map(|b| b.parse().expect("clap restricts the values"));
    let input = resolve_input(&args.input)?;
    prepare_out(&args.out)?;
    let start = Instant::now();
    let (planes, mask) = match input {
        Input::Raw(path) => {
            let png = polar_io::read_mosaic(&path)?;
            let (raw, bits) = significant_bits(&path, png, bits, args.align)?;
            let level = (1u32 << bits) - 1;
            check_exposure(&path, &raw, bits, level)?;
            let planes = stokes_planes(&raw, args.demosaic)?;
            let mask = validity_mask(&raw, level, args.demosaic, &planes.s0);
            (planes, Some(mask))
        }
        Input::Stokes(path) => {
            let stokes = polar_io::read_exr(&path, LINEAR_STOKES_CHANNELS)?;
            (StokesPlanes::from_linear_stokes(&stokes), None)
        }
    };
    let computed = start.elapsed();
    write_outputs(&args.out, &planes, mask.as_ref())?;
    let (w, h) = planes.size();
    eprintln!(
        "{w}x{h} ({}) in {:.1} ms, outputs in {:.1} ms -> {}",
        args.demosaic,
        computed.as_secs_f64() * 1e3,
        (start.elapsed() - computed).as_secs_f64() * 1e3,
        args.out.display()
    );
    Ok(())
}

/// Applies `--bit-depth`/`--align`: returns the samples as right-aligned DN and their bit count.
fn significant_bits(
    path: &Path,
    png: GrayPng,
    bits: Option<u8>,
    align: Align,
) -> Result<(Gray<u16>, u8), CliError> {
    let container = png.bit_depth.bits();
    let bits = bits.unwrap_or(container);
    if bits > container {
        return Err(CliError::BitDepthTooLarge {
            path: path.to_owned(),
            bits,
            container,
        });
    }
    let mut raw = png.image;
    if bits == container {
        return Ok((raw, bits));
    }
    let shift = container - bits;
    let (bad, hint): (Box<dyn Fn(u16) -> bool>, _) = match align {
        Align::Left => (
            Box::new(move |v| v & ((1 << shift) - 1) != 0),
            " (low bits are set; try --align right)",
        ),
        Align::Right => (
            Box::new(move |v| v >> bits != 0),
            " (value too large; try --align left)",
        ),
    };
    let w = raw.width();
    if let Some(k) = raw.as_slice().iter().position(|&v| bad(v)) {
        let align = if align == Align::Left {
            "left"
        } else {
            "right"
        };
        let value = raw.as_slice()[k];
        return Err(CliError::Alignment {
            path: path.to_owned(),
            x: k % w,
            y: k / w,
            value,
            bits,
            container,
            align,
            hint,
        });
    }
    if align == Align::Left {
        raw.as_mut_slice().iter_mut().for_each(|v| *v >>= shift);
    }
    Ok((raw, bits))
}

/// Rejects frames without usable light; warns about partly saturated ones.
fn check_exposure(path: &Path, raw: &Gray<u16>, bits: u8, level: u32) -> Result<(), CliError> {
    if raw.as_slice().iter().all(|&v| v == 0) {
        return Err(CliError::AllZero(path.to_owned()));
    }
    let saturated = count_saturated(raw, level);
    let n = raw.as_slice().len();
    if saturated == n {
        return Err(CliError::AllSaturated {
            path: path.to_owned(),
            level,
            bits,
        });
    }
    if saturated > 0 {
        eprintln!(
            "warning: {}: {saturated} of {n} pixels ({:.3}%) are saturated at {level} DN; flagged in mask.png",
            path.display(),
            100.0 * saturated as f64 / n as f64
        );
    }
    Ok(())
}

/// Writes every output file of the subcommand into `out`.
fn write_outputs(
    out: &Path,
    planes: &StokesPlanes,
    mask: Option<&Gray<u8>>,
) -> Result<(), CliError> {
    polar_io::write_exr(
        out.join("stokes.exr"),
        &planes.linear_stokes(),
        LINEAR_STOKES_CHANNELS,
    )?;
    polar_io::write_exr(out.join("dolp.exr"), &planes.dolp, Y_CHANNEL)?;
    polar_io::write_exr(out.join("aolp.exr"), &planes.aolp, Y_CHANNEL)?;
    polar_io::write_rgb8_png(out.join("aolp.png"), &aolp_hsv(&planes.aolp, &planes.dolp))?;
    polar_io::write_rgb8_png(out.join("dolp.png"), &colormap(&planes.dolp, 0.0, 1.0))?;
    let s0_max = quantile(&planes.s0, 0.995).unwrap_or(1.0);
    polar_io::write_rgb8_png(out.join("s0.png"), &colormap(&planes.s0, 0.0, s0_max))?;
    if let Some(mask) = mask {
        polar_io::write_gray8_png(out.join("mask.png"), mask)?;
    }
    Ok(())
}
