//! Hard cases for every task through `polar-vision run`: frames that are tiny, huge, dark,
//! saturated, unpolarized, fully polarized or partly undefined. Each must end in a clear
//! error (for frames with no information at all) or in outputs that are finite where the
//! conventions define them: unit or zero normals, depth finite or NaN only off the
//! objects, labels 0..=3, a 0/255 mask, transmission in (0, 1], finite dehazed radiance.

mod common;

use std::path::Path;

use common::{arg, json, vision};
use polar_image::{Gray, Mosaic, NormalImage, StokesImage};
use polar_io::files;
use polar_io::files::vision as out_files;

/// A sample directory holding only `stokes.exr` made of `f(x, y) -> [S0, S1, S2]`.
fn stokes_sample(dir: &Path, w: usize, h: usize, f: impl Fn(usize, usize) -> [f32; 3]) {
    std::fs::create_dir_all(dir).unwrap();
    let data = (0..w * h)
        .flat_map(|k| {
            let [s0, s1, s2] = f(k % w, k / w);
            [s0, s1, s2, 0.0]
        })
        .collect();
    let img = StokesImage::from_vec(w, h, data).unwrap();
    polar_io::write_exr(dir.join(files::STOKES), &img, polar_io::STOKES_CHANNELS).unwrap();
}

/// A sample directory holding only a 16-bit `raw.png`.
fn raw_sample(dir: &Path, w: usize, h: usize, f: impl Fn(usize, usize) -> u16) {
    std::fs::create_dir_all(dir).unwrap();
    let raw = Mosaic::from_vec(w, h, (0..w * h).map(|k| f(k % w, k / w)).collect()).unwrap();
    polar_io::write_gray16_png(dir.join(files::RAW), &raw).unwrap();
}

/// A lit sphere-like blob: S0 bright in a disc, DoLP rising toward its rim.
fn blob(w: usize, h: usize, x: usize, y: usize) -> [f32; 3] {
    let (cx, cy, r) = (w as f32 / 2.0, h as f32 / 2.0, w.min(h) as f32 * 0.35);
    let (dx, dy) = (x as f32 + 0.5 - cx, y as f32 + 0.5 - cy);
    let rho = (dx * dx + dy * dy).sqrt() / r;
    if rho >= 1.0 {
        return [0.2, 0.0, 0.0];
    }
    let dolp = 0.3 * rho * rho;
    let phi = dy.atan2(dx);
    [1.0, dolp * (2.0 * phi).cos(), dolp * (2.0 * phi).sin()]
}

/// Runs every task on `sample`; returns the output folder after checking its outputs.
fn run_all(sample: &Path) -> tempfile::TempDir {
    let out = tempfile::tempdir().unwrap();
    let result = vision(&["run", arg(sample), "--out", arg(out.path())]);
    assert!(result.is_ok(), "{}: {:?}", sample.display(), result);
    check_outputs(out.path());
    out
}

fn check_outputs(out: &Path) {
    let read = |name: &str, ch: &str| polar_io::read_exr_channel(out.join(name), ch).ok();
    let normals: polar_io::Result<NormalImage> =
        polar_io::read_exr(out.join(out_files::NORMAL), polar_io::RGB_CHANNELS);
    if let Ok(fg) = normals {
        for n in fg.pixels() {
            let len = n.iter().map(|v| v * v).sum::<f32>().sqrt();
            assert!(len == 0.0 || (len - 1.0).abs() < 1e-3, "normal {n:?}");
        }
    }
    for (name, lo, hi) in [
        (out_files::TRANSMISSION, f32::MIN_POSITIVE, 1.0),
        (out_files::DEHAZED, f32::MIN, f32::MAX),
        (out_files::NORMAL_CONFIDENCE, 0.0, 1.0),
        (out_files::TRANSPARENT_SCORE, 0.0, 1.0),
        (out_files::MATERIAL_CONFIDENCE, 0.0, 1.0),
    ] {
        if let Some(img) = read(name, "Y") {
            let bad = img
                .as_slice()
                .iter()
                .find(|v| !(v.is_finite() && **v >= lo && **v <= hi));
            assert!(bad.is_none(), "{name}: {bad:?} outside [{lo}, {hi}]");
        }
    }
    if let Some(depth) = read(out_files::DEPTH, "Y") {
        assert!(
            depth.as_slice().iter().all(|v| v.is_finite() || v.is_nan()),
            "depth ±inf"
        );
    }
    if let Ok(labels) = polar_io::read_gray8_png(out.join(out_files::MATERIAL)) {
        assert!(
            labels.as_slice().iter().all(|&l| l <= 3),
            "material label > 3"
        );
    }
    if let Ok(mask) = polar_io::read_gray8_png(out.join(out_files::TRANSPARENT)) {
        assert!(
            mask.as_slice().iter().all(|&m| m == 0 || m == 255),
            "mask not 0/255"
        );
    }
}

