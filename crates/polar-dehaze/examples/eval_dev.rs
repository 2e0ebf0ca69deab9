//! Accuracy and speed of both dehazing methods on the haze samples of a dataset.
//!
//! `cargo run -p polar-dehaze --release --example dehaze_eval_dev [-- DIR [raw|stokes] [single-p] [-v]]`
//! (default `/work/data/dev`, `stokes`; `single-p` sets `varying_airlight: false`). Per method and averaged over the `haze-*`
//! samples: PSNR and SSIM of the dehazed S0 against `gt/dehazed.exr` (`gt/clear.exr` where
//! a sample has none), over the whole frame and the object pixels, next to those of the
//! hazy input S0, and the mean absolute error and Pearson correlation of `t` against
//! `gt/transmission.exr` (all as `polar_eval::dehaze_metrics` scores them for `eval`), and
//! the time of `dehaze`. Raw input is brought to the truth's radiance unit by its
//! least-squares gain to the sample's `stokes.exr`, as `eval` does; a dataset folder other than the default takes every sample
//! whose name holds `haze`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use polar_dehaze::{DehazeOptions, Method, dehaze};
use polar_eval::dehaze_metrics;
use polar_image::Gray;
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::{DemosaicMethod, Observation, StokesPlanes};

fn observation(dir: &Path, raw: bool, fov: f64) -> Observation {
    let camera = CameraModel::Pinhole { fov_x_deg: fov };
    if raw {
        let png =
            polar_io::read_mosaic(dir.join(polar_io::files::RAW)).expect(polar_io::files::RAW);
        let planes =
            polar_sensor::stokes_planes(&png.image, DemosaicMethod::Residual).expect("demosaic");
        let flags = polar_sensor::mask::validity_mask(
            &png.image,
            u32::from(png.bit_depth.max_value()),
            DemosaicMethod::Residual,
            &planes.s0,
        );
        Observation::new(planes, camera).with_flags(flags)
    } else {
        let img = polar_io::read_exr(
            dir.join(polar_io::files::STOKES),
            polar_io::LINEAR_STOKES_CHANNELS,
        )
        .expect(polar_io::files::STOKES);
        Observation::new(StokesPlanes::from_linear_stokes(&img), camera)
    }
}

#[derive(Default, Clone, Copy)]
struct Row {
    psnr: f64,
    ssim: f64,
    obj_psnr: f64,
    obj_ssim: f64,
    t_mae: f64,
    t_corr: f64,
    ms: f64,
}

impl Row {
    fn add(&mut self, o: &Row) {
        self.psnr += o.psnr;
        self.ssim += o.ssim;
        self.obj_psnr += o.obj_psnr;
        self.obj_ssim += o.obj_ssim;
        self.t_mae += o.t_mae;
        self.t_corr += o.t_corr;
        self.ms += o.ms;
    }
}

/// The command line.
struct Options {
    root: PathBuf,
    raw: bool,
    verbose: bool,
    single_p: bool,
}

fn options() -> Options {
    let args: Vec<String> = std::env::args().skip(1).collect();
    Options {
        root: PathBuf::from(args.first().map_or("/work/data/dev", String::as_str)),
        raw: args.iter().any(|a| a == "raw"),
        verbose: args.iter().any(|a| a == "-v"),
        single_p: args.iter().any(|a| a == "single-p"),
    }
}

/// The samples under `root` whose name holds `haze`, sorted.
fn haze_dirs(root: &Path) -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root)
        .expect("dataset dir")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().contains("haze"))
        })
        .collect();
    dirs.sort();
    dirs
}

const METHODS: [Method; 2] = [Method::Polarization, Method::DarkChannel];

/// The running sums: the hazy input, each of [`METHODS`], and the polarization method's
/// fallbacks.
#[derive(Default)]
struct Sums {
    hazy: Row,
    methods: [Row; 2],
    fallbacks: usize,
}

fn main() {
    let o = options();
    let dirs = haze_dirs(&o.root);
    let mut sums = Sums::default();
    for dir in &dirs {
        println!("{}", evaluate_sample(dir, &o, &mut sums));
    }
    print_summary(&sums, dirs.len(), o.raw);
}

