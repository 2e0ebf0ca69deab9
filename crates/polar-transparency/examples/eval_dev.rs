//! Evaluates transparent-object detection on the dev set.
//!
//! ```text
//! cargo run -p polar-transparency --release --example transparent_eval_dev -- [DATA_DIR] [--stokes] [-v]
//!     [--model FILE|builtin] [--glass PREFIX] [--thresholds T,T,...]
//! ```
//! `DATA_DIR` defaults to `/work/data/dev`; `--model` uses the learned segmenter with that
//! model file; `--glass` names the glass samples (default `glass-`); `--thresholds` scores
//! each threshold in turn (default: the segmenter's own). Observations are decoded from `raw.png`
//! (residual demosaicing, validity flags; `--stokes` reads the noiseless `stokes.exr`).
//! Per noise level: on `glass-*`, mean and pooled mask IoU, precision and recall against
//! `gt/transparent.png`; on `materials-*` (opaque dielectrics and metals, no glass), the
//! false-positive area: the share of object pixels (labels 1, 2 of `gt/material.png`)
//! and of all pixels called transparent. Then the time of one 1024x1024 detection.
//! With the environment variable `DUMP=dir`, writes a picture per sample there.

use std::path::{Path, PathBuf};
use std::time::Instant;

use polar_image::{Gray, Image};
use polar_imgproc::iou;
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::mask::validity_mask;
use polar_sensor::{DemosaicMethod, Observation, StokesPlanes, stokes_planes};
use polar_transparency::knn::{BUILTIN_MODEL, EXPECT, KnnClassifier};
use polar_transparency::{Segmenter, TransparencyOptions, detect};

/// The binaries' allocator, so the times are what `polar-vision run` sees.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

struct Case {
    name: String,
    noise: String,
    obs: Observation,
    transparent: Option<Gray<u8>>,
    material: Option<Gray<u8>>,
}

fn load(dir: &Path, from_stokes: bool) -> Case {
    let s = polar_io::read_sample(dir).expect("sample reads");
    let meta = &s.meta;
    let fov = meta["camera"]["fov_deg"].as_f64().expect("camera.fov_deg");
    let noise = meta["sensor"]["noise"]["name"]
        .as_str()
        .unwrap_or("?")
        .to_owned();
    let camera = CameraModel::Pinhole { fov_x_deg: fov };
    let obs = if from_stokes {
        let st = polar_io::read_exr(
            dir.join(polar_io::files::STOKES),
            polar_io::LINEAR_STOKES_CHANNELS,
        )
        .expect(polar_io::files::STOKES);
        Observation::new(StokesPlanes::from_linear_stokes(&st), camera)
    } else {
        let raw = s.raw.expect(polar_io::files::RAW).image;
        let bits = meta["sensor"]["bit_depth"].as_u64().unwrap_or(16) as u32;
        let planes = stokes_planes(&raw, DemosaicMethod::Residual).expect("demosaic");
        let flags = validity_mask(&raw, (1 << bits) - 1, DemosaicMethod::Residual, &planes.s0);
        Observation::new(planes, camera).with_flags(flags)
    };
    Case {
        name: dir.file_name().unwrap().to_string_lossy().into_owned(),
        noise,
        obs,
        transparent: s.gt.transparent,
        material: s.gt.material,
    }
}

fn dirs(root: &Path, prefix: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root)
        .expect("data dir")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with(prefix))
        })
        .collect();
    v.sort();
    v
}

fn binary(g: &Gray<u8>) -> Gray<u8> {
    Gray::from_vec(
        g.width(),
        g.height(),
        g.as_slice().iter().map(|&v| u8::from(v != 0)).collect(),
    )
    .unwrap()
}

#[derive(Default)]
struct Glass {
    n: usize,
    iou_sum: f64,
    tp: u64,
    fp: u64,
    fneg: u64,
    secs: f64,
}

#[derive(Default)]
struct Opaque {
    n: usize,
    object: u64,
    object_fp: u64,
    pixels: u64,
    fp: u64,
}

/// The command line.
struct Options {
    root: PathBuf,
    from_stokes: bool,
    verbose: bool,
    /// `DUMP`: a picture per sample there.
    dump: Option<String>,
    segmenter: Segmenter,
    thresholds: Vec<Option<f32>>,
    /// Name prefix of the glass samples.
    prefix: String,
}

