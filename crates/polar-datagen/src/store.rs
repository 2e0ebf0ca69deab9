//! The dataset on disk: sample directories committed atomically (write into `.staging/`, then
//! rename), `manifest.jsonl` (one line per committed sample), `run.json` (what run this is)
//! and SHA-256 checksums that tie the manifest to the files.

use std::collections::BTreeMap;
use std::fs;
use std::io::Write;
use std::path::Path;

use polar_render::Polarization;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::params::SampleParams;

pub use polar_io::files::dataset::{MANIFEST, RUN_RECORD, SUITE_COPY};
/// Hidden directory where samples are written before the atomic rename.
pub const STAGING: &str = ".staging";
/// Lock file of a dataset directory: a run holds an exclusive OS lock on it while it writes.
/// The OS releases the lock when the process ends, even when killed; the file stays.
pub const LOCK: &str = ".polar-datagen.lock";

/// One manifest line: a committed sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ManifestEntry {
    /// Sample id = directory name.
    pub id: String,
    /// Sample seed.
    pub seed: u64,
    /// Every parameter of the sample.
    pub params: SampleParams,
    /// SHA-256 (hex) of every file, by path relative to the sample directory ('/' separated).
    pub files: BTreeMap<String, String>,
    /// Light-transport model the renderer used.
    pub model: Polarization,
    /// Wall-clock seconds: render and the whole sample.
    pub timings: Timings,
}

/// Wall-clock timings of one sample (vary run to run; everything else is deterministic).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Timings {
    /// Seconds spent in the renderer.
    pub render_seconds: f64,
    /// Seconds for the whole sample: render, sensor, encode, checksum, commit.
    pub total_seconds: f64,
}

/// What run a dataset directory holds; a resumed run must match it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct RunRecord {
    /// Suite name.
    pub suite: String,
    /// SHA-256 of the suite file text.
    pub suite_sha256: String,
    /// `ci` or `full`.
    pub size: crate::suite::SizeName,
    /// Shard index, 1-based.
    pub shard: u32,
    /// Number of shards.
    pub shards: u32,
    /// Number of samples this shard is responsible for.
    pub expected: usize,
}

/// Checksums of every file under `dir`, keyed by '/'-separated relative path, sorted.
pub fn checksum_dir(dir: &Path) -> Result<BTreeMap<String, String>, Error> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_owned()];
    while let Some(d) = stack.pop() {
        for entry in fs::read_dir(&d).map_err(Error::io(&d))? {
            let path = entry.map_err(Error::io(&d))?.path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let rel = path.strip_prefix(dir).unwrap_or(&path);
                let key = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy())
                    .collect::<Vec<_>>()
                    .join("/");
                out.insert(key, polar_io::sha256_file(&path)?);
            }
        }
    }
    Ok(out)
}

/// Checks every file of an entry against its checksum; the error names the first bad file.
pub fn verify_entry(dataset: &Path, entry: &ManifestEntry) -> Result<(), Error> {
    let dir = dataset.join(&entry.id);
    for (rel, expected) in &entry.files {
        let path = dir.join(rel);
        let actual = polar_io::sha256_file(&path)?;
        if &actual != expected {
            return Err(Error::Checksum {
                path,
                expected: expected.clone(),
                actual,
            });
        }
    }
    Ok(())
}

/// The file [`ensure_writable`] creates and removes.
const PROBE: &str = ".write-probe";

/// Creates `dir` if needed and proves it writable by creating and removing a probe file.
pub fn ensure_writable(dir: &Path) -> Result<(), Error> {
    let fail = |source| Error::OutputNotWritable {
        path: dir.to_owned(),
        source,
    };
    fs::create_dir_all(dir).map_err(fail)?;
    let probe = dir.join(PROBE);
    fs::write(&probe, b"probe").map_err(fail)?;
    fs::remove_file(&probe).map_err(fail)
}

/// Checks that `suite` may write into `dir`: absent, empty, or a dataset of this program,
/// recognised by its run record or manifest. Anything else may hold the user's files, which a
/// run must never overwrite or delete. What a starting run writes before its run record (the
/// lock, the write probe, the run record's temporary file) does not count, so that a second
/// run started at the same moment reaches the lock and says that another run holds it.
pub fn check_dataset_dir(dir: &Path) -> Result<(), Error> {
    if !dir.exists() || dir.join(RUN_RECORD).is_file() || dir.join(MANIFEST).is_file() {
        return Ok(());
    }
    if !dir.is_dir() {
        return Err(Error::NotADataset {
            path: dir.to_owned(),
            found: "a file, not a directory".into(),
        });
    }
    let run_tmp = Path::new(RUN_RECORD).with_extension("tmp");
    let starting = [Path::new(LOCK), Path::new(PROBE), &run_tmp];
    let mut names = Vec::new();
    for entry in fs::read_dir(dir).map_err(Error::io(dir))? {
        let name = entry.map_err(Error::io(dir))?.file_name();
        if !starting.contains(&Path::new(&name)) {
            names.push(name.to_string_lossy().into_owned());
        }
    }
    if names.is_empty() {
        return Ok(());
    }
    names.sort();
    let more = names.len().saturating_sub(3);
    names.truncate(3);
    let mut found = names.join(", ");
    if more > 0 {
        found.push_str(&format!(" and {more} more"));
    }
    Err(Error::NotADataset {
        path: dir.to_owned(),
        found,
    })
}

