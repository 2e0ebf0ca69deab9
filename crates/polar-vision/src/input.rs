//! Reading one observation: a raw mosaic PNG, or a sample directory (its `raw.png` by
//! default, else its `stokes.exr`), into a [`polar_sensor::Observation`] through `polar-io`.
//!
//! Nothing here reads our dataset generator's private `meta.json` keys but two optional,
//! documented ones (docs/conventions.md): `camera.fov_deg`, the horizontal field of view
//! (`--fov` overrides it; without either the camera is taken as orthographic), and
//! `sensor.pattern`, the filter layout of `raw.png` (`--pattern` overrides it; default mono).

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use polar_image::Mosaic;
use polar_io::files;
use polar_io::{LINEAR_STOKES_CHANNELS, MosaicPng, RGB_LINEAR_STOKES_CHANNELS};
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::mask::{count_saturated, validity_mask, validity_mask_rgb};
use polar_sensor::{
    ColorStokesPlanes, DemosaicMethod, MosaicPattern, Observation, StokesPlanes, stokes_planes,
    stokes_planes_rgb,
};
use rayon::prelude::*;
use serde_json::{Map, Value};

use crate::error::CliError;
use crate::timings::Timings;

/// Options that say how to read the input (shared by `stokes`, `run` and `eval`).
#[derive(Clone, Debug, Args)]
pub struct InputArgs {
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
    /// sample depth, less the low bits that are 0 in every sample of a 16-bit PNG (data
    /// aligned left, read as --align left would). Use 10 or 12 for such sensors stored in
    /// 16-bit PNGs, with --align; 16 reads the samples as they are.
    #[arg(long, value_name = "BITS", value_parser = clap::builder::PossibleValuesParser::new(["8", "10", "12", "16"]))]
    pub bit_depth: Option<String>,
    /// Where fewer-bit data sit in a 16-bit PNG: `right` (values 0..2^bits-1) or `left`
    /// (shifted up, low bits zero). Outputs are in DN of the --bit-depth data either way.
    #[arg(long, value_enum, default_value_t = Align::Right)]
    pub align: Align,
    /// The sensor's black level (pedestal), in DN of the data (after --bit-depth and
    /// --align): subtracted from every sample, at 0 the least, before demosaicing; the
    /// saturated samples are found before. A pedestal left in adds unpolarized light and
    /// lowers every DoLP. Default 0: the camera already subtracted it.
    #[arg(long, value_name = "DN", default_value_t = 0)]
    pub black_level: u16,
    /// Filters over a raw mosaic: `mono` (IMX250MZR: polarizers only) or `rgb` (IMX250MYR:
    /// 2x2 polarizer blocks under an RGGB Bayer pattern, width and height multiples of 4;
    /// polanalyser's COLOR_PolarRGB). Default: `sensor.pattern` of the sample's meta.json
    /// where it is given, else mono. With rgb, the Stokes images are per colour and DoLP,
    /// AoLP, the pictures and the tasks use the Rec. 709 luminance of the colours' Stokes.
    #[arg(long, value_name = "NAME", value_parser = parse_pattern)]
    pub pattern: Option<MosaicPattern>,
}

/// What was read of one input: the observation the tasks take (for a colour mosaic, of
/// its luminance), the per-colour planes of a colour mosaic, and warnings for the user.
#[derive(Debug)]
pub struct Reading {
    /// Stokes planes (luminance for a colour mosaic), flags and camera.
    pub obs: Observation,
    /// Per-colour Stokes planes, for a colour mosaic only.
    pub colors: Option<ColorStokesPlanes>,
    /// E.g. saturated pixels, which are flagged.
    pub warnings: Vec<String>,
    /// Wall time of each stage of the reading (`--timings`).
    pub timings: Timings,
}

/// Alignment of fewer-bit data in wider PNG samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Align {
    /// Most significant bits used; the low bits are zero.
    Left,
    /// Least significant bits used; values are at most `2^bits − 1`.
    Right,
}

/// Which file of a sample directory to read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Source {
    /// `raw.png`, the mosaic a camera gives (demosaiced here).
    Raw,
    /// `stokes.exr`, Stokes planes computed elsewhere.
    Stokes,
}

fn parse_method(s: &str) -> Result<DemosaicMethod, String> {
    s.parse()
        .map_err(|e: polar_sensor::SensorError| e.to_string())
}

