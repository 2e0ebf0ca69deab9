//! The dataset machinery with a stand-in worker (no renderer): failures, resume and
//! checksum verification of committed samples.

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use polar_datagen::Error;
use polar_datagen::params::SampleParams;
use polar_datagen::progress::Progress;
use polar_datagen::run::{RunOptions, SampleWorker, Shard, WorkReport, prepare_output, run_suite};
use polar_datagen::store::{read_manifest, verify_entry};
use polar_datagen::suite::{SizeName, Suite};
use polar_io::files;

const SUITE: &str = include_str!("../../../datasets-synth/suites/tiny.toml");

/// Writes the seed as bytes (and an empty meta.json); fails on one id when asked; counts calls.
struct Fake {
    fail_on: Option<&'static str>,
    calls: AtomicUsize,
}

impl SampleWorker for Fake {
    fn produce(&self, p: &SampleParams, dir: &Path) -> Result<WorkReport, Error> {
        self.calls.fetch_add(1, Ordering::Relaxed);
        if self.fail_on == Some(p.id.as_str()) {
            return Err(Error::Sample {
                id: p.id.clone(),
                message: "injected failure".into(),
            });
        }
        std::fs::create_dir_all(dir.join(files::GT_DIR)).unwrap();
        std::fs::write(dir.join(files::META), b"{}").unwrap();
        std::fs::write(dir.join(files::RAW), p.seed.to_le_bytes()).unwrap();
        std::fs::write(dir.join(files::GT_DEPTH), p.index.to_le_bytes()).unwrap();
        Ok(WorkReport {
            model: polar_render::Polarization::None,
            render_seconds: 0.0,
        })
    }
}

fn options(out: &Path) -> RunOptions {
    RunOptions {
        out: out.to_owned(),
        size: SizeName::Ci,
        shard: Shard::ALL,
        jobs: 1,
        progress: Progress::Quiet,
    }
}

#[test]
fn a_failed_run_keeps_its_committed_samples_and_resume_remakes_only_the_rest() {
    let t = tempfile::tempdir().unwrap();
    let suite = Suite::parse(SUITE).unwrap();
    let opts = options(t.path());
    prepare_output(&suite, SUITE, &opts).unwrap();
    // jobs = 1 runs in plan order: sfp-00000..2, then glass-00000..2.
    let failing = Fake {
        fail_on: Some("glass-00001"),
        calls: AtomicUsize::new(0),
    };
    let err = run_suite(&suite, &opts, &failing).unwrap_err().to_string();
    assert!(
        err.contains("glass-00001") && err.contains("injected"),
        "{err}"
    );
    let committed = read_manifest(t.path()).unwrap();
    assert_eq!(committed.len(), 4);
    for e in &committed {
        verify_entry(t.path(), e).unwrap();
    }
    assert!(!t.path().join("glass-00001").exists());

    // Corrupt one committed sample: resume must notice the checksum and make it again.
    std::fs::write(t.path().join("sfp-00000/raw.png"), b"tampered").unwrap();
    let good = Fake {
        fail_on: None,
        calls: AtomicUsize::new(0),
    };
    let summary = run_suite(&suite, &opts, &good).unwrap();
    assert_eq!(
        good.calls.load(Ordering::Relaxed),
        3,
        "glass-00001, glass-00002 and the tampered sfp-00000"
    );
    assert_eq!(summary.families["sfp"].resumed, 2);
    assert_eq!(summary.families["glass"].made, 2);
    let all = read_manifest(t.path()).unwrap();
    assert_eq!(all.len(), 6);
    for e in &all {
        verify_entry(t.path(), e).unwrap();
    }
    assert!(
        summary.table().contains("None"),
        "the workers' transport model is listed"
    );
}

#[test]
fn a_directory_of_another_run_is_refused() {
    let t = tempfile::tempdir().unwrap();
    let suite = Suite::parse(SUITE).unwrap();
    prepare_output(&suite, SUITE, &options(t.path())).unwrap();
    let other = SUITE.replace("seed = 7", "seed = 8");
    let err =
        prepare_output(&Suite::parse(&other).unwrap(), &other, &options(t.path())).unwrap_err();
    assert!(err.to_string().contains("different run"), "{err}");
    let sharded = RunOptions {
        shard: Shard { k: 1, n: 2 },
        ..options(t.path())
    };
    assert!(prepare_output(&suite, SUITE, &sharded).is_err());
}

fn fake() -> Fake {
    Fake {
        fail_on: None,
        calls: AtomicUsize::new(0),
    }
}

/// Issue #22 (item 7): with `run.json` gone, a resume checks every kept sample's seed and
/// parameters against the plan: the samples of the same suite are kept, those of another
/// suite (another seed) are made again.
#[test]
fn resume_without_run_record_remakes_the_samples_of_another_suite() {
    let t = tempfile::tempdir().unwrap();
    let suite = Suite::parse(SUITE).unwrap();
    let opts = options(t.path());
    prepare_output(&suite, SUITE, &opts).unwrap();
    run_suite(&suite, &opts, &fake()).unwrap();

    std::fs::remove_file(t.path().join(files::dataset::RUN_RECORD)).unwrap();
    prepare_output(&suite, SUITE, &opts).unwrap();
    let same = fake();
    run_suite(&suite, &opts, &same).unwrap();
    assert_eq!(
        same.calls.load(Ordering::Relaxed),
        0,
        "same suite re-rendered"
    );

    std::fs::remove_file(t.path().join(files::dataset::RUN_RECORD)).unwrap();
    let text = SUITE.replace("seed = 7", "seed = 8");
    let other = Suite::parse(&text).unwrap();
    prepare_output(&other, &text, &opts).unwrap();
    let remade = fake();
    let summary = run_suite(&other, &opts, &remade).unwrap();
    assert_eq!(
        remade.calls.load(Ordering::Relaxed),
        6,
        "kept another suite's samples"
    );
    assert!(summary.families.values().all(|f| f.resumed == 0));
    let planned = polar_datagen::run::plan(&other, SizeName::Ci);
    let manifest = read_manifest(t.path()).unwrap();
    for p in &planned {
        let e = manifest.iter().find(|e| e.id == p.id).unwrap();
        assert_eq!(e.seed, p.seed, "{}", p.id);
        let raw = std::fs::read(t.path().join(&p.id).join(files::RAW)).unwrap();
        assert_eq!(raw, p.seed.to_le_bytes(), "{}", p.id);
    }
}

/// Issue #22 (item 4): in a dataset, a folder named like a planned sample that this program
/// did not write (no manifest entry, no meta.json) is an error naming it, and is kept.
#[test]
fn a_foreign_folder_named_like_a_sample_is_never_deleted() {
    let t = tempfile::tempdir().unwrap();
    let suite = Suite::parse(SUITE).unwrap();
    let opts = options(t.path());
    prepare_output(&suite, SUITE, &opts).unwrap();
    std::fs::create_dir(t.path().join("sfp-00001")).unwrap();
    std::fs::write(t.path().join("sfp-00001/photo.jpg"), b"jpeg").unwrap();
    let err = run_suite(&suite, &opts, &fake()).unwrap_err().to_string();
    assert!(
        err.contains("sfp-00001") && err.contains("not written by polar-datagen"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(t.path().join("sfp-00001/photo.jpg")).unwrap(),
        b"jpeg"
    );
}
