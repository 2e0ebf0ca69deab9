//! `polar-vision eval`: every sample of a dataset through `run`, in parallel, resumable and
//! shardable; per-sample records, aggregates per family and task, and a summary table.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use polar_eval::{Aggregate, SCHEMA_VERSION, Summary, aggregate, family_of};
use polar_io::Shard;
use polar_io::files;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::CliError;
use crate::out_dir::prepare_resumable;
use crate::run::{RunArgs, SampleReport, run_sample};

/// Per-sample record kept under `OUT/samples/<name>/`, what makes a run resumable.
const RECORD: &str = polar_io::files::vision::EVAL_RECORD;

/// Arguments of `polar-vision eval`.
#[derive(Debug, Args)]
#[command(
    after_help = "Writes OUT/samples/<name>/ (the outputs of `run` for each sample and \
eval.json, its record), OUT/metrics.json (schema_version, per sample keyed by folder name, \
aggregates per family and task) and OUT/summary.md (a table). A sample that fails is recorded \
and the others go on. Rerunning the same command resumes: samples with a record made with the \
same options from the same files (names, sizes and modification times under the sample's \
folder) are not run again. With --shard K/N only the samples whose index i (sorted by \
name) has i mod N = K-1 are run; `polar-vision eval-merge` joins the shards' outputs."
)]
pub struct EvalArgs {
    /// A dataset folder: its sub-folders holding raw.png or stokes.exr are the samples
    /// (a polar-datagen output, or any folder of sample directories).
    pub dataset: PathBuf,
    /// How each sample is run (the options of `polar-vision run`).
    #[command(flatten)]
    pub run: EvalRunArgs,
    /// Samples evaluated at once (default: all cores).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub jobs: Option<u16>,
    /// Evaluate only shard K of N (1-based).
    #[arg(long, value_name = "K/N")]
    pub shard: Option<Shard>,
    /// Evaluate only the samples of these families (a sample folder's name without its
    /// trailing `-<digits>`, e.g. `sfp` for `sfp-00012`), comma-separated. Default: all.
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub family: Vec<String>,
}

/// `run`'s options as `eval` takes them (the sample comes from the dataset).
#[derive(Debug, Args)]
pub struct EvalRunArgs {
    /// Output directory: new, empty, or an earlier output of polar-vision (an evaluation
    /// with the same options resumes in it; samples run again are replaced as a whole).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Tasks, comma-separated (default: all).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = crate::tasks::Task::ALL)]
    pub tasks: Vec<crate::tasks::Task>,
    /// Which file of each sample to read (default: raw.png where there is one).
    #[arg(long, value_enum)]
    pub input: Option<crate::input::Source>,
    /// How to read the input.
    #[command(flatten)]
    pub read: crate::input::InputArgs,
    /// Options of the tasks.
    #[command(flatten)]
    task: crate::task_options::TaskArgs,
}

impl EvalRunArgs {
    fn as_run(&self, sample: &Path, out: &Path) -> RunArgs {
        RunArgs {
            sample: sample.to_owned(),
            out: out.to_owned(),
            tasks: self.tasks.clone(),
            input: self.input,
            threads: None,
            read: self.read.clone(),
            task: self.task.clone(),
        }
    }

    /// What must be equal for a stored record to be reused: the options and the contents
    /// of the models they name (a model retrained in place is a different model).
    fn fingerprint(&self) -> Result<String, CliError> {
        let models = self.task.model_digests()?;
        Ok(format!(
            "{:?}|{:?}|{:?}|{:?}|{models:?}",
            self.tasks, self.input, self.read, self.task
        ))
    }
}

/// One sample's record.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Record {
    /// The options it was made with ([`EvalRunArgs`]).
    pub options: String,
    /// The files under the sample's folder it was made from, with their sizes and
    /// modification times ([`Record`]s without it match no sample and are made again).
    #[serde(default)]
    pub inputs: String,
    /// The run's report, or why the sample could not be read.
    pub result: Result<SampleReport, String>,
}

