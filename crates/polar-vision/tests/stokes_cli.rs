//! End-to-end tests of `polar-vision stokes`: the real binary in a temporary directory.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use polar_image::Mosaic;
use polar_image::quantile;
use polar_io::RGB_LINEAR_STOKES_CHANNELS;
use polar_io::files::{self, vision};
use polar_sensor::picture::{colormap, srgb_into};
use polar_sensor::{DemosaicMethod, StokesPlanes, stokes_planes, stokes_planes_rgb};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_polar-vision"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Runs `stokes` and asserts failure with a message containing `needle`.
fn fails_with(args: &[&str], needle: &str) {
    let out = run(args);
    assert!(!out.status.success(), "expected failure for {args:?}");
    assert!(
        stderr(&out).contains(needle),
        "stderr for {args:?} lacks {needle:?}:\n{}",
        stderr(&out)
    );
}

fn mosaic8(w: usize, h: usize) -> Mosaic<u8> {
    Mosaic::from_vec(
        w,
        h,
        (0..w * h)
            .map(|i| (20 + (i * 37 + i / w * 11) % 200) as u8)
            .collect(),
    )
    .unwrap()
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

const OUTPUTS: [&str; 7] = [
    vision::STOKES,
    vision::DOLP,
    vision::AOLP,
    vision::AOLP_PICTURE,
    vision::DOLP_PICTURE,
    vision::S0_PICTURE,
    vision::MASK,
];

#[test]
fn writes_every_output_and_matches_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let raw = mosaic8(16, 12);
    let input = dir.path().join(files::RAW);
    polar_io::write_gray8_png(&input, &raw).unwrap();
    let out_dir = dir.path().join("out");
    for method in DemosaicMethod::ALL {
        let out = run(&[
            "stokes",
            p(&input),
            "--out",
            p(&out_dir),
            "--demosaic",
            method.name(),
        ]);
        assert!(out.status.success(), "{method}: {}", stderr(&out));
        for f in OUTPUTS {
            assert!(out_dir.join(f).is_file(), "{method}: missing {f}");
        }
        let want = stokes_planes(&raw, method).unwrap();
        let got = polar_io::read_exr(
            out_dir.join(vision::STOKES),
            polar_io::LINEAR_STOKES_CHANNELS,
        )
        .unwrap();
        assert_eq!(got, want.linear_stokes(), "{method}");
        let dolp = polar_io::read_exr_channel(out_dir.join(vision::DOLP), "Y").unwrap();
        assert_eq!(dolp.size(), want.dolp.size());
        // The palette pictures read back as the library's viridis maps, pixel for pixel.
        let s0_max = quantile(want.s0.as_slice().iter().copied(), 0.995).unwrap();
        for (file, plane, top) in [
            (vision::DOLP_PICTURE, &want.dolp, 1.0),
            (vision::S0_PICTURE, &want.s0, s0_max),
        ] {
            let picture = polar_io::read_rgb8_png(out_dir.join(file)).unwrap();
            assert_eq!(picture, colormap(plane, 0.0, top), "{method}: {file}");
        }
    }
}

#[test]
fn sample_directory_with_raw_png_or_only_stokes_exr() {
    let dir = tempfile::tempdir().unwrap();
    let sample = dir.path().join("sample");
    std::fs::create_dir(&sample).unwrap();
    polar_io::write_gray8_png(sample.join(files::RAW), &mosaic8(8, 8)).unwrap();
    let out1 = dir.path().join("o1");
    let first = run(&["stokes", p(&sample), "--out", p(&out1)]);
    assert!(first.status.success(), "{}", stderr(&first));
    assert!(
        stderr(&first).contains("(demosaic residual)"),
        "{}",
        stderr(&first)
    );

    // Only stokes.exr: DoLP/AoLP from it directly.
    std::fs::remove_file(sample.join(files::RAW)).unwrap();
    std::fs::copy(out1.join(vision::STOKES), sample.join(files::STOKES)).unwrap();
    let out2 = dir.path().join("o2");
    let out = run(&["stokes", p(&sample), "--out", p(&out2)]);
    assert!(out.status.success(), "{}", stderr(&out));
    // Issue #22: the status line names what was read, not a demosaicing method it never ran.
    let status = stderr(&out);
    assert!(
        status.contains("(Stokes EXR, not demosaiced)") && !status.contains("residual"),
        "{status}"
    );
    assert_eq!(
        polar_io::read_exr_channel(out1.join(vision::DOLP), "Y").unwrap(),
        polar_io::read_exr_channel(out2.join(vision::DOLP), "Y").unwrap()
    );

    std::fs::remove_file(sample.join(files::STOKES)).unwrap();
    fails_with(
        &["stokes", p(&sample), "--out", p(&out2)],
        "not a PNG file nor a sample directory",
    );
}

