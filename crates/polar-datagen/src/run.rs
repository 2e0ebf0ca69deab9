//! Running a suite: plan the samples of a shard, skip the ones already committed, produce the
//! rest in parallel (each sample is independent and seeded), commit each atomically, report.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use polar_io::{StagedDir, files};
use polar_render::Polarization;
use rayon::prelude::*;

pub use polar_io::Shard;

use crate::Error;
use crate::params::{SampleParams, draw_params};
use crate::progress::Progress;
use crate::store::{self, ManifestEntry, RunRecord, Timings};
use crate::suite::{SizeName, Suite};

/// What the per-sample work reports back to the runner.
#[derive(Clone, Debug, PartialEq)]
pub struct WorkReport {
    /// Light-transport model the renderer chose (e.g. which bounces and BSDF lobes it needed).
    pub model: Polarization,
    /// Seconds spent rendering.
    pub render_seconds: f64,
}

/// The per-sample work: write every file of one sample (meta.json, raw.png, stokes.exr, gt/...)
/// into `dir`, an existing empty staging directory. Must depend only on `params`.
pub trait SampleWorker: Sync {
    /// Produces one sample into `dir`.
    fn produce(&self, params: &SampleParams, dir: &Path) -> Result<WorkReport, Error>;
}

/// Every sample of the suite at `size`, in global order.
pub fn plan(suite: &Suite, size: SizeName) -> Vec<SampleParams> {
    suite
        .families
        .iter()
        .flat_map(|f| (0..f.size(size).count).map(move |i| draw_params(suite, f, size, i)))
        .collect()
}

/// The samples of one shard.
pub fn plan_shard(suite: &Suite, size: SizeName, shard: Shard) -> Vec<SampleParams> {
    plan(suite, size)
        .into_iter()
        .enumerate()
        .filter(|(i, _)| shard.owns(*i))
        .map(|(_, p)| p)
        .collect()
}

/// How to run a suite.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Dataset directory.
    pub out: PathBuf,
    /// `ci` or `full`.
    pub size: SizeName,
    /// Which shard to make.
    pub shard: Shard,
    /// Samples rendered at once (each also uses rayon inside the renderer).
    pub jobs: usize,
    /// Show a progress bar (terminal) or plain lines.
    pub progress: Progress,
}

/// Per-family line of the final summary.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FamilySummary {
    /// Family kind name.
    pub kind: String,
    /// Samples this shard owns.
    pub expected: usize,
    /// Samples found committed from an earlier run.
    pub resumed: usize,
    /// Samples made by this run.
    pub made: usize,
    /// Render seconds over all committed samples of the family.
    pub render_seconds: f64,
    /// Light-transport models used.
    pub models: BTreeSet<Polarization>,
}

/// The outcome of a suite run.
#[derive(Clone, Debug, Default)]
pub struct RunSummary {
    /// By family name, in suite order via `order`.
    pub families: BTreeMap<String, FamilySummary>,
    /// Family names in suite order.
    pub order: Vec<String>,
    /// Wall-clock seconds of this run.
    pub seconds: f64,
}

/// Most samples rendered at once (`--jobs`): far above any machine's cores, low enough that
/// the thread pool can start.
pub const MAX_JOBS: usize = 1024;

/// A dataset directory ready for [`run_suite`]: its run record, and its lock, held until this
/// value is dropped so that no other run writes into the directory meanwhile.
#[derive(Debug)]
pub struct PreparedRun {
    /// The run record of the directory.
    pub record: RunRecord,
    _lock: fs::File,
}