/// Both methods on one sample, scored by `polar_eval::dehaze_metrics` against
/// `gt/dehazed.exr` (`gt/clear.exr` where the sample has none); adds to `sums` and returns
/// the sample's line.
fn evaluate_sample(dir: &Path, o: &Options, sums: &mut Sums) -> String {
    let sample = polar_io::read_sample(dir).expect("sample");
    let fov = sample.meta["camera"]["fov_deg"].as_f64().unwrap_or(45.0);
    let obs = observation(dir, o.raw, fov);
    let clear = sample
        .gt
        .dehazed
        .as_ref()
        .or(sample.gt.clear.as_ref())
        .expect(polar_io::files::GT_CLEAR);
    let gt_t = sample
        .gt
        .transmission
        .as_ref()
        .expect(polar_io::files::GT_TRANSMISSION);
    // Raw input is in DN: the least-squares gain to the sample's stokes.exr S0 (as `eval`).
    let k = if o.raw {
        let truth = polar_io::read_exr_channel(dir.join(polar_io::files::STOKES), "S0")
            .expect(polar_io::files::STOKES);
        let s0 = obs.planes.s0.as_slice();
        polar_eval::gain_to(s0, truth.as_slice(), |k| obs.is_valid(k)).expect("gain") as f32
    } else {
        1.0
    };
    let to_radiance = |g: &Gray<f32>| {
        Gray::from_vec(
            g.width(),
            g.height(),
            g.as_slice().iter().map(|v| v * k).collect(),
        )
        .expect("size")
    };
    let hazy = to_radiance(&obs.planes.s0);
    let labels = sample.gt.material.as_ref();
    let mut line = format!("{:<12}", dir.file_name().unwrap().to_string_lossy());
    for (i, m) in METHODS.iter().enumerate() {
        let opts = DehazeOptions {
            method: *m,
            varying_airlight: !o.single_p,
            ..DehazeOptions::default()
        };
        let start = Instant::now();
        let out = dehaze(&obs, &opts).expect("dehaze");
        let ms = start.elapsed().as_secs_f64() * 1e3;
        let t = Some((&out.transmission, gt_t));
        let score =
            dehaze_metrics(&hazy, &to_radiance(&out.radiance), clear, t, labels).expect("metrics");
        let (h, row) = (
            rows(&score, false),
            Row {
                ms,
                ..rows(&score, true)
            },
        );
        if i == 0 {
            sums.hazy.add(&h);
            line += &format!(" hazy {:6.2} dB obj {:6.2} dB", h.psnr, h.obj_psnr);
        }
        sums.methods[i].add(&row);
        if *m == Method::Polarization && out.method != Method::Polarization {
            sums.fallbacks += 1;
        }
        line += &format!(
            " | {m}: {:6.2} dB ssim {:.3} obj {:6.2} dB t mae {:.3} r {:.3} p {:.3} A {:.3}",
            row.psnr,
            row.ssim,
            row.obj_psnr,
            row.t_mae,
            row.t_corr,
            out.airlight_dolp,
            out.airlight_inf / obs.s0_scale()
        );
        if o.verbose && !out.warnings.is_empty() {
            line += &format!(" {:?}", out.warnings);
        }
    }
    line
}

/// The scores of the dehazed output (`dehazed`) or of the hazy input as one row (NaN where
/// the sample lacks what a score needs).
fn rows(m: &polar_eval::DehazeMetrics, dehazed: bool) -> Row {
    let pick =
        |h: &polar_eval::ImageScore, d: &polar_eval::ImageScore| if dehazed { *d } else { *h };
    let whole = pick(&m.hazy, &m.dehazed);
    let obj = m.objects.as_ref().map(|o| pick(&o.hazy, &o.dehazed));
    Row {
        psnr: whole.psnr_db,
        ssim: whole.ssim,
        obj_psnr: obj.map_or(f64::NAN, |s| s.psnr_db),
        obj_ssim: obj.map_or(f64::NAN, |s| s.ssim),
        t_mae: m.transmission_mae.unwrap_or(f64::NAN),
        t_corr: m.transmission_correlation.unwrap_or(f64::NAN),
        ms: 0.0,
    }
}

fn print_summary(sums: &Sums, count: usize, raw: bool) {
    let n = count.max(1) as f64;
    let hazy = &sums.hazy;
    println!(
        "\n{count} samples ({}), means (PSNR/SSIM: whole frame; objects only):\n  hazy input      PSNR {:6.2} dB  SSIM {:.3}; PSNR {:6.2} dB  SSIM {:.3}",
        if raw {
            "raw.png, residual demosaicing"
        } else {
            polar_io::files::STOKES
        },
        hazy.psnr / n,
        hazy.ssim / n,
        hazy.obj_psnr / n,
        hazy.obj_ssim / n
    );
    for (m, s) in METHODS.iter().zip(&sums.methods) {
        println!(
            "  {:<14}  PSNR {:6.2} dB  SSIM {:.3}; PSNR {:6.2} dB  SSIM {:.3}; t MAE {:.3}  t Pearson {:.3}  {:.2} ms/sample",
            m.to_string(),
            s.psnr / n,
            s.ssim / n,
            s.obj_psnr / n,
            s.obj_ssim / n,
            s.t_mae / n,
            s.t_corr / n,
            s.ms / n
        );
    }
    println!("  polarization fell back on {} sample(s)", sums.fallbacks);
}