#[test]
fn odd_tiny_zero_and_saturated_frames_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let case = |name: &str, img: Mosaic<u8>| -> PathBuf {
        let path = dir.path().join(name);
        polar_io::write_gray8_png(&path, &img).unwrap();
        path
    };
    let odd = case("odd.png", mosaic8(15, 12));
    fails_with(&["stokes", p(&odd), "--out", p(&out)], "must be even");
    let tiny = case("tiny.png", mosaic8(1, 1));
    fails_with(&["stokes", p(&tiny), "--out", p(&out)], "1x1");
    let zero = case("zero.png", Mosaic::new(8, 8));
    fails_with(&["stokes", p(&zero), "--out", p(&out)], "every pixel is 0");
    let sat = case("sat.png", Mosaic::from_vec(8, 8, vec![255; 64]).unwrap());
    fails_with(
        &["stokes", p(&sat), "--out", p(&out)],
        "every pixel is saturated",
    );

    // Partly saturated: works, warns, and flags the mask.
    let mut part = mosaic8(8, 8);
    part.as_mut_slice()[0] = 255;
    let part = case("part.png", part);
    let res = run(&["stokes", p(&part), "--out", p(&out)]);
    assert!(res.status.success());
    assert!(stderr(&res).contains("1 of 64 pixels"), "{}", stderr(&res));
    let mask = polar_io::read_gray8_png(out.join(vision::MASK)).unwrap();
    assert_eq!(mask.pixel(0, 0)[0], polar_sensor::mask::SATURATED);
    assert_eq!(mask.pixel(7, 7)[0], 0);
}

