//! The output folders of the subcommands: never the input, never a user's own folder, and
//! written as a whole (polar-io's [`StagedDir`]) so that a failed run leaves no partial set
//! and a rerun no stale file.

use std::path::{Path, PathBuf};

use polar_io::files::vision;
use polar_io::{StagedDir, check_replaceable};

use crate::error::CliError;

/// What the marker file says to a person who finds it.
const MARKER_TEXT: &str = "This folder was written by polar-vision. A later run with --out \
pointing here replaces it as a whole.\n";

/// Checks, before any work, that `out` may receive the outputs of a run on `input`.
pub fn check(input: &Path, out: &Path) -> Result<(), CliError> {
    check_out_apart(input, out)?;
    check_replaceable(out, vision::MARKER)?;
    Ok(())
}

/// A staging folder for the outputs of one run into `out`.
pub fn stage(out: &Path) -> Result<StagedDir, CliError> {
    Ok(StagedDir::new(out, vision::MARKER)?)
}

/// Marks the staged outputs as polar-vision's and moves them onto their folder, without
/// syncing them to disk first (as OpenCV or Mitsuba leave their outputs): the sync would
/// take longer than the computation, and a rerun recomputes them.
pub fn commit(staged: StagedDir) -> Result<(), CliError> {
    mark(staged.path())?;
    staged.commit_cached()?;
    Ok(())
}

/// Prepares a folder that a command fills over several runs (`eval` resumes in it): new,
/// empty or marked as polar-vision's; created and marked.
pub fn prepare_resumable(out: &Path) -> Result<(), CliError> {
    check_replaceable(out, vision::MARKER)?;
    std::fs::create_dir_all(out).map_err(|e| CliError::write(out, e))?;
    mark(out)
}

fn mark(dir: &Path) -> Result<(), CliError> {
    let path = dir.join(vision::MARKER);
    std::fs::write(&path, MARKER_TEXT).map_err(|e| CliError::write(&path, e))
}

/// Refuses an output folder that would overwrite the input: the input sample directory
/// itself or a folder inside it, or the folder of an input file.
fn check_out_apart(input: &Path, out: &Path) -> Result<(), CliError> {
    let (base, inside_too) = if input.is_dir() {
        (input.to_owned(), true)
    } else {
        let parent = input.parent().filter(|p| !p.as_os_str().is_empty());
        (parent.unwrap_or(Path::new(".")).to_owned(), false)
    };
    let Ok(base) = base.canonicalize() else {
        return Ok(());
    };
    let out_abs = absolute_existing_prefix(out);
    let clash = if inside_too {
        out_abs.starts_with(&base)
    } else {
        out_abs == base
    };
    if clash {
        return Err(CliError::OutDir {
            path: out.to_owned(),
            reason: format!(
                "it is {} the input {}; its files would be overwritten",
                if out_abs == base {
                    "the folder of"
                } else {
                    "inside"
                },
                input.display()
            ),
        });
    }
    Ok(())
}

/// `path` made absolute through its longest existing ancestor (the rest appended as is).
fn absolute_existing_prefix(path: &Path) -> PathBuf {
    let mut rest = Vec::new();
    let mut p = path.to_owned();
    loop {
        if let Ok(c) = p.canonicalize() {
            return rest.iter().rev().fold(c, |acc, part| acc.join(part));
        }
        match (p.file_name().map(|n| n.to_owned()), p.parent()) {
            (Some(name), Some(parent)) => {
                rest.push(name);
                p = if parent.as_os_str().is_empty() {
                    PathBuf::from(".")
                } else {
                    parent.to_owned()
                };
            }
            _ => return path.to_owned(),
        }
    }
}
