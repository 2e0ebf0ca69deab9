//! Shared fixtures of the end-to-end tests: datasets made once per test binary with the
//! dataset generator's library, and the vision CLI driven through `polar_vision::cli`.

#![allow(dead_code)] // each test binary uses a different part

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use polar_datagen::progress::Progress;
use polar_datagen::run::{RunOptions, Shard, prepare_output, run_suite};
use polar_datagen::sample::RenderWorker;
use polar_datagen::suite::{SizeName, Suite};
use serde_json::Value;

/// The workspace root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Makes `suite` (a file under datasets-synth/suites) at `size` into `out`.
pub fn make_suite(suite: &str, size: SizeName, out: &Path) {
    let path = root().join("datasets-synth/suites").join(suite);
    let text = std::fs::read_to_string(&path).expect("suite file");
    let parsed = Suite::parse(&text).expect("suite parses");
    let opts = RunOptions {
        out: out.to_owned(),
        size,
        shard: Shard::ALL,
        jobs: 2,
        progress: Progress::Quiet,
    };
    prepare_output(&parsed, &text, &opts).expect("dataset folder");
    run_suite(&parsed, &opts, &RenderWorker).expect("suite renders");
}

/// The `standard` suite at its `ci` size, made once per test binary.
pub fn standard_ci() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().expect("temp dir");
        make_suite("standard.toml", SizeName::Ci, dir.path());
        dir
    })
    .path()
}

/// Runs `polar-vision ARGS`; `Ok(all tasks succeeded)` or the error's message.
pub fn vision(args: &[&str]) -> Result<bool, String> {
    let argv = std::iter::once("polar-vision").chain(args.iter().copied());
    polar_vision::cli::run_cli(argv).map_err(|e| e.to_string())
}

/// A path as a `&str` argument.
pub fn arg(p: &Path) -> &str {
    p.to_str().expect("UTF-8 temp path")
}

/// Reads a JSON file.
pub fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("JSON file")).expect("JSON")
}

/// The mean of `key` (dotted path) for `task` over `family` in an eval `metrics.json`.
pub fn family_mean(metrics: &Value, family: &str, task: &str, key: &str) -> f64 {
    metrics["families"][family][task]["means"][key]
        .as_f64()
        .unwrap_or_else(|| panic!("no {family}/{task}/{key} in metrics.json"))
}