#[test]
fn twelve_bit_data_left_or_right_aligned_in_16_bit_png() {
    let dir = tempfile::tempdir().unwrap();
    let right: Mosaic<u16> = Mosaic::from_vec(
        8,
        8,
        (0..64).map(|i| (100 + i * 61 % 3900) as u16).collect(),
    )
    .unwrap();
    let left = Mosaic::from_vec(8, 8, right.as_slice().iter().map(|v| v << 4).collect()).unwrap();
    let (rp, lp) = (dir.path().join("right.png"), dir.path().join("left.png"));
    polar_io::write_gray16_png(&rp, &right).unwrap();
    polar_io::write_gray16_png(&lp, &left).unwrap();
    let (o1, o2) = (dir.path().join("o1"), dir.path().join("o2"));
    let ok = run(&[
        "stokes",
        p(&rp),
        "--out",
        p(&o1),
        "--bit-depth",
        "12",
        "--align",
        "right",
    ]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    let ok = run(&[
        "stokes",
        p(&lp),
        "--out",
        p(&o2),
        "--bit-depth",
        "12",
        "--align",
        "left",
    ]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    let s = |o: &Path| polar_io::read_exr_channel(o.join(vision::STOKES), "S0").unwrap();
    assert_eq!(s(&o1), s(&o2), "both alignments give the same DN");

    fails_with(
        &["stokes", p(&lp), "--out", p(&o1), "--bit-depth", "12"],
        "try --align left",
    );
    fails_with(
        &[
            "stokes",
            p(&rp),
            "--out",
            p(&o1),
            "--bit-depth",
            "12",
            "--align",
            "left",
        ],
        "try --align right",
    );
    let eight = dir.path().join("eight.png");
    polar_io::write_gray8_png(&eight, &mosaic8(8, 8)).unwrap();
    fails_with(
        &["stokes", p(&eight), "--out", p(&o1), "--bit-depth", "12"],
        "more than the 8-bit samples",
    );
    fails_with(
        &["stokes", p(&eight), "--out", p(&o1), "--bit-depth", "11"],
        "invalid value '11'",
    );
}

#[test]
fn truncated_non_png_missing_input_and_bad_arguments() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let good = dir.path().join("good.png");
    polar_io::write_gray8_png(&good, &mosaic8(64, 64)).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    let truncated = dir.path().join("truncated.png");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    fails_with(
        &["stokes", p(&truncated), "--out", p(&out)],
        "truncated or corrupt",
    );
    let text = dir.path().join("notes.png");
    std::fs::write(&text, "not an image").unwrap();
    fails_with(
        &["stokes", p(&text), "--out", p(&out)],
        "truncated or corrupt",
    );
    fails_with(
        &[
            "stokes",
            p(&dir.path().join("missing.png")),
            "--out",
            p(&out),
        ],
        "no such file",
    );
    fails_with(
        &["stokes", p(&good), "--out", p(&out), "--demosaic", "cubic"],
        "unknown demosaicing method `cubic`",
    );
    fails_with(&["stokes", p(&good)], "--out");
    for bad in ["1.5", "-0.1", "a lot"] {
        fails_with(
            &[
                "run",
                p(&good),
                "--out",
                p(&out),
                "--dehaze-min-airlight",
                bad,
            ],
            "--dehaze-min-airlight",
        );
    }
    // --out naming a file is rejected before any work.
    fails_with(&["stokes", p(&good), "--out", p(&good)], "not a folder");
    assert!(
        !out.exists(),
        "a failed run must not leave its output folder"
    );
}

/// A rerun replaces the whole output set (no stale file of the earlier run stays), and a
/// user's own non-empty folder is refused and left as it was (hostile-input issue, item 10).
#[test]
fn out_folder_is_replaced_as_a_whole_and_a_user_folder_is_kept() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join(files::RAW);
    polar_io::write_gray8_png(&input, &mosaic8(16, 12)).unwrap();
    let out = dir.path().join("o");
    let first = run(&["stokes", p(&input), "--out", p(&out)]);
    assert!(first.status.success(), "{}", stderr(&first));
    assert!(out.join(vision::MASK).is_file());
    let again = run(&["stokes", p(&input), "--out", p(&out), "--outputs", "dolp"]);
    assert!(again.status.success(), "{}", stderr(&again));
    assert!(
        !out.join(vision::MASK).exists(),
        "stale mask.png of the first run"
    );
    assert!(out.join(vision::DOLP).is_file());
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|n| n.to_string_lossy().starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "staging left behind: {leftovers:?}");
    let photos = dir.path().join("photos");
    std::fs::create_dir(&photos).unwrap();
    std::fs::write(photos.join("cat.jpg"), b"meow").unwrap();
    fails_with(&["stokes", p(&input), "--out", p(&photos)], "did not write");
    assert_eq!(std::fs::read(photos.join("cat.jpg")).unwrap(), b"meow");
    assert_eq!(std::fs::read_dir(&photos).unwrap().count(), 1);
}

#[test]
fn help_explains_every_option() {
    let out = run(&["stokes", "--help"]);
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    for needle in [
        "--out",
        "--demosaic",
        "superpixel",
        "bilinear",
        "newton",
        "--bit-depth",
        "--align",
        vision::AOLP_PICTURE,
        vision::MASK,
    ] {
        assert!(help.contains(needle), "help lacks {needle}:\n{help}");
    }
}

/// `--help` gives every method a line, and without `--demosaic` the output is
/// `residual`'s (the method with the lowest error in the README's table).
#[test]
fn help_lists_every_method_and_the_default_is_residual() {
    let help = String::from_utf8(run(&["stokes", "--help"]).stdout).unwrap();
    for m in DemosaicMethod::ALL {
        assert!(
            help.lines().any(|l| l.trim_start().starts_with(m.name())),
            "no line for {m} in:\n{help}"
        );
    }
    assert!(help.contains("[default: residual]"), "{help}");

    let dir = tempfile::tempdir().unwrap();
    let raw = mosaic8(12, 10);
    let input = dir.path().join(files::RAW);
    polar_io::write_gray8_png(&input, &raw).unwrap();
    let out_dir = dir.path().join("out");
    assert!(
        run(&["stokes", p(&input), "--out", p(&out_dir)])
            .status
            .success()
    );
    let got = polar_io::read_exr(
        out_dir.join(vision::STOKES),
        polar_io::LINEAR_STOKES_CHANNELS,
    )
    .unwrap();
    let want = stokes_planes(&raw, DemosaicMethod::Residual).unwrap();
    assert_eq!(got, want.linear_stokes());
}

