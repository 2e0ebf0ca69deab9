//! The sample directory of `conventions.md`: `meta.json` (required) plus optional `raw.png`,
//! `stokes.exr`, `polarizers.exr` and `gt/{normal,depth,clear,transmission,dehazed}.exr`, `gt/{material,transparent}.png`.
//! Reading checks every file against the format's rules and that all images share one size;
//! writing checks the same, then writes the whole directory atomically.

use std::path::{Path, PathBuf};

use polar_image::{Gray, Image, NormalImage, PolarizerStack, StokesImage};
use serde_json::{Map, Value};

use crate::atomic::write_atomic;
use crate::error::{Error, Result};
use crate::png::{
    MosaicPng, check_mosaic_size, read_gray8_png, read_mosaic, write_gray_png, write_gray8_png,
};
use crate::staged::StagedDir;
use crate::validate::{Rule, Validation, check_channels, check_stokes, check_u8};
use crate::{POLARIZER_CHANNELS, RGB_CHANNELS, STOKES_CHANNELS, Y_CHANNEL, read_exr, write_exr};

/// File names inside a sample directory, relative to it.
pub mod files {
    /// What produced the sample (JSON object). The only required file.
    pub const META: &str = "meta.json";
    /// Grayscale mosaic, 8- or 16-bit, linear DN.
    pub const RAW: &str = "raw.png";
    /// Float32 S0, S1, S2, S3 in the camera frame.
    pub const STOKES: &str = "stokes.exr";
    /// Float32 I0, I45, I90, I135: the noiseless full-resolution images behind the four
    /// micro-polarizers (simulated samples; an addition of this project).
    pub const POLARIZERS: &str = "polarizers.exr";
    /// The folder of the ground-truth files below.
    pub const GT_DIR: &str = "gt";
    /// Float32 R, G, B: unit camera-frame normal, 0 where no surface.
    pub const GT_NORMAL: &str = "gt/normal.exr";
    /// Float32 Y: distance along -z, 0 where no surface.
    pub const GT_DEPTH: &str = "gt/depth.exr";
    /// 8-bit labels, see [`MaterialLabel`](crate::sample::MaterialLabel).
    pub const GT_MATERIAL: &str = "gt/material.png";
    /// 8-bit mask: 255 on transparent objects, else 0.
    pub const GT_TRANSPARENT: &str = "gt/transparent.png";
    /// Float32 Y: S0 of the same view without the participating medium.
    pub const GT_CLEAR: &str = "gt/clear.exr";
    /// Float32 Y in `[0, 1]`: transmittance of the medium along each pixel's central ray to
    /// the first surface (an addition of this project, for dehazing).
    pub const GT_TRANSMISSION: &str = "gt/transmission.exr";
    /// Float32 Y: S0 of the same view with the medium removed from the camera rays only
    /// (no attenuation, no airlight up to the first surface), the objects still lit
    /// through the medium: what dehazing recovers (an addition of this project).
    pub const GT_DEHAZED: &str = "gt/dehazed.exr";

