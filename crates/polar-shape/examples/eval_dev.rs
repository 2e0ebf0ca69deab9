//! Runs both shape-from-polarization methods on the `sfp-*` samples of a dataset and
//! prints the angular error of the normals over object pixels (gt material label != 0),
//! split by the sensor noise level, with timings, the foreground IoU against the object
//! mask and a "full" mean that scores missed object pixels as facing the camera.
//!
//! `cargo run -p polar-shape --release --example sfp_eval_dev -- [DATASET] [--exr] [--debug DIR]
//! [--only TEXT] [--no-speed] [--ior N|auto]` (default `/work/data/dev`; samples `sfp-*` and
//! the Mitsuba task scenes `mts-shape-*`; `--only` keeps names containing TEXT, `--no-speed`
//! skips the timing of upscaled frames, `--ior` as `polar-vision run --ior`, default 1.5,
//! `--oracle-fg` also runs the local method on the true object mask, `--working-size` as
//! `polar-vision run --sfp-working-size`).
//! Each line also gives the index used and its source, and the true indices of the
//! sample's objects from its meta.json (read here for evaluation only), and the light
//! fitted to the shading (direction in the camera frame, strength, ambient). The Stokes planes come from the raw mosaic (residual
//! demosaicing, saturation flagged) as a camera would give them; `--exr` uses
//! `stokes.exr` instead. `--debug DIR` writes foreground / reflection / error pictures.

use std::path::{Path, PathBuf};
use std::time::Instant;

use polar_image::{Gray, Image, NormalImage};
use polar_imgproc::angular_error;
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::mask::validity_mask;
use polar_sensor::{DemosaicMethod, Observation, StokesPlanes, stokes_planes};
use polar_shape::{Integrator, IorOption, Method, ShapeOptions, estimate_shape};

struct Args {
    root: PathBuf,
    exr: bool,
    debug: Option<PathBuf>,
    /// Only samples whose name contains this.
    only: Option<String>,
    speed: bool,
    ior: IorOption,
    /// Also run the local method on the true object mask.
    oracle_fg: bool,
    /// `ShapeOptions::working_size`.
    working_size: usize,
}

fn args() -> Args {
    let mut a = Args {
        root: "/work/data/dev".into(),
        exr: false,
        debug: None,
        only: None,
        speed: true,
        ior: IorOption::Default,
        oracle_fg: false,
        working_size: polar_shape::scale::WORKING_SIZE,
    };
    let mut it = std::env::args().skip(1);
    while let Some(s) = it.next() {
        match s.as_str() {
            "--exr" => a.exr = true,
            "--debug" => a.debug = it.next().map(PathBuf::from),
            "--only" => a.only = it.next(),
            "--no-speed" => a.speed = false,
            "--oracle-fg" => a.oracle_fg = true,
            "--working-size" => {
                let v = it.next().unwrap_or_default();
                a.working_size = v
                    .parse()
                    .unwrap_or_else(|e| panic!("--working-size {v}: {e}"));
            }
            "--ior" => {
                let v = it.next().unwrap_or_default();
                a.ior = v.parse().unwrap_or_else(|e| panic!("--ior {v}: {e}"));
            }
            "--help" | "-h" => {
                println!(
                    "sfp_eval_dev [DATASET] [--exr] [--debug DIR] [--only TEXT] [--no-speed] [--ior N|auto] [--oracle-fg] [--working-size N]"
                );
                std::process::exit(0);
            }
            _ => a.root = s.into(),
        }
    }
    a
}

fn observation(dir: &Path, fov: f64, exr: bool) -> Observation {
    let camera = CameraModel::Pinhole { fov_x_deg: fov };
    if exr {
        let img = polar_io::read_exr(
            dir.join(polar_io::files::STOKES),
            polar_io::LINEAR_STOKES_CHANNELS,
        )
        .unwrap();
        Observation::new(StokesPlanes::from_linear_stokes(&img), camera)
    } else {
        let png = polar_io::read_mosaic(dir.join(polar_io::files::RAW)).unwrap();
        let m = DemosaicMethod::Residual;
        let planes = stokes_planes(&png.image, m).unwrap();
        let flags = validity_mask(
            &png.image,
            u32::from(png.bit_depth.max_value()),
            m,
            &planes.s0,
        );
        Observation::new(planes, camera).with_flags(flags)
    }
}