#[test]
fn outputs_writes_only_the_files_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join(files::RAW);
    polar_io::write_gray8_png(&input, &mosaic8(16, 12)).unwrap();
    let out = dir.path().join("o");
    let result = run(&[
        "stokes",
        p(&input),
        "--out",
        p(&out),
        "--outputs",
        "stokes,dolp",
    ]);
    assert!(result.status.success(), "{}", stderr(&result));
    let mut written: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    written.sort();
    assert_eq!(written, [vision::MARKER, vision::DOLP, vision::STOKES]);
    fails_with(
        &[
            "stokes",
            p(&input),
            "--out",
            p(&out),
            "--outputs",
            "normals",
        ],
        "invalid value",
    );
}

#[test]
fn an_output_folder_inside_the_input_sample_is_refused() {
    // Regression: `stokes SAMPLE --out SAMPLE` overwrote the sample's stokes.exr.
    let dir = tempfile::tempdir().unwrap();
    let sample = dir.path().join("sample");
    std::fs::create_dir(&sample).unwrap();
    polar_io::write_gray8_png(sample.join(files::RAW), &mosaic8(8, 8)).unwrap();
    fails_with(
        &["stokes", p(&sample), "--out", p(&sample)],
        "would be overwritten",
    );
    let inner = sample.join("out");
    fails_with(&["stokes", p(&sample), "--out", p(&inner)], "inside");
    assert!(!inner.exists(), "nothing is created before the refusal");
    let raw = sample.join(files::RAW);
    fails_with(
        &["stokes", p(&raw), "--out", p(&sample)],
        "would be overwritten",
    );
    fails_with(
        &["run", p(&sample), "--out", p(&sample)],
        "would be overwritten",
    );
    let beside = dir.path().join("beside");
    let ok = run(&["stokes", p(&raw), "--out", p(&beside)]);
    assert!(ok.status.success(), "{}", stderr(&ok));
}

/// `--max-pixels` moves the header check's limit both ways (hostile-input issue, item 2).
#[test]
fn max_pixels_refuses_larger_images_from_the_header() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join(files::RAW);
    polar_io::write_gray8_png(&input, &mosaic8(16, 12)).unwrap();
    let out = dir.path().join("o");
    fails_with(
        &["stokes", p(&input), "--out", p(&out), "--max-pixels", "191"],
        "16x12 is more than the 191 pixels",
    );
    assert!(!out.exists());
    let ok = run(&["stokes", p(&input), "--out", p(&out), "--max-pixels", "192"]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    fails_with(
        &["stokes", p(&input), "--out", p(&out), "--max-pixels", "0"],
        "--max-pixels",
    );
}

