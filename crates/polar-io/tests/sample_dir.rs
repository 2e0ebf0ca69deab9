//! Sample directories: round trips, partial samples, and each error a sample can carry.

use std::path::Path;

use polar_image::{Gray, Image, Mosaic, PolarizerStack, StokesImage};
use polar_io::{
    BitDepth, Error, GroundTruth, MaterialLabel, MosaicPng, STOKES_CHANNELS, Sample, Validation,
    files, read_json, read_sample, read_sample_with, write_exr, write_gray8_png, write_gray16_png,
    write_json, write_sample, write_sample_into,
};
use serde_json::{Map, Value, json};

const W: usize = 6;
const H: usize = 4;

fn meta() -> Map<String, Value> {
    let v = json!({"size": [W, H], "sensor": "IMX250MZR", "spp": 64, "seconds": 1.5, "scene": {"name": "spheres"}});
    v.as_object().unwrap().clone()
}

fn stokes() -> StokesImage {
    let data = (0..W * H)
        .flat_map(|i| [1.0 + i as f32, 0.25, -0.5, 0.0625])
        .collect();
    Image::from_vec(W, H, data).unwrap()
}

fn raw16() -> MosaicPng {
    let data = (0..W * H).map(|i| (i * 2731) as u16).collect();
    MosaicPng {
        image: Mosaic::from_vec(W, H, data).unwrap(),
        bit_depth: BitDepth::Sixteen,
    }
}

fn polarizers() -> PolarizerStack {
    let data = (0..W * H)
        .flat_map(|i| [0.5 + i as f32, 0.25, 0.0, 0.125])
        .collect();
    Image::from_vec(W, H, data).unwrap()
}

fn full_sample() -> Sample {
    let labels = (0..W * H).map(|i| (i % 4) as u8).collect();
    let mask = (0..W * H)
        .map(|i| if i % 4 == 3 { 255 } else { 0 })
        .collect();
    Sample {
        meta: meta(),
        raw: Some(raw16()),
        stokes: Some(stokes()),
        polarizers: Some(polarizers()),
        gt: GroundTruth {
            normal: Some(Image::from_vec(W, H, [0.0, 0.6, 0.8].repeat(W * H)).unwrap()),
            depth: Some(Gray::from_vec(W, H, vec![2.5; W * H]).unwrap()),
            material: Some(Gray::from_vec(W, H, labels).unwrap()),
            transparent: Some(Gray::from_vec(W, H, mask).unwrap()),
            clear: Some(Gray::from_vec(W, H, vec![0.75; W * H]).unwrap()),
            transmission: Some(Gray::from_vec(W, H, vec![0.5; W * H]).unwrap()),
            dehazed: Some(Gray::from_vec(W, H, vec![0.625; W * H]).unwrap()),
        },
    }
}

fn write_meta(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    write_json(dir.join(files::META), &meta()).unwrap();
}

#[test]
fn full_sample_round_trip_is_exact() {
    let root = tempfile::tempdir().unwrap();
    let dir = root.path().join("suite/sample_0001"); // parents are created
    let sample = full_sample();
    write_sample(&dir, &sample).unwrap();
    assert_eq!(read_sample(&dir).unwrap(), sample);
    for f in [
        files::META,
        files::RAW,
        files::STOKES,
        files::POLARIZERS,
        files::GT_NORMAL,
        files::GT_CLEAR,
        files::GT_TRANSMISSION,
        files::GT_DEHAZED,
    ] {
        assert!(dir.join(f).is_file(), "{f}");
    }
    // Nothing but the sample is left beside it (no temporary directories).
    let siblings: Vec<_> = std::fs::read_dir(root.path().join("suite"))
        .unwrap()
        .collect();
    assert_eq!(siblings.len(), 1);
}

#[test]
fn eight_bit_raw_round_trip_keeps_its_depth() {
    let root = tempfile::tempdir().unwrap();
    let data = (0..W * H).map(|i| (i * 11 % 256) as u16).collect();
    let raw = MosaicPng {
        image: Mosaic::from_vec(W, H, data).unwrap(),
        bit_depth: BitDepth::Eight,
    };
    let sample = Sample {
        meta: meta(),
        raw: Some(raw),
        ..Default::default()
    };
    write_sample(root.path().join("s"), &sample).unwrap();
    assert_eq!(read_sample(root.path().join("s")).unwrap(), sample);
}

#[test]
fn sample_with_only_raw_png_is_read() {
    let root = tempfile::tempdir().unwrap();
    write_meta(root.path());
    write_gray16_png(root.path().join(files::RAW), &raw16().image).unwrap();
    let s = read_sample(root.path()).unwrap();
    assert_eq!(s.raw, Some(raw16()));
    assert!(s.stokes.is_none() && s.gt == GroundTruth::default());
    assert_eq!(s.meta["sensor"], "IMX250MZR");
}

