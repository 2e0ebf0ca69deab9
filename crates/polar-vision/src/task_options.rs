//! The options of the tasks (shared by `run` and `eval`) and the dispatch to each task.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use clap::Args;
use polar_learn::{Expect, Knn};
use polar_material::Classifier;
use polar_transparency::{Method as TransparentMethod, Segmenter};

use crate::error::CliError;
use polar_dehaze::Method as DehazeMethod;
use polar_shape::{Integrator, IorOption, Method};

use crate::tasks::{Context, Failure, Outcome, Task};

/// Options of the analysis tasks.
#[derive(Clone, Debug, Args)]
pub struct TaskArgs {
    /// Horizontal field of view of the camera in degrees, for the per-pixel Stokes frame.
    /// Default: `camera.fov_deg` of the sample's meta.json, else an orthographic camera
    /// (the image axes as the Stokes frame: exact at the centre, off by a few degrees in
    /// the corners of a wide-angle view).
    #[arg(long, value_name = "DEG", value_parser = parse_fov)]
    pub fov: Option<f64>,
    /// Refractive index of the objects (sfp): a number, or `auto` to estimate it from the
    /// diffuse DoLP profile at the occluding contours (1.5 with the reason where the image
    /// gives too little evidence). Default: 1.5; `auto` is opt-in, as on our own renders it
    /// is less accurate than 1.5 (docs/benchmarks.md).
    #[arg(long, value_name = "N|auto", value_parser = parse_ior)]
    pub ior: Option<IorOption>,
    /// Shape from polarization, how the azimuth ambiguity is resolved:
    ///   local   occluding-boundary propagation with a convexity prior (fast)
    ///   global  height from polarization and shading as one sparse least squares
    #[arg(verbatim_doc_comment)]
    #[arg(long, value_name = "NAME", default_value = "local", value_parser = parse_name::<Method>)]
    pub sfp_method: Method,
    /// Shape from polarization, depth from normals:
    ///   poisson  weighted least squares over the objects only (the default)
    ///   fc       Frankot-Chellappa, least squares in the Fourier domain (whole frame)
    #[arg(verbatim_doc_comment)]
    #[arg(long, value_name = "NAME", default_value = "poisson", value_parser = parse_name::<Integrator>)]
    pub integrator: Integrator,
    /// Shape from polarization works in an image with this many pixels on its long side, up
    /// to twice as many: a larger frame is binned by the largest factor that keeps it at
    /// least this long (Stokes vectors averaged over blocks, as larger pixels would measure
    /// them) and the results are interpolated back. Its windows are a few pixels wide, so
    /// this makes it independent of the camera's resolution, less sensitive to noise, and
    /// fast. 0 works in the frame's own pixels.
    #[arg(long, value_name = "PIXELS", default_value_t = polar_shape::scale::WORKING_SIZE)]
    pub sfp_working_size: usize,
    /// Dehazing method:
    ///   polarization  Schechner-Narasimhan-Nayar: the airlight from its polarization
    ///   dark-channel  He-Sun-Tang dark channel prior on S0 (the baseline; no polarization)
    #[arg(verbatim_doc_comment)]
    #[arg(long, value_name = "NAME", default_value = "polarization", value_parser = parse_name::<DehazeMethod>)]
    pub dehaze_method: DehazeMethod,
    /// Dehazing by polarization leaves a frame unchanged (with a warning) where the airlight
    /// it finds makes up less than this share of the light on average: a haze-free frame's
    /// glossy highlights would otherwise be read as thin haze. 0 dehazes every frame.
    #[arg(long, value_name = "SHARE", default_value_t = polar_dehaze::MIN_AIRLIGHT_SHARE, value_parser = parse_share, allow_negative_numbers = true)]
    pub dehaze_min_airlight: f32,
    /// Material classification by k nearest neighbours with this model file (made by
    /// `polar-vision train material`), or `builtin` for the model shipped with the program
    /// (trained on datasets-synth/suites/material-train.toml). Default: the physics rule,
    /// which needs no training.
    #[arg(long, value_name = "FILE")]
    pub material_model: Option<PathBuf>,
    /// Transparent-object segmenter:
    ///   cues     the cue score (coherent DoLP) with Otsu's threshold, bounded by the background's level; no training
    ///   learned  k nearest neighbours over per-pixel cue features (--transparent-model), voting among the pixels the cue score passes
    #[arg(verbatim_doc_comment)]
    #[arg(long, value_name = "NAME", default_value = "cues", value_parser = parse_name::<TransparentMethod>)]
    pub transparent_method: TransparentMethod,
    /// The object pixels for sfp and material, in place of sfp's own foreground: `gt` (the
    /// sample's gt/material.png, label not 0: shape from polarization scored with a known
    /// object mask, as published benchmarks give one) or a PNG of the frame's size from
    /// another segmenter, non-zero on objects (grayscale of any depth, RGB, palette; a
    /// transparent pixel is background). Its outline is taken for the objects' occluding
    /// contour, where normals lie in the image plane: mark whole objects, since a cut
    /// through one becomes a false rim. A relative FILE that does not
    /// exist as given is looked for in the sample directory, so `eval --objects mask.png`
    /// reads each sample's own.
    #[arg(long, value_name = "gt|FILE", value_parser = parse_objects)]
    pub objects: Option<ObjectsSource>,
    /// The model file of `--transparent-method learned` (made by `polar-vision train
    /// transparent`), or `builtin` (the default) for the model shipped with the program
    /// (trained on datasets-synth/suites/transparent-train.toml).
    #[arg(long, value_name = "FILE")]
    pub transparent_model: Option<PathBuf>,
}

/// The `--material-model` / `--transparent-model` value naming the model compiled into the
/// program.
pub const BUILTIN_MODEL: &str = "builtin";