/// `--pattern rgb`: stokes.exr holds the nine colour channels with the library's values,
/// dolp.exr and aolp.exr the luminance's (Y) and each colour's (R, G, B); s0.png is colour.
#[test]
fn rgb_pattern_writes_colour_channels_and_matches_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let raw = mosaic8(16, 12);
    let input = dir.path().join("colour.png");
    polar_io::write_gray8_png(&input, &raw).unwrap();
    let out_dir = dir.path().join("out");
    let args = [
        "stokes",
        p(&input),
        "--out",
        p(&out_dir),
        "--pattern",
        "rgb",
    ];
    let out = run(&[&args[..], &["--demosaic", "bilinear"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("bilinear, rgb"), "{}", stderr(&out));
    let want = stokes_planes_rgb(&raw, DemosaicMethod::Bilinear).unwrap();
    let stokes = out_dir.join(vision::STOKES);
    let mut names = polar_io::exr_channel_names(&stokes).unwrap();
    names.sort();
    let mut expected = RGB_LINEAR_STOKES_CHANNELS.map(String::from).to_vec();
    expected.sort();
    assert_eq!(names, expected);
    for (k, name) in RGB_LINEAR_STOKES_CHANNELS.into_iter().enumerate() {
        let p = &want.colors[k % 3];
        let plane = [&p.s0, &p.s1, &p.s2][k / 3];
        assert_eq!(
            &polar_io::read_exr_channel(&stokes, name).unwrap(),
            plane,
            "{name}"
        );
    }
    let lum = want.luminance();
    for (file, pick) in [
        (
            vision::DOLP,
            (|p: &StokesPlanes| p.dolp.clone()) as fn(&StokesPlanes) -> _,
        ),
        (vision::AOLP, |p: &StokesPlanes| p.aolp.clone()),
    ] {
        let path = out_dir.join(file);
        let same = |a: &polar_image::Gray<f32>, b: &polar_image::Gray<f32>| {
            a.as_slice()
                .iter()
                .map(|v| v.to_bits())
                .eq(b.as_slice().iter().map(|v| v.to_bits()))
        };
        assert!(
            same(
                &polar_io::read_exr_channel(&path, "Y").unwrap(),
                &pick(&lum)
            ),
            "{file} Y"
        );
        for (c, name) in ["R", "G", "B"].into_iter().enumerate() {
            let got = polar_io::read_exr_channel(&path, name).unwrap();
            assert!(same(&got, &pick(&want.colors[c])), "{file} {name}");
        }
    }
    // s0.png: the colours' S0 as sRGB up to the 99.5th percentile of the brightest channel.
    let s0 = polar_io::read_rgb8_png(out_dir.join(vision::S0_PICTURE)).unwrap();
    let planes = want.colors.each_ref().map(|p| p.s0.as_slice());
    let brightest = (0..16 * 12).map(|k| planes[0][k].max(planes[1][k]).max(planes[2][k]));
    let mut picture = vec![[0u8; 3]; 16 * 12];
    srgb_into(planes, quantile(brightest, 0.995).unwrap(), &mut picture);
    assert_eq!(s0.pixels(), picture.as_slice());
}

/// A colour stokes.exr as the input (the file itself, or a sample directory holding only
/// it) gives back the same nine channels and the same luminance DoLP and AoLP, bit for bit:
/// reading is exact and the products are the same formulas on the same values.
#[test]
fn colour_stokes_exr_is_read_back_as_colour() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("colour.png");
    polar_io::write_gray8_png(&input, &mosaic8(16, 12)).unwrap();
    let first = dir.path().join("first");
    let res = run(&["stokes", p(&input), "--out", p(&first), "--pattern", "rgb"]);
    assert!(res.status.success(), "{}", stderr(&res));
    let sample = dir.path().join("sample");
    std::fs::create_dir(&sample).unwrap();
    std::fs::copy(first.join(vision::STOKES), sample.join(files::STOKES)).unwrap();
    for source in [first.join(vision::STOKES), sample] {
        let again = dir.path().join("again");
        let res = run(&["stokes", p(&source), "--out", p(&again)]);
        assert!(res.status.success(), "{}", stderr(&res));
        assert!(stderr(&res).contains("Stokes EXR"), "{}", stderr(&res));
        for (file, names) in [
            (vision::STOKES, &RGB_LINEAR_STOKES_CHANNELS[..]),
            (vision::DOLP, &["Y", "R", "G", "B"][..]),
            (vision::AOLP, &["Y", "R", "G", "B"][..]),
        ] {
            for name in names {
                let read = |d: &Path| polar_io::read_exr_channel(d.join(file), name).unwrap();
                let (a, b) = (read(&first), read(&again));
                let bits = |g: &polar_image::Gray<f32>| -> Vec<u32> {
                    g.as_slice().iter().map(|v| v.to_bits()).collect()
                };
                assert_eq!(bits(&a), bits(&b), "{} {file} {name}", source.display());
            }
        }
    }
}

