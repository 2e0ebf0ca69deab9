//! Demosaicing error table: for each method, PSNR of I0..I135 and mean absolute
//! error of DoLP and AoLP against full-resolution ground truth, next to its speed.
//!
//! `cargo run --release -p polar-sensor --example demosaic_error [-- --markdown]`
//!
//! One table per synthetic 1024x768 field (see `tests/common/demosaic_eval.rs`): edges
//! and fine texture, edges only, fine texture only. The four full-resolution polarizer
//! images come from `SensorModel::polarizer_images` (ideal polarizers); the mosaic from
//! an ideal, noiseless 16-bit sensor (so only demosaicing error is measured, plus 0.5 DN
//! rounding). `superpixel` is compared with the ground truth averaged over each 2x2
//! block (the best a half-resolution image can do). ms = best of 3 runs of `demosaic()`.

#[path = "../tests/common/demosaic_eval.rs"]
mod demosaic_eval;

use std::time::{Duration, Instant};

use demosaic_eval::{Field, errors, truth_stokes};
use polar_image::PolarizerStack;
use polar_sensor::products::StokesPlanes;
use polar_sensor::{DemosaicMethod, SensorModel, demosaic};

const W: usize = 1024;
const H: usize = 768;

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

/// Runs every method on one field and prints its table.
fn table(field: Field, markdown: bool) {
    let stokes = truth_stokes(W, H, field);
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
    println!(
        "\n{W}x{H} synthetic field ({}), ideal 16-bit sensor; PSNR in dB (peak 65535)",
        field.label()
    );
    if markdown {
        println!("| {} |", header.join(" | "));
        println!("|{}", "---|".repeat(header.len()));
    } else {
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
        let e = if m == DemosaicMethod::Superpixel {
            errors(&stack, &truth_half, &truth_half_planes)
        } else {
            errors(&stack, &truth, &truth_planes)
        };
        let [p0, p45, p90, p135] = e.psnr;
        let ms = best.as_secs_f64() * 1e3;
        if markdown {
            println!(
                "| {} | {p0:.2} | {p45:.2} | {p90:.2} | {p135:.2} | {:.5} | {:.3} | {ms:.1} |",
                m.name(),
                e.dolp,
                e.aolp_deg
            );
        } else {
            println!(
                "{:<11}{p0:>9.2}{p45:>9.2}{p90:>9.2}{p135:>10.2}{:>10.5}{:>16.3}{ms:>9.1}",
                m.name(),
                e.dolp,
                e.aolp_deg
            );
        }
    }
}

fn main() {
    let markdown = std::env::args().any(|a| a == "--markdown");
    for field in Field::ALL {
        table(field, markdown);
    }
}