/// Which samples an evaluation covered: shard `shard` of `shards` of the `samples` its
/// dataset and `--family` selected, so that `eval-merge` can tell a missing shard.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Selection {
    /// The shard, 1..=`shards`.
    pub shard: u32,
    /// Number of shards.
    pub shards: u32,
    /// Samples of the whole selection, every shard's.
    pub samples: usize,
}

/// `OUT/metrics.json` of `eval`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct EvalReport {
    /// Layout version.
    pub schema_version: u32,
    /// The samples the evaluation covered (absent in reports of earlier versions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub selection: Option<Selection>,
    /// Per sample (folder name): the report or the error.
    pub samples: BTreeMap<String, Result<SampleReport, String>>,
    /// Per family, per task: means of every metric, counts and time per megapixel.
    pub families: BTreeMap<String, BTreeMap<String, Aggregate>>,
}

/// Runs the subcommand; `Ok(false)` when a sample or a task failed.
pub fn eval(args: &EvalArgs) -> Result<bool, CliError> {
    args.run.task.check_models(&args.run.tasks)?;
    let samples = select_samples(&args.dataset, &args.family)?;
    let shard = args.shard.unwrap_or(Shard::ALL);
    let mine: Vec<&PathBuf> = samples
        .iter()
        .enumerate()
        .filter(|(i, _)| shard.owns(*i))
        .map(|(_, s)| s)
        .collect();
    let out = &args.run.out;
    prepare_resumable(out)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.map_or(0, usize::from))
        .build()
        .map_err(|e| CliError::Threads(e.to_string()))?;
    let bar = progress(mine.len());
    let fingerprint = args.run.fingerprint()?;
    let records: Vec<(String, Record)> = pool.install(|| {
        mine.par_iter()
            .map(|s| {
                let r = evaluate_one(s, out, &args.run, &fingerprint);
                bar.inc(1);
                r
            })
            .collect::<Result<_, _>>()
    })?;
    bar.finish_and_clear();
    let dirs = records
        .iter()
        .map(|(n, _)| (n.clone(), out.join("samples").join(n)))
        .collect();
    let selection = Selection {
        shard: shard.k,
        shards: shard.n,
        samples: samples.len(),
    };
    let report = write_report(
        out,
        records.into_iter().map(|(n, r)| (n, r.result)).collect(),
        &dirs,
        Some(selection),
    )?;
    print_failures(&report);
    Ok(report
        .samples
        .values()
        .all(|r| r.as_ref().is_ok_and(SampleReport::all_ok)))
}

/// Arguments of `polar-vision eval-merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The `--out` folders of the shards (or one folder all shards wrote into). A folder
    /// given twice is read once; a sample recorded in two of them, shards of other options
    /// or of another selection of samples, and shards that together miss samples of their
    /// selection (a shard not given or not finished) are errors.
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// Where the joined metrics.json and summary.md go.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// Joins the per-sample records of shard folders into one report.
pub fn merge(args: &MergeArgs) -> Result<bool, CliError> {
    let mut samples = BTreeMap::new();
    let mut dirs = BTreeMap::new();
    let mut options: Option<String> = None;
    let mut read = BTreeSet::new();
    let mut selections = Vec::new();
    for dir in &args.shards {
        if !read.insert(dir.canonicalize().map_err(|e| CliError::read(dir, e))?) {
            continue;
        }
        selections.push((dir, read_selection(dir)?));
        for (name, record) in read_records(dir)? {
            let here = dir.join("samples").join(&name);
            if options.get_or_insert_with(|| record.options.clone()) != &record.options {
                return Err(CliError::MergeOptions(here));
            }
            if let Some(first) = dirs.insert(name.clone(), here.clone()) {
                return Err(CliError::MergeDuplicate {
                    name,
                    first,
                    second: here,
                });
            }
            samples.insert(name, record.result);
        }
    }
    if samples.is_empty() {
        return Err(CliError::NoSamples(args.shards[0].clone()));
    }
    let selection = whole_selection(&selections, samples.len())?;
    prepare_resumable(&args.out)?;
    let report = write_report(&args.out, samples, &dirs, selection)?;
    print_failures(&report);
    Ok(report.samples.values().all(Result::is_ok))
}

