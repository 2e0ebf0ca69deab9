//! Speed of the front end on a full frame, next to the machine's memory bandwidth.
//!
//! `cargo run --release -p polar-sensor --example bench_frontend -- FRAME.png [REPS] [--json] [--only=METHOD] [--pattern=rgb]`
//!
//! Times raw -> S0, S1, S2, DoLP, AoLP (f32, caller-allocated planes) for each
//! demosaicing method (per colour for `--pattern=rgb`: a colour mosaic through
//! `stokes_planes_rgb_into`), and a parallel large copy (read + write) as the bandwidth
//! yardstick. The lower bound for the fused chain is (bytes read + bytes written) /
//! bandwidth. `tools/bench_frontend.py` runs polanalyser on the same frame and
//! prints both in one table.

use std::time::{Duration, Instant};

use polar_sensor::products::{
    ColorStokesPlanes, StokesPlanes, simd_target, stokes_planes_into, stokes_planes_rgb_into,
};
use polar_sensor::{DemosaicMethod, Mosaic, MosaicPattern, MosaicSample};
use rayon::prelude::*;

/// Fastest of `reps` timings of `f` after one warm-up call (the least disturbed by
/// other processes on a shared machine; used for every row alike).
fn best_time(reps: usize, mut f: impl FnMut()) -> Duration {
    f();
    let t: Vec<Duration> = (0..reps)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed()
        })
        .collect();
    t.into_iter().min().expect("reps >= 1")
}

/// Bandwidths in bytes/s (read + write counted) over 256 MiB, parallel in 1 MiB chunks:
/// `(memcpy, stream)`, where memcpy is libc's (non-temporal stores for large copies)
/// and stream is a STREAM-"scale"-like loop `b[i] = 1.5 a[i]` with ordinary stores,
/// the same kind of stores the front end makes.
fn bandwidths(reps: usize) -> (f64, f64) {
    let n = 64 << 20;
    let src = vec![1.0f32; n];
    let mut dst = vec![0.0f32; n];
    let chunk = 1 << 18;
    let copy = best_time(reps, || {
        dst.par_chunks_mut(chunk)
            .zip(src.par_chunks(chunk))
            .for_each(|(d, s)| d.copy_from_slice(s));
    });
    let scale = best_time(reps, || {
        dst.par_chunks_mut(chunk)
            .zip(src.par_chunks(chunk))
            .for_each(|(d, s)| {
                for (d, s) in d.iter_mut().zip(s) {
                    *d = 1.5 * s;
                }
            });
    });
    std::hint::black_box(&dst);
    let bytes = 2.0 * 4.0 * n as f64;
    (bytes / copy.as_secs_f64(), bytes / scale.as_secs_f64())
}

fn bench<T: MosaicSample>(
    raw: &Mosaic<T>,
    reps: usize,
    only: Option<&str>,
    pattern: MosaicPattern,
) -> Vec<(DemosaicMethod, Duration)> {
    DemosaicMethod::ALL
        .into_iter()
        .filter(|m| only.is_none_or(|o| o == m.name()))
        .map(|m| {
            let (w, h) = m.output_size(raw.width(), raw.height());
            let reps = if m == DemosaicMethod::Newton {
                reps.min(5)
            } else {
                reps
            };
            let t = match pattern {
                MosaicPattern::Mono => {
                    let mut out = StokesPlanes::new(w, h);
                    best_time(reps, || stokes_planes_into(raw, m, &mut out).unwrap())
                }
                MosaicPattern::Rgb => {
                    let mut out = ColorStokesPlanes::new(w, h);
                    best_time(reps, || stokes_planes_rgb_into(raw, m, &mut out).unwrap())
                }
            };
            (m, t)
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let json = args.iter().any(|a| a == "--json");
    let only = args.iter().find_map(|a| a.strip_prefix("--only="));
    let pattern: MosaicPattern = args
        .iter()
        .find_map(|a| a.strip_prefix("--pattern="))
        .map_or(MosaicPattern::Mono, |p| {
            p.parse().expect("--pattern=mono|rgb")
        });
    let pos: Vec<&String> = args.iter().filter(|a| !a.starts_with("--")).collect();
    let path = pos
        .first()
        .map(|s| s.as_str())
        .unwrap_or("tests/data/real/carps_IMX250MZR.png");
    let reps: usize = pos
        .get(1)
        .map_or(20, |s| s.parse().expect("REPS is a number"));
    let png = polar_io::read_mosaic(path).expect("frame reads");
    let (w, h) = png.image.size();
    let bytes_per_sample = usize::from(png.bit_depth.bits() / 8);
    let results = if bytes_per_sample == 1 {
        let raw8: Mosaic<u8> = Mosaic::from_vec(
            w,
            h,
            png.image.as_slice().iter().map(|&v| v as u8).collect(),
        )
        .unwrap();
        bench(&raw8, reps, only, pattern)
    } else {
        bench(&png.image, reps, only, pattern)
    };
    let (memcpy_bw, stream_bw) = bandwidths(reps);
    let bandwidth = memcpy_bw.max(stream_bw);
    let threads = rayon::current_num_threads();
    // Fused bilinear chain: reads the mosaic once, writes five f32 planes (per colour).
    let planes = match pattern {
        MosaicPattern::Mono => 5,
        MosaicPattern::Rgb => 15,
    };
    let moved = (w * h * (bytes_per_sample + planes * 4)) as f64;
    let bound = moved / bandwidth;
    if json {
        let items: Vec<String> = results
            .iter()
            .map(|(m, t)| format!("\"{}\": {:.6}", m.name(), t.as_secs_f64()))
            .collect();
        println!(
            "{{\"width\": {w}, \"height\": {h}, \"threads\": {threads}, \"simd\": \"{}\", \"memcpy_gb_s\": {:.3}, \"stream_gb_s\": {:.3}, \"bytes_moved\": {moved}, \"bound_s\": {bound:.6}, \"seconds\": {{{}}}}}",
            simd_target(),
            memcpy_bw / 1e9,
            stream_bw / 1e9,
            items.join(", ")
        );
        return;
    }
    println!(
        "{w}x{h}, {threads} threads, SIMD target {}, bandwidth (read+write) memcpy {:.2} GB/s, stream-scale {:.2} GB/s; bound uses the larger",
        simd_target(),
        memcpy_bw / 1e9,
        stream_bw / 1e9
    );
    println!("{:<12} {:>10} {:>12}", "method", "ms", "x bound");
    for (m, t) in results {
        let ratio = if m == DemosaicMethod::Bilinear {
            format!("{:.2}", t.as_secs_f64() / bound)
        } else {
            "-".into()
        };
        println!(
            "{:<12} {:>10.2} {:>12}",
            m.name(),
            t.as_secs_f64() * 1e3,
            ratio
        );
    }
    println!(
        "bandwidth bound for {:.1} MB moved: {:.2} ms",
        moved / 1e6,
        bound * 1e3
    );
}