/// Checks the options and the output directory (new, empty, or a dataset of this same run),
/// takes its lock and writes the run record, before any rendering.
pub fn prepare_output(
    suite: &Suite,
    suite_text: &str,
    opts: &RunOptions,
) -> Result<PreparedRun, Error> {
    if !(1..=MAX_JOBS).contains(&opts.jobs) {
        return Err(Error::Option {
            option: "--jobs",
            message: format!("{} must be in 1..={MAX_JOBS} (0 = one per CPU)", opts.jobs),
        });
    }
    store::check_dataset_dir(&opts.out)?;
    store::ensure_writable(&opts.out)?;
    let lock = store::lock_dataset(&opts.out)?;
    let record = RunRecord {
        suite: suite.name.clone(),
        suite_sha256: polar_io::sha256_hex(suite_text.as_bytes()),
        size: opts.size,
        shard: opts.shard.k,
        shards: opts.shard.n,
        expected: plan_shard(suite, opts.size, opts.shard).len(),
    };
    let path = opts.out.join(store::RUN_RECORD);
    let old_missing = !path.exists();
    if !old_missing {
        let old: RunRecord = polar_io::read_json(&path)?;
        if old != record {
            let reason = if old.suite_sha256 != record.suite_sha256 {
                format!("suite '{}' with another text", old.suite)
            } else {
                format!("size {:?}, shard {}/{}", old.size, old.shard, old.shards)
            };
            return Err(Error::RunMismatch {
                path: opts.out.clone(),
                reason,
            });
        }
    } else {
        polar_io::write_json(&path, &record)?;
    }
    // Written after the run record, which marks the directory as a dataset of this program.
    let copy = opts.out.join(store::SUITE_COPY);
    if !copy.exists() || old_missing {
        polar_io::write_atomic(&copy, suite_text.as_bytes())?;
    }
    Ok(PreparedRun {
        record,
        _lock: lock,
    })
}

/// `params` as the manifest records them (serialised and read back), so that a recorded
/// sample compares equal to its plan bit for bit.
fn as_recorded(params: &SampleParams) -> Option<SampleParams> {
    let text = serde_json::to_string(params).ok()?;
    serde_json::from_str(&text).ok()
}

/// Keeps the manifest entries of this shard whose files are intact and whose seed and
/// parameters are the planned ones (a dataset whose run record was lost may hold samples of
/// another suite); removes staging leftovers and the sample directories not kept, so they are
/// made again. A directory named like a sample that this program did not write (no manifest
/// entry, no meta.json) is an error, never deleted.
fn recover(out: &Path, jobs: &[SampleParams]) -> Result<Vec<ManifestEntry>, Error> {
    let staging = out.join(store::STAGING);
    if staging.exists() {
        fs::remove_dir_all(&staging).map_err(Error::io(&staging))?;
    }
    let planned: BTreeMap<&str, &SampleParams> = jobs.iter().map(|p| (p.id.as_str(), p)).collect();
    let manifest = store::read_manifest(out)?;
    let recorded: BTreeSet<&str> = manifest.iter().map(|e| e.id.as_str()).collect();
    let mut kept: Vec<ManifestEntry> = Vec::new();
    let mut kept_ids: BTreeSet<&str> = BTreeSet::new();
    for e in &manifest {
        let fine = planned
            .get(e.id.as_str())
            .is_some_and(|p| e.seed == p.seed && as_recorded(p).as_ref() == Some(&e.params))
            && out.join(&e.id).is_dir()
            && !kept_ids.contains(e.id.as_str())
            && store::verify_entry(out, e).is_ok();
        if fine {
            kept_ids.insert(&e.id);
            kept.push(e.clone());
        }
    }
    for id in planned.keys() {
        let dir = out.join(id);
        if !dir.exists() || kept_ids.contains(id) {
            continue;
        }
        if !recorded.contains(id) && !dir.join(polar_io::files::META).is_file() {
            return Err(Error::Sample {
                id: (*id).to_owned(),
                message: format!(
                    "{} was not written by polar-datagen (no manifest entry, no meta.json); move it out of the dataset, it is never deleted",
                    dir.display()
                ),
            });
        }
        fs::remove_dir_all(&dir).map_err(Error::io(&dir))?;
    }
    store::write_manifest(out, &kept)?;
    Ok(kept)
}

/// Produces, checksums and commits one sample; returns its manifest entry.
fn make_one(
    worker: &dyn SampleWorker,
    out: &Path,
    params: &SampleParams,
) -> Result<ManifestEntry, Error> {
    let start = Instant::now();
    let staged = StagedDir::within(
        &out.join(&params.id),
        &out.join(store::STAGING),
        files::META,
    )?;
    let report = worker.produce(params, staged.path())?;
    let files = store::checksum_dir(staged.path())?;
    staged.commit()?;
    Ok(ManifestEntry {
        id: params.id.clone(),
        seed: params.seed,
        params: params.clone(),
        files,
        model: report.model,
        timings: Timings {
            render_seconds: report.render_seconds,
            total_seconds: start.elapsed().as_secs_f64(),
        },
    })
}