/// The [`Selection`] in a shard folder's metrics.json; `None` where the file or the entry
/// is absent (a report of an earlier version, or a shard that wrote none).
fn read_selection(dir: &Path) -> Result<Option<Selection>, CliError> {
    #[derive(Deserialize)]
    struct Head {
        #[serde(default)]
        selection: Option<Selection>,
    }
    let path = dir.join(files::vision::METRICS);
    if !path.is_file() {
        return Ok(None);
    }
    Ok(polar_io::read_json::<Head>(&path)?.selection)
}

/// The selection the merged shards make up, after checking that they come from one
/// selection and that together they hold all of its `found` samples; `None`, unchecked,
/// when a shard folder does not say its selection.
fn whole_selection(
    selections: &[(&PathBuf, Option<Selection>)],
    found: usize,
) -> Result<Option<Selection>, CliError> {
    let Some(known) = selections
        .iter()
        .map(|(_, s)| *s)
        .collect::<Option<Vec<Selection>>>()
    else {
        return Ok(None);
    };
    let first = known[0];
    let same = |s: &Selection| (s.shards, s.samples) == (first.shards, first.samples);
    if let Some(i) = known.iter().position(|s| !same(s)) {
        return Err(CliError::MergeSelection(selections[i].0.clone()));
    }
    if found != first.samples {
        let seen: BTreeSet<u32> = known.iter().map(|s| s.shard).collect();
        return Err(CliError::MergeIncomplete {
            found,
            expected: first.samples,
            seen: seen
                .iter()
                .map(u32::to_string)
                .collect::<Vec<_>>()
                .join(", "),
            shards: first.shards,
        });
    }
    Ok(Some(Selection {
        shard: 1,
        shards: 1,
        samples: found,
    }))
}

/// The sample directories under `dataset`, sorted by name (hidden folders skipped).
pub fn list_samples(dataset: &Path) -> Result<Vec<PathBuf>, CliError> {
    let entries = std::fs::read_dir(dataset).map_err(|e| CliError::read(dataset, e))?;
    let mut out = Vec::new();
    for e in entries {
        let path = e.map_err(|e| CliError::read(dataset, e))?.path();
        let hidden = path
            .file_name()
            .and_then(|n| n.to_str())
            .is_none_or(|n| n.starts_with('.'));
        let is_sample = path.join(files::RAW).is_file() || path.join(files::STOKES).is_file();
        if path.is_dir() && !hidden && is_sample {
            out.push(path);
        }
    }
    out.sort();
    if out.is_empty() {
        return Err(CliError::NoSamples(dataset.to_owned()));
    }
    Ok(out)
}

/// The sample directories of `dataset` ([`list_samples`]) of the given families (all when
/// `families` is empty).
pub fn select_samples(dataset: &Path, families: &[String]) -> Result<Vec<PathBuf>, CliError> {
    let mut samples = list_samples(dataset)?;
    if !families.is_empty() {
        samples.retain(|s| families.iter().any(|f| f == family_of(&sample_name(s))));
        if samples.is_empty() {
            return Err(CliError::NoSamples(dataset.to_owned()));
        }
    }
    Ok(samples)
}

