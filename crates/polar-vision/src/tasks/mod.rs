//! The analysis tasks as `run` and `eval` see them: a closed set, run in dependency order
//! over one [`Context`], each writing its outputs and, with ground truth, its metrics.

pub mod dehaze;
pub mod material;
pub mod sfp;
pub mod transparent;

use std::fmt;
use std::path::{Path, PathBuf};

use clap::ValueEnum;
use polar_image::{Gray, NormalImage};
use polar_io::GroundTruth;
use polar_sensor::Observation;
use serde_json::Value;

use crate::error::CliError;

/// One analysis task.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, ValueEnum)]
pub enum Task {
    /// Shape from polarization: normal.exr, depth.exr (polar-shape).
    Sfp,
    /// Transparent-object detection: transparent.png (polar-transparency).
    Transparent,
    /// Material classification: material.png (polar-material; uses sfp's normals, made for
    /// it when sfp is not requested, and the transparency mask when that task ran).
    Material,
    /// Polarization dehazing: dehazed.exr, transmission.exr (polar-dehaze).
    Dehaze,
}

impl Task {
    /// Every task, in the order they run (a task's inputs come before it).
    pub const ALL: [Task; 4] = [Task::Sfp, Task::Transparent, Task::Material, Task::Dehaze];

    /// The name used on the command line and in `metrics.json`.
    pub fn name(self) -> &'static str {
        match self {
            Task::Sfp => "sfp",
            Task::Transparent => "transparent",
            Task::Material => "material",
            Task::Dehaze => "dehaze",
        }
    }
}

impl fmt::Display for Task {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What the tasks read, and what earlier tasks left for later ones.
pub struct Context<'a> {
    /// The observation.
    pub obs: &'a Observation,
    /// Ground truth, where the sample has any.
    pub gt: &'a GroundTruth,
    /// Where outputs go.
    pub out: &'a Path,
    /// Ground-truth radiance per unit of the observation's S0, where known (see `run`).
    pub radiance_per_unit: Option<f64>,
    /// The object mask of `--objects`, which `sfp` takes for its foreground.
    pub known_objects: Option<Gray<u8>>,
    /// Normals from `sfp`, for `material`.
    pub normals: Option<NormalImage>,
    /// Object mask from `sfp` (255 on objects), for `material`.
    pub objects: Option<Gray<u8>>,
    /// Transparency mask from `transparent`, for `material`.
    pub transparent: Option<Gray<u8>>,
}

/// What one task reports: metrics (with ground truth) and messages for the user.
#[derive(Debug, Default)]
pub struct Outcome {
    /// Task metrics, `None` without the ground truth they need.
    pub metrics: Option<Value>,
    /// Warnings and fallbacks taken.
    pub messages: Vec<String>,
}

/// Why a task did not produce its outputs.
#[derive(Debug)]
pub enum Failure {
    /// The input does not allow the task (said why); not an error of the program.
    CannotRun(String),
    /// Reading or writing failed.
    Cli(CliError),
}

impl From<CliError> for Failure {
    fn from(e: CliError) -> Self {
        Failure::Cli(e)
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Failure::CannotRun(why) => write!(f, "cannot run: {why}"),
            Failure::Cli(e) => write!(f, "{e}"),
        }
    }
}

/// The object pixels of the conventions (`gt/material.png` label != 0), if known.
pub fn object_mask(gt: &GroundTruth) -> Option<Gray<u8>> {
    let m = gt.material.as_ref()?;
    let mut out = m.clone();
    out.as_mut_slice()
        .iter_mut()
        .for_each(|v| *v = u8::from(*v != 0));
    Some(out)
}

/// A write failure of an output.
pub fn io(e: polar_io::Error) -> Failure {
    Failure::Cli(e.into())
}

/// Compression of a task's float output whose every pixel carries noise (a radiance, a
/// score, normals): run-length, nearly free; deflate costs seconds per 5-megapixel frame
/// and shrinks such floats by a few percent.
pub const NOISY: polar_io::ExrCompression = polar_io::ExrCompression::Rle;

/// Compression of a task's float output that is constant off the objects or smooth (a
/// depth, a confidence, a transmission): deflate (ZIP), which shrinks those runs and
/// slopes by a third to 98 % at little cost.
pub const SPARSE: polar_io::ExrCompression = polar_io::ExrCompression::Zip;

/// Writes `plane` as the channel Y of the float EXR `path`.
pub fn write_plane(
    path: PathBuf,
    plane: &Gray<f32>,
    compression: polar_io::ExrCompression,
) -> Result<(), polar_io::Error> {
    polar_io::write_exr_plane(path, plane, polar_io::Y_CHANNEL[0], compression)
}

/// `OUT/pictures/NAME`.
pub fn picture_path(out: &Path, name: &str) -> PathBuf {
    out.join(polar_io::files::vision::PICTURES).join(name)
}

/// The message a task run by a kNN model reports: its size.
pub fn knn_message(model: &polar_learn::KnnModel) -> String {
    let h = &model.header;
    format!("kNN classifier: k = {}, {} training points", h.k, h.points)
}

/// Serializes task metrics for `metrics.json`.
pub fn to_json(value: &impl serde::Serialize) -> Result<Value, CliError> {
    serde_json::to_value(value).map_err(|e| CliError::Json(e.to_string()))
}