#[test]
fn sample_with_only_stokes_exr_is_read() {
    let root = tempfile::tempdir().unwrap();
    write_meta(root.path());
    write_exr(root.path().join(files::STOKES), &stokes(), STOKES_CHANNELS).unwrap();
    let s = read_sample(root.path()).unwrap();
    assert_eq!(s.stokes, Some(stokes()));
    assert!(s.raw.is_none());
}

#[test]
fn missing_meta_json_is_not_found_naming_it() {
    let root = tempfile::tempdir().unwrap();
    write_gray16_png(root.path().join(files::RAW), &raw16().image).unwrap();
    let err = read_sample(root.path()).unwrap_err();
    assert!(
        matches!(&err, Error::NotFound { path } if path.ends_with("meta.json")),
        "{err}"
    );
}

#[test]
fn missing_sample_directory_is_not_found() {
    let err = read_sample("/nonexistent/sample").unwrap_err();
    assert!(matches!(err, Error::NotFound { .. }), "{err}");
}

#[test]
fn bad_meta_json_is_corrupt_or_not_an_object() {
    let root = tempfile::tempdir().unwrap();
    let meta = root.path().join(files::META);
    std::fs::write(&meta, b"{\"spp\": 64,").unwrap();
    assert!(matches!(
        read_sample(root.path()),
        Err(Error::Corrupt { format: "JSON", .. })
    ));
    std::fs::write(&meta, b"[1, 2]").unwrap();
    assert!(matches!(
        read_sample(root.path()),
        Err(Error::MetaNotObject {
            found: "an array",
            ..
        })
    ));
}

#[test]
fn sizes_that_disagree_name_both_files() {
    let root = tempfile::tempdir().unwrap();
    write_meta(root.path());
    write_gray16_png(root.path().join(files::RAW), &raw16().image).unwrap();
    std::fs::create_dir(root.path().join("gt")).unwrap();
    write_gray8_png(root.path().join(files::GT_MATERIAL), &Gray::new(W, H + 2)).unwrap();
    match read_sample(root.path()).unwrap_err() {
        Error::SizeMismatch {
            path,
            found,
            expected,
            reference,
        } => {
            assert!(path.ends_with(files::GT_MATERIAL) && reference.ends_with(files::RAW));
            assert_eq!((found, expected), ((W, H + 2), (W, H)));
        }
        other => panic!("{other}"),
    }
    // Writing such a sample is refused the same way, before anything is written.
    let mut s = full_sample();
    s.gt.depth = Some(Gray::new(W + 2, H));
    let target = root.path().join("out");
    assert!(matches!(
        write_sample(&target, &s),
        Err(Error::SizeMismatch { .. })
    ));
    assert!(!target.exists());
}

#[test]
fn odd_raw_mosaic_in_a_sample_is_a_size_error() {
    let root = tempfile::tempdir().unwrap();
    write_meta(root.path());
    write_gray8_png(root.path().join(files::RAW), &Gray::new(5, 4)).unwrap();
    assert!(matches!(
        read_sample(root.path()),
        Err(Error::MosaicSize {
            width: 5,
            height: 4,
            ..
        })
    ));
}

#[test]
fn nan_stokes_is_rejected_unless_validation_is_skipped() {
    let root = tempfile::tempdir().unwrap();
    write_meta(root.path());
    let mut bad = stokes();
    bad.as_mut_slice()[4 * (W + 1)] = f32::NAN; // S0 at pixel (1, 1)
    write_exr(root.path().join(files::STOKES), &bad, STOKES_CHANNELS).unwrap();
    match read_sample(root.path()).unwrap_err() {
        Error::InvalidValue {
            channel,
            x: 1,
            y: 1,
            ..
        } => assert_eq!(channel, "S0"),
        other => panic!("{other}"),
    }
    let s = read_sample_with(root.path(), Validation::Skip).unwrap();
    assert!(s.stokes.unwrap().pixel(1, 1)[0].is_nan());
}

