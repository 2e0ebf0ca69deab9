//! `polar-vision stokes`: raw mosaic -> Stokes, DoLP, AoLP and pictures.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use polar_image::{Gray, quantile};
use polar_io::files::vision;
use polar_io::{
    ExrCompression, LINEAR_STOKES_CHANNELS, RGB_CHANNELS, RGB_LINEAR_STOKES_CHANNELS, Y_CHANNEL,
};
use polar_sensor::picture::{aolp_hsv_into, colormap_index_into, srgb_into, viridis_palette};
use polar_sensor::{ColorStokesPlanes, StokesPlanes};

use crate::error::CliError;
use crate::input::{InputArgs, InputFile, read_input, resolve};
use crate::out_dir;
use crate::timings::Timings;
use crate::writes::Writes;

/// Arguments of `polar-vision stokes`.
#[derive(Debug, Args)]
#[command(
    after_help = "Writes to --out: stokes.exr (channels S0, S1, S2, in DN), dolp.exr and aolp.exr \
(channel Y; NaN where S0 = 0), aolp.png (hue = AoLP, value = DoLP), dolp.png (DoLP 0..1 on a viridis map), \
s0.png (S0 from 0 to its 99.5th percentile on a viridis map) and mask.png (0 valid, 1 saturated, \
2 zero intensity; see polar_sensor::mask).\n\n\
With --pattern rgb: stokes.exr has the channels S0.R, S0.G, S0.B, S1.R, ... S2.B (per colour, \
as Mitsuba 3 names them); dolp.exr and aolp.exr have Y (of the Rec. 709 luminance \
Y = 0.2126 R + 0.7152 G + 0.0722 B of the colours' Stokes vectors) and R, G, B (per colour); \
s0.png shows S0 in colour (sRGB, from 0 to the 99.5th percentile of the brightest channel); \
aolp.png, dolp.png and mask.png are of the luminance."
)]
pub struct StokesArgs {
    /// A raw mosaic PNG (8- or 16-bit grayscale, IMX250MZR layout, or IMX250MYR with
    /// --pattern rgb), a Stokes EXR (S0, S1, S2, or a colour one's S0.R ... S2.B), or a
    /// sample directory holding raw.png (or, without raw.png, stokes.exr).
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
    /// Also print the wall time of each stage: reading, exposure checks, demosaicing with
    /// the Stokes products (one fused pass), the validity mask, each output file (encoded
    /// in parallel, so their times overlap) and moving the folder into place.
    #[arg(long)]
    pub timings: bool,
}

/// Runs the subcommand.
pub fn run(args: &StokesArgs) -> Result<(), CliError> {
    let file = resolve(&args.input, None)?;
    out_dir::check(&args.input, &args.out)?;
    let start = Instant::now();
    let mut reading = read_input(&file, &args.read)?;
    let obs = &reading.obs;
    reading
        .warnings
        .iter()
        .for_each(|w| eprintln!("warning: {w}"));
    let mask = matches!(file, InputFile::Raw(_)).then_some(&obs.flags);
    let computed = start.elapsed();
    let mut timings = std::mem::take(&mut reading.timings);
    let staged = timings.time("staging folder", || out_dir::stage(&args.out))?;
    let planes = Planes {
        planes: &obs.planes,
        colors: reading.colors.as_ref(),
    };
    timings.extend(write_outputs(staged.path(), planes, mask, &args.outputs)?);
    timings.time("commit", || out_dir::commit(staged))?;
    let (w, h) = obs.size();
    // A Stokes EXR is read as it is: --demosaic does not apply to it.
    let colour = if reading.colors.is_some() {
        ", rgb"
    } else {
        ""
    };
    let source = match &file {
        InputFile::Raw(_) => format!("demosaic {}{colour}", args.read.demosaic),
        InputFile::Stokes(_) => "Stokes EXR, not demosaiced".into(),
    };
    eprintln!(
        "{w}x{h} ({source}) in {:.1} ms, outputs in {:.1} ms -> {}",
        computed.as_secs_f64() * 1e3,
        (start.elapsed() - computed).as_secs_f64() * 1e3,
        args.out.display()
    );
    if args.timings {
        eprintln!("timings: {timings}");
    }
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

/// What the outputs show: the Stokes planes (of the luminance for a colour mosaic) and,
/// for a colour mosaic, each colour's planes.
#[derive(Clone, Copy, Debug)]
pub struct Planes<'a> {
    /// S0..S2, DoLP and AoLP of the observation.
    pub planes: &'a StokesPlanes,
    /// Per-colour planes of a colour mosaic.
    pub colors: Option<&'a ColorStokesPlanes>,
}