#[derive(Default)]
struct Acc {
    means: Vec<f64>,
    medians: Vec<f64>,
    pooled: Vec<(f64, usize)>,
    secs: f64,
    ious: Vec<f64>,
    /// Mean error with missing object pixels scored as facing the camera.
    covered: Vec<f64>,
}

/// Per (method, noise level): the accumulated scores.
type Scores = std::collections::BTreeMap<(String, String), Acc>;

fn main() {
    let a = args();
    let dirs = sample_dirs(&a);
    if let Some(first) = dirs.first().filter(|_| a.speed) {
        speed(first);
    }
    let mut acc = Scores::new();
    for dir in &dirs {
        println!("{}", evaluate_sample(dir, &a, &mut acc));
    }
    print_summary(&acc);
}

/// The shape samples under `a.root` (ours `sfp-*`, Mitsuba's `mts-shape-*`), sorted.
fn sample_dirs(a: &Args) -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&a.root)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name().and_then(|n| n.to_str()).is_some_and(|n| {
                (n.starts_with("sfp-") || n.starts_with("mts-shape-"))
                    && a.only.as_deref().is_none_or(|o| n.contains(o))
            })
        })
        .collect();
    dirs.sort();
    dirs
}

/// Runs both methods (and the oracle foregrounds where asked) on one sample, adds their
/// scores to `acc` and returns the sample's line.
fn evaluate_sample(dir: &Path, a: &Args, acc: &mut Scores) -> String {
    let s = polar_io::read_sample(dir).unwrap();
    // polar-datagen: sensor.noise.name; the Mitsuba task scenes: sensor.noise.
    let noise_key = &s.meta["sensor"]["noise"];
    let noise = noise_key["name"]
        .as_str()
        .or(noise_key.as_str())
        .unwrap_or("?")
        .to_string();
    let fov = s.meta["camera"]["fov_deg"].as_f64().expect("fov_deg");
    let obs = observation(dir, fov, a.exr);
    let gt = s.gt.normal.as_ref().expect("gt normal");
    let label = s.gt.material.as_ref().expect("gt material");
    let mask = Gray::from_vec(
        label.width(),
        label.height(),
        label.as_slice().iter().map(|&l| u8::from(l != 0)).collect(),
    )
    .unwrap();
    let name = dir.file_name().unwrap().to_string_lossy().to_string();
    let true_iors: Vec<String> = s.meta["scene"]["objects"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|o| o["material"]["ior"].as_f64())
        .map(|n| format!("{n:.3}"))
        .collect();
    let mut line = format!("{name} {noise:9} true n [{}]", true_iors.join(" "));
    let truth = Truth {
        gt,
        mask: &mask,
        fov,
    };
    for m in [Method::Local, Method::Global] {
        let e = acc.entry((m.to_string(), noise.clone())).or_default();
        line += &score_method(&obs, m, a, &truth, e, &name);
    }
    if a.oracle_fg {
        for prior_only in [false, true] {
            let (mean, median, normals) = oracle_foreground(&obs, gt, &mask, prior_only);
            let (ez, ea) = split_error(&normals, gt, &mask, fov);
            line += &format!(
                " | gt mask (prior only {prior_only}): mean {mean:5.1} med {median:5.1} zen {ez:4.1} az {ea:4.1}"
            );
            let e = acc
                .entry((format!("oracle{}", u8::from(prior_only)), noise.clone()))
                .or_default();
            e.means.push(mean);
            e.medians.push(median);
        }
    }
    if let Some(d) = &a.debug {
        cue_pictures(d, &name, &obs);
    }
    line
}

/// A sample's true normals, object mask and field of view.
struct Truth<'a> {
    gt: &'a NormalImage,
    mask: &'a Gray<u8>,
    fov: f64,
}

