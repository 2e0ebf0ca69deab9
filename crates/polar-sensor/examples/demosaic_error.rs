//! Demosaicing error table: for each method, PSNR of I0..I135 and mean absolute
//! error of DoLP and AoLP against full-resolution ground truth, next to its speed.
//!
//! `cargo run --release -p polar-sensor --example demosaic_error [-- --markdown] [--no-texture]`
//! (`--no-texture` drops the zone plate and the stripes: edges and smooth fields only)
//!
//! Ground truth: a synthetic 1024x768 linear Stokes field with sharp edges (a disc and
//! a rectangle that differ in S0, DoLP and AoLP from the background), a zone-plate
//! chirp in S0 (fine texture up to the mosaic's Nyquist frequency), a smooth AoLP
//! rotation and a DoLP gradient. The four full-resolution polarizer images come from
//! `SensorModel::polarizer_images` (ideal polarizers); the mosaic from an ideal,
//! noiseless 16-bit sensor (so only demosaicing error is measured, plus 0.5 DN rounding).
//! `superpixel` is compared with the ground truth averaged over each 2x2 block (the
//! best a half-resolution image can do). AoLP error is the circular difference (mod
//! 180°) where the true DoLP >= 0.05; DoLP/AoLP MAE skip undefined pixels.

use std::f32::consts::PI;
use std::time::{Duration, Instant};

use polar_image::{PolarizerStack, StokesImage};
use polar_sensor::products::StokesPlanes;
use polar_sensor::{DemosaicMethod, SensorModel, demosaic};

const W: usize = 1024;
const H: usize = 768;

/// The synthetic Stokes field (S3 = 0), in DN of a 16-bit sensor.
fn truth_stokes(texture: bool) -> StokesImage {
    let mut s = StokesImage::new(W, H);
    for (k, px) in s.pixels_mut().iter_mut().enumerate() {
        let (x, y) = ((k % W) as f32, (k / W) as f32);
        let mut s0 = 30000.0;
        let mut dolp = 0.1 + 0.4 * x / W as f32;
        let mut aolp = PI * (x + 0.5 * y) / W as f32;
        // Zone plate in the lower left quarter: local frequency grows to 0.5 cycles/pixel.
        let (zx, zy) = (x - 200.0, y - 560.0);
        let r2 = zx * zx + zy * zy;
        if texture && r2 < 190.0 * 190.0 {
            s0 += 12000.0 * (PI * r2 / (2.0 * 190.0)).cos();
        }
        // A bright, strongly polarized disc.
        if (x - 650.0).powi(2) + (y - 250.0).powi(2) < 140.0f32.powi(2) {
            s0 = 50000.0;
            dolp = 0.8;
            aolp = 30f32.to_radians();
        }
        // A dark, weakly polarized rectangle with a different angle.
        if (300.0..520.0).contains(&x) && (80.0..300.0).contains(&y) {
            s0 = 8000.0;
            dolp = 0.15;
            aolp = 120f32.to_radians();
        }
        // Thin stripes: 2-pixel-wide lines every 9 pixels in the right band.
        if texture && x > 850.0 && (y as usize) % 9 < 2 {
            s0 *= 0.5;
            aolp += PI / 3.0;
        }
        *px = [
            s0,
            s0 * dolp * (2.0 * aolp).cos(),
            s0 * dolp * (2.0 * aolp).sin(),
            0.0,
        ];
    }
    s
}

/// 2x2 block means of a full-resolution stack.
fn block_mean(stack: &PolarizerStack) -> PolarizerStack {
    let (w, h) = (stack.width() / 2, stack.height() / 2);
    let mut out = PolarizerStack::new(w, h);
    for (k, px) in out.pixels_mut().iter_mut().enumerate() {
        let (x, y) = (2 * (k % w), 2 * (k / w));
        *px = std::array::from_fn(|c| {
            0.25 * (stack.pixel(x, y)[c]
                + stack.pixel(x + 1, y)[c]
                + stack.pixel(x, y + 1)[c]
                + stack.pixel(x + 1, y + 1)[c])
        });
    }
    out
}

