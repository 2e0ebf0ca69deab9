//! Output folders written as a whole: every file goes into a hidden sibling staging folder,
//! which [`StagedDir::commit`] moves onto the target in one step. A failed or interrupted
//! run leaves the previous output (or nothing) in place, never a partial or mixed set, and a
//! rerun leaves no stale file of an earlier run behind.
//!
//! A folder is replaced only if it is empty or holds the program's marker file, so a
//! user's own folder given by mistake as the output is refused, not emptied.

use std::path::{Path, PathBuf};

use crate::atomic::temp_sibling;
use crate::error::{Error, Result};

/// A staging folder for the output folder `target`; removed on drop unless committed.
#[derive(Debug)]
pub struct StagedDir {
    target: PathBuf,
    staging: PathBuf,
    marker: &'static str,
    committed: bool,
}

impl StagedDir {
    /// Checks that `target` may be replaced (missing, an empty folder, or a folder holding
    /// the file `marker`) and creates a fresh staging folder beside it.
    pub fn new(target: &Path, marker: &'static str) -> Result<Self> {
        let target = absolute(target)?;
        let staging = temp_sibling(&target);
        Self::at(target, staging, marker)
    }

    /// [`StagedDir::new`] with the staging folder at `staging_root/<target's name>` (replacing
    /// a leftover of an interrupted run there), for a program that keeps its unfinished work
    /// in one place it cleans up (`staging_root` must be on the target's file system).
    pub fn within(target: &Path, staging_root: &Path, marker: &'static str) -> Result<Self> {
        let target = absolute(target)?;
        let staging = staging_root.join(target.file_name().unwrap_or_default());
        if staging.exists() {
            std::fs::remove_dir_all(&staging).map_err(|e| Error::io(&staging, "output", e))?;
        }
        Self::at(target, staging, marker)
    }

    fn at(target: PathBuf, staging: PathBuf, marker: &'static str) -> Result<Self> {
        check_replaceable(&target, marker)?;
        std::fs::create_dir_all(&staging).map_err(|e| Error::io(&staging, "output", e))?;
        Ok(Self {
            target,
            staging,
            marker,
            committed: false,
        })
    }

    /// The folder to write the outputs into.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Syncs every file and folder of the staged folder to disk, then moves it onto the
    /// target (the old target, if any, is removed after the swap): after a power loss the
    /// target is the old set or the whole new one, which a resumable program may trust.
    /// The staged folder must hold the marker, so that the next run may replace it in turn.
    pub fn commit(self) -> Result<PathBuf> {
        sync_tree(&self.staging)?;
        self.commit_cached()
    }

    /// [`StagedDir::commit`] without the sync: the swap still protects against the program
    /// failing, but the files may still be in the page cache only, as any image tool leaves
    /// its outputs (a power loss right after may lose them).
    pub fn commit_cached(mut self) -> Result<PathBuf> {
        if !self.staging.join(self.marker).is_file() {
            return Err(Error::io(
                &self.staging.join(self.marker),
                "output",
                std::io::Error::other("the output marker was not written"),
            ));
        }
        let old = temp_sibling(&self.target);
        let had_old = self.target.exists();
        if had_old {
            std::fs::rename(&self.target, &old)
                .map_err(|e| Error::io(&self.target, "output", e))?;
        }
        if let Err(e) = std::fs::rename(&self.staging, &self.target) {
            if had_old {
                let _ = std::fs::rename(&old, &self.target);
            }
            return Err(Error::io(&self.target, "output", e));
        }
        self.committed = true;
        if had_old {
            std::fs::remove_dir_all(&old).map_err(|e| Error::io(&old, "output", e))?;
        }
        Ok(self.target.clone())
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if !self.committed {
            // Best effort: an interrupted run must not leave its staging folder behind.
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}

/// `fsync`s every file under `dir`, then `dir` itself (so its entries are on disk too).
fn sync_tree(dir: &Path) -> Result<()> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, "output", e))?;
    for entry in entries {
        let path = entry.map_err(|e| Error::io(dir, "output", e))?.path();
        if path.is_dir() {
            sync_tree(&path)?;
        } else {
            sync_path(&path)?;
        }
    }
    sync_path(dir)
}

fn sync_path(path: &Path) -> Result<()> {
    std::fs::File::open(path)
        .and_then(|f| f.sync_all())
        .map_err(|e| Error::io(path, "output", e))
}

/// Refuses a `target` that exists and is not a folder this program may replace: a file, or
/// a non-empty folder without `marker`.
pub fn check_replaceable(target: &Path, marker: &str) -> Result<()> {
    let refuse = |why: &str| {
        Err(Error::io(
            target,
            "output",
            std::io::Error::other(why.to_owned()),
        ))
    };
    if !target.exists() {
        return Ok(());
    }
    if !target.is_dir() {
        return refuse("exists and is not a folder");
    }
    let mut entries = std::fs::read_dir(target).map_err(|e| Error::io(target, "output", e))?;
    if entries.next().is_none() || target.join(marker).is_file() {
        return Ok(());
    }
    refuse(&format!(
        "is a non-empty folder this program did not write (no {marker}); \
         refusing to replace it: choose a new or empty folder"
    ))
}

