//! `polar-vision run`: one sample directory (or raw PNG) through the requested tasks.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use polar_eval::{SCHEMA_VERSION, Summary};
use polar_image::Gray;
use polar_io::files::{self, vision};
use polar_io::{GroundTruth, Validation};
use serde::{Deserialize, Serialize};

use crate::error::CliError;
use crate::input::{InputArgs, InputFile, Source, camera_model, read_input, resolve};
use crate::out_dir;
use crate::stokes::{Output, Planes, write_outputs};
use crate::task_options::{ObjectsSource, TaskArgs};
use crate::tasks::{Context, Failure, Task, object_mask};

/// Arguments of `polar-vision run`.
#[derive(Debug, Args)]
#[command(
    after_help = "Writes to --out the Stokes outputs of `stokes` (stokes.exr, dolp.exr, \
aolp.exr, aolp.png, ...), each task's outputs (sfp: normal.exr, depth.exr, normal_confidence.exr, \
reflection.png; transparent: transparent.png, transparent_score.exr; material: material.png, \
material_confidence.exr; dehaze: dehazed.exr, transmission.exr, haze_depth.exr), pictures under \
pictures/, and, where the sample has gt/, metrics.json with each task's figures and time. \
A task that cannot run on the input says why; the others still run. Exit code 0 only if every \
requested task succeeded."
)]
pub struct RunArgs {
    /// A sample directory (raw.png and/or stokes.exr, optional meta.json and gt/), or a raw
    /// mosaic PNG.
    pub sample: PathBuf,
    /// Output directory: new, empty, or an earlier output of polar-vision, which is
    /// replaced as a whole once every file is written.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Tasks to run, comma-separated (default: all). They run in the order sfp,
    /// transparent, material, dehaze; material uses sfp's normals and object mask (made
    /// for it, not written, when sfp is not requested) and the transparency mask, which
    /// relabels its objects transparent except those it calls metal.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = Task::ALL)]
    pub tasks: Vec<Task>,
    /// Which file of a sample directory to read: raw (the camera's mosaic; the default
    /// where there is one) or stokes (stokes.exr).
    #[arg(long, value_enum)]
    pub input: Option<Source>,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub threads: Option<u16>,
    /// How to read the input.
    #[command(flatten)]
    pub read: InputArgs,
    /// Options of the tasks.
    #[command(flatten)]
    pub task: TaskArgs,
}

/// What `run` found for one sample: `metrics.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SampleReport {
    /// Layout version of this file ([`polar_eval::SCHEMA_VERSION`]).
    pub schema_version: u32,
    /// The input file read.
    pub input: String,
    /// Image width and height.
    pub size: [usize; 2],
    /// Seconds to read and demosaic.
    pub read_seconds: f64,
    /// Warnings about the input (e.g. saturated pixels).
    pub warnings: Vec<String>,
    /// Per task: status, messages, time and metrics.
    pub tasks: BTreeMap<String, Summary>,
}

impl SampleReport {
    /// `true` when every task succeeded.
    pub fn all_ok(&self) -> bool {
        self.tasks.values().all(|s| s.ok)
    }
}

/// Runs the subcommand; `Ok(false)` when a task could not run.
pub fn run(args: &RunArgs) -> Result<bool, CliError> {
    args.task.check_models(&args.tasks)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.map_or(0, usize::from))
        .build()
        .map_err(|e| CliError::Threads(e.to_string()))?;
    let report = pool.install(|| run_sample(&args.sample, &args.out, args))?;
    report
        .warnings
        .iter()
        .for_each(|w| eprintln!("warning: {w}"));
    for (task, s) in &report.tasks {
        let status = if s.ok { "ok" } else { "FAILED" };
        eprintln!("{task}: {status} in {:.3} s", s.seconds);
        for m in &s.messages {
            eprintln!("  {m}");
        }
    }
    Ok(report.all_ok())
}

