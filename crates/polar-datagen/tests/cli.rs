//! End-to-end behaviour of the real `polar-datagen` binary in temporary directories, with tiny
//! images and low spp so each test takes seconds.

use polar_io::files;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const TINY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../datasets-synth/suites/tiny.toml"
);

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_polar-datagen"))
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("binary runs")
}

fn run_ok(args: &[&str]) -> Output {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 temp path")
}

/// Every image file (not meta.json, which records timings) under the sample dirs, by path.
fn images(dataset: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dataset.to_owned()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let rel = p
                .strip_prefix(dataset)
                .unwrap()
                .to_string_lossy()
                .into_owned();
            if p.is_dir() {
                stack.push(p);
            } else if rel.ends_with(".png") || rel.ends_with(".exr") {
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

fn manifest_ids(dataset: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(dataset.join(files::dataset::MANIFEST)).unwrap();
    text.lines()
        .map(|l| {
            serde_json::from_str::<serde_json::Value>(l).unwrap()["id"]
                .as_str()
                .unwrap()
                .to_owned()
        })
        .collect()
}

#[test]
fn images_are_byte_identical_whatever_the_jobs_or_shards() {
    let t = tempfile::tempdir().unwrap();
    let (a, b) = (t.path().join("jobs1"), t.path().join("jobs2"));
    run_ok(&["suite", TINY, "--out", s(&a), "--jobs", "1", "--quiet"]);
    run_ok(&["suite", TINY, "--out", s(&b), "--jobs", "2", "--quiet"]);
    let (s1, s2, merged) = (
        t.path().join("s1"),
        t.path().join("s2"),
        t.path().join("merged"),
    );
    run_ok(&["suite", TINY, "--out", s(&s1), "--shard", "1/2", "--quiet"]);
    run_ok(&["suite", TINY, "--out", s(&s2), "--shard", "2/2", "--quiet"]);
    run_ok(&["merge", s(&s2), s(&s1), "--out", s(&merged)]);
    let reference = images(&a);
    // tiny.toml ci: 2 families x 3 samples x 7 image files.
    assert_eq!(reference.len(), 42, "{:?}", reference.keys());
    assert!(reference == images(&b), "--jobs 2 differs from --jobs 1");
    assert!(
        reference == images(&merged),
        "merged shards differ from the unsharded run"
    );
    assert_eq!(manifest_ids(&a), manifest_ids(&merged));
    assert!(manifest_ids(&s1).len() == 3 && manifest_ids(&s2).len() == 3);
}

#[test]
fn a_killed_run_resumes_to_a_complete_consistent_dataset() {
    let t = tempfile::tempdir().unwrap();
    let suite = t.path().join("long.toml");
    let text = std::fs::read_to_string(TINY).unwrap().replace(
        "count = 3, width = 16, height = 16, spp = 2",
        "count = 40, width = 16, height = 16, spp = 1",
    );
    std::fs::write(&suite, text).unwrap();
    let out = t.path().join("data");
    let mut child = bin()
        .args([
            "suite",
            s(&suite),
            "--out",
            s(&out),
            "--jobs",
            "2",
            "--quiet",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let manifest = out.join(files::dataset::MANIFEST);
    while std::fs::read_to_string(&manifest).map_or(0, |m| m.lines().count()) < 3 {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no progress within 60 s"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let partial = std::fs::read_to_string(&manifest).unwrap().lines().count();
    assert!(
        partial < 80,
        "the run finished before it was killed; the test needs more samples"
    );
    // No half-written sample: every committed-looking directory has all its files.
    for e in std::fs::read_dir(&out).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if p.is_dir() && !name.starts_with('.') {
            for f in [
                files::META,
                files::RAW,
                files::STOKES,
                files::POLARIZERS,
                files::GT_NORMAL,
                files::GT_DEPTH,
                files::GT_MATERIAL,
            ] {
                assert!(p.join(f).is_file(), "{name}/{f} missing after the kill");
            }
        }
    }
    let rerun = run_ok(&[
        "suite",
        s(&suite),
        "--out",
        s(&out),
        "--jobs",
        "2",
        "--quiet",
    ]);
    let table = String::from_utf8_lossy(&rerun.stdout);
    assert!(table.contains("total"), "{table}");
    // Complete and consistent: 80 entries, unique, each dir matching its checksums, nothing else.
    let ids = manifest_ids(&out);
    assert_eq!(ids.len(), 80);
    let dirs: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert!(
        !dirs.iter().any(|d| d.starts_with('.')),
        "staging left behind: {dirs:?}"
    );
    let mut sorted = dirs.clone();
    sorted.sort();
    assert_eq!(sorted, ids);
    for line in std::fs::read_to_string(&manifest).unwrap().lines() {
        let entry: polar_datagen::store::ManifestEntry = serde_json::from_str(line).unwrap();
        polar_datagen::store::verify_entry(&out, &entry).unwrap();
    }
}

#[test]
fn merge_fails_naming_a_tampered_file_or_a_missing_shard() {
    let t = tempfile::tempdir().unwrap();
    let (s1, s2) = (t.path().join("s1"), t.path().join("s2"));
    run_ok(&["suite", TINY, "--out", s(&s1), "--shard", "1/2", "--quiet"]);
    run_ok(&["suite", TINY, "--out", s(&s2), "--shard", "2/2", "--quiet"]);
    let missing = run(&["merge", s(&s1), "--out", s(&t.path().join("m0"))]);
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("missing shard(s) 2/2"));
    let id = &manifest_ids(&s2)[0];
    let victim: PathBuf = s2.join(id).join(files::STOKES);
    let mut bytes = std::fs::read(&victim).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0x01;
    std::fs::write(&victim, bytes).unwrap();
    let merged = t.path().join("m1");
    let out = run(&["merge", s(&s1), s(&s2), "--out", s(&merged)]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("checksum mismatch") && err.contains(s(&victim)),
        "{err}"
    );
    assert!(
        !merged.join(files::dataset::MANIFEST).exists(),
        "a failed merge wrote a manifest"
    );
}

#[test]
fn bad_suite_files_and_outputs_fail_before_any_work() {
    let t = tempfile::tempdir().unwrap();
    let bad = t.path().join("bad.toml");
    let text = std::fs::read_to_string(TINY).unwrap().replace(
        "kind = \"shape\"",
        "kind = \"shape\"\nranges = { ior = [0.5, 1.5] }",
    );
    std::fs::write(&bad, text).unwrap();
    let out = t.path().join("never");
    let r = run(&["suite", s(&bad), "--out", s(&out)]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        !r.status.success()
            && err.contains("bad.toml")
            && err.contains("ior")
            && err.contains("[1, 3]"),
        "{err}"
    );
    assert!(!out.exists(), "output created for a bad suite");

    let file = t.path().join("a-file");
    std::fs::write(&file, b"x").unwrap();
    let r = run(&["suite", TINY, "--out", s(&file.join("sub"))]);
    assert!(
        String::from_utf8_lossy(&r.stderr).contains("not writable"),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );

    let r = run(&["suite", TINY, "--out", s(&out), "--shard", "3/2"]);
    assert!(!r.status.success() && String::from_utf8_lossy(&r.stderr).contains("K/N"));
    assert!(!out.exists());
}

#[test]
fn demo_writes_a_sample_with_pictures() {
    let t = tempfile::tempdir().unwrap();
    let demo = t.path().join("demo");
    run_ok(&["demo", "--out", s(&demo), "--size", "32", "--spp", "2"]);
    for f in [files::META, files::RAW, files::STOKES, files::GT_NORMAL] {
        assert!(demo.join(f).is_file(), "demo/{f}");
    }
    let pictures = demo.join(files::vision::PICTURES);
    for f in [
        files::vision::AOLP_PICTURE,
        files::vision::DOLP_PICTURE,
        files::vision::S0_PICTURE,
    ] {
        assert!(pictures.join(f).is_file(), "demo/pictures/{f}");
    }
}

const SCENE: &str = r#"
version = 1
[render]
spp = 4
seed = 1
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov_deg = 30.0
width = 16
height = 16
[materials.sphere]
type = "plastic"
albedo = 0.5
ior = 1.5
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "sphere"
[[lights]]
type = "environment"
radiance = 0.5
[sensor]
bits = 10
read_noise_e = 3.0
"#;

#[test]
fn render_is_seeded_and_rejects_bad_scene_files_before_rendering() {
    let t = tempfile::tempdir().unwrap();
    let scene = t.path().join("scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let (a, b, c) = (t.path().join("a"), t.path().join("b"), t.path().join("c"));
    run_ok(&[
        "render",
        s(&scene),
        "--out",
        s(&a),
        "--spp",
        "2",
        "--seed",
        "3",
    ]);
    run_ok(&[
        "render",
        s(&scene),
        "--out",
        s(&b),
        "--spp",
        "2",
        "--seed",
        "3",
    ]);
    run_ok(&[
        "render",
        s(&scene),
        "--out",
        s(&c),
        "--spp",
        "2",
        "--seed",
        "4",
    ]);
    let raw = |d: &Path| std::fs::read(d.join(files::RAW)).unwrap();
    assert_eq!(raw(&a), raw(&b), "same seed, different raw.png");
    assert_ne!(raw(&a), raw(&c), "the seed does not reach the noise");
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(a.join(files::META)).unwrap()).unwrap();
    assert_eq!(meta["sensor"]["bit_depth"], 10);
    assert_eq!(meta["spp"], 2);

    let bad = t.path().join("bad.toml");
    std::fs::write(
        &bad,
        SCENE.replace("radius = 1.0", "radius = 1.0\ncolour = 2"),
    )
    .unwrap();
    let out = t.path().join("never");
    let r = run(&["render", s(&bad), "--out", s(&out)]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        !r.status.success() && err.contains("bad.toml") && err.contains("colour"),
        "{err}"
    );
    std::fs::write(&bad, SCENE.replace("bits = 10", "bitz = 10")).unwrap();
    let r = run(&["render", s(&bad), "--out", s(&out)]);
    assert!(String::from_utf8_lossy(&r.stderr).contains("bitz"));
    assert!(!out.exists(), "output created for a bad scene");
}

/// `polarizers.exr` holds what the micro-polarizers see: decoding it with the
/// closed-form Stokes of polar-optics gives back the rendered AoLP exactly, and
/// S0 and DoLP scaled by the extinction ratio's `(1 + t²)` and `(1 − t²)/(1 + t²)`.
#[test]
fn polarizer_images_decode_to_the_rendered_stokes() {
    use polar_optics::stokes::{aolp, dolp, linear_stokes_from_quad};
    let t = tempfile::tempdir().unwrap();
    let demo = t.path().join("demo");
    run_ok(&["demo", "--out", s(&demo), "--size", "32", "--spp", "4"]);
    let stokes: polar_image::StokesImage =
        polar_io::read_exr(demo.join(files::STOKES), polar_io::STOKES_CHANNELS).unwrap();
    let quad: polar_image::PolarizerStack =
        polar_io::read_exr(demo.join(files::POLARIZERS), polar_io::POLARIZER_CHANNELS).unwrap();
    let mut s0_ratio: Option<f32> = None;
    let mut checked = 0;
    for (s, i) in stokes.pixels().iter().zip(quad.pixels()) {
        let [q0, q1, q2] = linear_stokes_from_quad(i[0], i[1], i[2], i[3]);
        if s[0] < 1e-3 || dolp(s[0], s[1], s[2]) < 0.05 {
            continue;
        }
        // f32 sums of a few terms: relative error ~1e-6; 1e-4 leaves room and still
        // catches a swapped channel (an error of order 1).
        let ratio = *s0_ratio.get_or_insert(q0 / s[0]);
        assert!((q0 / s[0] - ratio).abs() < 1e-4 * ratio, "S0 scale varies");
        assert!(dolp(q0, q1, q2) <= dolp(s[0], s[1], s[2]) * (1.0 + 1e-4));
        let d = (aolp(q0, q1, q2) - aolp(s[0], s[1], s[2])).abs();
        let d = d.min(std::f32::consts::PI - d);
        assert!(d < 1e-3, "AoLP differs by {d} rad");
        checked += 1;
    }
    assert!(checked > 20, "only {checked} polarized pixels to check");
}

/// Generates the two-sample haze suite (24 × 16 pixels, 4 spp) under `dir`; returns the
/// dataset directory and the suite run's table.
fn haze_suite(dir: &Path) -> (PathBuf, String) {
    let suite = dir.join("haze.toml");
    std::fs::write(
        &suite,
        r#"version = 1
name = "haze-test"
seed = 3
[[noise]]
name = "clean"
full_well_e = 60000
read_noise_e = 0.0
bits = 16
shot_noise = false
[[family]]
name = "haze"
kind = "haze"
ci = { count = 2, width = 24, height = 16, spp = 4 }
full = { count = 2, width = 24, height = 16, spp = 4 }
ranges = { density = [0.03, 0.04], scene_depth = [40.0, 60.0] }
"#,
    )
    .unwrap();
    let out = dir.join("data");
    let run = run_ok(&["suite", s(&suite), "--out", s(&out), "--quiet"]);
    (out, String::from_utf8_lossy(&run.stdout).into_owned())
}

#[test]
fn haze_samples_carry_the_clear_view_and_the_transmission_map() {
    let t = tempfile::tempdir().unwrap();
    let (out, table) = haze_suite(t.path());
    // The Henyey-Greenstein haze polarizes linearly and never couples S3.
    assert!(
        table.contains("haze") && table.contains("Linear"),
        "{table}"
    );
    for id in manifest_ids(&out) {
        // read_sample checks transmission in [0, 1] and clear S0 finite and >= 0.
        let sample = polar_io::read_sample(out.join(&id)).unwrap();
        let transmission = sample.gt.transmission.expect(files::GT_TRANSMISSION);
        let clear = sample.gt.clear.expect(files::GT_CLEAR);
        let hazy = sample.stokes.expect(files::STOKES).channel(0);
        // Sight lines cross 40-60 m of haze with sigma_t >= 0.03 /m: transmittance well below 1.
        let least = transmission.as_slice().iter().copied().fold(1.0, f32::min);
        assert!(least < 0.5, "{id}: least transmittance {least}");
        let differs = hazy
            .as_slice()
            .iter()
            .zip(clear.as_slice())
            .filter(|(h, c)| (*h - *c).abs() > 1e-3 * c.abs().max(1e-3))
            .count();
        assert!(
            differs > hazy.as_slice().len() / 2,
            "{id}: haze changed only {differs} pixels"
        );
    }
}

#[test]
fn haze_samples_carry_the_dehazed_view() {
    let t = tempfile::tempdir().unwrap();
    let (out, _) = haze_suite(t.path());
    let ids = manifest_ids(&out);
    assert_eq!(ids.len(), 2);
    for id in ids {
        assert!(out.join(&id).join(polar_io::files::GT_DEHAZED).is_file());
        // read_sample also checks dehazed S0 finite, >= 0 and the size of stokes.exr.
        let sample = polar_io::read_sample(out.join(&id)).unwrap();
        let dehazed = sample.gt.dehazed.expect(files::GT_DEHAZED);
        let hazy = sample.stokes.expect(files::STOKES).channel(0);
        let clear = sample.gt.clear.expect(files::GT_CLEAR);
        assert_eq!(dehazed.size(), (24, 16), "{id}");
        assert!(
            dehazed
                .as_slice()
                .iter()
                .all(|v| v.is_finite() && *v >= 0.0),
            "{id}: dehazed S0 not finite and >= 0"
        );
        assert!(
            dehazed.as_slice().iter().any(|v| *v > 0.0),
            "{id}: all dark"
        );
        // Not a copy of either render: without airlight and attenuation the dehazed view
        // differs from the hazy one almost everywhere (40-60 m of haze on every sight line;
        // 382 and 383 of 384 pixels measured).
        let differs = |other: &polar_image::Gray<f32>| {
            dehazed
                .as_slice()
                .iter()
                .zip(other.as_slice())
                .filter(|(d, o)| (*d - *o).abs() > 1e-3 * o.abs().max(1e-3))
                .count()
        };
        let n = hazy.as_slice().len();
        assert!(
            differs(&hazy) > n / 2,
            "{id}: dehazed is nearly the hazy view"
        );
        // Where a surface is seen, the dehazed view is lit through the haze, the clear
        // one by the unattenuated sun: they differ there (about 3/4 of these views).
        assert!(
            differs(&clear) > n / 4,
            "{id}: dehazed is nearly the clear view"
        );
    }
}

/// Stderr of a run that must fail.
fn fails(args: &[&str]) -> String {
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "{args:?} succeeded: {err}");
    err
}

/// The names in `dir` (hidden ones too), sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Issue #22 (item 4): `suite --out` into a folder of the user's files (a `suite.toml`, a
/// folder named like a sample with a photo) refuses before writing anything.
#[test]
fn suite_refuses_a_folder_that_is_not_a_dataset() {
    let t = tempfile::tempdir().unwrap();
    let user = t.path().join("photos");
    std::fs::create_dir_all(user.join("sfp-00001")).unwrap();
    std::fs::write(user.join(files::dataset::SUITE_COPY), b"mine").unwrap();
    std::fs::write(user.join("sfp-00001/photo.jpg"), b"jpeg").unwrap();
    let err = fails(&["suite", TINY, "--out", s(&user), "--quiet"]);
    assert!(
        err.contains("is not a polar-datagen dataset") && err.contains("sfp-00001, suite.toml"),
        "{err}"
    );
    assert_eq!(names(&user), ["sfp-00001", files::dataset::SUITE_COPY]);
    assert_eq!(
        std::fs::read(user.join(files::dataset::SUITE_COPY)).unwrap(),
        b"mine"
    );
    assert_eq!(names(&user.join("sfp-00001")), ["photo.jpg"]);
}

/// Issue #22 (item 6): while another run holds a dataset's lock, `suite` stops at once and
/// says so; once the lock is released the same command runs.
#[test]
fn suite_refuses_a_dataset_another_run_holds() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("ds");
    std::fs::create_dir(&out).unwrap();
    let lock = polar_datagen::store::lock_dataset(&out).unwrap();
    let err = fails(&["suite", TINY, "--out", s(&out), "--quiet"]);
    assert!(
        err.contains("in use by another polar-datagen run") && err.contains(".polar-datagen.lock"),
        "{err}"
    );
    assert_eq!(names(&out), [".polar-datagen.lock"], "wrote while locked");
    drop(lock);
    run_ok(&["suite", TINY, "--out", s(&out), "--quiet"]);
    assert_eq!(manifest_ids(&out).len(), 6);
}

/// Issue #22 (items 3 and 9): sizes that would exhaust memory or run for years, and bad
/// options, are refused at once naming the key or option the user wrote.
#[test]
fn size_keys_and_options_are_bounded_and_named() {
    let t = tempfile::tempdir().unwrap();
    let suite = t.path().join("big.toml");
    let text = std::fs::read_to_string(TINY).unwrap();
    std::fs::write(&suite, text.replacen("count = 3", "count = 1000000000", 1)).unwrap();
    let out = t.path().join("never");
    let err = fails(&["suite", s(&suite), "--out", s(&out)]);
    assert!(
        err.contains("ci.count = 1000000000 exceeds 1000000"),
        "{err}"
    );
    // The suite error names the suite file once, not twice.
    assert_eq!(err.matches("big.toml").count(), 1, "{err}");
    let err = fails(&["suite", TINY, "--out", s(&out), "--jobs", "100000000000"]);
    assert!(err.contains("--jobs") && err.contains("1..=1024"), "{err}");
    let err = fails(&["demo", "--out", s(&out), "--spp", "4294967295"]);
    assert!(
        err.contains("--spp") && err.contains("1..=1048576"),
        "{err}"
    );
    assert!(!out.exists(), "output created for refused arguments");

    let scene = t.path().join("huge.toml");
    std::fs::write(&scene, SCENE.replace("width = 16", "width = 100000")).unwrap();
    let start = Instant::now();
    let err = fails(&["render", s(&scene), "--out", s(&out)]);
    assert!(
        err.contains("`camera.width`") && err.contains("16384"),
        "{err}"
    );
    assert!(
        start.elapsed() < Duration::from_secs(30),
        "refused only after work"
    );
    // A scene error names the scene file once (no "suite x.toml: x.toml:").
    assert_eq!(err.matches("huge.toml").count(), 1, "{err}");
    assert!(err.starts_with("polar-datagen: error: scene "), "{err}");
}

/// Issue #22 (item 9): `demo --out .` names no sample directory; it is refused naming `--out`
/// instead of writing `./sample` while saying "wrote .".
#[test]
fn demo_out_must_name_a_directory() {
    let t = tempfile::tempdir().unwrap();
    let out = bin()
        .current_dir(t.path())
        .args(["demo", "--out", ".", "--size", "8", "--spp", "1"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--out"), "{err}");
    assert!(names(t.path()).is_empty(), "wrote {:?}", names(t.path()));
}

/// Issue #22 (items 8 and 9): `render` checks the image size and the `[sensor]` table before
/// rendering, names the key the user wrote, and leaves no staging directory behind.
#[test]
fn render_validates_size_and_sensor_first_and_leaves_no_staging() {
    let t = tempfile::tempdir().unwrap();
    let cases = [
        (
            SCENE
                .replace("width = 16", "width = 501")
                .replace("height = 16", "height = 401"),
            "`camera.width`: 501 must be even",
        ),
        (
            SCENE.replace("bits = 10", "bits = 10\nfull_well_e = -100"),
            "full_well_e = -100 must be >= 1",
        ),
        (
            SCENE.replace("bits = 10", "bits = 0"),
            "bits = 0 must be in 8..=16",
        ),
    ];
    for (i, (text, message)) in cases.iter().enumerate() {
        let scene = t.path().join(format!("scene{i}.toml"));
        std::fs::write(&scene, text).unwrap();
        let err = fails(&["render", s(&scene), "--out", s(&t.path().join("out"))]);
        assert!(err.contains(message), "{err}");
        assert!(
            !err.contains("photons_per_unit") && !err.contains("gain"),
            "internal name in: {err}"
        );
    }
    assert_eq!(
        names(t.path()),
        ["scene0.toml", "scene1.toml", "scene2.toml"],
        "left files behind"
    );
}