/// Runs (or resumes) one shard of a suite. Call [`prepare_output`] first.
pub fn run_suite(
    suite: &Suite,
    opts: &RunOptions,
    worker: &dyn SampleWorker,
) -> Result<RunSummary, Error> {
    let start = Instant::now();
    let jobs = plan_shard(suite, opts.size, opts.shard);
    let kept = recover(&opts.out, &jobs)?;
    let done: BTreeSet<String> = kept.iter().map(|e| e.id.clone()).collect();
    let todo: Vec<&SampleParams> = jobs.iter().filter(|p| !done.contains(&p.id)).collect();
    let mut summary = summary_skeleton(suite, &jobs, &kept);
    let progress = opts.progress.start(todo.len() as u64, kept.len() as u64);
    let entries = Mutex::new(kept);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs.max(1))
        .build()
        .map_err(|e| Error::Option {
            option: "--jobs",
            message: format!("cannot start {} threads: {e}", opts.jobs),
        })?;
    pool.install(|| {
        todo.par_iter().try_for_each(|p| {
            let entry = make_one(worker, &opts.out, p)?;
            let mut all = entries.lock().unwrap_or_else(|e| e.into_inner());
            store::append_manifest(&opts.out, &entry)?;
            progress.tick(&entry.id, entry.timings.total_seconds);
            all.push(entry);
            Ok::<(), Error>(())
        })
    })?;
    progress.finish();
    let entries = entries.into_inner().unwrap_or_else(|e| e.into_inner());
    store::write_manifest(&opts.out, &entries)?;
    let staging = opts.out.join(store::STAGING);
    if staging.exists() {
        fs::remove_dir_all(&staging).map_err(Error::io(&staging))?;
    }
    for e in entries.iter().filter(|e| !done.contains(&e.id)) {
        if let Some(f) = summary.families.get_mut(&e.params.family) {
            f.made += 1;
            add_entry(f, e);
        }
    }
    summary.seconds = start.elapsed().as_secs_f64();
    Ok(summary)
}

fn add_entry(f: &mut FamilySummary, e: &ManifestEntry) {
    f.render_seconds += e.timings.render_seconds;
    f.models.insert(e.model);
}

fn summary_skeleton(suite: &Suite, jobs: &[SampleParams], kept: &[ManifestEntry]) -> RunSummary {
    let mut s = RunSummary::default();
    for fam in &suite.families {
        let mut f = FamilySummary {
            kind: fam.kind.name().into(),
            expected: jobs.iter().filter(|p| p.family == fam.name).count(),
            ..FamilySummary::default()
        };
        for e in kept.iter().filter(|e| e.params.family == fam.name) {
            f.resumed += 1;
            add_entry(&mut f, e);
        }
        s.order.push(fam.name.clone());
        s.families.insert(fam.name.clone(), f);
    }
    s
}

impl RunSummary {
    /// The final table: one row per family, then a total.
    pub fn table(&self) -> String {
        let mut t = format!(
            "{:<16} {:<12} {:>8} {:>8} {:>6} {:>10}  {}\n",
            "family", "kind", "samples", "resumed", "made", "render s", "light-transport model"
        );
        let mut total = FamilySummary::default();
        for name in &self.order {
            let Some(f) = self.families.get(name) else {
                continue;
            };
            let model = if f.models.is_empty() {
                "-".into()
            } else {
                f.models
                    .iter()
                    .map(|m| format!("{m:?}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            t.push_str(&format!(
                "{:<16} {:<12} {:>8} {:>8} {:>6} {:>10.1}  {}\n",
                name, f.kind, f.expected, f.resumed, f.made, f.render_seconds, model
            ));
            total.expected += f.expected;
            total.resumed += f.resumed;
            total.made += f.made;
            total.render_seconds += f.render_seconds;
        }
        t.push_str(&format!(
            "{:<16} {:<12} {:>8} {:>8} {:>6} {:>10.1}  wall {:.1} s\n",
            "total",
            "",
            total.expected,
            total.resumed,
            total.made,
            total.render_seconds,
            self.seconds
        ));
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_parsing_accepts_k_of_n_and_rejects_the_rest() {
        assert_eq!("2/3".parse::<Shard>().unwrap(), Shard { k: 2, n: 3 });
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    #[test]
    fn shards_partition_the_indices() {
        let n = 3;
        for i in 0..20 {
            let owners = (1..=n).filter(|&k| Shard { k, n }.owns(i)).count();
            assert_eq!(owners, 1, "index {i}");
        }
    }
}
