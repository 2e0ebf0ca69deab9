//! The options of the tasks (shared by `run` and `eval`) and the dispatch to each task.

use std::path::PathBuf;
use std::sync::Arc;

use clap::Args;
use polar_material::Classifier;
use polar_material::knn::KnnClassifier;

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
    /// Dehazing method:
    ///   polarization  Schechner-Narasimhan-Nayar: the airlight from its polarization
    ///   dark-channel  He-Sun-Tang dark channel prior on S0 (the baseline; no polarization)
    #[arg(verbatim_doc_comment)]
    #[arg(long, value_name = "NAME", default_value = "polarization", value_parser = parse_name::<DehazeMethod>)]
    pub dehaze_method: DehazeMethod,
    /// Material classification by k nearest neighbours with this model file (made by
    /// `polar-vision train material`), or `builtin` for the model shipped with the program
    /// (trained on datasets-synth/suites/material-train.toml). Default: the physics rule,
    /// which needs no training.
    #[arg(long, value_name = "FILE")]
    pub material_model: Option<PathBuf>,
}

/// The `--material-model` value naming the model compiled into the program.
pub const BUILTIN_MODEL: &str = "builtin";

impl TaskArgs {
    /// The material classifier the options select; a model file that cannot be used is an
    /// error naming it (checked before any sample is read).
    pub fn material_classifier(&self) -> Result<Classifier, CliError> {
        let Some(path) = &self.material_model else {
            return Ok(Classifier::Physics);
        };
        let clf = if path.as_os_str() == BUILTIN_MODEL {
            KnnClassifier::from_bytes(polar_material::knn::BUILTIN_MODEL, path)
        } else {
            KnnClassifier::load(path)
        };
        Ok(Classifier::Knn(Arc::new(clf.map_err(|e| {
            CliError::Model(format!("--material-model: {e}"))
        })?)))
    }

    /// Hex SHA-256 of the `--material-model` contents (of the compiled-in model for
    /// `builtin`), `None` without one: what ties a stored result to the model it was made with.
    pub fn material_model_digest(&self) -> Result<Option<String>, CliError> {
        let Some(path) = &self.material_model else {
            return Ok(None);
        };
        let digest = if path.as_os_str() == BUILTIN_MODEL {
            polar_io::sha256_hex(polar_material::knn::BUILTIN_MODEL)
        } else {
            polar_io::sha256_file(path)
                .map_err(|e| CliError::Model(format!("--material-model: {e}")))?
        };
        Ok(Some(digest))
    }
}

fn parse_name<T: std::str::FromStr>(s: &str) -> Result<T, String>
where
    T::Err: std::fmt::Display,
{
    s.parse().map_err(|e: T::Err| e.to_string())
}

fn parse_fov(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if v > 0.0 && v < 180.0 {
        Ok(v)
    } else {
        Err(format!("{v} is not a field of view in (0, 180) degrees"))
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
