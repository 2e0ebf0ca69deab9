//! Evaluates material classification on the dev family: `materials-*` sample directories.
//!
//! ```text
//! cargo run -p polar-material --release --example material_eval_dev -- [DATA_DIR] [--stokes]
//! ```
//! `DATA_DIR` defaults to `/work/data/dev`. `--stats` prints per ground-truth object the
//! cue statistics instead; the environment variable `DUMP=dir` writes a picture per
//! sample (S0, DoLP, AoLP phase against the gt normals, gt and predicted labels). The observation is decoded from `raw.png`
//! (residual demosaicing, validity flags, so the noise level of the sample applies);
//! `--stokes` reads the noiseless `stokes.exr` instead. Printed per noise level and per
//! input setting (automatic object mask; ground-truth object mask; ground-truth mask and
//! normals): accuracy over object pixels (gt label 1 or 2; a pixel called background
//! counts as wrong), metal-vs-dielectric accuracy over object pixels the classifier calls
//! object, per-class IoU of the 3-class confusion matrix, object-mask IoU, and time.

use std::path::{Path, PathBuf};
use std::time::Instant;

use polar_image::{Gray, Image, NormalImage};
use polar_imgproc::{ConfusionMatrix, iou};
use polar_material::{Classifier, MaterialOptions, classify};
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::mask::validity_mask;
use polar_sensor::{DemosaicMethod, Observation, StokesPlanes, stokes_planes};

/// One loaded sample.
struct Case {
    name: String,
    noise: String,
    obs: Observation,
    truth: Gray<u8>,
    normals: Option<NormalImage>,
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
        truth: s.gt.material.expect(polar_io::files::GT_MATERIAL),
        normals: s.gt.normal,
    }
}

#[derive(Default)]
struct Tally {
    n: usize,
    object: u64,
    correct: u64,
    called_object: u64,
    md_correct: u64,
    confusion: [[u64; 3]; 3],
    mask_iou: f64,
    seconds: f64,
}

impl Tally {
    fn add(&mut self, truth: &Gray<u8>, pred: &Gray<u8>, secs: f64) {
        let t3 = clamp3(truth);
        let p3 = clamp3(pred);
        let cm = ConfusionMatrix::from_labels(&t3, &p3, 3).expect("labels");
        for (a, row) in self.confusion.iter_mut().enumerate() {
            for (b, v) in row.iter_mut().enumerate() {
                *v += cm.count(a, b);
            }
        }
        for (&t, &p) in t3.as_slice().iter().zip(p3.as_slice()) {
            if t == 0 {
                continue;
            }
            self.object += 1;
            self.correct += u64::from(t == p);
            if p != 0 {
                self.called_object += 1;
                self.md_correct += u64::from(t == p);
            }
        }
        let fg = |g: &Gray<u8>| {
            Gray::from_vec(
                g.width(),
                g.height(),
                g.as_slice().iter().map(|&v| u8::from(v != 0)).collect(),
            )
            .unwrap()
        };
        self.mask_iou += iou(&fg(&p3), &fg(&t3)).unwrap().unwrap_or(1.0);
        self.seconds += secs;
        self.n += 1;
    }

    fn print(&self, what: &str) {
        let pct = |a: u64, b: u64| 100.0 * a as f64 / b.max(1) as f64;
        let class_iou = |c: usize| {
            let tp = self.confusion[c][c];
            let fp: u64 = (0..3).map(|t| self.confusion[t][c]).sum::<u64>() - tp;
            let fneg: u64 = self.confusion[c].iter().sum::<u64>() - tp;
            tp as f64 / (tp + fp + fneg).max(1) as f64
        };
        println!(
            "  {what:<22} n={:2} acc(obj)={:5.1}%  metal-vs-diel={:5.1}% (of {:4.1}% called object)  IoU bg/diel/metal={:.3}/{:.3}/{:.3}  maskIoU={:.3}  {:.1} ms/img",
            self.n,
            pct(self.correct, self.object),
            pct(self.md_correct, self.called_object),
            pct(self.called_object, self.object),
            class_iou(0),
            class_iou(1),
            class_iou(2),
            self.mask_iou / self.n.max(1) as f64,
            1e3 * self.seconds / self.n.max(1) as f64
        );
    }
}

fn clamp3(g: &Gray<u8>) -> Gray<u8> {
    // Transparent (3) counts as background here: the material family has none.
    let v = g
        .as_slice()
        .iter()
        .map(|&l| if l > 2 { 0 } else { l })
        .collect();
    Gray::from_vec(g.width(), g.height(), v).unwrap()
}