fn parse_pattern(s: &str) -> Result<MosaicPattern, String> {
    s.parse()
        .map_err(|e: polar_sensor::SensorError| e.to_string())
}

/// The key of `meta.json` that names the filter layout of `raw.png` (docs/conventions.md).
pub const META_PATTERN_KEY: &str = "sensor.pattern";

/// The filter layout of the raw mosaic `path`: `flag` (`--pattern`) if given, else
/// `sensor.pattern` of the `meta.json` beside a sample's `raw.png`, else mono. A value
/// there that is not a known pattern is an error naming the file and the key.
pub fn mosaic_pattern(path: &Path, flag: Option<MosaicPattern>) -> Result<MosaicPattern, CliError> {
    if let Some(p) = flag {
        return Ok(p);
    }
    let dir = match path.parent() {
        Some(dir) if path.file_name() == Some(files::RAW.as_ref()) => dir,
        _ => return Ok(MosaicPattern::Mono),
    };
    let Some(meta) = polar_io::read_optional_meta(dir)? else {
        return Ok(MosaicPattern::Mono);
    };
    let Some(value) = meta.get("sensor").and_then(|s| s.get("pattern")) else {
        return Ok(MosaicPattern::Mono);
    };
    value
        .as_str()
        .and_then(|v| v.parse().ok())
        .ok_or_else(|| CliError::MetaValue {
            path: dir.join(files::META),
            key: META_PATTERN_KEY,
            value: value.to_string(),
            expected: format!("one of {}", MosaicPattern::names().join(", ")),
        })
}

/// The file an input path resolves to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum InputFile {
    /// A raw mosaic PNG.
    Raw(PathBuf),
    /// A Stokes EXR.
    Stokes(PathBuf),
}

/// Resolves `path` (a raw PNG, a Stokes EXR by its `.exr` extension, or a sample
/// directory) before any work; `source` forces one file.
pub fn resolve(path: &Path, source: Option<Source>) -> Result<InputFile, CliError> {
    if !path.exists() {
        return Err(polar_io::Error::NotFound {
            path: path.to_owned(),
        }
        .into());
    }
    if !path.is_dir() {
        let exr = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        return match source {
            Some(Source::Stokes) => Ok(InputFile::Stokes(path.to_owned())),
            None if exr => Ok(InputFile::Stokes(path.to_owned())),
            _ => Ok(InputFile::Raw(path.to_owned())),
        };
    }
    let (raw, stokes) = (path.join(files::RAW), path.join(files::STOKES));
    match source {
        Some(Source::Raw) if raw.is_file() => Ok(InputFile::Raw(raw)),
        Some(Source::Stokes) if stokes.is_file() => Ok(InputFile::Stokes(stokes)),
        Some(s) => Err(CliError::MissingSource {
            dir: path.to_owned(),
            file: if s == Source::Raw {
                files::RAW
            } else {
                files::STOKES
            },
        }),
        None if raw.is_file() => Ok(InputFile::Raw(raw)),
        None if stokes.is_file() => Ok(InputFile::Stokes(stokes)),
        None => Err(CliError::Input(path.to_owned())),
    }
}

/// Reads `file` into an observation (camera orthographic; see [`camera_model`]), with
/// warnings for the user (e.g. saturated pixels, which are flagged).
pub fn read_observation(
    file: &InputFile,
    args: &InputArgs,
) -> Result<(Observation, Vec<String>), CliError> {
    read_input(file, args).map(|r| (r.obs, r.warnings))
}

/// Reads `file`: a raw mosaic in the layout of [`mosaic_pattern`], or a Stokes EXR.
pub fn read_input(file: &InputFile, args: &InputArgs) -> Result<Reading, CliError> {
    match file {
        InputFile::Raw(path) => read_raw(path, args),
        InputFile::Stokes(path) => read_stokes(path),
    }
}

