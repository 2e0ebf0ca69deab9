//! Merging shard directories into one dataset: every shard of one suite run present, every
//! file's checksum verified before anything is copied, samples committed atomically.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use polar_io::{StagedDir, files};

use crate::Error;
use crate::run::{Shard, plan};
use crate::store::{self, ManifestEntry, RunRecord};
use crate::suite::Suite;

/// Verifies the shards and joins them into `out`; returns the number of samples.
pub fn merge(shards: &[PathBuf], out: &Path) -> Result<usize, Error> {
    let first = shards
        .first()
        .ok_or_else(|| Error::Merge("no shard directories given".into()))?;
    let record0: RunRecord = polar_io::read_json(first.join(store::RUN_RECORD))?;
    let suite_path = first.join(store::SUITE_COPY);
    let suite_text = std::fs::read_to_string(&suite_path).map_err(Error::io(&suite_path))?;
    let suite = Suite::parse(&suite_text).map_err(|message| Error::Suite {
        path: suite_path,
        message,
    })?;
    let mut seen_shards = BTreeSet::new();
    let mut entries: Vec<(PathBuf, ManifestEntry)> = Vec::new();
    for dir in shards {
        let record: RunRecord = polar_io::read_json(dir.join(store::RUN_RECORD))?;
        check_same_run(&record0, &record, dir)?;
        if !seen_shards.insert(record.shard) {
            return Err(Error::Merge(format!(
                "shard {}/{} given twice ({})",
                record.shard,
                record.shards,
                dir.display()
            )));
        }
        let manifest = store::read_manifest(dir)?;
        if manifest.len() != record.expected {
            return Err(Error::Merge(format!(
                "{} is incomplete: {} of {} samples (rerun its suite command to finish it)",
                dir.display(),
                manifest.len(),
                record.expected
            )));
        }
        for e in manifest {
            store::verify_entry(dir, &e)?;
            entries.push((dir.clone(), e));
        }
    }
    let missing: Vec<String> = (1..=record0.shards)
        .filter(|k| !seen_shards.contains(k))
        .map(|k| format!("{k}/{}", record0.shards))
        .collect();
    if !missing.is_empty() {
        return Err(Error::Merge(format!(
            "missing shard(s) {}",
            missing.join(", ")
        )));
    }
    let expected: BTreeSet<String> = plan(&suite, record0.size)
        .into_iter()
        .map(|p| p.id)
        .collect();
    let got: BTreeSet<String> = entries.iter().map(|(_, e)| e.id.clone()).collect();
    if expected != got || got.len() != entries.len() {
        return Err(Error::Merge(
            "the shards' samples do not add up to the suite's samples".into(),
        ));
    }
    write_merged(out, &suite_text, &record0, &entries)?;
    Ok(entries.len())
}

fn check_same_run(a: &RunRecord, b: &RunRecord, dir: &Path) -> Result<(), Error> {
    if a.suite_sha256 != b.suite_sha256 || a.size != b.size || a.shards != b.shards {
        return Err(Error::Merge(format!(
            "{} is from another run (suite '{}', size {:?}, {} shards) than the first shard (suite '{}', size {:?}, {} shards)",
            dir.display(),
            b.suite,
            b.size,
            b.shards,
            a.suite,
            a.size,
            a.shards
        )));
    }
    Ok(())
}

fn write_merged(
    out: &Path,
    suite_text: &str,
    record0: &RunRecord,
    entries: &[(PathBuf, ManifestEntry)],
) -> Result<(), Error> {
    store::ensure_writable(out)?;
    if out.join(store::RUN_RECORD).exists() || out.join(store::MANIFEST).exists() {
        return Err(Error::Merge(format!(
            "{} already holds a dataset; merge into a new directory",
            out.display()
        )));
    }
    for (dir, e) in entries {
        let staged = StagedDir::within(&out.join(&e.id), &out.join(store::STAGING), files::META)?;
        store::copy_dir(&dir.join(&e.id), staged.path())?;
        staged.commit()?;
    }
    let _ = std::fs::remove_dir_all(out.join(store::STAGING));
    let list: Vec<ManifestEntry> = entries.iter().map(|(_, e)| e.clone()).collect();
    store::write_manifest(out, &list)?;
    polar_io::write_atomic(out.join(store::SUITE_COPY), suite_text.as_bytes())?;
    let all = Shard::ALL;
    let record = RunRecord {
        shard: all.k,
        shards: all.n,
        expected: list.len(),
        ..record0.clone()
    };
    Ok(polar_io::write_json(out.join(store::RUN_RECORD), &record)?)
}