fn object_mask(truth: &Gray<u8>) -> Gray<u8> {
    let v = truth
        .as_slice()
        .iter()
        .map(|&l| u8::from(l == 1 || l == 2))
        .collect();
    Gray::from_vec(truth.width(), truth.height(), v).unwrap()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let from_stokes = args.iter().any(|a| a == "--stokes");
    let verbose = args.iter().any(|a| a == "-v");
    let root = args
        .iter()
        .find(|a| !a.starts_with('-'))
        .map_or_else(|| PathBuf::from("/work/data/dev"), PathBuf::from);
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect("data dir")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("materials-"))
        })
        .collect();
    dirs.sort();
    let cases: Vec<Case> = dirs.iter().map(|d| load(d, from_stokes)).collect();
    let mut noises: Vec<String> = cases.iter().map(|c| c.noise.clone()).collect();
    noises.sort();
    noises.dedup();
    let clf = Classifier::Physics;
    if args.iter().any(|a| a == "--stats") {
        cases.iter().for_each(stats);
        return;
    }
    println!(
        "{} materials samples from {} ({})",
        cases.len(),
        root.display(),
        if from_stokes {
            polar_io::files::STOKES
        } else {
            polar_io::files::RAW
        }
    );
    for noise in &noises {
        println!("noise = {noise}");
        for setting in 0..3 {
            let mut tally = Tally::default();
            for c in cases.iter().filter(|c| &c.noise == noise) {
                let fg = object_mask(&c.truth);
                let (fg_in, n_in) = match setting {
                    0 => (None, None),
                    1 => (Some(&fg), None),
                    _ => (Some(&fg), c.normals.as_ref()),
                };
                let t = Instant::now();
                let out = classify(&c.obs, n_in, fg_in, None, &clf, &MaterialOptions::default())
                    .expect("classify");
                let secs = t.elapsed().as_secs_f64();
                if setting == 0
                    && let Ok(d) = std::env::var("DUMP")
                {
                    dump(Path::new(&d), c, &out.labels);
                }
                if verbose {
                    let mut one = Tally::default();
                    one.add(&c.truth, &out.labels, secs);
                    one.print(&format!("{} s{setting}", c.name));
                }
                tally.add(&c.truth, &out.labels, secs);
            }
            let what = ["auto mask", "gt mask", "gt mask + gt normals"][setting];
            tally.print(what);
        }
    }
    time_megapixel(&clf);
}

/// Time of one 1024x1024 classification (a tiled dev observation).
fn time_megapixel(clf: &Classifier) {
    let n = 1024;
    let mut planes = StokesPlanes::new(n, n);
    for y in 0..n {
        for x in 0..n {
            let k = y * n + x;
            let (dx, dy) = ((x % 256) as f32 - 128.0, (y % 256) as f32 - 128.0);
            let r = (dx * dx + dy * dy).sqrt() / 100.0;
            let rho = if r < 1.0 { 0.3 * r * r } else { 0.0 };
            let az = dy.atan2(dx);
            planes.s0.as_mut_slice()[k] = 1.0;
            planes.s1.as_mut_slice()[k] = rho * (2.0 * az).cos();
            planes.s2.as_mut_slice()[k] = rho * (2.0 * az).sin();
        }
    }
    let planes = StokesPlanes::from_linear_stokes(&planes.linear_stokes());
    let obs = Observation::new(planes, CameraModel::Orthographic);
    let t = Instant::now();
    let out = classify(&obs, None, None, None, clf, &MaterialOptions::default()).unwrap();
    println!(
        "1 MP (1024x1024, synthetic discs): {:.0} ms, {} object pixels",
        t.elapsed().as_secs_f64() * 1e3,
        out.labels.as_slice().iter().filter(|&&l| l != 0).count()
    );
}

/// Writes `DIR/<name>.png`: S0, DoLP (x4), AoLP-phase against the gt normals (red along
/// the azimuth, blue across, brightness DoLP x4), gt labels, predicted labels.
fn dump(dir: &Path, c: &Case, pred: &Gray<u8>) {
    let (w, h) = c.obs.size();
    let f = polar_material::features::Features::new(&c.obs).unwrap();
    let cues = c
        .normals
        .as_ref()
        .map(|n| polar_material::cues::from_normals(&c.obs, &f, n).unwrap());
    let panels = 5;
    let mut img = Image::<u8, 3>::new(w * panels, h);
    let to8 = |v: f32| (v.clamp(0.0, 1.0) * 255.0) as u8;
    let lab = |l: u8| match l {
        1 => [0, 200, 0],
        2 => [230, 180, 0],
        3 => [0, 120, 255],
        _ => [40, 40, 40],
    };
    let iw = w * panels;
    let px = img.pixels_mut();
    for y in 0..h {
        for x in 0..w {
            let k = y * w + x;
            let g = to8(f.s0[k].max(0.0).sqrt());
            px[y * iw + x] = [g, g, g];
            let d = to8(4.0 * f.dolp[k]);
            px[y * iw + w + x] = [d, d, d];
            let ph = cues.as_ref().map_or(f32::NAN, |c| c.phase[k]);
            let v = 4.0 * f.dolp[k];
            px[y * iw + 2 * w + x] = if ph.is_finite() {
                [to8(v * ph.max(0.0)), to8(v * 0.2), to8(v * (-ph).max(0.0))]
            } else {
                [0, 0, 0]
            };
            px[y * iw + 3 * w + x] = lab(c.truth.as_slice()[k]);
            px[y * iw + 4 * w + x] = lab(pred.as_slice()[k]);
        }
    }
    // Twice the size, for viewing.
    let mut big = Image::<u8, 3>::new(2 * iw, 2 * h);
    let bw = 2 * iw;
    let src = img.pixels();
    for (k, p) in big.pixels_mut().iter_mut().enumerate() {
        *p = src[(k / bw / 2) * iw + (k % bw) / 2];
    }
    std::fs::create_dir_all(dir).unwrap();
    polar_io::write_rgb8_png(dir.join(format!("{}.png", c.name)), &big).unwrap();
}