/// Takes the exclusive lock of dataset directory `dir` (see [`LOCK`]); held until the file
/// is dropped. Fails at once, naming the directory, when another run holds it.
pub fn lock_dataset(dir: &Path) -> Result<fs::File, Error> {
    let path = dir.join(LOCK);
    let file = fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .map_err(Error::io(&path))?;
    match file.try_lock() {
        Ok(()) => Ok(file),
        Err(fs::TryLockError::WouldBlock) => Err(Error::Locked {
            path: dir.to_owned(),
        }),
        Err(fs::TryLockError::Error(e)) => Err(Error::Io { path, source: e }),
    }
}

/// Reads the manifest's complete lines. A torn last line (the run was killed while appending)
/// is dropped; a bad line elsewhere is an error naming it.
pub fn read_manifest(dataset: &Path) -> Result<Vec<ManifestEntry>, Error> {
    let path = dataset.join(MANIFEST);
    let text = match fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(Error::Io { path, source: e }),
    };
    parse_manifest(&path, &text)
}

/// The manifest's entries from its text, by the rules of [`read_manifest`]; `path` only
/// names it in errors.
pub fn parse_manifest(path: &Path, text: &str) -> Result<Vec<ManifestEntry>, Error> {
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    let mut out = Vec::with_capacity(lines.len());
    for (i, line) in lines.iter().enumerate() {
        match serde_json::from_str(line) {
            Ok(e) => out.push(e),
            Err(_) if i + 1 == lines.len() && !text.ends_with('\n') => break,
            Err(e) => {
                return Err(Error::Json {
                    path: path.to_owned(),
                    message: format!("line {}: {e}", i + 1),
                });
            }
        }
    }
    Ok(out)
}

/// Rewrites the whole manifest atomically, entries sorted by id.
pub fn write_manifest(dataset: &Path, entries: &[ManifestEntry]) -> Result<(), Error> {
    let mut sorted: Vec<&ManifestEntry> = entries.iter().collect();
    sorted.sort_by(|a, b| a.id.cmp(&b.id));
    let mut text = String::new();
    for e in sorted {
        text.push_str(&manifest_line(dataset, e)?);
    }
    Ok(polar_io::write_atomic(
        dataset.join(MANIFEST),
        text.as_bytes(),
    )?)
}

fn manifest_line(dataset: &Path, e: &ManifestEntry) -> Result<String, Error> {
    let line = serde_json::to_string(e).map_err(|err| Error::Json {
        path: dataset.join(MANIFEST),
        message: err.to_string(),
    })?;
    Ok(format!("{line}\n"))
}

/// Appends one entry to the manifest with a single write, then fsyncs it.
pub fn append_manifest(dataset: &Path, entry: &ManifestEntry) -> Result<(), Error> {
    let path = dataset.join(MANIFEST);
    let line = manifest_line(dataset, entry)?;
    let mut f = fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .map_err(Error::io(&path))?;
    f.write_all(line.as_bytes()).map_err(Error::io(&path))?;
    f.sync_data().map_err(Error::io(&path))
}

/// Recursively copies a directory (merge copies into staging, then commits with a rename).
pub fn copy_dir(from: &Path, to: &Path) -> Result<(), Error> {
    fs::create_dir_all(to).map_err(Error::io(to))?;
    for entry in fs::read_dir(from).map_err(Error::io(from))? {
        let path = entry.map_err(Error::io(from))?.path();
        let dest = to.join(path.file_name().unwrap_or_default());
        if path.is_dir() {
            copy_dir(&path, &dest)?;
        } else {
            fs::copy(&path, &dest).map_err(Error::io(&path))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torn_last_manifest_line_is_dropped_but_bad_middle_line_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        fs::write(dir.path().join(MANIFEST), "{\"id\":").unwrap();
        assert!(read_manifest(dir.path()).unwrap().is_empty());
        fs::write(dir.path().join(MANIFEST), "garbage\n{}\n").unwrap();
        let e = read_manifest(dir.path()).unwrap_err().to_string();
        assert!(e.contains("line 1"), "{e}");
    }

    #[test]
    fn checksum_dir_covers_nested_files() {
        let dir = tempfile::tempdir().unwrap();
        fs::create_dir_all(dir.path().join(polar_io::files::GT_DIR)).unwrap();
        fs::write(dir.path().join("gt/a.bin"), b"abc").unwrap();
        fs::write(dir.path().join(polar_io::files::META), b"{}").unwrap();
        let sums = checksum_dir(dir.path()).unwrap();
        assert_eq!(
            sums.keys().collect::<Vec<_>>(),
            ["gt/a.bin", polar_io::files::META]
        );
        assert_eq!(sums["gt/a.bin"], polar_io::sha256_hex(b"abc"));
    }
}