#[test]
fn two_by_two_frames_run_every_task() {
    let dir = tempfile::tempdir().unwrap();
    let s = dir.path().join("tiny");
    stokes_sample(&s, 2, 2, |x, y| [1.0 + x as f32, 0.1 * y as f32, 0.0]);
    run_all(&s);
    let r = dir.path().join("tiny-raw");
    raw_sample(&r, 2, 2, |x, y| 1000 + 300 * (x + 2 * y) as u16);
    run_all(&r);
}

#[test]
fn unpolarized_and_fully_polarized_frames() {
    let dir = tempfile::tempdir().unwrap();
    let flat = dir.path().join("dolp0");
    stokes_sample(&flat, 32, 24, |x, y| {
        [0.5 + 0.01 * (x + y) as f32, 0.0, 0.0]
    });
    run_all(&flat);
    let full = dir.path().join("dolp1");
    stokes_sample(&full, 32, 24, |x, _| {
        let a = x as f32 * 0.2;
        [1.0, a.cos(), a.sin()]
    });
    run_all(&full);
}

#[test]
fn zero_and_undefined_pixels_inside_a_valid_frame() {
    let dir = tempfile::tempdir().unwrap();
    let s = dir.path().join("holes");
    stokes_sample(&s, 40, 30, |x, y| match (x + 3 * y) % 11 {
        0 => [0.0, 0.0, 0.0],
        1 => [f32::NAN, 0.0, 0.0],
        _ => blob(40, 30, x, y),
    });
    run_all(&s);
}

/// `--objects` that cannot be used is a clear error naming the file, before any output: a
/// mask missing, of another size than the frame, or `gt` where the sample has none. A mask
/// found inside the sample directory is used (its pixels, and only those, get normals);
/// one that marks no pixel is used with a warning.
#[test]
fn object_masks_that_cannot_be_used_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let s = dir.path().join("blob");
    stokes_sample(&s, 40, 30, |x, y| blob(40, 30, x, y));
    let out = dir.path().join("out");
    let run = |objects: &str| {
        vision(&[
            "run",
            arg(&s),
            "--out",
            arg(&out),
            "--tasks",
            "sfp",
            "--objects",
            objects,
        ])
    };
    let err = run("nowhere.png").unwrap_err();
    assert!(err.contains("nowhere.png"), "{err}");
    polar_io::write_gray8_png(s.join("small.png"), &Gray::<u8>::new(39, 30)).unwrap();
    let err = run("small.png").unwrap_err();
    assert!(
        err.contains("small.png") && err.contains("39x30, the frame 40x30"),
        "{err}"
    );
    let err = run("gt").unwrap_err();
    assert!(
        err.contains("gt/material.png") && err.contains("missing"),
        "{err}"
    );
    assert!(!out.exists(), "an output folder was left behind");
    let mut mask = Gray::<u8>::new(40, 30);
    mask.as_mut_slice()[..40 * 10].fill(255);
    polar_io::write_gray8_png(s.join("top.png"), &mask).unwrap();
    assert_eq!(run("top.png"), Ok(true));
    let normals: NormalImage =
        polar_io::read_exr(out.join(out_files::NORMAL), ["R", "G", "B"]).unwrap();
    for (k, n) in normals.pixels().iter().enumerate() {
        assert_eq!(n.iter().any(|v| *v != 0.0), k < 40 * 10, "pixel {k}: {n:?}");
    }
    // A mask without any object runs, with a warning in the sample's report.
    polar_io::write_gray8_png(s.join("none.png"), &Gray::<u8>::new(40, 30)).unwrap();
    std::fs::remove_dir_all(&out).unwrap();
    let report = dir.path().join("eval");
    let eval = ["eval", arg(dir.path()), "--out", arg(&report)];
    let args = [&eval[..], &["--tasks", "sfp", "--objects", "none.png"]].concat();
    assert_eq!(vision(&args), Ok(true));
    let warnings = json(&report.join("metrics.json"))["samples"]["blob"]["Ok"]["warnings"].clone();
    assert!(
        warnings
            .to_string()
            .contains("none.png: the object mask marks no pixel"),
        "{warnings}"
    );
}

#[test]
fn all_black_and_all_white_raw_frames_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let black = dir.path().join("black");
    raw_sample(&black, 16, 16, |_, _| 0);
    let out = tempfile::tempdir().unwrap();
    let err = vision(&["run", arg(&black), "--out", arg(out.path())]).unwrap_err();
    assert!(err.contains("every pixel is 0"), "{err}");
    let white = dir.path().join("white");
    raw_sample(&white, 16, 16, |_, _| u16::MAX);
    let err = vision(&["run", arg(&white), "--out", arg(out.path())]).unwrap_err();
    assert!(err.contains("saturated"), "{err}");
}