/// Reads `sample`, runs the tasks of `args`, writes every output into `out`, and returns
/// the report (also written as `metrics.json` where the sample has ground truth).
pub fn run_sample(sample: &Path, out: &Path, args: &RunArgs) -> Result<SampleReport, CliError> {
    let file = resolve(sample, args.input)?;
    out_dir::check(sample, out)?;
    let start = Instant::now();
    let dir = sample.is_dir().then_some(sample);
    let meta = dir.map(polar_io::read_optional_meta).transpose()?.flatten();
    let reading = read_input(&file, &args.read)?;
    let (mut obs, mut warnings) = (reading.obs, reading.warnings);
    obs.camera = camera_model(args.task.fov, meta.as_ref());
    let gt = match dir {
        Some(d) => polar_io::read_ground_truth(d, Validation::Check)?,
        None => GroundTruth::default(),
    };
    check_gt_size(sample, &gt, obs.size())?;
    let known_objects = args
        .task
        .objects
        .as_ref()
        .map(|source| read_objects(source, sample, &gt, obs.size()))
        .transpose()?;
    if let Some((path, mask)) = &known_objects
        && mask.as_slice().iter().all(|&v| v == 0)
    {
        warnings.push(format!(
            "{}: the object mask marks no pixel; the tasks that take it find no object",
            path.display()
        ));
    }
    let known_objects = known_objects.map(|(_, mask)| mask);
    let read_seconds = start.elapsed().as_secs_f64();
    let raw_mask = matches!(file, InputFile::Raw(_)).then_some(&obs.flags);
    let staged = out_dir::stage(out)?;
    let out = staged.path();
    let planes = Planes {
        planes: &obs.planes,
        colors: reading.colors.as_ref(),
    };
    write_outputs(out, planes, raw_mask, &Output::ALL)?;
    std::fs::create_dir_all(out.join(vision::PICTURES))
        .map_err(|e| CliError::write(out.join(vision::PICTURES), e))?;
    let mut ctx = Context {
        obs: &obs,
        gt: &gt,
        out,
        radiance_per_unit: radiance_per_unit(&file, dir, &obs, &gt)?,
        known_objects,
        normals: None,
        objects: None,
        transparent: None,
    };
    let (w, h) = obs.size();
    let megapixels = (w * h) as f64 / 1e6;
    let mut tasks = BTreeMap::new();
    for task in Task::ALL.into_iter().filter(|t| args.tasks.contains(t)) {
        let t0 = Instant::now();
        let result = crate::task_options::execute(task, &mut ctx, &args.task);
        let seconds = t0.elapsed().as_secs_f64();
        let summary = match result {
            Ok(o) => Summary {
                ok: true,
                messages: o.messages,
                seconds,
                megapixels,
                metrics: o.metrics,
            },
            Err(Failure::Cli(e)) => return Err(e),
            Err(f @ Failure::CannotRun(_)) => Summary {
                ok: false,
                messages: vec![f.to_string()],
                seconds,
                megapixels,
                metrics: None,
            },
        };
        tasks.insert(task.name().to_owned(), summary);
    }
    let report = SampleReport {
        schema_version: SCHEMA_VERSION,
        input: file_name(&file),
        size: [w, h],
        read_seconds,
        warnings,
        tasks,
    };
    if has_any(&gt) {
        polar_io::write_json(out.join(vision::METRICS), &report)?;
    }
    out_dir::commit(staged)?;
    Ok(report)
}

/// The factor from the observation's unit to the ground truth's radiance, for metrics that
/// compare intensities (dehazing): 1 for `stokes.exr` input; for a raw mosaic, the least
/// squares gain from its S0 to the sample's `stokes.exr` S0 over valid pixels (a camera
/// frame is in DN, the truth in radiance). `None` where neither tells.
fn radiance_per_unit(
    file: &InputFile,
    dir: Option<&Path>,
    obs: &polar_sensor::Observation,
    gt: &GroundTruth,
) -> Result<Option<f64>, CliError> {
    let stokes = dir.map(|d| d.join(vision::STOKES)).filter(|p| p.is_file());
    match (file, stokes) {
        (InputFile::Stokes(_), _) => Ok(Some(1.0)),
        (InputFile::Raw(_), Some(path)) if gt.clear.is_some() || gt.dehazed.is_some() => {
            let truth = polar_io::read_exr_channel(&path, "S0")?;
            let s0 = obs.planes.s0.as_slice();
            Ok(polar_eval::gain_to(s0, truth.as_slice(), |k| {
                obs.is_valid(k)
            }))
        }
        _ => Ok(None),
    }
}

fn file_name(file: &InputFile) -> String {
    match file {
        InputFile::Raw(p) | InputFile::Stokes(p) => p.display().to_string(),
    }
}

fn has_any(gt: &GroundTruth) -> bool {
    *gt != GroundTruth::default()
}

/// The object mask `--objects` names for `sample`, of the frame's `size`, and the file it
/// came from: the sample's gt/material.png (label not 0; its size is checked with the rest
/// of the ground truth), or a PNG file ([`polar_io::read_mask_png`]), as given where it
/// exists and else inside the sample directory.
fn read_objects(
    source: &ObjectsSource,
    sample: &Path,
    gt: &GroundTruth,
    size: (usize, usize),
) -> Result<(PathBuf, Gray<u8>), CliError> {
    match source {
        ObjectsSource::GroundTruth => {
            let path = match sample.is_dir() {
                true => sample.join(files::GT_MATERIAL),
                false => sample.to_owned(),
            };
            match object_mask(gt) {
                Some(mask) => Ok((path, mask)),
                None => Err(CliError::Objects {
                    path,
                    reason: "missing: --objects gt reads a sample directory's gt/material.png"
                        .into(),
                }),
            }
        }
        ObjectsSource::File(p) => {
            let path = if p.exists() || p.is_absolute() || !sample.is_dir() {
                p.clone()
            } else {
                sample.join(p)
            };
            let mask = polar_io::read_mask_png(&path, size)?;
            Ok((path, mask))
        }
    }
}

/// Ground truth of another size than the input cannot be scored: a clear error.
fn check_gt_size(sample: &Path, gt: &GroundTruth, size: (usize, usize)) -> Result<(), CliError> {
    let sizes = [
        gt.normal.as_ref().map(|i| i.size()),
        gt.depth.as_ref().map(|i| i.size()),
        gt.material.as_ref().map(|i| i.size()),
        gt.transparent.as_ref().map(|i| i.size()),
        gt.clear.as_ref().map(|i| i.size()),
        gt.dehazed.as_ref().map(|i| i.size()),
        gt.transmission.as_ref().map(|i| i.size()),
    ];
    match sizes.into_iter().flatten().find(|&s| s != size) {
        Some(gt_size) => Err(CliError::GtSize {
            sample: sample.to_owned(),
            input: size,
            gt: gt_size,
        }),
        None => Ok(()),
    }
}
