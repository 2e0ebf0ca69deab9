//! `polar-vision train`: fits a learned model of a task on a labelled dataset and writes
//! its model file (polar-learn's format).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use polar_io::GroundTruth;
use polar_io::Validation;
use polar_learn::{Expect, KnnModel, TrainingSummary};
use polar_sensor::Observation;
use polar_shape::{ShapeOptions, estimate_shape};
use rayon::prelude::*;

use crate::error::CliError;
use crate::eval::{progress, select_samples};
use crate::input::{InputArgs, Source, camera_model, read_observation, resolve};

/// The tasks that have a learned model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TrainTask {
    /// Material classification (metal against dielectric) by k nearest neighbours, from the
    /// labels of gt/material.png (1 dielectric, 2 metal).
    Material,
    /// Transparent-object segmentation (transparent against everything else) by k nearest
    /// neighbours, from gt/transparent.png (non-zero = transparent), over every valid pixel.
    Transparent,
}

impl TrainTask {
    /// The task's name, as in metrics.json.
    fn name(self) -> &'static str {
        match self {
            TrainTask::Material => "material",
            TrainTask::Transparent => "transparent",
        }
    }

    /// What the task's model file declares.
    fn expect(self) -> Expect<'static> {
        match self {
            TrainTask::Material => polar_material::knn::EXPECT,
            TrainTask::Transparent => polar_transparency::knn::EXPECT,
        }
    }

    /// Where the features' normals and object mask come from, where another task gives
    /// them (the model's summary says so).
    fn cues(self) -> Option<&'static str> {
        match self {
            TrainTask::Material => Some("sfp normals and object mask (default options)"),
            TrainTask::Transparent => None,
        }
    }

    /// Appends the training points of one sample (none where it lacks the labels).
    fn add_pixels(
        self,
        obs: &Observation,
        gt: &GroundTruth,
        points: &mut Vec<f32>,
        classes: &mut Vec<u8>,
    ) -> Result<(), String> {
        match (self, &gt.material, &gt.transparent) {
            (TrainTask::Material, Some(labels), _) => {
                let shape =
                    estimate_shape(obs, &ShapeOptions::default()).map_err(|e| e.to_string())?;
                polar_material::knn::add_training_pixels(
                    obs,
                    Some(&shape.normal),
                    Some(&shape.foreground),
                    labels,
                    points,
                    classes,
                )
                .map_err(|e| e.to_string())
            }
            (TrainTask::Transparent, _, Some(labels)) => {
                polar_transparency::knn::add_training_pixels(obs, labels, points, classes)
                    .map_err(|e| e.to_string())
            }
            _ => Ok(()),
        }
    }
}

/// Arguments of `polar-vision train`.
#[derive(Debug, Args)]
#[command(
    after_help = "Reads every sample directory of DATASET (as `eval` does) through the same input \
path as `run` (raw.png by default), computes the task's per-pixel features on the pixels the \
classifier takes for objects (material: with the normals and object mask of shape from polarization \
at its default options, as `run` gives them), labels them from the sample's ground truth, keeps a class-balanced \
subsample of at most --max-points (fixed by --seed: the same command gives the same file), and \
writes the model file: format version, task, feature list, standardization, k, the training set's \
summary and the points. Use it with `run --material-model FILE` or `run --transparent-method \
learned --transparent-model FILE` (or `eval`)."
)]
pub struct TrainArgs {
    /// The task to train for.
    #[arg(value_enum)]
    pub task: TrainTask,
    /// A dataset folder whose sub-folders are samples with ground truth (a polar-datagen
    /// output).
    pub dataset: PathBuf,
    /// Where the model file goes.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Neighbours that vote.
    #[arg(long, value_name = "K", default_value_t = 15, value_parser = clap::value_parser!(u16).range(1..))]
    pub k: u16,
    /// Most training points kept (half per class): the model's size and query time.
    #[arg(long, value_name = "N", default_value_t = 4000, value_parser = clap::value_parser!(u32).range(2..=10_000_000))]
    pub max_points: u32,
    /// Seed of the subsample.
    #[arg(long, value_name = "SEED", default_value_t = 1)]
    pub seed: u64,
    /// Use only the samples of these families (e.g. `materials`), comma-separated.
    /// Default: all.
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub family: Vec<String>,
    /// Which file of each sample to read (default: raw.png where there is one).
    #[arg(long, value_enum)]
    pub input: Option<Source>,
    /// How to read the input.
    #[command(flatten)]
    pub read: InputArgs,
}

/// Runs the subcommand.
pub fn train(args: &TrainArgs) -> Result<bool, CliError> {
    let start = Instant::now();
    let samples = select_samples(&args.dataset, &args.family)?;
    let bar = progress(samples.len());
    let per_sample: Vec<(Vec<f32>, Vec<u8>)> = samples
        .par_iter()
        .map(|s| {
            let r = sample_pixels(s, args);
            bar.inc(1);
            r
        })
        .collect::<Result<_, _>>()?;
    bar.finish_and_clear();
    let (mut points, mut classes) = (Vec::new(), Vec::new());
    for (p, c) in per_sample {
        points.extend(p);
        classes.extend(c);
    }
    let summary = summary(args, samples.len());
    let model = KnnModel::fit_balanced(
        args.task.expect(),
        usize::from(args.k),
        &points,
        &classes,
        args.max_points as usize,
        args.seed,
        summary,
    )
    .map_err(|e| CliError::Model(format!("{}: {e}", args.dataset.display())))?;
    polar_io::write_atomic(&args.out, &model.to_bytes())?;
    let s = &model.header.summary;
    eprintln!(
        "trained on {} samples: {:?} labelled pixels, kept {:?}; wrote {} in {:.1} s",
        s.samples,
        s.pixels_per_class,
        s.points_per_class,
        args.out.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(true)
}

/// Feature vectors and classes of one sample's labelled pixels.
fn sample_pixels(sample: &Path, args: &TrainArgs) -> Result<(Vec<f32>, Vec<u8>), CliError> {
    let file = resolve(sample, args.input)?;
    let (mut obs, _) = read_observation(&file, &args.read)?;
    let meta = polar_io::read_optional_meta(sample)?;
    obs.camera = camera_model(None, meta.as_ref());
    let gt = polar_io::read_ground_truth(sample, Validation::Check)?;
    let (mut points, mut classes) = (Vec::new(), Vec::new());
    args.task
        .add_pixels(&obs, &gt, &mut points, &mut classes)
        .map_err(|e| CliError::Task {
            task: args.task.name(),
            message: format!("{}: {e}", sample.display()),
        })?;
    Ok((points, classes))
}

/// The training set's summary; the settings are those that change the model's points.
fn summary(args: &TrainArgs, samples: usize) -> TrainingSummary {
    let settings: BTreeMap<String, String> = [
        ("input", format!("{:?}", args.input)),
        ("read", format!("{:?}", args.read)),
        ("k", args.k.to_string()),
        ("max_points", args.max_points.to_string()),
        ("seed", args.seed.to_string()),
    ]
    .into_iter()
    .chain(args.task.cues().map(|c| ("cues", c.to_owned())))
    .map(|(k, v)| (k.to_owned(), v))
    .collect();
    TrainingSummary {
        dataset: args.dataset.display().to_string(),
        samples,
        families: args.family.clone(),
        settings,
        ..Default::default()
    }
}