fn psnr(a: &PolarizerStack, b: &PolarizerStack, c: usize) -> f64 {
    let mse = a
        .pixels()
        .iter()
        .zip(b.pixels())
        .map(|(p, q)| f64::from(p[c] - q[c]).powi(2))
        .sum::<f64>()
        / a.pixels().len() as f64;
    10.0 * (65535.0f64.powi(2) / mse).log10()
}

/// Mean |DoLP error| and mean circular |AoLP error| in degrees (where true DoLP >= 0.05).
fn polar_errors(got: &StokesPlanes, truth: &StokesPlanes) -> (f64, f64) {
    let (mut sd, mut nd, mut sa, mut na) = (0.0, 0usize, 0.0, 0usize);
    for k in 0..truth.dolp.as_slice().len() {
        let (dt, dg) = (truth.dolp.as_slice()[k], got.dolp.as_slice()[k]);
        if !(dt.is_finite() && dg.is_finite()) {
            continue;
        }
        sd += f64::from((dg - dt).abs());
        nd += 1;
        if dt >= 0.05 {
            let d = f64::from((got.aolp.as_slice()[k] - truth.aolp.as_slice()[k]).abs())
                % std::f64::consts::PI;
            sa += d.min(std::f64::consts::PI - d).to_degrees();
            na += 1;
        }
    }
    (sd / nd.max(1) as f64, sa / na.max(1) as f64)
}

fn main() {
    let markdown = std::env::args().any(|a| a == "--markdown");
    let texture = !std::env::args().any(|a| a == "--no-texture");
    let stokes = truth_stokes(texture);
    let sensor = SensorModel::ideal(16);
    let truth = sensor.polarizer_images(&stokes).expect("valid field");
    let raw = sensor.expose(&stokes).expect("valid field").raw;
    let truth_half = block_mean(&truth);
    let (truth_planes, truth_half_planes) = (
        StokesPlanes::from_stack(&truth),
        StokesPlanes::from_stack(&truth_half),
    );

    let header = [
        "method",
        "PSNR I0",
        "PSNR I45",
        "PSNR I90",
        "PSNR I135",
        "MAE DoLP",
        "MAE AoLP (deg)",
        "ms",
    ];
    if markdown {
        println!("| {} |", header.join(" | "));
        println!("|{}", "---|".repeat(header.len()));
    } else {
        let what = if texture {
            "edges + fine texture"
        } else {
            "edges only"
        };
        println!(
            "{W}x{H} synthetic field ({what}), ideal 16-bit sensor; PSNR in dB (peak 65535); ms = demosaic() alone"
        );
        println!(
            "{:<11}{:>9}{:>9}{:>9}{:>10}{:>10}{:>16}{:>9}",
            header[0], header[1], header[2], header[3], header[4], header[5], header[6], header[7]
        );
    }
    for m in DemosaicMethod::ALL {
        let mut best = Duration::MAX;
        let mut stack = None;
        for _ in 0..3 {
            let t = Instant::now();
            stack = Some(demosaic(&raw, m).expect("even size"));
            best = best.min(t.elapsed());
        }
        let stack = stack.expect("ran");
        let (reference, reference_planes) = if m == DemosaicMethod::Superpixel {
            (&truth_half, &truth_half_planes)
        } else {
            (&truth, &truth_planes)
        };
        let p: Vec<f64> = (0..4).map(|c| psnr(&stack, reference, c)).collect();
        let (ed, ea) = polar_errors(&StokesPlanes::from_stack(&stack), reference_planes);
        let ms = best.as_secs_f64() * 1e3;
        if markdown {
            println!(
                "| {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.5} | {:.3} | {:.1} |",
                m.name(),
                p[0],
                p[1],
                p[2],
                p[3],
                ed,
                ea,
                ms
            );
        } else {
            println!(
                "{:<11}{:>9.2}{:>9.2}{:>9.2}{:>10.2}{:>10.5}{:>16.3}{:>9.1}",
                m.name(),
                p[0],
                p[1],
                p[2],
                p[3],
                ed,
                ea,
                ms
            );
        }
    }
}