#[test]
fn stokes_frames_without_light_are_clear_errors_like_raw_ones() {
    // Regression: an all-zero, all-NaN or all-negative stokes.exr exited 0 with no word,
    // while the raw path refuses an all-zero frame.
    for (name, s0) in [("zero", 0.0f32), ("nan", f32::NAN), ("negative", -1.0)] {
        let dir = tempfile::tempdir().unwrap();
        let s = dir.path().join(name);
        stokes_sample(&s, 16, 16, |_, _| [s0, 0.0, 0.0]);
        let out = tempfile::tempdir().unwrap();
        let err = vision(&["run", arg(&s), "--out", arg(out.path())]).unwrap_err();
        assert!(err.contains("no light"), "{name}: {err}");
    }
}

#[test]
fn an_almost_dark_stokes_frame_gives_documented_empty_results() {
    let dir = tempfile::tempdir().unwrap();
    let s = dir.path().join("dark");
    stokes_sample(&s, 16, 16, |x, y| {
        [if (x, y) == (3, 3) { 1e-6 } else { 0.0 }, 0.0, 0.0]
    });
    let out = run_all(&s);
    let normals: polar_io::Result<NormalImage> =
        polar_io::read_exr(out.path().join(out_files::NORMAL), polar_io::RGB_CHANNELS);
    let lit = normals
        .unwrap()
        .pixels()
        .iter()
        .filter(|n| n.iter().any(|&v| v != 0.0))
        .count();
    assert!(lit <= 1, "{lit} normals on a frame with one lit pixel");
}

#[test]
fn partly_saturated_raw_frames_flag_and_go_on() {
    let dir = tempfile::tempdir().unwrap();
    let s = dir.path().join("sat");
    raw_sample(&s, 48, 32, |x, y| {
        let [s0, s1, s2] = blob(48, 32, x, y);
        let theta = [[90.0f32, 45.0], [135.0, 0.0]][y % 2][x % 2].to_radians();
        let i = 0.5 * (s0 + s1 * (2.0 * theta).cos() + s2 * (2.0 * theta).sin());
        if x < 6 {
            4095
        } else {
            (i * 3000.0) as u16 + 20
        }
    });
    run_all(&s);
}

#[test]
fn an_eight_megapixel_frame_runs_every_task() {
    let dir = tempfile::tempdir().unwrap();
    let s = dir.path().join("big");
    let (w, h) = (3264, 2448);
    raw_sample(&s, w, h, |x, y| {
        let [s0, s1, s2] = blob(w, h, x, y);
        let theta = [[90.0f32, 45.0], [135.0, 0.0]][y % 2][x % 2].to_radians();
        (2000.0 * (s0 + s1 * (2.0 * theta).cos() + s2 * (2.0 * theta).sin())) as u16 + 50
    });
    run_all(&s);
}

/// The same camera data as an 8-bit PNG, in a 16-bit PNG aligned right, and aligned left
/// (read without options: the low bits that are 0 in every sample are found) give every
/// task the same outputs, byte for byte: nothing depends on the container or the data's
/// place in it.
#[test]
fn a_frame_reads_the_same_in_every_bit_alignment() {
    let frame = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/real/camera_IMX250MZR.png");
    let full = polar_io::read_gray8_png(frame).unwrap();
    let (x0, y0, w, h) = (1024, 896, 192, 160);
    let crop: Vec<u8> = (0..w * h)
        .map(|k| full.as_slice()[(y0 + k / w) * full.width() + x0 + k % w])
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let sample = |name: &str| dir.path().join(name);
    std::fs::create_dir_all(sample("eight")).unwrap();
    let eight = Gray::from_vec(w, h, crop.clone()).unwrap();
    polar_io::write_gray8_png(sample("eight").join(files::RAW), &eight).unwrap();
    raw_sample(&sample("right"), w, h, |x, y| u16::from(crop[y * w + x]));
    raw_sample(&sample("left"), w, h, |x, y| {
        u16::from(crop[y * w + x]) << 8
    });
    let outs: Vec<_> = ["eight", "right", "left"]
        .iter()
        .map(|s| run_all(&sample(s)))
        .collect();
    let mut compared = 0;
    for entry in std::fs::read_dir(outs[0].path()).unwrap() {
        let name = entry.unwrap().file_name();
        let is_image = [".exr", ".png"]
            .iter()
            .any(|e| name.to_string_lossy().ends_with(e));
        if !is_image {
            continue;
        }
        let bytes = |o: &tempfile::TempDir| std::fs::read(o.path().join(&name)).unwrap();
        for o in &outs[1..] {
            assert!(
                bytes(&outs[0]) == bytes(o),
                "{} differs",
                name.to_string_lossy()
            );
        }
        compared += 1;
    }
    assert!(compared >= 15, "only {compared} outputs compared");
}