    /// What `polar-vision` writes into its output directory (docs/conventions.md).
    pub mod vision {
        /// Float32 S0, S1, S2 (S3 where known).
        pub const STOKES: &str = "stokes.exr";
        /// Float32 Y: degree of linear polarization.
        pub const DOLP: &str = "dolp.exr";
        /// Float32 Y: angle of linear polarization, radians in `[0, π)`.
        pub const AOLP: &str = "aolp.exr";
        /// 8-bit RGB picture: hue = AoLP, value = DoLP (also in polar-datagen's `pictures/`).
        pub const AOLP_PICTURE: &str = "aolp.png";
        /// 8-bit palette picture: viridis DoLP (also in polar-datagen's `pictures/`).
        pub const DOLP_PICTURE: &str = "dolp.png";
        /// 8-bit palette picture: viridis S0, RGB sRGB for a colour mosaic (also in
        /// polar-datagen's `pictures/`).
        pub const S0_PICTURE: &str = "s0.png";
        /// 8-bit validity mask of a raw input: 0 valid, 1 saturated, 2 zero S0.
        pub const MASK: &str = "mask.png";
        /// Float32 R, G, B: unit camera-frame normals (shape from polarization).
        pub const NORMAL: &str = "normal.exr";
        /// Float32 Y: relative depth from the normals.
        pub const DEPTH: &str = "depth.exr";
        /// Float32 Y: per-pixel confidence in `[0, 1]` of the normals.
        pub const NORMAL_CONFIDENCE: &str = "normal_confidence.exr";
        /// 8-bit reflection type per pixel: 0 none, 1 diffuse, 2 specular, 3 mixed.
        pub const REFLECTION: &str = "reflection.png";
        /// 8-bit material labels as `gt/material.png`.
        pub const MATERIAL: &str = "material.png";
        /// Float32 Y: confidence of the material label in `[0, 1]`.
        pub const MATERIAL_CONFIDENCE: &str = "material_confidence.exr";
        /// 8-bit mask as `gt/transparent.png`.
        pub const TRANSPARENT: &str = "transparent.png";
        /// Float32 Y: transparency score in `[0, 1]`.
        pub const TRANSPARENT_SCORE: &str = "transparent_score.exr";
        /// Float32 Y: dehazed radiance.
        pub const DEHAZED: &str = "dehazed.exr";
        /// Float32 Y: estimated transmission in `(0, 1]`.
        pub const TRANSMISSION: &str = "transmission.exr";
        /// Float32 Y: relative depth `−ln t` from the transmission.
        pub const HAZE_DEPTH: &str = "haze_depth.exr";
        /// Per-task status, timings and (with ground truth) metrics.
        pub const METRICS: &str = "metrics.json";
        /// Folder of 8-bit pictures for people (names in [`pictures`]).
        pub const PICTURES: &str = "pictures";
        /// The per-sample record of `polar-vision eval` that makes a rerun resume.
        pub const EVAL_RECORD: &str = "eval.json";
        /// Marker of an output folder written by polar-vision: only a folder that holds it
        /// (or an empty one) is replaced by a later run.
        pub const MARKER: &str = ".polar-vision";

        /// The 8-bit RGB pictures of the tasks, inside [`PICTURES`].
        pub mod pictures {
            /// Normals from polarization as colours.
            pub const NORMAL: &str = "normal.png";
            /// Reflection types.
            pub const REFLECTION: &str = "reflection.png";
            /// S0, estimated normals, true normals and angular error side by side (only
            /// where the sample has `gt/normal.exr`).
            pub const NORMAL_ERROR: &str = "normal_error.png";
            /// Material labels.
            pub const MATERIAL: &str = "material.png";
            /// S0, estimated labels and true labels side by side (only where the sample has
            /// `gt/material.png`).
            pub const MATERIAL_ERROR: &str = "material_error.png";
            /// Transparency overlay.
            pub const TRANSPARENT: &str = "transparent.png";
            /// S0 beside the transparency mask against the truth: found, false and missed
            /// pixels (only where the sample has `gt/transparent.png`).
            pub const TRANSPARENT_ERROR: &str = "transparent_error.png";
            /// Hazy, dehazed and transmission side by side.
            pub const DEHAZE: &str = "dehaze.png";
        }
    }

    /// What `polar-datagen suite` writes into a dataset directory beside the samples.
    pub mod dataset {
        /// One JSON line per sample: id, seed, parameters, sha256 of every file, timings.
        pub const MANIFEST: &str = "manifest.jsonl";
        /// The run record (suite, size, shards).
        pub const RUN_RECORD: &str = "run.json";
        /// Copy of the suite file (merge re-derives the expected ids from it).
        pub const SUITE_COPY: &str = "suite.toml";
    }
}

/// Labels of `gt/material.png` (and of the vision CLI's `material.png`): the pixel value is
/// the discriminant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum MaterialLabel {
    /// Background: floors, walls, sky (excluded from accuracy figures); also where no
    /// surface is.
    #[default]
    Background = 0,
    /// Opaque dielectric.
    Dielectric = 1,
    /// Metal.
    Metal = 2,
    /// Transparent object.
    Transparent = 3,
}

impl MaterialLabel {
    /// Every label, in the order of their values.
    pub const ALL: [Self; 4] = [
        Self::Background,
        Self::Dielectric,
        Self::Metal,
        Self::Transparent,
    ];

    /// The pixel value of the label.
    pub const fn value(self) -> u8 {
        self as u8
    }

    /// The label of pixel value `v`, if it is one.
    pub fn from_value(v: u8) -> Option<Self> {
        Self::ALL.into_iter().find(|l| l.value() == v)
    }
}

/// Value of `gt/transparent.png` on transparent objects (0 elsewhere).
pub const TRANSPARENT_MASK_ON: u8 = 255;