/// Runs method `m` on `obs`, adds its scores to `e` and returns its part of the line.
fn score_method(
    obs: &Observation,
    m: Method,
    a: &Args,
    truth: &Truth,
    e: &mut Acc,
    name: &str,
) -> String {
    let (gt, mask) = (truth.gt, truth.mask);
    let opts = ShapeOptions {
        method: m,
        integrator: Integrator::Poisson,
        ior: a.ior,
        working_size: a.working_size,
    };
    let t = Instant::now();
    let shape = estimate_shape(obs, &opts).unwrap();
    let secs = t.elapsed().as_secs_f64();
    let st = angular_error(&shape.normal, gt, Some(mask)).unwrap();
    let missing = count_missing(&shape.normal, mask);
    let iou = polar_imgproc::iou(&shape.foreground, mask)
        .unwrap()
        .unwrap_or(0.0);
    e.ious.push(iou);
    let mut line = String::new();
    if m == Method::Local {
        let light = shape.light.map_or("none".into(), |l| {
            let d = l.direction().unwrap_or_default();
            format!(
                "({:.2} {:.2} {:.2}) x{:.2} + {:.2}",
                d.x,
                d.y,
                d.z,
                l.strength(),
                l.ambient
            )
        });
        line += &format!(" | n {:.3} {} | light {light}", shape.ior, shape.ior_source);
    }
    e.secs += secs;
    if let Some(st) = st {
        e.means.push(st.mean);
        e.medians.push(st.median);
        e.pooled.push((st.mean, st.count));
        line += &format!(
            " | {m}: mean {:5.1} med {:5.1} <11.25 {:4.0}% miss {missing:4} iou {iou:.2} ({:.0} ms)",
            st.mean,
            st.median,
            st.pct_below_11_25,
            secs * 1e3
        );
    }
    let full = angular_error(&facing_where_missing(&shape.normal), gt, Some(mask))
        .unwrap()
        .map_or(f64::NAN, |s| s.mean);
    e.covered.push(full);
    line += &format!(" full {full:5.1}");
    let (ez, ea) = split_error(&shape.normal, gt, mask, truth.fov);
    line += &format!(" zen {ez:4.1} az {ea:4.1}");
    if let Some(d) = &a.debug {
        debug_pictures(d, name, &m.to_string(), &shape, gt, mask);
    }
    line
}

/// One line per method and noise level: means, medians, pooled mean, IoU, time.
fn print_summary(acc: &Scores) {
    println!(
        "\nsummary (per-sample mean of mean / median of per-sample medians, pooled pixel mean):"
    );
    for ((m, noise), e) in acc {
        let n = e.means.len().max(1) as f64;
        let mut med = e.medians.clone();
        med.sort_by(f64::total_cmp);
        let (num, den) = e
            .pooled
            .iter()
            .fold((0.0, 0usize), |s, (m, c)| (s.0 + m * *c as f64, s.1 + c));
        println!(
            "{m:6} {noise:9}: mean {:5.2}  median-of-medians {:5.2}  mean-of-medians {:5.2}  pooled mean {:5.2}  fg IoU {:.2} full mean {:5.2} time/sample {:.1} ms",
            e.means.iter().sum::<f64>() / n,
            med.get(med.len() / 2).copied().unwrap_or(f64::NAN),
            e.medians.iter().sum::<f64>() / n,
            num / den.max(1) as f64,
            e.ious.iter().sum::<f64>() / n,
            e.covered.iter().sum::<f64>() / n,
            e.secs / n * 1e3
        );
    }
}

/// Mean and median error and the normals of the local method given the true object mask as its
/// foreground (index 1.5): what a perfect foreground would be worth.
fn oracle_foreground(
    obs: &Observation,
    gt: &NormalImage,
    mask: &Gray<u8>,
    prior_only: bool,
) -> (f64, f64, NormalImage) {
    let cues = polar_shape::cues::Cues::new(obs, polar_shape::DEFAULT_IOR).unwrap();
    let true_fg: Vec<bool> = mask
        .as_slice()
        .iter()
        .zip(&cues.valid)
        .map(|(&m, &v)| m != 0 && v)
        .collect();
    let prior = polar_shape::local::boundary_prior(
        &cues,
        &true_fg,
        polar_shape::local::Outline::Given(&true_fg),
    )
    .unwrap();
    let fg = if prior_only {
        polar_shape::foreground::foreground(&cues).unwrap()
    } else {
        true_fg
    };
    let est = polar_shape::local::disambiguate_with(&cues, &fg, &prior).unwrap();
    let (w, h) = mask.size();
    let data = est
        .normals
        .iter()
        .flat_map(|n| [n.x as f32, n.y as f32, n.z as f32])
        .collect();
    let normals: NormalImage = Image::from_vec(w, h, data).unwrap();
    let (mean, median) = angular_error(&normals, gt, Some(mask))
        .unwrap()
        .map_or((f64::NAN, f64::NAN), |s| (s.mean, s.median));
    (mean, median, normals)
}

