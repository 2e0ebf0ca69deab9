//! The model file: round trip, and each way a file can be wrong is a clear error naming it.

use std::path::Path;

use polar_learn::{
    Expect, FORMAT_VERSION, Knn, KnnModel, LearnError, TrainingSummary, balanced_subsample,
};

const FEATURES: [&str; 2] = ["a", "b"];
const CLASSES: [&str; 2] = ["left", "right"];
const EXPECT: Expect<'static> = Expect {
    task: "demo",
    features: &FEATURES,
    classes: &CLASSES,
};

/// Two separable clusters: class 0 around (-1, 0), class 1 around (+1, 0), the second
/// feature 100 times wider (standardization must keep it from dominating).
fn model(k: usize) -> KnnModel {
    let mut points = Vec::new();
    let mut labels = Vec::new();
    for i in 0..40 {
        let jitter = (i as f32 * 0.618).fract() - 0.5;
        let class = i % 2;
        let x = if class == 0 { -1.0 } else { 1.0 } + 0.3 * jitter;
        points.extend([x, 100.0 * jitter]);
        labels.push(class as u8);
    }
    let mut summary = TrainingSummary {
        dataset: "synthetic".into(),
        samples: 1,
        ..Default::default()
    };
    summary.settings.insert("seed".into(), "7".into());
    KnnModel::fit(EXPECT, k, points, labels, summary).unwrap()
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let m = model(3);
    let path = dir.path().join("m.bin");
    std::fs::write(&path, m.to_bytes()).unwrap();
    let back = KnnModel::load(&path, EXPECT).unwrap();
    assert_eq!(back, m);
    assert_eq!(back.header.format_version, FORMAT_VERSION);
}

#[test]
fn knn_separates_a_tiny_separable_set() {
    let knn = Knn::<2>::new(model(5), Path::new("mem")).unwrap();
    // Points near each cluster get all 5 votes of their class; the wide second feature
    // (standardized to unit variance) does not outvote the first.
    assert_eq!(knn.fraction(&[-1.1, 40.0], 1), 0.0);
    assert_eq!(knn.fraction(&[0.9, -40.0], 1), 1.0);
    assert_eq!(knn.fraction(&[0.9, -40.0], 0), 0.0);
    // A non-finite feature is read as the training mean instead of poisoning the search.
    let f = knn.fraction(&[1.0, f32::NAN], 1);
    assert_eq!(f, 1.0);
}

#[test]
fn other_task_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "m.bin", &model(3).to_bytes());
    let other = Expect {
        task: "transparency",
        ..EXPECT
    };
    let e = KnnModel::load(&path, other).unwrap_err();
    assert!(matches!(e, LearnError::WrongTask { .. }), "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("m.bin") && msg.contains("knn demo") && msg.contains("knn transparency"),
        "{msg}"
    );
}

#[test]
fn other_feature_list_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "m.bin", &model(3).to_bytes());
    let other = Expect {
        features: &["a", "c"],
        ..EXPECT
    };
    let e = KnnModel::load(&path, other).unwrap_err();
    assert!(matches!(e, LearnError::WrongFeatures { .. }), "{e}");
    assert!(
        e.to_string().contains("m.bin") && e.to_string().contains("retrain"),
        "{e}"
    );
}

#[test]
fn stale_format_version_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut m = model(3);
    m.header.format_version = FORMAT_VERSION + 1;
    let path = write(dir.path(), "old.bin", &m.to_bytes());
    let e = KnnModel::load(&path, EXPECT).unwrap_err();
    assert!(
        matches!(e, LearnError::Stale { found, supported, .. } if found == FORMAT_VERSION + 1 && supported == FORMAT_VERSION),
        "{e}"
    );
    assert!(e.to_string().contains("old.bin"));
}

#[test]
fn truncated_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = model(3).to_bytes();
    for cut in [0, 5, 11, 30, bytes.len() - 1] {
        let path = write(dir.path(), "cut.bin", &bytes[..cut]);
        let e = KnnModel::load(&path, EXPECT).unwrap_err();
        assert!(matches!(e, LearnError::Corrupt { .. }), "cut at {cut}: {e}");
        assert!(e.to_string().contains("cut.bin"));
    }
}

#[test]
fn corrupt_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let good = model(3).to_bytes();
    // Not a model file at all.
    let p = write(dir.path(), "png.bin", b"\x89PNG\r\n\x1a\n0000");
    assert!(matches!(
        KnnModel::load(&p, EXPECT),
        Err(LearnError::Corrupt { .. })
    ));
    // A header length far beyond the file: refused before any allocation.
    let mut big = good.clone();
    big[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    let p = write(dir.path(), "big.bin", &big);
    let e = KnnModel::load(&p, EXPECT).unwrap_err();
    assert!(e.to_string().contains("header length"), "{e}");
    // A point count beyond the body: refused, no allocation of that many points.
    let mut m = model(3);
    m.header.points = usize::MAX / 2;
    let p = write(dir.path(), "count.bin", &m.to_bytes());
    let e = KnnModel::load(&p, EXPECT).unwrap_err();
    assert!(matches!(e, LearnError::Corrupt { .. }), "{e}");
    // A label outside the classes.
    let mut bad = good.clone();
    *bad.last_mut().unwrap() = 9;
    let p = write(dir.path(), "label.bin", &bad);
    let e = KnnModel::load(&p, EXPECT).unwrap_err();
    assert!(e.to_string().contains("label 9"), "{e}");
    // A NaN feature value in the body.
    let mut nan = good.clone();
    let at = nan.len() - 40 - 4;
    nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    let p = write(dir.path(), "nan.bin", &nan);
    let e = KnnModel::load(&p, EXPECT).unwrap_err();
    assert!(e.to_string().contains("non-finite"), "{e}");
}

#[test]
fn missing_file_names_the_path() {
    let e = KnnModel::load(Path::new("/nonexistent/model.bin"), EXPECT).unwrap_err();
    assert!(matches!(e, LearnError::Io { .. }) && e.to_string().contains("/nonexistent/model.bin"));
}

#[test]
fn fit_refuses_a_missing_class_and_a_large_k() {
    let e = KnnModel::fit(
        EXPECT,
        1,
        vec![0.0, 0.0],
        vec![0],
        TrainingSummary::default(),
    );
    assert!(matches!(e, Err(LearnError::Fit(m)) if m.contains("right")));
    let e = KnnModel::fit(
        EXPECT,
        3,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![0, 1],
        TrainingSummary::default(),
    );
    assert!(matches!(e, Err(LearnError::Fit(m)) if m.contains("k = 3")));
}

#[test]
fn balanced_subsample_is_balanced_and_deterministic() {
    // 90 of class 0, 10 of class 1.
    let labels: Vec<u8> = (0..100).map(|i| u8::from(i % 10 == 0)).collect();
    let a = balanced_subsample(&labels, 2, 20, 42);
    assert_eq!(a, balanced_subsample(&labels, 2, 20, 42));
    assert_ne!(a, balanced_subsample(&labels, 2, 20, 43));
    let ones = a.iter().filter(|&&i| labels[i] == 1).count();
    assert_eq!((a.len(), ones), (30, 10));
}