/// A Stokes EXR: `S0, S1, S2`, or, without those, a colour one's `S0.R ... S2.B` (as
/// `stokes --pattern rgb` and Mitsuba 3's RGB modes write), whose observation is the
/// luminance.
fn read_stokes(path: &Path) -> Result<Reading, CliError> {
    let mut timings = Timings::default();
    let names = polar_io::exr_channel_names(path)?;
    let has = |want: &[&str]| want.iter().all(|c| names.iter().any(|n| n == c));
    let colour = !has(&LINEAR_STOKES_CHANNELS) && has(&RGB_LINEAR_STOKES_CHANNELS);
    let (planes, colors) = if colour {
        let stokes = timings.time("read stokes.exr", || {
            polar_io::read_exr(path, RGB_LINEAR_STOKES_CHANNELS)
        })?;
        let colors = timings.time("products", || {
            ColorStokesPlanes::from_rgb_linear_stokes(&stokes)
        });
        (colors.luminance(), Some(colors))
    } else {
        let stokes = timings.time("read stokes.exr", || {
            polar_io::read_exr(path, LINEAR_STOKES_CHANNELS)
        })?;
        let planes = timings.time("products", || StokesPlanes::from_linear_stokes(&stokes));
        (planes, None)
    };
    // As for a raw frame with no light: nothing can be computed anywhere.
    if !planes
        .s0
        .as_slice()
        .iter()
        .any(|&v| v > 0.0 && v.is_finite())
    {
        return Err(CliError::NoLight(path.to_owned()));
    }
    Ok(Reading {
        obs: Observation::new(planes, CameraModel::Orthographic),
        colors,
        warnings: vec![],
        timings,
    })
}

/// A raw mosaic PNG through `--bit-depth`/`--align`, the exposure checks and the
/// demosaicing of its pattern; a colour mosaic's observation is its luminance.
fn read_raw(path: &Path, args: &InputArgs) -> Result<Reading, CliError> {
    let bits = args.bit_depth.as_deref().map(|b| {
        b.parse::<u8>()
            .expect("clap restricts the values to 8, 10, 12, 16")
    });
    let pattern = mosaic_pattern(path, args.pattern)?;
    let mut timings = Timings::default();
    let png = timings.time("read raw.png", || polar_io::read_mosaic(path))?;
    let (raw, level, warnings) = timings.time("exposure checks", || {
        let (bits, align, note) = match bits {
            Some(bits) => (bits, args.align, None),
            None => alignment_as_found(path, &png),
        };
        let (raw, bits) = significant_bits(path, png, bits, align)?;
        let (w, h) = raw.size();
        pattern
            .check_size(w, h)
            .map_err(|source| CliError::Pattern {
                path: path.to_owned(),
                pattern,
                source,
            })?;
        let level = saturation_level(&raw, bits);
        let (raw, level) = without_black_level(path, raw, level, args)?;
        let warnings = note
            .into_iter()
            .chain(check_exposure(path, &raw, bits, level)?);
        Ok::<_, CliError>((raw, level, warnings.collect()))
    })?;
    let demosaic = "demosaic + products";
    let (planes, flags, colors) = match pattern {
        MosaicPattern::Mono => {
            let planes = timings.time(demosaic, || stokes_planes(&raw, args.demosaic))?;
            let flags = timings.time("validity mask", || {
                validity_mask(&raw, level, args.demosaic, &planes.s0)
            });
            (planes, flags, None)
        }
        MosaicPattern::Rgb => {
            let colors = timings.time(demosaic, || stokes_planes_rgb(&raw, args.demosaic))?;
            let planes = timings.time("luminance", || colors.luminance());
            let flags = timings.time("validity mask", || {
                validity_mask_rgb(&raw, level, args.demosaic, &planes.s0)
            })?;
            (planes, flags, Some(colors))
        }
    };
    Ok(Reading {
        obs: Observation::new(planes, CameraModel::Orthographic).with_flags(flags),
        colors,
        timings,
        warnings,
    })
}

/// The camera: `--fov` if given, else `camera.fov_deg` of `meta` (a horizontal field of
/// view in degrees, as docs/conventions.md documents it), else orthographic.
pub fn camera_model(fov: Option<f64>, meta: Option<&Map<String, Value>>) -> CameraModel {
    let from_meta = || {
        let cam = meta?.get("camera")?;
        let horizontal = cam
            .get("fov_axis")
            .and_then(Value::as_str)
            .is_none_or(|a| a == "x");
        cam.get("fov_deg")
            .and_then(Value::as_f64)
            .filter(|_| horizontal)
    };
    match fov.or_else(from_meta) {
        Some(f) if f > 0.0 && f < 180.0 => CameraModel::Pinhole { fov_x_deg: f },
        _ => CameraModel::Orthographic,
    }
}