fn sample_name(sample: &Path) -> String {
    sample
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Runs one sample unless its record made with the same options from the same files
/// exists; records the result.
fn evaluate_one(
    sample: &Path,
    out: &Path,
    run: &EvalRunArgs,
    fingerprint: &str,
) -> Result<(String, Record), CliError> {
    let name = sample_name(sample);
    let dir = out.join("samples").join(&name);
    let path = dir.join(RECORD);
    let inputs = input_stamp(sample);
    if let Ok(old) = polar_io::read_json::<Record>(&path)
        && old.options == fingerprint
        && old.inputs == inputs
    {
        return Ok((name, old));
    }
    let result = run_sample(sample, &dir, &run.as_run(sample, &dir)).map_err(|e| e.to_string());
    let record = Record {
        options: fingerprint.to_owned(),
        inputs,
        result,
    };
    prepare_resumable(&dir)?;
    polar_io::write_json(&path, &record)?;
    Ok((name, record))
}

/// The files under `sample`, each with its size and modification time (a symbolic link's
/// target's; a link is not descended into, so a link to a parent folder is no loop), in
/// name order: a sample rendered again or a file of it replaced since its record was made
/// does not resume from that record. What cannot be read is stamped as such; reading the
/// sample then fails in its run, which its record keeps.
fn input_stamp(sample: &Path) -> String {
    let mut files = Vec::new();
    let mut folders = vec![sample.to_owned()];
    while let Some(folder) = folders.pop() {
        let Ok(entries) = std::fs::read_dir(&folder) else {
            files.push(format!("{} unreadable", folder.display()));
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if entry.file_type().is_ok_and(|t| t.is_dir()) {
                folders.push(path);
                continue;
            }
            let name = path.strip_prefix(sample).unwrap_or(&path).display();
            files.push(match std::fs::metadata(&path) {
                Ok(meta) => format!("{name} {} {}", meta.len(), modified_nanos(&meta)),
                Err(_) => format!("{name} unreadable"),
            });
        }
    }
    files.sort();
    files.join("; ")
}

/// Modification time in nanoseconds since the Unix epoch, 0 where the system gives none.
fn modified_nanos(meta: &std::fs::Metadata) -> u128 {
    meta.modified()
        .ok()
        .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
        .map_or(0, |d| d.as_nanos())
}

fn read_records(dir: &Path) -> Result<Vec<(String, Record)>, CliError> {
    let root = dir.join("samples");
    let entries = std::fs::read_dir(&root).map_err(|e| CliError::read(&root, e))?;
    let mut out = Vec::new();
    for e in entries {
        let path = e.map_err(|e| CliError::read(&root, e))?.path().join(RECORD);
        if path.is_file() {
            let name = sample_name(path.parent().expect("a record lies in a sample folder"));
            out.push((name, polar_io::read_json(&path)?));
        }
    }
    Ok(out)
}

/// Writes metrics.json and summary.md into `out`, with the pictures of each task's worst
/// samples ([`WORST`]) copied from their output folders `dirs` (sample name -> folder).
fn write_report(
    out: &Path,
    samples: BTreeMap<String, Result<SampleReport, String>>,
    dirs: &BTreeMap<String, PathBuf>,
    selection: Option<Selection>,
) -> Result<EvalReport, CliError> {
    let ok: BTreeMap<String, BTreeMap<String, Summary>> = samples
        .iter()
        .filter_map(|(n, r)| r.as_ref().ok().map(|r| (n.clone(), r.tasks.clone())))
        .collect();
    let report = EvalReport {
        schema_version: SCHEMA_VERSION,
        selection,
        families: aggregate(&ok),
        samples,
    };
    polar_io::write_json(out.join(files::vision::METRICS), &report)?;
    remove_worst_pictures(out)?;
    let mut summary = summary_markdown(&report);
    for of in &WORST {
        let worst = worst_samples(&report, of);
        let pictures = copy_worst_pictures(out, dirs, of, &worst)?;
        summary += &worst_markdown(of, &worst, &pictures);
    }
    std::fs::write(out.join("summary.md"), summary)
        .map_err(|e| CliError::write(out.join("summary.md"), e))?;
    Ok(report)
}

/// The headline figures of each task, in the order a reader looks for them.
const HEADLINES: [(&str, &str, &str); 18] = [
    ("sfp", "normal.mean_deg", "mean angular error (deg)"),
    (
        "sfp",
        "normal.coverage",
        "share of object pixels with a normal",
    ),
    ("sfp", "normal.median_deg", "median angular error (deg)"),
    ("sfp", "normal.depth.relative_rmse", "depth RMSE / range"),
    (
        "material",
        "metal_vs_dielectric_accuracy",
        "metal vs dielectric accuracy",
    ),
    (
        "material",
        "opaque_coverage",
        "share of opaque object pixels labelled metal or dielectric",
    ),
    ("material", "class_iou.1", "dielectric IoU"),
    ("material", "class_iou.2", "metal IoU"),
    ("transparent", "iou", "mask IoU"),
    (
        "transparent",
        "false_positive_on_distractors",
        "false positives on opaque objects",
    ),
    (
        "dehaze",
        "against_dehazed.dehazed.psnr_db",
        "dehazed PSNR vs gt/dehazed (dB)",
    ),
    (
        "dehaze",
        "against_dehazed.hazy.psnr_db",
        "hazy PSNR vs gt/dehazed (dB)",
    ),
    (
        "dehaze",
        "against_dehazed.reachable.dehazed_psnr_db",
        "dehazed PSNR vs gt/dehazed, reachable pixels (dB)",
    ),
    (
        "dehaze",
        "against_dehazed.reachable.hazy_psnr_db",
        "hazy PSNR vs gt/dehazed, reachable pixels (dB)",
    ),
    (
        "dehaze",
        "against_dehazed.objects.dehazed.psnr_db",
        "dehazed PSNR vs gt/dehazed, object pixels (dB)",
    ),
    (
        "dehaze",
        "against_dehazed.objects.hazy.psnr_db",
        "hazy PSNR vs gt/dehazed, object pixels (dB)",
    ),
    (
        "dehaze",
        "against_clear.dehazed.psnr_db",
        "dehazed PSNR vs gt/clear (dB)",
    ),
    (
        "dehaze",
        "against_dehazed.transmission_correlation",
        "transmission correlation",
    ),
];

/// `summary.md`: per family and task, the sample counts, time per megapixel and headlines.
pub fn summary_markdown(report: &EvalReport) -> String {
    let failed = report.samples.values().filter(|r| r.is_err()).count();
    let mut s = format!(
        "# Evaluation summary\n\n{} samples, {failed} unreadable.\n\n\
| family | task | ok | failed | s / MP | figure | mean |\n|---|---|---|---|---|---|---|\n",
        report.samples.len()
    );
    for (family, tasks) in &report.families {
        for (task, agg) in tasks {
            let time = agg.seconds_per_mp.map_or("-".into(), |t| format!("{t:.3}"));
            let figures: Vec<(&str, f64)> = HEADLINES
                .iter()
                .filter(|(t, _, _)| t == task)
                .filter_map(|(_, key, label)| agg.means.get(*key).map(|v| (*label, *v)))
                .collect();
            let head = format!(
                "| {family} | {task} | {} | {} | {time} |",
                agg.samples, agg.failed
            );
            if figures.is_empty() {
                let _ = writeln!(s, "{head} - | - |");
            }
            for (label, v) in figures {
                let _ = writeln!(s, "{head} {label} | {v:.4} |");
            }
        }
    }
    s
}

/// How many samples per task summary.md shows as the worst.
pub const WORST_SAMPLES: usize = 5;

/// A sample's name and its task's metrics.
type Scored<'a> = (&'a str, &'a serde_json::Value);

/// A task whose worst samples summary.md shows, with the picture each sample's run wrote.
struct WorstOf {
    /// The task, as in a sample's `tasks`.
    task: &'static str,
    /// The figure that ranks the samples: a dotted path into the task's metrics.
    key: &'static str,
    /// Larger values of the figure are worse (an error, not an accuracy).
    larger_is_worse: bool,
    /// The picture (in the sample's `pictures/`) copied to
    /// `pictures/worst-<task>-<rank>-<name>.png`.
    picture: &'static str,
    /// summary.md's section: its heading after "the N samples with the", its text, and the
    /// columns between the sample's name and its picture, with their cells.
    heading: &'static str,
    text: &'static str,
    columns: &'static [&'static str],
    cells: fn(&serde_json::Value) -> Vec<String>,
}