/// The estimate with `(0, 0, 1)` (facing the camera) where it has no normal, so a
/// foreground that misses object pixels is scored on them too.
fn facing_where_missing(n: &NormalImage) -> NormalImage {
    let mut out = n.clone();
    for p in out.pixels_mut() {
        if p.iter().all(|v| *v == 0.0) {
            *p = [0.0, 0.0, 1.0];
        }
    }
    out
}

fn count_missing(n: &NormalImage, mask: &Gray<u8>) -> usize {
    n.pixels()
        .iter()
        .zip(mask.as_slice())
        .filter(|(p, m)| **m != 0 && p.iter().all(|v| *v == 0.0))
        .count()
}

fn debug_pictures(
    dir: &Path,
    name: &str,
    m: &str,
    shape: &polar_shape::Shape,
    gt: &NormalImage,
    mask: &Gray<u8>,
) {
    std::fs::create_dir_all(dir).unwrap();
    let (w, h) = shape.normal.size();
    // Left: estimate as RGB normal map; middle: ground truth; right: error (gray, 0-45 deg), red = reflection mixed, blue = specular.
    let mut rgb = Image::<u8, 3>::new(3 * w, h);
    let px = rgb.pixels_mut();
    for y in 0..h {
        for x in 0..w {
            let k = y * w + x;
            let e = shape.normal.pixels()[k];
            let g = gt.pixels()[k];
            let enc = |v: f32| ((v * 0.5 + 0.5) * 255.0).clamp(0.0, 255.0) as u8;
            px[y * 3 * w + x] = e.map(enc);
            px[y * 3 * w + w + x] = g.map(enc);
            let dot = (e[0] * g[0] + e[1] * g[1] + e[2] * g[2]).clamp(-1.0, 1.0);
            let ang = dot.acos().to_degrees();
            let v = if mask.as_slice()[k] != 0 {
                (ang / 45.0 * 255.0).min(255.0) as u8
            } else {
                0
            };
            let fg = shape.foreground.as_slice()[k] != 0;
            let r = shape.reflection.as_slice()[k];
            px[y * 3 * w + 2 * w + x] = match (fg, r) {
                (false, _) => [0, 0, v / 2 + 20],
                (_, 2) => [v, v, 255],
                (_, 3) => [255, v, v],
                _ => [v, v, v],
            };
        }
    }
    polar_io::write_rgb8_png(dir.join(format!("{name}_{m}.png")), &upscale(&rgb, 3)).unwrap();
    // Foreground against the object mask: white both, red foreground only, blue object only.
    let mut fgt = Image::<u8, 3>::new(w, h);
    for (k, p) in fgt.pixels_mut().iter_mut().enumerate() {
        *p = match (shape.foreground.as_slice()[k] != 0, mask.as_slice()[k] != 0) {
            (true, true) => [255, 255, 255],
            (true, false) => [255, 0, 0],
            (false, true) => [0, 0, 255],
            (false, false) => [0, 0, 0],
        };
    }
    polar_io::write_rgb8_png(dir.join(format!("{name}_{m}_fg.png")), &fgt).unwrap();
}