/// Ground-truth images of a sample; each is optional.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GroundTruth {
    /// `gt/normal.exr`.
    pub normal: Option<NormalImage>,
    /// `gt/depth.exr`.
    pub depth: Option<Gray<f32>>,
    /// `gt/material.png`.
    pub material: Option<Gray<u8>>,
    /// `gt/transparent.png`.
    pub transparent: Option<Gray<u8>>,
    /// `gt/clear.exr`.
    pub clear: Option<Gray<f32>>,
    /// `gt/transmission.exr`.
    pub transmission: Option<Gray<f32>>,
    /// `gt/dehazed.exr`.
    pub dehazed: Option<Gray<f32>>,
}

/// One sample directory in memory.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sample {
    /// `meta.json`: size, sensor, camera, scene, renderer, spp, seconds, and any other keys.
    pub meta: Map<String, Value>,
    /// `raw.png`, with the bit depth it is stored at.
    pub raw: Option<MosaicPng>,
    /// `stokes.exr`.
    pub stokes: Option<StokesImage>,
    /// `polarizers.exr`.
    pub polarizers: Option<PolarizerStack>,
    /// `gt/`.
    pub gt: GroundTruth,
}

/// Reads a sample directory, checking values (see [`read_sample_with`]).
pub fn read_sample(dir: impl AsRef<Path>) -> Result<Sample> {
    read_sample_with(dir, Validation::Check)
}

/// Reads a sample directory. `meta.json` must exist and hold a JSON object; every other file
/// is read if present. With [`Validation::Check`]: S0 finite and `>= 0`, S1..S3, normals,
/// polarizer intensities (finite, `>= 0`), depth, clear and dehazed S0 finite (and `>= 0`), transmission in `[0, 1]`,
/// material labels in 0..=3, the transparency mask 0 or 255. Mosaic size and equal sizes across files are always checked.
pub fn read_sample_with(dir: impl AsRef<Path>, validation: Validation) -> Result<Sample> {
    let dir = dir.as_ref();
    if !dir.is_dir() {
        return Err(Error::NotFound {
            path: dir.to_owned(),
        });
    }
    let meta = read_meta(&dir.join(files::META))?;
    let opt = |name: &str| optional(dir.join(name));
    let sample = Sample {
        meta,
        raw: opt(files::RAW)?.map(read_mosaic).transpose()?,
        stokes: opt(files::STOKES)?
            .map(|p| read_exr(p, STOKES_CHANNELS))
            .transpose()?,
        polarizers: opt(files::POLARIZERS)?
            .map(|p| read_exr(p, POLARIZER_CHANNELS))
            .transpose()?,
        gt: read_gt_files(dir)?,
    };
    check_sample(dir, &sample, validation)?;
    Ok(sample)
}

/// Reads the ground truth of a sample directory (`gt/`; each file optional), with the
/// checks of [`read_sample_with`] on what is there; `meta.json` is not needed.
pub fn read_ground_truth(dir: impl AsRef<Path>, validation: Validation) -> Result<GroundTruth> {
    let dir = dir.as_ref();
    let sample = Sample {
        gt: read_gt_files(dir)?,
        ..Sample::default()
    };
    check_sample(dir, &sample, validation)?;
    Ok(sample.gt)
}

/// `meta.json` of a sample directory if it has one (a JSON object).
pub fn read_optional_meta(dir: impl AsRef<Path>) -> Result<Option<Map<String, Value>>> {
    optional(dir.as_ref().join(files::META))?
        .map(|p| read_meta(&p))
        .transpose()
}

fn read_gt_files(dir: &Path) -> Result<GroundTruth> {
    let opt = |name: &str| optional(dir.join(name));
    Ok(GroundTruth {
        normal: opt(files::GT_NORMAL)?
            .map(|p| read_exr(p, RGB_CHANNELS))
            .transpose()?,
        depth: opt(files::GT_DEPTH)?
            .map(|p| read_exr(p, Y_CHANNEL))
            .transpose()?,
        material: opt(files::GT_MATERIAL)?.map(read_gray8_png).transpose()?,
        transparent: opt(files::GT_TRANSPARENT)?
            .map(read_gray8_png)
            .transpose()?,
        clear: opt(files::GT_CLEAR)?
            .map(|p| read_exr(p, Y_CHANNEL))
            .transpose()?,
        transmission: opt(files::GT_TRANSMISSION)?
            .map(|p| read_exr(p, Y_CHANNEL))
            .transpose()?,
        dehazed: opt(files::GT_DEHAZED)?
            .map(|p| read_exr(p, Y_CHANNEL))
            .transpose()?,
    })
}

