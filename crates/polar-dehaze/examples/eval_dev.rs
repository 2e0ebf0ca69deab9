//! Accuracy and speed of both dehazing methods on the haze samples of a dataset.
//!
//! `cargo run -p polar-dehaze --release --example dehaze_eval_dev [-- DIR [raw|stokes] [single-p] [-v]]`
//! (default `/work/data/dev`, `stokes`; `single-p` sets `varying_airlight: false`). Per method and averaged over the `haze-*`
//! samples: PSNR and SSIM of the dehazed S0 against `gt/dehazed.exr` (`gt/clear.exr` where
//! a sample has none; data range = max of the reference; `polar_imgproc::psnr`/`ssim`)
//! next to those of the hazy input S0,
//! mean absolute error and Pearson correlation of `t` against `gt/transmission.exr`, and
//! the time of `dehaze`. Raw input is brought to the truth's radiance unit by the sensor's
//! conversion in meta.json; a dataset folder other than the default takes every sample
//! whose name holds `haze`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use polar_dehaze::{DehazeOptions, Method, dehaze};
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

fn pearson(a: &[f32], b: &[f32]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (
        a.iter().map(|&v| f64::from(v)).sum::<f64>() / n,
        b.iter().map(|&v| f64::from(v)).sum::<f64>() / n,
    );
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (&x, &y) in a.iter().zip(b) {
        let (dx, dy) = (f64::from(x) - ma, f64::from(y) - mb);
        sab += dx * dy;
        saa += dx * dx;
        sbb += dy * dy;
    }
    if saa > 0.0 && sbb > 0.0 {
        sab / (saa * sbb).sqrt()
    } else {
        0.0
    }
}

fn mae(a: &[f32], b: &[f32]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(&x, &y)| f64::from((x - y).abs()))
        .sum::<f64>()
        / a.len() as f64
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

/// Whole-frame PSNR and SSIM, then both over the object pixels (`gt/material.png` label
/// != 0, as the conventions define accuracy figures): PSNR of their MSE, mean of the SSIM map.
fn image_scores(clear: &Gray<f32>, img: &Gray<f32>, objects: &[bool]) -> [f64; 4] {
    let range = f64::from(clear.as_slice().iter().copied().fold(0.0, f32::max));
    let mut map = Gray::new(clear.width(), clear.height());
    let ssim = polar_imgproc::ssim_map(clear, img, range, &mut map).unwrap();
    let (mut se, mut ss, mut n) = (0.0f64, 0.0f64, 0.0f64);
    for (k, &o) in objects.iter().enumerate() {
        if o {
            let d = f64::from(clear.as_slice()[k] - img.as_slice()[k]);
            se += d * d;
            ss += f64::from(map.as_slice()[k]);
            n += 1.0;
        }
    }
    [
        polar_imgproc::psnr(clear, img, range).unwrap(),
        ssim,
        10.0 * (range * range / (se / n.max(1.0))).log10(),
        ss / n.max(1.0),
    ]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let root = PathBuf::from(args.first().map_or("/work/data/dev", String::as_str));
    let raw = args.iter().any(|a| a == "raw");
    let verbose = args.iter().any(|a| a == "-v");
    let single_p = args.iter().any(|a| a == "single-p");
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect("dataset dir")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().contains("haze"))
        })
        .collect();
    dirs.sort();
    let methods = [Method::Polarization, Method::DarkChannel];
    let (mut hazy, mut sums) = (Row::default(), [Row::default(); 2]);
    let mut fallbacks = 0;
    for dir in &dirs {
        let sample = polar_io::read_sample(dir).expect("sample");
        let fov = sample.meta["camera"]["fov_deg"].as_f64().unwrap_or(45.0);
        let obs = observation(dir, raw, fov);
        // Score against gt/dehazed (what a dehazer can reach) where the sample has it.
        let clear = sample
            .gt
            .dehazed
            .as_ref()
            .or(sample.gt.clear.as_ref())
            .expect(polar_io::files::GT_CLEAR);
        // Raw input is in DN: the sensor's conversion to the truth's radiance unit.
        let sensor = &sample.meta["sensor"];
        let dn_per_radiance = sensor["dn_per_radiance"].as_f64().unwrap_or_else(|| {
            sensor["photons_per_unit"].as_f64().unwrap_or(1.0)
                / sensor["gain_e_per_dn"].as_f64().unwrap_or(1.0)
        });
        let k = if raw {
            (1.0 / dn_per_radiance) as f32
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
        let gt_t = sample
            .gt
            .transmission
            .as_ref()
            .expect(polar_io::files::GT_TRANSMISSION);
        let objects: Vec<bool> = match &sample.gt.material {
            Some(m) => m.as_slice().iter().map(|&l| l != 0).collect(),
            None => vec![true; clear.as_slice().len()],
        };
        let [p0, s0, op0, os0] = image_scores(clear, &to_radiance(&obs.planes.s0), &objects);
        hazy.add(&Row {
            psnr: p0,
            ssim: s0,
            obj_psnr: op0,
            obj_ssim: os0,
            ..Row::default()
        });
        let mut line = format!(
            "{:<12} hazy {p0:6.2} dB obj {op0:6.2} dB",
            dir.file_name().unwrap().to_string_lossy()
        );
        for (m, sum) in methods.iter().zip(sums.iter_mut()) {
            let opts = DehazeOptions {
                method: *m,
                varying_airlight: !single_p,
                ..DehazeOptions::default()
            };
            let start = Instant::now();
            let out = dehaze(&obs, &opts).expect("dehaze");
            let ms = start.elapsed().as_secs_f64() * 1e3;
            let [p, s, op, os] = image_scores(clear, &to_radiance(&out.radiance), &objects);
            let row = Row {
                psnr: p,
                ssim: s,
                obj_psnr: op,
                obj_ssim: os,
                t_mae: mae(out.transmission.as_slice(), gt_t.as_slice()),
                t_corr: pearson(out.transmission.as_slice(), gt_t.as_slice()),
                ms,
            };
            sum.add(&row);
            if *m == Method::Polarization && out.method != Method::Polarization {
                fallbacks += 1;
            }
            line += &format!(
                " | {m}: {p:6.2} dB ssim {s:.3} obj {op:6.2} dB t mae {:.3} r {:.3} p {:.3} A {:.3}",
                row.t_mae,
                row.t_corr,
                out.airlight_dolp,
                out.airlight_inf / obs.s0_scale()
            );
            if verbose && !out.warnings.is_empty() {
                line += &format!(" {:?}", out.warnings);
            }
        }
        println!("{line}");
    }
    let n = dirs.len().max(1) as f64;
    println!(
        "\n{} samples ({}), means (PSNR/SSIM: whole frame; objects only):\n  hazy input      PSNR {:6.2} dB  SSIM {:.3}; PSNR {:6.2} dB  SSIM {:.3}",
        dirs.len(),
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
    for (m, s) in methods.iter().zip(&sums) {
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
    println!("  polarization fell back on {fallbacks} sample(s)");
}