/// The tasks whose worst samples summary.md shows.
const WORST: [WorstOf; 3] = [
    WorstOf {
        task: "sfp",
        key: "normal.mean_deg",
        larger_is_worse: true,
        picture: files::vision::pictures::NORMAL_ERROR,
        heading: "largest mean angular error",
        text: "Mean angular error (deg) over object pixels, overall and per reflection type \
the method chose (a type's error says where it fails: wrong azimuth from a specular/diffuse \
mix-up, wrong zenith from the index or dilution). Pictures: S0 | estimated normals | true \
normals | angular error (viridis, 0 to 90 deg).",
        columns: &[
            "mean", "median", "diffuse", "specular", "mixed", "none", "index",
        ],
        cells: sfp_cells,
    },
    WorstOf {
        task: "material",
        key: "metal_vs_dielectric_accuracy",
        larger_is_worse: false,
        picture: files::vision::pictures::MATERIAL_ERROR,
        heading: "lowest metal vs dielectric accuracy",
        text: "Accuracy over the opaque object pixels labelled metal or dielectric, the share \
of them so labelled, and the classes' IoU. Pictures: S0 | estimated labels | true labels \
(dielectric orange, metal blue, transparent cyan).",
        columns: &["accuracy", "labelled share", "dielectric IoU", "metal IoU"],
        cells: material_cells,
    },
    WorstOf {
        task: "transparent",
        key: "iou",
        larger_is_worse: false,
        picture: files::vision::pictures::TRANSPARENT_ERROR,
        heading: "smallest mask IoU",
        text: "Low precision is glass marked where there is none (shiny opaque objects, \
edges, shadows); low recall is glass missed. Pictures: S0 | the mask against the truth: found \
green, false red, missed blue.",
        columns: &[
            "IoU",
            "precision",
            "recall",
            "false positives on opaque objects",
        ],
        cells: transparent_cells,
    },
];