/// `path` as an absolute path (the current directory prepended), so that `.` or `out/..`
/// name a folder with a parent to stage beside.
fn absolute(path: &Path) -> Result<PathBuf> {
    let abs = std::path::absolute(path).map_err(|e| Error::io(path, "output", e))?;
    let normal: PathBuf = abs.components().fold(PathBuf::new(), |mut p, c| {
        match c {
            std::path::Component::ParentDir => {
                p.pop();
            }
            std::path::Component::CurDir => {}
            other => p.push(other),
        }
        p
    });
    let cwd = std::env::current_dir().unwrap_or_default();
    if normal.parent().is_none() || cwd.starts_with(&normal) {
        return Err(Error::io(
            path,
            "output",
            std::io::Error::other("is the current folder or one above it; name a folder"),
        ));
    }
    Ok(normal)
}

#[cfg(test)]
mod tests {
    use super::*;

    const MARK: &str = ".mark";

    fn tmp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("polar-io-staged-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn stage_with(target: &Path, files: &[&str]) -> Result<PathBuf> {
        let s = StagedDir::new(target, MARK)?;
        for f in files {
            std::fs::write(s.path().join(f), f).unwrap();
        }
        s.commit()
    }

    #[test]
    fn a_rerun_replaces_the_whole_set() {
        let root = tmp("rerun");
        let out = root.join("out");
        stage_with(&out, &[MARK, "a.txt", "stale.txt"]).unwrap();
        stage_with(&out, &[MARK, "a.txt"]).unwrap();
        let mut names: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(names, [MARK, "a.txt"]);
        let leftovers = std::fs::read_dir(&root).unwrap().count();
        assert_eq!(leftovers, 1, "only out/ remains beside it");
    }

    #[test]
    fn synced_and_cached_commits_move_nested_folders_whole() {
        let root = tmp("nested");
        for (name, synced) in [("synced", true), ("cached", false)] {
            let out = root.join(name);
            let s = StagedDir::new(&out, MARK).unwrap();
            std::fs::create_dir(s.path().join("pictures")).unwrap();
            std::fs::write(s.path().join("pictures/p.png"), "p").unwrap();
            std::fs::write(s.path().join(MARK), "").unwrap();
            if synced {
                s.commit()
            } else {
                s.commit_cached()
            }
            .unwrap();
            assert_eq!(std::fs::read(out.join("pictures/p.png")).unwrap(), b"p");
        }
    }

    #[test]
    fn a_user_folder_is_refused_and_kept() {
        let root = tmp("user");
        let out = root.join("photos");
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("holiday.jpg"), b"x").unwrap();
        let err = StagedDir::new(&out, MARK).unwrap_err().to_string();
        assert!(err.contains("did not write"), "{err}");
        assert_eq!(std::fs::read(out.join("holiday.jpg")).unwrap(), b"x");
        let file = root.join("file");
        std::fs::write(&file, b"y").unwrap();
        assert!(StagedDir::new(&file, MARK).is_err());
    }

    #[test]
    fn a_failed_run_leaves_the_old_output_and_no_staging() {
        let root = tmp("failed");
        let out = root.join("out");
        stage_with(&out, &[MARK, "old.txt"]).unwrap();
        {
            let s = StagedDir::new(&out, MARK).unwrap();
            std::fs::write(s.path().join("new.txt"), b"n").unwrap();
            // Dropped without commit, as on an error path.
        }
        assert!(out.join("old.txt").is_file());
        assert_eq!(std::fs::read_dir(&root).unwrap().count(), 1);
        // A set without the marker is not committed.
        assert!(stage_with(&out, &["new.txt"]).is_err());
        assert!(out.join("old.txt").is_file());
    }

    #[test]
    fn missing_parents_are_created() {
        let root = tmp("parents");
        let out = root.join("a").join("b");
        assert_eq!(stage_with(&out, &[MARK]).unwrap(), out);
    }

    #[test]
    fn dot_and_parent_components_name_the_folder() {
        let root = tmp("dots");
        let out = root.join("out");
        std::fs::create_dir(&out).unwrap();
        let got = stage_with(&out.join("..").join("out").join("."), &[MARK]).unwrap();
        assert_eq!(got, out);
        assert!(out.join(MARK).is_file());
    }

    /// `within`: a leftover of an interrupted run in the staging root is replaced, the
    /// commit moves the set onto the target, and a failure cleans the staging folder.
    #[test]
    fn within_a_staging_root_replaces_leftovers_and_cleans_up() {
        let root = tmp("within");
        let (out, staging) = (root.join("sample-1"), root.join(".staging"));
        std::fs::create_dir_all(staging.join("sample-1")).unwrap();
        std::fs::write(staging.join("sample-1/leftover"), b"l").unwrap();
        let s = StagedDir::within(&out, &staging, MARK).unwrap();
        assert_eq!(s.path(), staging.join("sample-1"));
        assert!(!s.path().join("leftover").exists());
        std::fs::write(s.path().join(MARK), b"m").unwrap();
        s.commit().unwrap();
        assert!(out.join(MARK).is_file());
        {
            let s = StagedDir::within(&out, &staging, MARK).unwrap();
            std::fs::write(s.path().join("new"), b"n").unwrap();
        }
        assert!(!staging.join("sample-1").exists());
        assert!(out.join(MARK).is_file() && !out.join("new").exists());
    }
}