#[test]
fn invalid_ground_truth_values_are_refused_on_write() {
    let root = tempfile::tempdir().unwrap();
    let target = root.path().join("s");
    let mut inf_normal = full_sample();
    inf_normal.gt.normal.as_mut().unwrap().as_mut_slice()[1] = f32::INFINITY;
    let mut bad_label = full_sample();
    bad_label.gt.material.as_mut().unwrap().as_mut_slice()[0] =
        MaterialLabel::Transparent.value() + 1;
    let mut bad_mask = full_sample();
    bad_mask.gt.transparent.as_mut().unwrap().as_mut_slice()[0] = 1;
    let mut neg_depth = full_sample();
    neg_depth.gt.depth.as_mut().unwrap().as_mut_slice()[0] = -1.0;
    let mut neg_dehazed = full_sample();
    neg_dehazed.gt.dehazed.as_mut().unwrap().as_mut_slice()[3] = -0.5;
    // Transmittance above 1 (and NaN) is not a transmittance.
    let mut over_one = full_sample();
    over_one.gt.transmission.as_mut().unwrap().as_mut_slice()[2] = 1.01;
    let mut neg_polarizer = full_sample();
    neg_polarizer.polarizers.as_mut().unwrap().as_mut_slice()[5] = -0.25;
    let mut nan_transmission = full_sample();
    nan_transmission
        .gt
        .transmission
        .as_mut()
        .unwrap()
        .as_mut_slice()[0] = f32::NAN;
    for (s, file) in [
        (over_one, files::GT_TRANSMISSION),
        (neg_polarizer, files::POLARIZERS),
        (nan_transmission, files::GT_TRANSMISSION),
        (inf_normal, files::GT_NORMAL),
        (bad_label, files::GT_MATERIAL),
        (bad_mask, files::GT_TRANSPARENT),
        (neg_depth, files::GT_DEPTH),
        (neg_dehazed, files::GT_DEHAZED),
    ] {
        match write_sample(&target, &s).unwrap_err() {
            Error::InvalidValue { path, .. } => assert!(path.ends_with(file), "{path:?}"),
            other => panic!("{file}: {other}"),
        }
        assert!(!target.exists());
    }
}

#[test]
fn rewriting_a_sample_replaces_it_whole() {
    let root = tempfile::tempdir().unwrap();
    let dir = root.path().join("s");
    write_sample(&dir, &full_sample()).unwrap();
    let only_raw = Sample {
        meta: meta(),
        raw: Some(raw16()),
        ..Default::default()
    };
    write_sample(&dir, &only_raw).unwrap();
    assert_eq!(read_sample(&dir).unwrap(), only_raw);
    assert!(!dir.join("gt").exists() && !dir.join(files::STOKES).exists());
    assert_eq!(std::fs::read_dir(root.path()).unwrap().count(), 1);
}

#[test]
fn write_sample_into_fills_a_staged_folder_and_keeps_its_other_files() {
    let root = tempfile::tempdir().unwrap();
    let dir = root.path().join("staged");
    std::fs::create_dir(&dir).unwrap();
    std::fs::write(dir.join("extra.txt"), b"kept").unwrap();
    write_sample_into(&dir, &full_sample()).unwrap();
    assert_eq!(read_sample(&dir).unwrap(), full_sample());
    assert_eq!(std::fs::read(dir.join("extra.txt")).unwrap(), b"kept");
    // The checks come first: a bad sample writes nothing.
    let fresh = root.path().join("fresh");
    std::fs::create_dir(&fresh).unwrap();
    let mut bad = full_sample();
    bad.stokes.as_mut().unwrap().as_mut_slice()[0] = f32::NAN;
    assert!(matches!(
        write_sample_into(&fresh, &bad),
        Err(Error::InvalidValue { .. })
    ));
    assert_eq!(std::fs::read_dir(&fresh).unwrap().count(), 0);
}

#[test]
fn write_sample_onto_a_file_is_refused() {
    let root = tempfile::tempdir().unwrap();
    let target = root.path().join("s");
    std::fs::write(&target, b"keep me").unwrap();
    assert!(matches!(
        write_sample(&target, &full_sample()),
        Err(Error::Io { .. })
    ));
    assert_eq!(std::fs::read(&target).unwrap(), b"keep me");
    assert_eq!(std::fs::read_dir(root.path()).unwrap().count(), 1);
}

#[test]
fn json_round_trip() {
    let root = tempfile::tempdir().unwrap();
    let path = root.path().join("metrics.json");
    let v = json!({"shape": {"mae_deg": 12.5}, "seconds": [0.1, 0.2]});
    write_json(&path, &v).unwrap();
    assert_eq!(read_json::<Value>(&path).unwrap(), v);
}

/// A folder that is not a sample (no meta.json) is refused by `write_sample`, not replaced.
#[test]
fn writing_onto_a_user_folder_is_refused_and_keeps_it() {
    let root = tempfile::tempdir().unwrap();
    let dir = root.path().join("photos");
    std::fs::create_dir(&dir).unwrap();
    std::fs::write(dir.join("holiday.jpg"), b"x").unwrap();
    let err = write_sample(&dir, &full_sample()).unwrap_err().to_string();
    assert!(
        err.contains("photos") && err.contains("did not write"),
        "{err}"
    );
    assert_eq!(std::fs::read(dir.join("holiday.jpg")).unwrap(), b"x");
    assert_eq!(
        std::fs::read_dir(root.path()).unwrap().count(),
        1,
        "no staging left"
    );
}