/// The saturation level in DN of right-aligned `bits`-bit data: `2^bits − 1`, or a lower
/// level the frame itself shows. A 16-bit PNG may hold 10- or 12-bit data (a camera's
/// ADC): where the frame's maximum is `2^b − 1` for a smaller `b >= 8` and at least two
/// pixels hold it, those pixels are clipped at the ADC's top and are flagged.
pub fn saturation_level(raw: &Mosaic<u16>, bits: u8) -> u32 {
    let full = (1u32 << bits) - 1;
    let max = raw.as_slice().iter().copied().max().map_or(0, u32::from);
    let at_max = raw
        .as_slice()
        .iter()
        .filter(|&&v| u32::from(v) == max)
        .count();
    let adc_top = (8..bits).any(|b| max == (1u32 << b) - 1);
    if adc_top && at_max >= 2 { max } else { full }
}

/// `raw` less `--black-level` (at 0 the least) and its saturation `level` less the same:
/// the samples at the level stay flagged. A black level at or above the saturation level
/// leaves no signal: an error.
fn without_black_level(
    path: &Path,
    mut raw: Mosaic<u16>,
    level: u32,
    args: &InputArgs,
) -> Result<(Mosaic<u16>, u32), CliError> {
    let black = args.black_level;
    if black == 0 {
        return Ok((raw, level));
    }
    if u32::from(black) >= level {
        return Err(CliError::BlackLevel {
            path: path.to_owned(),
            black,
            level,
        });
    }
    raw.as_mut_slice()
        .par_iter_mut()
        .for_each(|v| *v = v.saturating_sub(black));
    Ok((raw, level - u32::from(black)))
}

/// The bits and alignment of a PNG read without `--bit-depth`: where every sample of a
/// 16-bit PNG has its `k` low bits zero (`1 <= k <= 8`), `16 − k`-bit data aligned left
/// (a camera's 10- or 12-bit ADC), read as `--bit-depth 16−k --align left` would, so their
/// DN, saturation level and quantisation step are the data's and a frame reads the same
/// aligned either way, with a note for the user; else the PNG's sample depth.
fn alignment_as_found(path: &Path, png: &MosaicPng) -> (u8, Align, Option<String>) {
    let container = png.bit_depth.bits();
    let any_bits = png
        .image
        .as_slice()
        .par_iter()
        .fold(|| 0u16, |a, &v| a | v)
        .reduce(|| 0, |a, b| a | b);
    let zeros = if container == 16 && any_bits != 0 {
        any_bits.trailing_zeros().min(8) as u8
    } else {
        0
    };
    if zeros == 0 {
        return (container, Align::Right, None);
    }
    let bits = container - zeros;
    let low = match zeros {
        1 => "low bit of every sample is".to_owned(),
        n => format!("low {n} bits of every sample are"),
    };
    let note = format!(
        "{}: the {low} 0: read as {bits}-bit data aligned left (--bit-depth 16 reads the \
         samples as they are)",
        path.display()
    );
    (bits, Align::Left, Some(note))
}