/// Writes `sample` as the directory `dir` (parents are created), after the checks of
/// [`read_sample_with`] with [`Validation::Check`]. Atomic through a [`StagedDir`], so `dir`
/// is never seen half-written; an existing `dir` must be a sample (hold `meta.json`) or empty.
pub fn write_sample(dir: impl AsRef<Path>, sample: &Sample) -> Result<()> {
    let dir = dir.as_ref();
    check_sample(dir, sample, Validation::Check)?;
    let staged = StagedDir::new(dir, files::META)?;
    write_sample_files(staged.path(), sample)?;
    staged.commit().map(drop)
}

/// Writes `sample` into the existing directory `dir` after the checks of [`write_sample`],
/// not atomically: for a caller that stages the directory itself (a dataset's
/// [`StagedDir::within`]) and may add files of its own.
pub fn write_sample_into(dir: impl AsRef<Path>, sample: &Sample) -> Result<()> {
    let dir = dir.as_ref();
    check_sample(dir, sample, Validation::Check)?;
    write_sample_files(dir, sample)
}

/// Writes any serializable value as pretty JSON (e.g. `metrics.json`), atomically.
pub fn write_json(path: impl AsRef<Path>, value: &impl serde::Serialize) -> Result<()> {
    let path = path.as_ref();
    let mut text = serde_json::to_vec_pretty(value).map_err(|source| Error::JsonWrite {
        path: path.to_owned(),
        source,
    })?;
    text.push(b'\n');
    write_atomic(path, &text)
}

/// Reads a JSON file into any deserializable type.
pub fn read_json<T: serde::de::DeserializeOwned>(path: impl AsRef<Path>) -> Result<T> {
    let path = path.as_ref();
    let text = std::fs::read(path).map_err(|e| Error::io(path, "JSON", e))?;
    parse_json(path, &text)
}

/// [`read_json`] of bytes already in memory; `path` only names them in errors.
pub fn parse_json<T: serde::de::DeserializeOwned>(path: &Path, bytes: &[u8]) -> Result<T> {
    serde_json::from_slice(bytes).map_err(|e| Error::corrupt(path, "JSON", e))
}

fn read_meta(path: &Path) -> Result<Map<String, Value>> {
    let text = std::fs::read(path).map_err(|e| Error::io(path, "JSON", e))?;
    parse_meta(path, &text)
}

/// The `meta.json` rule on bytes in memory: a JSON object ([`Error::MetaNotObject`] if not);
/// `path` only names them in errors.
pub fn parse_meta(path: &Path, bytes: &[u8]) -> Result<Map<String, Value>> {
    match parse_json::<Value>(path, bytes)? {
        Value::Object(map) => Ok(map),
        other => Err(Error::MetaNotObject {
            path: path.to_owned(),
            found: json_type(&other),
        }),
    }
}