impl TaskArgs {
    /// The material classifier the options select; a model file that cannot be used is an
    /// error naming it (checked before any sample is read).
    pub fn material_classifier(&self) -> Result<Classifier, CliError> {
        Ok(match &self.material_model {
            None => Classifier::Physics,
            Some(path) => Classifier::Knn(Arc::new(load_knn(
                "--material-model",
                path,
                polar_material::knn::BUILTIN_MODEL,
                polar_material::knn::EXPECT,
            )?)),
        })
    }

    /// The transparent segmenter the options select (as [`Self::material_classifier`]).
    pub fn transparent_segmenter(&self) -> Result<Segmenter, CliError> {
        Ok(match self.transparent_model_path()? {
            None => Segmenter::Cues,
            Some(path) => Segmenter::Knn(Arc::new(load_knn(
                "--transparent-model",
                path,
                polar_transparency::knn::BUILTIN_MODEL,
                polar_transparency::knn::EXPECT,
            )?)),
        })
    }

    /// The transparent model the options name: `--transparent-model`, by default
    /// `builtin`, with `--transparent-method learned`; none with `cues`, where naming a
    /// model is an error (it would be ignored).
    fn transparent_model_path(&self) -> Result<Option<&Path>, CliError> {
        match (self.transparent_method, &self.transparent_model) {
            (TransparentMethod::Cues, None) => Ok(None),
            (TransparentMethod::Cues, Some(p)) => Err(CliError::Model(format!(
                "--transparent-model {}: only used with --transparent-method learned",
                p.display()
            ))),
            (TransparentMethod::Learned, p) => {
                Ok(Some(p.as_deref().unwrap_or(Path::new(BUILTIN_MODEL))))
            }
        }
    }

    /// Loads the models `tasks` use, so that an unusable model file is an error before any
    /// sample is read.
    pub fn check_models(&self, tasks: &[Task]) -> Result<(), CliError> {
        if tasks.contains(&Task::Material) {
            self.material_classifier()?;
        }
        if tasks.contains(&Task::Transparent) {
            self.transparent_segmenter()?;
        }
        Ok(())
    }

    /// Hex SHA-256 of the contents of each model the options use (of the compiled-in model
    /// for `builtin`), in task order, `None` where a task uses none: what ties a stored
    /// result to the models it was made with.
    pub fn model_digests(&self) -> Result<[Option<String>; 2], CliError> {
        let material = self
            .material_model
            .as_deref()
            .map(|p| model_digest("--material-model", p, polar_material::knn::BUILTIN_MODEL));
        let transparent = self.transparent_model_path()?.map(|p| {
            model_digest(
                "--transparent-model",
                p,
                polar_transparency::knn::BUILTIN_MODEL,
            )
        });
        Ok([material.transpose()?, transparent.transpose()?])
    }
}

/// The kNN model `path` of option `option` (`builtin`: the compiled-in `builtin` bytes),
/// checked against `expect`; an error names the option and the file.
fn load_knn<const D: usize>(
    option: &str,
    path: &Path,
    builtin: &[u8],
    expect: Expect<'_>,
) -> Result<Knn<D>, CliError> {
    let knn = if path.as_os_str() == BUILTIN_MODEL {
        Knn::from_bytes(builtin, path, expect)
    } else {
        Knn::load(path, expect)
    };
    knn.map_err(|e| CliError::Model(format!("{option}: {e}")))
}

/// Hex SHA-256 of model `path` of option `option` (of `builtin` for `builtin`).
fn model_digest(option: &str, path: &Path, builtin: &[u8]) -> Result<String, CliError> {
    if path.as_os_str() == BUILTIN_MODEL {
        Ok(polar_io::sha256_hex(builtin))
    } else {
        polar_io::sha256_file(path).map_err(|e| CliError::Model(format!("{option}: {e}")))
    }
}

fn parse_name<T: std::str::FromStr>(s: &str) -> Result<T, String>
where
    T::Err: std::fmt::Display,
{
    s.parse().map_err(|e: T::Err| e.to_string())
}

/// Where `--objects` takes the object mask from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ObjectsSource {
    /// The sample's gt/material.png, label not 0.
    GroundTruth,
    /// A PNG, non-zero on objects ([`polar_io::read_mask_png`]).
    File(PathBuf),
}

fn parse_objects(s: &str) -> Result<ObjectsSource, String> {
    match s {
        "" => Err("an empty path".into()),
        "gt" => Ok(ObjectsSource::GroundTruth),
        _ => Ok(ObjectsSource::File(s.into())),
    }
}

fn parse_fov(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if v > 0.0 && v < 180.0 {
        Ok(v)
    } else {
        Err(format!("{v} is not a field of view in (0, 180) degrees"))
    }
}

fn parse_share(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v} is not a share in [0, 1]"))
    }
}

fn parse_ior(s: &str) -> Result<IorOption, String> {
    if s == "auto" {
        return Ok(IorOption::Estimate);
    }
    let v: f64 = s
        .parse()
        .map_err(|_| format!("{s:?} is neither a number nor `auto`"))?;
    if (1.0..=4.0).contains(&v) && v > 1.0 {
        Ok(IorOption::Given(v))
    } else {
        Err(format!("{v} is not a refractive index in (1, 4]"))
    }
}

/// Runs one task on the context.
pub fn execute(task: Task, ctx: &mut Context<'_>, args: &TaskArgs) -> Result<Outcome, Failure> {
    match task {
        Task::Sfp => crate::tasks::sfp::run(ctx, args),
        Task::Material => crate::tasks::material::run(ctx, args),
        Task::Dehaze => crate::tasks::dehaze::run(ctx, args),
        Task::Transparent => crate::tasks::transparent::run(ctx, args),
    }
}