/// Without `--pattern`, `sensor.pattern` of the sample's meta.json decides; the flag
/// overrides it; an unknown value there is an error naming the file and the key; a
/// `sensor` that is not an object (or has no pattern) means mono.
#[test]
fn pattern_from_meta_json_and_the_flag_overrides_it() {
    let dir = tempfile::tempdir().unwrap();
    let sample = dir.path().join("sample");
    std::fs::create_dir(&sample).unwrap();
    polar_io::write_gray8_png(sample.join(files::RAW), &mosaic8(16, 16)).unwrap();
    let out = dir.path().join("out");
    let stokes_names = |extra: &[&str]| -> Vec<String> {
        let res = run(&[&["stokes", p(&sample), "--out", p(&out)], extra].concat());
        assert!(res.status.success(), "{}", stderr(&res));
        polar_io::exr_channel_names(out.join(vision::STOKES)).unwrap()
    };
    let meta = sample.join(files::META);
    for (json, colour) in [
        (r#"{"sensor": {"pattern": "rgb", "bit_depth": 8}}"#, true),
        (r#"{"sensor": {"pattern": "mono"}}"#, false),
        (r#"{"sensor": "IMX250MZR"}"#, false),
        (r#"{}"#, false),
    ] {
        std::fs::write(&meta, json).unwrap();
        assert_eq!(
            stokes_names(&[]).len(),
            if colour { 9 } else { 3 },
            "{json}"
        );
    }
    std::fs::write(&meta, r#"{"sensor": {"pattern": "rgb"}}"#).unwrap();
    assert_eq!(stokes_names(&["--pattern", "mono"]).len(), 3);
    std::fs::write(&meta, r#"{"sensor": {"pattern": "cmyk"}}"#).unwrap();
    fails_with(
        &["stokes", p(&sample), "--out", p(&out)],
        "meta.json: `sensor.pattern` is \"cmyk\"; expected one of mono, rgb",
    );
    fails_with(
        &["stokes", p(&sample), "--out", p(&out), "--pattern", "cmyk"],
        "unknown mosaic pattern `cmyk`",
    );
}

#[test]
fn rgb_mosaic_not_of_whole_4x4_tiles_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("colour.png");
    polar_io::write_gray8_png(&input, &mosaic8(12, 10)).unwrap();
    let out = dir.path().join("out");
    fails_with(
        &["stokes", p(&input), "--out", p(&out), "--pattern", "rgb"],
        "does not fit the rgb pattern (--pattern, or sensor.pattern of meta.json): colour mosaic is 12x10: width and height must be multiples of 4",
    );
    // The same frame is a valid monochrome mosaic.
    assert!(
        run(&["stokes", p(&input), "--out", p(&out)])
            .status
            .success()
    );
}

#[test]
fn help_explains_the_colour_pattern() {
    let help = String::from_utf8(run(&["stokes", "--help"]).stdout).unwrap();
    for needle in [
        "--pattern",
        "rgb",
        "sensor.pattern",
        "S0.R",
        "luminance",
        "Rec. 709",
    ] {
        assert!(help.contains(needle), "help lacks {needle}:\n{help}");
    }
}

/// Without `--bit-depth`, 12-bit data aligned left in a 16-bit PNG (its low 4 bits 0 in
/// every sample) read as `--bit-depth 12 --align left` would: the same DN as the
/// right-aligned file, its ADC top (4095 << 4) flagged as saturated, and a note that says
/// so; `--bit-depth 16` reads the samples as they are.
#[test]
fn left_aligned_data_are_found_without_options() {
    let dir = tempfile::tempdir().unwrap();
    let mut right: Mosaic<u16> = Mosaic::from_vec(
        8,
        8,
        (0..64).map(|i| (101 + i * 61 % 3900) as u16).collect(),
    )
    .unwrap();
    right.as_mut_slice()[..2].fill(4095);
    let left = Mosaic::from_vec(8, 8, right.as_slice().iter().map(|v| v << 4).collect()).unwrap();
    let (rp, lp) = (dir.path().join("right.png"), dir.path().join("left.png"));
    polar_io::write_gray16_png(&rp, &right).unwrap();
    polar_io::write_gray16_png(&lp, &left).unwrap();
    let (o1, o2, o3) = (
        dir.path().join("o1"),
        dir.path().join("o2"),
        dir.path().join("o3"),
    );
    let ok = run(&["stokes", p(&rp), "--out", p(&o1)]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    assert!(!stderr(&ok).contains("aligned left"), "{}", stderr(&ok));
    let found = run(&["stokes", p(&lp), "--out", p(&o2)]);
    assert!(found.status.success(), "{}", stderr(&found));
    assert!(
        stderr(&found)
            .contains("low 4 bits of every sample are 0: read as 12-bit data aligned left"),
        "{}",
        stderr(&found)
    );
    let s = |o: &Path| polar_io::read_exr_channel(o.join(vision::STOKES), "S0").unwrap();
    assert_eq!(s(&o1), s(&o2), "both alignments give the same DN");
    let mask = polar_io::read_gray8_png(o2.join(vision::MASK)).unwrap();
    assert_eq!(mask.pixel(0, 0)[0], polar_sensor::mask::SATURATED);
    let as_is = run(&["stokes", p(&lp), "--out", p(&o3), "--bit-depth", "16"]);
    assert!(as_is.status.success(), "{}", stderr(&as_is));
    assert!(
        !stderr(&as_is).contains("aligned left"),
        "{}",
        stderr(&as_is)
    );
    // In the container's DN: 16 times as large (the residual demosaicing's one-DN weight
    // floor is then a sixteenth of the data's step, so not exactly 16 times).
    let sum = |o: &Path| s(o).as_slice().iter().map(|&v| f64::from(v)).sum::<f64>();
    let ratio = sum(&o3) / sum(&o1);
    assert!(
        (ratio - 16.0).abs() < 0.01,
        "--bit-depth 16: S0 ratio {ratio}"
    );
}

/// `--black-level` takes the sensor's pedestal off every sample before demosaicing: a
/// polarized frame with 64 DN added reads, with `--black-level 64`, exactly as the frame
/// without it (and, without the option, less polarized); its saturated samples stay
/// flagged; a black level at the saturation level is a clear error.
#[test]
fn black_level_is_taken_off_before_demosaicing() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (16, 16);
    let angle = |x: usize, y: usize| {
        polar_sensor::layout::CHANNEL_ANGLES_DEG[polar_sensor::layout::channel_at(x, y)]
            .to_radians()
    };
    let sample = |x: usize, y: usize| {
        let (s0, s1, s2) = (2000.0 + 40.0 * x as f64, 400.0, 200.0 + 10.0 * y as f64);
        let a = 2.0 * angle(x, y);
        (0.5 * (s0 + s1 * a.cos() + s2 * a.sin())).round() as u16
    };
    let frame = |pedestal: u16| {
        let mut m: Mosaic<u16> = Mosaic::from_vec(
            w,
            h,
            (0..w * h)
                .map(|k| sample(k % w, k / w) + pedestal)
                .collect(),
        )
        .unwrap();
        m.as_mut_slice()[..2].fill(4095);
        m
    };
    let (clean, lifted) = (dir.path().join("clean.png"), dir.path().join("lifted.png"));
    polar_io::write_gray16_png(&clean, &frame(0)).unwrap();
    polar_io::write_gray16_png(&lifted, &frame(64)).unwrap();
    let stokes = |input: &Path, options: &[&str], name: &str| {
        let out = dir.path().join(name);
        let res = run(&[&["stokes", p(input), "--out", p(&out)], options].concat());
        assert!(res.status.success(), "{}", stderr(&res));
        out
    };
    let reference = stokes(&clean, &[], "reference");
    let corrected = stokes(&lifted, &["--black-level", "64"], "corrected");
    let dolp = |o: &Path| polar_io::read_exr_channel(o.join(vision::DOLP), "Y").unwrap();
    let mask = polar_io::read_gray8_png(corrected.join(vision::MASK)).unwrap();
    assert_eq!(mask.pixel(0, 0)[0], polar_sensor::mask::SATURATED);
    // Equal wherever the flagged samples (4095 in both files, so 4095 and 4031 once the
    // pedestal is off) do not reach.
    let unflagged = |o: &Path| -> Vec<f32> {
        let d = dolp(o);
        (0..w * h)
            .filter(|&k| mask.as_slice()[k] == 0)
            .map(|k| d.as_slice()[k])
            .collect()
    };
    assert!(unflagged(&reference).len() > w * h / 2);
    assert_eq!(unflagged(&reference), unflagged(&corrected));
    let lowered = stokes(&lifted, &[], "lowered");
    let mean = |o: &Path| {
        dolp(o)
            .as_slice()
            .iter()
            .map(|&v| f64::from(v))
            .sum::<f64>()
    };
    assert!(
        mean(&lowered) < 0.97 * mean(&reference),
        "a pedestal lowers the DoLP"
    );
    fails_with(
        &[
            "stokes",
            p(&lifted),
            "--out",
            p(&dir.path().join("x")),
            "--black-level",
            "4095",
        ],
        "no signal is left",
    );
}