/// Applies `--bit-depth`/`--align`: returns the samples as right-aligned DN and their bit
/// count.
fn significant_bits(
    path: &Path,
    png: MosaicPng,
    bits: u8,
    align: Align,
) -> Result<(Mosaic<u16>, u8), CliError> {
    let container = png.bit_depth.bits();
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

/// Rejects frames without usable light; warnings for partly saturated and dim frames and
/// for a polarizer channel far darker than the others.
fn check_exposure(
    path: &Path,
    raw: &Mosaic<u16>,
    bits: u8,
    level: u32,
) -> Result<Vec<String>, CliError> {
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
    let saturation = (saturated > 0).then(|| {
        format!(
            "{}: {saturated} of {n} pixels ({:.3}%) are saturated at {level} DN; flagged in the mask",
            path.display(),
            100.0 * saturated as f64 / n as f64
        )
    });
    let stats = ExposureStats::of(raw);
    Ok(saturation
        .into_iter()
        .chain(dim_warning(path, &stats))
        .chain(dark_channel_warning(path, &stats))
        .collect())
}

/// What the dim and dark-channel warnings read of a raw frame, in one pass.
#[derive(Clone, Debug, PartialEq)]
struct ExposureStats {
    /// Sums of the four super-pixel positions (row-major within the 2×2 block).
    channel_sums: [f64; 4],
    /// Pixels per channel.
    channel_count: [usize; 4],
    /// Pixels at each level below [`DIM_LEVEL_DN`].
    dim_levels: [usize; DIM_LEVEL_DN as usize],
    /// All pixels.
    pixels: usize,
}

impl ExposureStats {
    fn of(raw: &Mosaic<u16>) -> Self {
        let w = raw.size().0.max(1);
        let empty = || Self {
            channel_sums: [0.0; 4],
            channel_count: [0; 4],
            dim_levels: [0; DIM_LEVEL_DN as usize],
            pixels: 0,
        };
        raw.as_slice()
            .par_chunks(w)
            .enumerate()
            .fold(empty, |mut s, (y, row)| {
                let mut sums = [0u64; 2];
                for pair in row.chunks(2) {
                    for (c, &v) in pair.iter().enumerate() {
                        sums[c] += u64::from(v);
                        if v < DIM_LEVEL_DN {
                            s.dim_levels[usize::from(v)] += 1;
                        }
                    }
                }
                for (c, sum) in sums.into_iter().enumerate() {
                    s.channel_sums[(y % 2) * 2 + c] += sum as f64;
                    s.channel_count[(y % 2) * 2 + c] += (row.len() + 1 - c) / 2;
                }
                s.pixels += row.len();
                s
            })
            .reduce(empty, |mut a, b| {
                (0..4).for_each(|c| {
                    a.channel_sums[c] += b.channel_sums[c];
                    a.channel_count[c] += b.channel_count[c];
                });
                a.dim_levels
                    .iter_mut()
                    .zip(b.dim_levels)
                    .for_each(|(x, y)| *x += y);
                a.pixels += b.pixels;
                a
            })
    }
}

/// A polarizer channel (one position of the 2×2 super-pixel, in mono and colour layouts
/// alike) whose mean is below this share of the brightest channel's: a scene gives that
/// only when polarized above DoLP 0.8 everywhere (a polarizer before the light); a dead
/// channel, a wrong layout or a bit-unpacking error gives it too.
pub const DARK_CHANNEL_SHARE: f64 = 0.1;

/// A warning when one polarizer channel is far darker than the others
/// ([`DARK_CHANNEL_SHARE`]).
fn dark_channel_warning(path: &Path, stats: &ExposureStats) -> Option<String> {
    let means: [f64; 4] =
        std::array::from_fn(|c| stats.channel_sums[c] / stats.channel_count[c].max(1) as f64);
    let brightest = means.iter().copied().fold(0.0, f64::max);
    let (dark, mean) = means
        .iter()
        .copied()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    (mean < DARK_CHANNEL_SHARE * brightest).then(|| {
        format!(
            "{}: the polarizer at row {}, column {} of each 2x2 super-pixel reads {mean:.1} DN on \
             average, the brightest channel {brightest:.1} DN: unless the whole view is \
             polarized above DoLP 0.8 (a polarizer before the light), a channel is dead, the \
             layout wrong or the bits unpacked wrongly",
            path.display(),
            dark / 2,
            dark % 2
        )
    })
}

/// Below this many DN at the 90th percentile a frame is too dim for polarization: the
/// rounding to whole DN alone gives unpolarized light a DoLP of `≈ 0.26 / DN`
/// ([`ROUNDING_DOLP`]), above the few percent a diffuse surface shows facing the camera.
pub const DIM_LEVEL_DN: u16 = 16;

/// The mean DoLP that rounding to whole DN gives unpolarized light of one DN per pixel:
/// each polarizer sample is off by a uniform error of variance 1/12, so `S1 = I0 − I90`
/// and `S2` have `σ = √(2/12)`, and with `S0 ≈ 2 I` the DoLP is Rayleigh-distributed with
/// mean `σ √(π/2) / (2 I)`.
pub const ROUNDING_DOLP: f64 = 0.2558;

/// A warning when nine pixels in ten are below [`DIM_LEVEL_DN`].
fn dim_warning(path: &Path, stats: &ExposureStats) -> Option<String> {
    let n = stats.pixels;
    // The smallest level at or below which nine pixels in ten lie, if below the limit.
    let mut below = 0;
    let p90 = stats.dim_levels.iter().position(|&c| {
        below += c;
        10 * below >= 9 * n
    })?;
    Some(format!(
        "{}: nine pixels in ten are at {p90} DN or below: rounding to whole DN alone gives \
         unpolarized light a DoLP of about {:.2} there, so polarization results are \
         unreliable (expose longer or average frames)",
        path.display(),
        ROUNDING_DOLP / (p90.max(1) as f64)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn dim_frames_are_warned_about_at_the_90th_percentile() {
        let path = Path::new("raw.png");
        // 100 pixels: `dark` of them at 3 DN, the rest at `bright` DN.
        let frame = |dark: usize, bright: u16| {
            let v = (0..100)
                .map(|k| if k < dark { 3 } else { bright })
                .collect();
            Mosaic::from_vec(10, 10, v).unwrap()
        };
        let warning =
            dim_warning(path, &ExposureStats::of(&frame(90, 200))).expect("nine in ten at 3 DN");
        assert!(warning.contains("at 3 DN or below"), "{warning}");
        assert!(warning.contains("about 0.09"), "{warning}");
        // A dark background under a tenth of well-exposed pixels is no dim frame...
        assert_eq!(dim_warning(path, &ExposureStats::of(&frame(89, 200))), None);
        // ...nor is a frame at the limit, while one a DN below it is.
        assert_eq!(
            dim_warning(path, &ExposureStats::of(&frame(0, DIM_LEVEL_DN))),
            None
        );
        assert!(dim_warning(path, &ExposureStats::of(&frame(0, DIM_LEVEL_DN - 1))).is_some());
        let warnings = check_exposure(path, &frame(95, 4095), 12, 4095).unwrap();
        for what in ["saturated", "nine pixels in ten"] {
            assert!(
                warnings.iter().any(|w| w.contains(what)),
                "{what}: {warnings:?}"
            );
        }
    }

    #[test]
    fn a_dark_polarizer_channel_is_warned_about() {
        let path = Path::new("raw.png");
        // 8x8, every channel at 1000 DN but the one at row `r`, column 1 of the super-pixel.
        let frame = |r: usize, level: u16| {
            let v = (0..64)
                .map(|k| {
                    if k / 8 % 2 == r && k % 2 == 1 {
                        level
                    } else {
                        1000
                    }
                })
                .collect();
            Mosaic::from_vec(8, 8, v).unwrap()
        };
        let warning =
            dark_channel_warning(path, &ExposureStats::of(&frame(1, 0))).expect("a dead channel");
        assert!(warning.contains("row 1, column 1"), "{warning}");
        assert!(dark_channel_warning(path, &ExposureStats::of(&frame(0, 90))).is_some());
        // A DoLP of 0.8 over the whole frame: the darkest channel at 0.11 of the brightest.
        assert_eq!(
            dark_channel_warning(path, &ExposureStats::of(&frame(0, 111))),
            None
        );
    }

    #[test]
    fn saturation_at_a_smaller_adc_top_is_found_only_when_repeated() {
        let img = |v: Vec<u16>| Mosaic::from_vec(v.len(), 1, v).unwrap();
        assert_eq!(saturation_level(&img(vec![4095, 4095, 10]), 16), 4095);
        assert_eq!(saturation_level(&img(vec![4095, 4000, 10]), 16), 65535);
        assert_eq!(saturation_level(&img(vec![4094, 4094, 10]), 16), 65535);
        assert_eq!(saturation_level(&img(vec![255, 255]), 8), 255);
    }

    #[test]
    fn camera_from_flag_then_meta_then_orthographic() {
        let meta = json!({"camera": {"fov_deg": 35.0, "fov_axis": "x"}});
        let meta = meta.as_object().unwrap();
        assert_eq!(
            camera_model(Some(50.0), Some(meta)),
            CameraModel::Pinhole { fov_x_deg: 50.0 }
        );
        assert_eq!(
            camera_model(None, Some(meta)),
            CameraModel::Pinhole { fov_x_deg: 35.0 }
        );
        let vertical = json!({"camera": {"fov_deg": 35.0, "fov_axis": "y"}});
        assert_eq!(
            camera_model(None, vertical.as_object()),
            CameraModel::Orthographic
        );
        assert_eq!(camera_model(None, None), CameraModel::Orthographic);
        assert_eq!(camera_model(Some(200.0), None), CameraModel::Orthographic);
    }
}