fn options() -> Options {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let from_stokes = args.iter().any(|a| a == "--stokes");
    let root = args
        .iter()
        .enumerate()
        .find(|(i, a)| {
            !a.starts_with('-')
                && (*i == 0 || !args[i - 1].starts_with("--") || args[i - 1] == "--stokes")
        })
        .map(|(_, a)| a)
        .map_or_else(|| PathBuf::from("/work/data/dev"), PathBuf::from);
    let value = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .map(|i| args[i + 1].clone())
    };
    let segmenter = match value("--model") {
        None => Segmenter::Cues,
        Some(m) if m == "builtin" => Segmenter::Knn(std::sync::Arc::new(
            KnnClassifier::from_bytes(BUILTIN_MODEL, Path::new("builtin"), EXPECT).unwrap(),
        )),
        Some(m) => Segmenter::Knn(std::sync::Arc::new(
            KnnClassifier::load(Path::new(&m), EXPECT).unwrap(),
        )),
    };
    let thresholds = match value("--thresholds") {
        None => vec![None],
        Some(t) => t.split(',').map(|v| Some(v.parse().unwrap())).collect(),
    };
    Options {
        root,
        from_stokes,
        verbose: args.iter().any(|a| a == "-v"),
        dump: std::env::var("DUMP").ok(),
        segmenter,
        thresholds,
        prefix: value("--glass").unwrap_or_else(|| "glass-".into()),
    }
}

fn main() {
    let o = options();
    let load_all = |prefix: &str| -> Vec<Case> {
        dirs(&o.root, prefix)
            .iter()
            .map(|d| load(d, o.from_stokes))
            .collect()
    };
    let (glass, opaque) = (load_all(&o.prefix), load_all("materials-"));
    println!(
        "{} glass and {} materials samples from {} ({})",
        glass.len(),
        opaque.len(),
        o.root.display(),
        if o.from_stokes {
            polar_io::files::STOKES
        } else {
            polar_io::files::RAW
        }
    );
    let mut noises: Vec<String> = glass
        .iter()
        .chain(&opaque)
        .map(|c| c.noise.clone())
        .collect();
    noises.sort();
    noises.dedup();
    for (noise, threshold) in noises
        .iter()
        .flat_map(|n| o.thresholds.iter().map(move |t| (n, *t)))
    {
        let opts = TransparencyOptions { threshold };
        let g = score_glass(&of_noise(&glass, noise), &o, &opts);
        let op = score_opaque(&of_noise(&opaque, noise), &o, &opts);
        println!("noise = {noise}, threshold {threshold:?}");
        print_scores(&g, &op);
    }
    time_megapixel(&o.segmenter);
}

/// The cases of noise level `noise`.
fn of_noise<'a>(cases: &'a [Case], noise: &str) -> Vec<&'a Case> {
    cases.iter().filter(|c| c.noise == noise).collect()
}

/// IoU, pixel counts and time over the glass samples.
fn score_glass(cases: &[&Case], o: &Options, opts: &TransparencyOptions) -> Glass {
    let mut g = Glass::default();
    for c in cases {
        let truth = binary(
            c.transparent
                .as_ref()
                .expect(polar_io::files::GT_TRANSPARENT),
        );
        let t = Instant::now();
        let out = detect(&c.obs, &o.segmenter, opts).expect("detect");
        g.secs += t.elapsed().as_secs_f64();
        let pred = binary(&out.mask);
        let one = iou(&pred, &truth).unwrap().unwrap_or(1.0);
        g.iou_sum += one;
        g.n += 1;
        let (mut tp, mut fp, mut fneg) = (0, 0, 0);
        for (&p, &t) in pred.as_slice().iter().zip(truth.as_slice()) {
            tp += u64::from(p == 1 && t == 1);
            fp += u64::from(p == 1 && t == 0);
            fneg += u64::from(p == 0 && t == 1);
        }
        g.tp += tp;
        g.fp += fp;
        g.fneg += fneg;
        if o.verbose {
            println!("  {} IoU {:.3} tp {tp} fp {fp} fn {fneg}", c.name, one);
        }
        if let Some(d) = &o.dump {
            picture(Path::new(d), c, &out.score, &out.mask, &truth);
        }
    }
    g
}