fn cue_pictures(dir: &Path, name: &str, obs: &Observation) {
    let cues = polar_shape::cues::Cues::new(obs, 1.5).unwrap();
    let z = polar_shape::foreground::rayleigh_statistic(&cues).unwrap();
    let fgm = polar_shape::foreground::foreground(&cues).unwrap();
    let (w, h) = obs.size();
    let mut rgb = Image::<u8, 3>::new(3 * w, h);
    let px = rgb.pixels_mut();
    for y in 0..h {
        for x in 0..w {
            let k = y * w + x;
            let s = (cues.s0n[k].max(0.0).sqrt() * 255.0).min(255.0) as u8;
            px[y * 3 * w + x] = [s, s, s];
            let d = (cues.dolp[k] * 4.0 * 255.0).min(255.0) as u8;
            let a = (cues.aolp[k] / std::f32::consts::PI * 255.0) as u8;
            px[y * 3 * w + w + x] = [d, a, 255 - a];
            // Rayleigh statistic, gray up to z = 100; orange where foreground.
            let e = (z.as_slice()[k].sqrt() / 10.0 * 255.0).min(255.0) as u8;
            px[y * 3 * w + 2 * w + x] = if fgm[k] { [255, e, 0] } else { [e, e, e] };
        }
    }
    polar_io::write_rgb8_png(dir.join(format!("{name}_cues.png")), &upscale(&rgb, 3)).unwrap();
}

fn upscale(src: &Image<u8, 3>, f: usize) -> Image<u8, 3> {
    let (w, h) = src.size();
    let mut out = Image::<u8, 3>::new(w * f, h * f);
    let px = out.pixels_mut();
    for y in 0..h * f {
        for x in 0..w * f {
            px[y * w * f + x] = src.pixels()[(y / f) * w + x / f];
        }
    }
    out
}

/// Mean absolute zenith error and mean absolute azimuth error (degrees) in the pixel frames.
fn split_error(est: &NormalImage, gt: &NormalImage, mask: &Gray<u8>, fov: f64) -> (f64, f64) {
    let cam = CameraModel::Pinhole { fov_x_deg: fov };
    let (w, h) = est.size();
    let (mut sz, mut sa, mut n) = (0.0, 0.0, 0.0);
    for k in 0..w * h {
        let (e, g) = (est.pixels()[k], gt.pixels()[k]);
        if mask.as_slice()[k] == 0 || e.iter().all(|v| *v == 0.0) || g.iter().all(|v| *v == 0.0) {
            continue;
        }
        let f = cam.frame(w, h, (k % w) as f64, (k / w) as f64);
        let v = |a: [f32; 3]| {
            nalgebra::Vector3::new(f64::from(a[0]), f64::from(a[1]), f64::from(a[2])).normalize()
        };
        let (ae, ze) = f.angles(&v(e));
        let (ag, zg) = f.angles(&v(g));
        let da = (ae - ag).rem_euclid(std::f64::consts::TAU);
        sz += (ze - zg).abs().to_degrees();
        let ad = da.min(std::f64::consts::TAU - da).to_degrees();
        sa += ad;
        if std::env::var("AZBINS").is_ok() && zg.to_degrees() > 15.0 {
            eprintln!("AZ {}", (ad / 45.0).round() as i32);
        }
        n += 1.0;
    }
    (sz / n, sa / n)
}

/// Times both methods on a sample upscaled (nearest neighbour) to 1024² and 512².
fn speed(dir: &Path) {
    let img: polar_image::LinearStokesImage = polar_io::read_exr(
        dir.join(polar_io::files::STOKES),
        polar_io::LINEAR_STOKES_CHANNELS,
    )
    .unwrap();
    for size in [512usize, 1024] {
        let (w, h) = img.size();
        let data = (0..size * size)
            .flat_map(|k| img.pixels()[((k / size) * h / size) * w + (k % size) * w / size])
            .collect();
        let big = polar_image::LinearStokesImage::from_vec(size, size, data).unwrap();
        let obs = Observation::new(
            StokesPlanes::from_linear_stokes(&big),
            CameraModel::Pinhole { fov_x_deg: 35.0 },
        );
        for m in [Method::Local, Method::Global] {
            for integ in [Integrator::FrankotChellappa, Integrator::Poisson] {
                let opts = ShapeOptions {
                    method: m,
                    integrator: integ,
                    ..ShapeOptions::default()
                };
                let t = Instant::now();
                estimate_shape(&obs, &opts).unwrap();
                println!(
                    "speed {size}x{size} {m} {integ}: {:.3} s",
                    t.elapsed().as_secs_f64()
                );
            }
        }
    }
}
