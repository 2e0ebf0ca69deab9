//! Replays the committed fuzz corpora (`fuzz/corpus/<target>/`) through the same harness
//! functions the cargo-fuzz targets run (`fuzz/harness.rs`), on the stable toolchain: every
//! input must give `Ok` or an error naming its file, without a panic, within the target's
//! allocation bound. One test, so that no other test's allocations enter the measurement.

#[allow(dead_code)] // the fuzz targets use the rest
#[path = "../fuzz/harness.rs"]
mod harness;

use std::path::PathBuf;

#[test]
fn every_fuzz_corpus_input_is_read_or_refused_within_its_bound() {
    let corpus = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus");
    for target in &harness::TARGETS {
        let dir = corpus.join(target.name);
        let mut inputs: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|entry| entry.expect("corpus entry").path())
            .collect();
        inputs.sort();
        assert!(!inputs.is_empty(), "{}: empty corpus", dir.display());
        for input in inputs {
            let data = std::fs::read(&input).expect("corpus file");
            eprintln!("{}", input.display());
            harness::check(target, &data);
        }
    }
}