/// False positives over the opaque (materials) samples.
fn score_opaque(cases: &[&Case], o: &Options, opts: &TransparencyOptions) -> Opaque {
    let mut op = Opaque::default();
    for c in cases {
        let mat = c.material.as_ref().expect(polar_io::files::GT_MATERIAL);
        let out = detect(&c.obs, &o.segmenter, opts).expect("detect");
        op.n += 1;
        for (&p, &l) in out.mask.as_slice().iter().zip(mat.as_slice()) {
            let obj = l == 1 || l == 2;
            op.object += u64::from(obj);
            op.object_fp += u64::from(obj && p != 0);
            op.pixels += 1;
            op.fp += u64::from(p != 0);
        }
        if let Some(d) = &o.dump {
            picture(Path::new(d), c, &out.score, &out.mask, &binary(mat));
        }
    }
    op
}

fn print_scores(g: &Glass, o: &Opaque) {
    let pct = |a: u64, b: u64| 100.0 * a as f64 / b.max(1) as f64;
    println!(
        "  glass     n={:2} mean IoU {:.3}  pooled IoU {:.3}  precision {:5.1}%  recall {:5.1}%  {:.1} ms/img",
        g.n,
        g.iou_sum / g.n.max(1) as f64,
        g.tp as f64 / (g.tp + g.fp + g.fneg).max(1) as f64,
        pct(g.tp, g.tp + g.fp),
        pct(g.tp, g.tp + g.fneg),
        1e3 * g.secs / g.n.max(1) as f64
    );
    println!(
        "  materials n={:2} false positives: {:5.2}% of opaque object pixels (labels 1, 2), {:5.2}% of all pixels",
        o.n,
        pct(o.object_fp, o.object),
        pct(o.fp, o.pixels)
    );
}

/// Time of one 1024x1024 detection on a synthetic scene (a polarized disc per 256² tile).
fn time_megapixel(segmenter: &Segmenter) {
    let n = 1024;
    let mut planes = StokesPlanes::new(n, n);
    for y in 0..n {
        for x in 0..n {
            let k = y * n + x;
            let (dx, dy) = ((x % 256) as f32 - 128.0, (y % 256) as f32 - 128.0);
            let r = (dx * dx + dy * dy).sqrt() / 100.0;
            let rho = if r < 1.0 { 0.2 * r * r } else { 0.0 };
            let az = dy.atan2(dx);
            planes.s0.as_mut_slice()[k] = 1.0;
            planes.s1.as_mut_slice()[k] = rho * (2.0 * az).cos();
            planes.s2.as_mut_slice()[k] = rho * (2.0 * az).sin();
        }
    }
    let planes = StokesPlanes::from_linear_stokes(&planes.linear_stokes());
    let obs = Observation::new(planes, CameraModel::Orthographic);
    let run = || {
        let t = Instant::now();
        let out = detect(&obs, segmenter, &TransparencyOptions::default()).unwrap();
        (t.elapsed().as_secs_f64() * 1e3, out)
    };
    let (first, out) = run();
    let mut ms: Vec<f64> = (0..5).map(|_| run().0).collect();
    ms.sort_by(f64::total_cmp);
    println!(
        "1 MP (1024x1024, synthetic discs): first call {first:.0} ms, median of 5 more {:.0} ms, {} pixels on",
        ms[2],
        out.mask.as_slice().iter().filter(|&&v| v != 0).count()
    );
}

/// `DIR/<name>.png` at twice the size: S0, score, predicted mask, ground truth.
fn picture(dir: &Path, c: &Case, score: &Gray<f32>, mask: &Gray<u8>, truth: &Gray<u8>) {
    let (w, h) = c.obs.size();
    let scale = c.obs.s0_scale();
    let panels = 4;
    let iw = panels * w;
    let mut img = Image::<u8, 3>::new(2 * iw, 2 * h);
    let to8 = |v: f32| (v.clamp(0.0, 1.0) * 255.0) as u8;
    let bw = 2 * iw;
    for (k, p) in img.pixels_mut().iter_mut().enumerate() {
        let (x, y) = ((k % bw) / 2, k / bw / 2);
        let (panel, xx) = (x / w, x % w);
        let j = y * w + xx;
        let v = match panel {
            0 => to8((c.obs.planes.s0.as_slice()[j] / scale).max(0.0).sqrt()),
            1 => to8(score.as_slice()[j]),
            2 => mask.as_slice()[j],
            _ => 255 * truth.as_slice()[j],
        };
        *p = [v, v, v];
    }
    std::fs::create_dir_all(dir).unwrap();
    polar_io::write_rgb8_png(dir.join(format!("{}.png", c.name)), &img).unwrap();
}