/// Prints per ground-truth object (8-connected component of one label) statistics of the
/// cues, measured with the ground-truth normals.
fn stats(c: &Case) {
    use polar_material::fresnel_cues::FresnelTable;
    let (w, h) = c.obs.size();
    let f = polar_material::features::Features::new(&c.obs).unwrap();
    let Some(n) = c.normals.as_ref() else { return };
    let cues = polar_material::cues::from_normals(&c.obs, &f, n).unwrap();
    let t = FresnelTable::new();
    let fgm: Vec<bool> = c
        .truth
        .as_slice()
        .iter()
        .map(|&v| v == 1 || v == 2)
        .collect();
    let regions = polar_material::Regions::new(&fgm, w, h).unwrap();
    let dist = polar_material::cues::silhouette_distance(&fgm, w, h);
    let sil = polar_material::cues::from_silhouette(&f, &fgm, &regions, &dist).unwrap();
    for l in [1u8, 2] {
        let m = Gray::from_vec(
            w,
            h,
            c.truth
                .as_slice()
                .iter()
                .map(|&v| u8::from(v == l))
                .collect(),
        )
        .unwrap();
        let mut lab = Gray::new(w, h);
        let cnt = polar_imgproc::label(&m, &mut lab, polar_imgproc::Connectivity::Eight).unwrap();
        for id in 1..=cnt as u32 {
            let ks: Vec<usize> = (0..w * h)
                .filter(|&k| lab.as_slice()[k] == id && f.valid[k])
                .collect();
            if ks.len() < 20 {
                continue;
            }
            let nn = ks.len() as f32;
            let mut rho: Vec<f32> = ks.iter().map(|&k| f.dolp[k]).collect();
            rho.sort_by(f32::total_cmp);
            let wsum: f32 = ks.iter().map(|&k| f.dolp[k]).sum();
            let ph: f32 = ks
                .iter()
                .filter(|&&k| cues.phase[k].is_finite())
                .map(|&k| f.dolp[k] * cues.phase[k])
                .sum::<f32>()
                / wsum.max(1e-9);
            let over = ks
                .iter()
                .filter(|&&k| {
                    cues.zenith[k].is_finite() && f.dolp[k] > t.metal_max(cues.zenith[k]) + 0.03
                })
                .count() as f32
                / nn;
            let pos = ks
                .iter()
                .filter(|&&k| cues.phase[k] > 0.5 && f.dolp[k] > 0.02)
                .count() as f32
                / nn;
            let band: Vec<usize> = ks
                .iter()
                .copied()
                .filter(|&k| sil.phase[k].is_finite())
                .collect();
            let bw: f32 = band.iter().map(|&k| f.dolp[k]).sum();
            let bph = band.iter().map(|&k| f.dolp[k] * sil.phase[k]).sum::<f32>() / bw.max(1e-9);
            let brad = band.iter().map(|&k| f.dolp[k] * sil.phase[k]).sum::<f32>()
                / band.len().max(1) as f32;
            let ceil = ks
                .iter()
                .filter(|&&k| f.dolp[k] > t.metal_ceiling() + 0.03)
                .count() as f32
                / nn;
            let s0: f32 = ks.iter().map(|&k| f.s0[k]).sum::<f32>() / nn;
            let mut s0v: Vec<f32> = ks.iter().map(|&k| f.s0[k]).collect();
            s0v.sort_by(f32::total_cmp);
            println!(
                "  {} {} label {l} area {:4} rho mean {:.3} p50 {:.3} p90 {:.3} | phase(w) {:+.2} diffuse-frac {:.2} | over-metal {:.2} | s0 mean {:.2} p10 {:.2} p90 {:.2} | noise {:.4} | band n {} ph {:+.2} rad {:+.3} ceil {:.2}",
                c.name,
                c.noise,
                ks.len(),
                wsum / nn,
                rho[ks.len() / 2],
                rho[ks.len() * 9 / 10],
                ph,
                pos,
                over,
                s0,
                s0v[ks.len() / 10],
                s0v[ks.len() * 9 / 10],
                f.pixel_noise,
                band.len(),
                bph,
                brad,
                ceil
            );
        }
    }
}