/// The task's metrics of the [`WORST_SAMPLES`] samples with the worst `of.key`, worst first
/// (ties by name); samples without the figure are left out.
fn worst_samples<'a>(report: &'a EvalReport, of: &WorstOf) -> Vec<Scored<'a>> {
    let mut scored: Vec<(&str, &serde_json::Value, f64)> = report
        .samples
        .iter()
        .filter_map(|(name, r)| {
            let metrics = r.as_ref().ok()?.tasks.get(of.task)?.metrics.as_ref()?;
            let value = of.key.split('.').fold(metrics, |v, k| &v[k]).as_f64()?;
            Some((name.as_str(), metrics, value))
        })
        .collect();
    scored.sort_by(|a, b| {
        let order = if of.larger_is_worse {
            b.2.total_cmp(&a.2)
        } else {
            a.2.total_cmp(&b.2)
        };
        order.then(a.0.cmp(b.0))
    });
    scored
        .into_iter()
        .take(WORST_SAMPLES)
        .map(|(n, m, _)| (n, m))
        .collect()
}

/// Removes the worst-sample pictures of an earlier report from `OUT/pictures/`.
fn remove_worst_pictures(out: &Path) -> Result<(), CliError> {
    let Ok(entries) = std::fs::read_dir(out.join(files::vision::PICTURES)) else {
        return Ok(());
    };
    for e in entries.flatten() {
        if e.file_name().to_string_lossy().starts_with("worst-") {
            std::fs::remove_file(e.path()).map_err(|err| CliError::write(e.path(), err))?;
        }
    }
    Ok(())
}