fn json_type(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// `Some(path)` if the file exists, `None` if not; other failures (permissions) are errors.
fn optional(path: PathBuf) -> Result<Option<PathBuf>> {
    match path.try_exists() {
        Ok(true) => Ok(Some(path)),
        Ok(false) => Ok(None),
        Err(e) => Err(Error::io(&path, "sample", e)),
    }
}

/// The value rules and the one-size rule; `dir` only names files in errors.
fn check_sample(dir: &Path, s: &Sample, validation: Validation) -> Result<()> {
    let gt = &s.gt;
    let mut sizes = SizeCheck::default();
    if let Some(raw) = &s.raw {
        let path = dir.join(files::RAW);
        check_mosaic_size(&path, raw.image.width(), raw.image.height())?;
        sizes.add(path, raw.image.size())?;
    }
    let other_files = [
        (files::STOKES, s.stokes.as_ref().map(Image::size)),
        (files::POLARIZERS, s.polarizers.as_ref().map(Image::size)),
        (files::GT_NORMAL, gt.normal.as_ref().map(Image::size)),
        (files::GT_DEPTH, gt.depth.as_ref().map(Image::size)),
        (files::GT_MATERIAL, gt.material.as_ref().map(Image::size)),
        (
            files::GT_TRANSPARENT,
            gt.transparent.as_ref().map(Image::size),
        ),
        (files::GT_CLEAR, gt.clear.as_ref().map(Image::size)),
        (
            files::GT_TRANSMISSION,
            gt.transmission.as_ref().map(Image::size),
        ),
        (files::GT_DEHAZED, gt.dehazed.as_ref().map(Image::size)),
    ];
    for (name, size) in other_files {
        if let Some(size) = size {
            sizes.add(dir.join(name), size)?;
        }
    }
    if validation == Validation::Check {
        check_values(dir, s)?;
    }
    Ok(())
}

fn check_values(dir: &Path, s: &Sample) -> Result<()> {
    use Rule::{Finite, FiniteNonNegative, UnitInterval};
    let gt = &s.gt;
    if let Some(stokes) = &s.stokes {
        check_stokes(&dir.join(files::STOKES), stokes)?;
    }
    if let Some(polarizers) = &s.polarizers {
        check_channels(
            &dir.join(files::POLARIZERS),
            polarizers,
            POLARIZER_CHANNELS,
            [FiniteNonNegative; 4],
        )?;
    }
    if let Some(normal) = &gt.normal {
        check_channels(
            &dir.join(files::GT_NORMAL),
            normal,
            RGB_CHANNELS,
            [Finite; 3],
        )?;
    }
    for (name, image, rule) in [
        (files::GT_DEPTH, &gt.depth, FiniteNonNegative),
        (files::GT_CLEAR, &gt.clear, FiniteNonNegative),
        (files::GT_TRANSMISSION, &gt.transmission, UnitInterval),
        (files::GT_DEHAZED, &gt.dehazed, FiniteNonNegative),
    ] {
        if let Some(image) = image {
            check_channels(&dir.join(name), image, Y_CHANNEL, [rule])?;
        }
    }
    if let Some(m) = &gt.material {
        check_u8(&dir.join(files::GT_MATERIAL), m, "a label 0..=3", |v| {
            MaterialLabel::from_value(v).is_some()
        })?;
    }
    if let Some(t) = &gt.transparent {
        check_u8(&dir.join(files::GT_TRANSPARENT), t, "0 or 255", |v| {
            v == 0 || v == TRANSPARENT_MASK_ON
        })?;
    }
    Ok(())
}

/// Remembers the first image size seen and reports any later one that differs.
#[derive(Default)]
struct SizeCheck {
    first: Option<(PathBuf, (usize, usize))>,
}

impl SizeCheck {
    fn add(&mut self, path: PathBuf, size: (usize, usize)) -> Result<()> {
        match &self.first {
            None => {
                self.first = Some((path, size));
                Ok(())
            }
            Some((_, expected)) if *expected == size => Ok(()),
            Some((reference, expected)) => Err(Error::SizeMismatch {
                path,
                found: size,
                expected: *expected,
                reference: reference.clone(),
            }),
        }
    }
}

fn write_sample_files(dir: &Path, s: &Sample) -> Result<()> {
    let gt = &s.gt;
    let has_gt = gt.normal.is_some()
        || gt.depth.is_some()
        || gt.material.is_some()
        || gt.transparent.is_some()
        || gt.clear.is_some()
        || gt.transmission.is_some()
        || gt.dehazed.is_some();
    if has_gt {
        let gt = dir.join(files::GT_DIR);
        std::fs::create_dir(&gt).map_err(|e| Error::io(&gt, "directory", e))?;
    }
    write_json(dir.join(files::META), &s.meta)?;
    let p = |name: &str| dir.join(name);
    if let Some(raw) = &s.raw {
        write_gray_png(p(files::RAW), raw)?;
    }
    if let Some(stokes) = &s.stokes {
        write_exr(p(files::STOKES), stokes, STOKES_CHANNELS)?;
    }
    if let Some(polarizers) = &s.polarizers {
        write_exr(p(files::POLARIZERS), polarizers, POLARIZER_CHANNELS)?;
    }
    if let Some(normal) = &gt.normal {
        write_exr(p(files::GT_NORMAL), normal, RGB_CHANNELS)?;
    }
    for (name, image) in [
        (files::GT_DEPTH, &gt.depth),
        (files::GT_CLEAR, &gt.clear),
        (files::GT_TRANSMISSION, &gt.transmission),
        (files::GT_DEHAZED, &gt.dehazed),
    ] {
        if let Some(image) = image {
            write_exr(p(name), image, Y_CHANNEL)?;
        }
    }
    for (name, image) in [
        (files::GT_MATERIAL, &gt.material),
        (files::GT_TRANSPARENT, &gt.transparent),
    ] {
        if let Some(image) = image {
            write_gray8_png(p(name), image)?;
        }
    }
    Ok(())
}
