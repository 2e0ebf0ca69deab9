//! Times every primitive on one large frame; `tools/bench_imgproc.py` writes the inputs,
//! times OpenCV / scikit-image on the same data and prints both side by side.
//!
//! Usage: `bench_imgproc <dir> [reps]` where `<dir>` holds `meta.json`-free raw files
//! written by the script: `img.f32`, `degraded.f32` (little-endian `f32`), `mask.u8`,
//! `img.u8`, and `size.txt` (`width height`). Prints one `name milliseconds` line per op
//! (best of `reps` runs after one warm-up).

use std::time::Instant;

use polar_image::Gray;
use polar_imgproc::*;

fn read_f32(path: &std::path::Path, w: usize, h: usize) -> Gray<f32> {
    let b = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let v = b
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    Gray::from_vec(w, h, v).expect("size of f32 input")
}

fn read_u8(path: &std::path::Path, w: usize, h: usize) -> Gray<u8> {
    let b = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Gray::from_vec(w, h, b).expect("size of u8 input")
}

/// Best wall time in milliseconds of `reps` runs after a warm-up (the minimum is the
/// least disturbed by other load on a shared machine).
fn time<R>(reps: usize, mut f: impl FnMut() -> R) -> f64 {
    std::hint::black_box(f());
    let mut t: Vec<f64> = (0..reps)
        .map(|_| {
            let s = Instant::now();
            std::hint::black_box(f());
            s.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[0]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dir = std::path::PathBuf::from(args.get(1).expect("usage: bench_imgproc <dir> [reps]"));
    let reps: usize = args.get(2).and_then(|r| r.parse().ok()).unwrap_or(7);
    let size = std::fs::read_to_string(dir.join("size.txt")).expect("size.txt");
    let wh: Vec<usize> = size
        .split_whitespace()
        .map(|v| v.parse().expect("size"))
        .collect();
    let (w, h) = (wh[0], wh[1]);
    let img = read_f32(&dir.join("img.f32"), w, h);
    let deg = read_f32(&dir.join("degraded.f32"), w, h);
    let mask = read_u8(&dir.join("mask.u8"), w, h);
    let img8 = read_u8(&dir.join("img.u8"), w, h);
    let mut out = Gray::<f32>::new(w, h);
    let mut out8 = Gray::<u8>::new(w, h);
    let mut lab = Gray::<u32>::new(w, h);
    let report = |name: &str, ms: f64| println!("{name} {ms:.3}");
    let r = Border::Reflect101;

    report(
        "gaussian_5x5",
        time(reps, || gaussian_blur(&img, &mut out, 5, 0.0).unwrap()),
    );
    report(
        "gaussian_sigma2",
        time(reps, || gaussian_blur(&img, &mut out, 0, 2.0).unwrap()),
    );
    report(
        "box_5x5",
        time(reps, || box_filter(&img, &mut out, 5, 5, r).unwrap()),
    );
    report(
        "box_31x31",
        time(reps, || box_filter(&img, &mut out, 31, 31, r).unwrap()),
    );
    report(
        "sobel_dx_k3",
        time(reps, || sobel(&img, &mut out, 1, 0, 3).unwrap()),
    );
    report(
        "sobel_dy_k5",
        time(reps, || sobel(&img, &mut out, 0, 1, 5).unwrap()),
    );
    report(
        "scharr_dx",
        time(reps, || scharr(&img, &mut out, 1, 0).unwrap()),
    );
    report(
        "erode_rect_5x5",
        time(reps, || {
            erode(&img, &mut out, MorphShape::Rect, 5, 5).unwrap()
        }),
    );
    report(
        "dilate_rect_15x15",
        time(reps, || {
            dilate(&img, &mut out, MorphShape::Rect, 15, 15).unwrap()
        }),
    );
    report(
        "erode_ellipse_7x7",
        time(reps, || {
            erode(&img, &mut out, MorphShape::Ellipse, 7, 7).unwrap()
        }),
    );
    report(
        "open_rect_5x5",
        time(reps, || {
            open(&img, &mut out, MorphShape::Rect, 5, 5).unwrap()
        }),
    );
    report(
        "median_f32_k3",
        time(reps, || median_blur(&img, &mut out, 3).unwrap()),
    );
    report(
        "median_f32_k5",
        time(reps, || median_blur(&img, &mut out, 5).unwrap()),
    );
    report(
        "median_u8_k5",
        time(reps, || median_blur_u8(&img8, &mut out8, 5).unwrap()),
    );
    report(
        "median_u8_k9",
        time(reps, || median_blur_u8(&img8, &mut out8, 9).unwrap()),
    );
    report(
        "guided_r8",
        time(reps, || {
            guided_filter(&img, &deg, &mut out, 8, 1e-3).unwrap()
        }),
    );
    report("otsu_f32", time(reps, || threshold_otsu(&img).unwrap()));
    report(
        "label_c8",
        time(reps, || {
            label(&mask, &mut lab, Connectivity::Eight).unwrap()
        }),
    );
    report(
        "label_stats_c8",
        time(reps, || {
            let n = label(&mask, &mut lab, Connectivity::Eight).unwrap();
            component_stats(&lab, n).unwrap()
        }),
    );
    report("psnr", time(reps, || psnr(&img, &deg, 1.0).unwrap()));
    report("ssim", time(reps, || ssim(&img, &deg, 1.0).unwrap()));
}