/// Copies each worst sample's picture to `OUT/pictures/worst-<task>-<rank>-<name>.png`;
/// the relative paths, `None` where a sample has no picture.
fn copy_worst_pictures(
    out: &Path,
    dirs: &BTreeMap<String, PathBuf>,
    of: &WorstOf,
    worst: &[Scored<'_>],
) -> Result<Vec<Option<String>>, CliError> {
    let folder = out.join(files::vision::PICTURES);
    let mut paths = Vec::new();
    for (rank, (name, _)) in worst.iter().enumerate() {
        let src = dirs
            .get(*name)
            .map(|d| d.join(files::vision::PICTURES).join(of.picture));
        let Some(src) = src.filter(|p| p.is_file()) else {
            paths.push(None);
            continue;
        };
        std::fs::create_dir_all(&folder).map_err(|e| CliError::write(&folder, e))?;
        let rel = format!(
            "{}/worst-{}-{}-{name}.png",
            files::vision::PICTURES,
            of.task,
            rank + 1
        );
        std::fs::copy(&src, out.join(&rel)).map_err(|e| CliError::write(out.join(&rel), e))?;
        paths.push(Some(rel));
    }
    Ok(paths)
}

/// summary.md's section of a task's worst samples: their figures and pictures.
fn worst_markdown(of: &WorstOf, worst: &[Scored<'_>], pictures: &[Option<String>]) -> String {
    if worst.is_empty() {
        return String::new();
    }
    let mut s = format!(
        "\n## {}: the {} samples with the {}\n\n{}\n\n| sample | {} | picture |\n|{}\n",
        of.task,
        worst.len(),
        of.heading,
        of.text,
        of.columns.join(" | "),
        "---|".repeat(of.columns.len() + 2),
    );
    for ((name, m), picture) in worst.iter().zip(pictures) {
        let picture = picture
            .as_ref()
            .map_or("-".into(), |p| format!("![{name}]({p})"));
        let _ = writeln!(s, "| {name} | {} | {picture} |", (of.cells)(m).join(" | "));
    }
    s
}

/// A figure with `decimals` decimals, `-` where absent.
fn figure(v: &serde_json::Value, decimals: usize) -> String {
    v.as_f64().map_or("-".into(), |x| format!("{x:.decimals$}"))
}

/// An sfp sample's mean and median error, its mean per reflection type and its index.
fn sfp_cells(m: &serde_json::Value) -> Vec<String> {
    let (n, by_type) = (&m["normal"], &m["normal"]["mean_deg_by_type"]);
    let index = m["ior"]["value"].as_f64().map_or("-".into(), |v| {
        format!("{v:.3} ({})", m["ior"]["source"].as_str().unwrap_or("?"))
    });
    let mut cells: Vec<String> = [&n["mean_deg"], &n["median_deg"]]
        .into_iter()
        .chain(["diffuse", "specular", "mixed", "none"].map(|t| &by_type[t]))
        .map(|v| figure(v, 1))
        .collect();
    cells.push(index);
    cells
}

/// A material sample's accuracy, labelled share and class IoUs.
fn material_cells(m: &serde_json::Value) -> Vec<String> {
    [
        &m["metal_vs_dielectric_accuracy"],
        &m["opaque_coverage"],
        &m["class_iou"][1],
        &m["class_iou"][2],
    ]
    .map(|v| figure(v, 3))
    .to_vec()
}

/// A transparency sample's mask figures.
fn transparent_cells(m: &serde_json::Value) -> Vec<String> {
    [
        "iou",
        "precision",
        "recall",
        "false_positive_on_distractors",
    ]
    .map(|k| figure(&m[k], 3))
    .to_vec()
}

/// A progress bar over `n` samples.
pub fn progress(n: usize) -> ProgressBar {
    let bar = ProgressBar::new(n as u64);
    if let Ok(style) =
        ProgressStyle::with_template("{bar:40} {pos}/{len} samples, {elapsed} ({eta} left)")
    {
        bar.set_style(style);
    }
    bar
}

fn print_failures(report: &EvalReport) {
    for (name, r) in &report.samples {
        match r {
            Err(e) => eprintln!("{name}: {e}"),
            Ok(rep) => {
                for (task, s) in rep.tasks.iter().filter(|(_, s)| !s.ok) {
                    eprintln!("{name}: {task}: {}", s.messages.join("; "));
                }
            }
        }
    }
}
