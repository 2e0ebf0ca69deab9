//! Atomic writes: write beside the target under a temporary name, then rename.
//! A reader never sees a half-written file, and a failed write leaves the old file intact.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// A fresh hidden name in the same directory as `path`, so the final rename stays on one
/// file system (rename is only atomic there).
pub(crate) fn temp_sibling(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map_or_else(|| "out".into(), |s| s.to_string_lossy());
    path.with_file_name(format!(".{name}.tmp-{}-{n}", std::process::id()))
}

/// Whether a write waits until its data is on disk (`fsync`) before it is renamed into place.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Durability {
    /// Survives a power loss right after the call: for small records a resumable program
    /// trusts (manifests, model files, eval records).
    Synced,
    /// In the page cache only, as any image library writes: for image files, whose folder
    /// [`crate::StagedDir::commit`] syncs as a whole where that matters.
    Cached,
}

/// Writes a file through `write_body`, atomically: the data goes to a temporary sibling that
/// is renamed onto `path` only after it was written and flushed (and, for [`Durability::Synced`],
/// synced to disk) without error.
pub(crate) fn write_file_atomic(
    path: &Path,
    durability: Durability,
    write_body: impl FnOnce(&mut BufWriter<File>) -> Result<()>,
) -> Result<()> {
    let tmp = temp_sibling(path);
    let result = (|| {
        let file = File::create(&tmp).map_err(|e| Error::io(path, "output", e))?;
        let mut writer = BufWriter::new(file);
        write_body(&mut writer)?;
        writer.flush().map_err(|e| Error::io(path, "output", e))?;
        if durability == Durability::Synced {
            writer
                .get_ref()
                .sync_all()
                .map_err(|e| Error::io(path, "output", e))?;
        }
        std::fs::rename(&tmp, path).map_err(|e| Error::io(path, "output", e))
    })();
    if result.is_err() {
        // Best effort: the temporary may not exist if creating it was what failed.
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes `bytes` to `path` atomically and durably (see `write_file_atomic`).
pub fn write_atomic(path: impl AsRef<Path>, bytes: &[u8]) -> Result<()> {
    let path = path.as_ref();
    write_file_atomic(path, Durability::Synced, |w| {
        w.write_all(bytes).map_err(|e| Error::io(path, "output", e))
    })
}