/// Writes the selected output files into `out`, encoding them in parallel; returns each
/// file's encoding time. EXR files are
/// uncompressed: the low mantissa bits of a camera's float Stokes planes are noise, which
/// neither RLE nor ZIP shrinks (RLE's output is as large, ZIP costs several times the
/// whole computation).
pub fn write_outputs(
    out: &Path,
    what: Planes<'_>,
    mask: Option<&Gray<u8>>,
    outputs: &[Output],
) -> Result<Timings, CliError> {
    let want = |o: Output| outputs.contains(&o);
    let planes = what.planes;
    let raw = ExrCompression::None;
    let mut jobs = Writes::default();
    if want(Output::Stokes) {
        jobs.push(vision::STOKES, move || {
            let path = out.join(vision::STOKES);
            match what.colors {
                Some(c) => {
                    let s: Vec<&Gray<f32>> = (0..3)
                        .flat_map(|k| c.colors.iter().map(move |p| [&p.s0, &p.s1, &p.s2][k]))
                        .collect();
                    polar_io::write_exr_planes(path, &s, &RGB_LINEAR_STOKES_CHANNELS, raw)
                }
                None => {
                    let s = [&planes.s0, &planes.s1, &planes.s2];
                    polar_io::write_exr_planes3(path, s, LINEAR_STOKES_CHANNELS, raw)
                }
            }
        });
    }
    type Pick = fn(&StokesPlanes) -> &Gray<f32>;
    let derived: [(Output, &'static str, Pick); 2] = [
        (Output::Dolp, vision::DOLP, |p| &p.dolp),
        (Output::Aolp, vision::AOLP, |p| &p.aolp),
    ];
    for (_, name, pick) in derived.into_iter().filter(|d| want(d.0)) {
        jobs.push(name, move || {
            let path = out.join(name);
            match what.colors {
                Some(c) => {
                    let mut p = vec![pick(planes)];
                    p.extend(c.colors.iter().map(pick));
                    let names = [
                        Y_CHANNEL[0],
                        RGB_CHANNELS[0],
                        RGB_CHANNELS[1],
                        RGB_CHANNELS[2],
                    ];
                    polar_io::write_exr_planes(path, &p, &names, raw)
                }
                None => polar_io::write_exr_plane(path, pick(planes), Y_CHANNEL[0], raw),
            }
        });
    }
    if want(Output::Pictures) {
        push_pictures(&mut jobs, out, what);
    }
    if let Some(mask) = mask.filter(|_| want(Output::Mask)) {
        jobs.push(vision::MASK, move || {
            polar_io::write_gray8_png(out.join(vision::MASK), mask)
        });
    }
    Ok(jobs.run()?)
}

/// The jobs of aolp.png, dolp.png (of `what.planes`) and s0.png (in colour for a colour mosaic).
fn push_pictures<'a>(jobs: &mut Writes<'a>, out: &'a Path, what: Planes<'a>) {
    let planes = what.planes;
    let size = planes.s0.size();
    jobs.push(vision::AOLP_PICTURE, move || {
        polar_io::write_rgb8_png_rows(out.join(vision::AOLP_PICTURE), size, |y, bytes| {
            let (px, k) = pixel_rows(size.0, y, bytes);
            aolp_hsv_into(
                &planes.aolp.as_slice()[k.clone()],
                &planes.dolp.as_slice()[k],
                px,
            );
        })
    });
    jobs.push(vision::DOLP_PICTURE, move || {
        viridis_png(
            &out.join(vision::DOLP_PICTURE),
            planes.dolp.as_slice(),
            size,
            1.0,
        )
    });
    jobs.push(vision::S0_PICTURE, move || {
        let path = out.join(vision::S0_PICTURE);
        match what.colors {
            Some(c) => {
                let s0 = c.colors.each_ref().map(|p| p.s0.as_slice());
                let brightest = (0..s0[0].len()).map(|k| s0[0][k].max(s0[1][k]).max(s0[2][k]));
                let s0_max = quantile(brightest, 0.995).unwrap_or(1.0);
                polar_io::write_rgb8_png_rows(path, size, |y, bytes| {
                    let (px, k) = pixel_rows(size.0, y, bytes);
                    srgb_into(s0.map(|p| &p[k.clone()]), s0_max, px);
                })
            }
            None => {
                let s0 = planes.s0.as_slice();
                let s0_max = quantile(s0.iter().copied(), 0.995).unwrap_or(1.0);
                viridis_png(&path, s0, size, s0_max)
            }
        }
    });
}

/// Writes `plane` (of `size`) from 0 to `top` on the viridis map, as a palette PNG.
fn viridis_png(path: &Path, plane: &[f32], size: (usize, usize), top: f32) -> polar_io::Result<()> {
    polar_io::write_indexed8_png_rows(path, size, viridis_palette(), |y, rows| {
        let first = y * size.0;
        colormap_index_into(&plane[first..first + rows.len()], 0.0, top, rows);
    })
}

/// A block of RGB rows from row `y` on, as pixels, and the plane indices they show.
fn pixel_rows(width: usize, y: usize, bytes: &mut [u8]) -> (&mut [[u8; 3]], Range<usize>) {
    let pixels = bytes.as_chunks_mut::<3>().0;
    let first = y * width;
    let len = pixels.len();
    (pixels, first..first + len)
}
