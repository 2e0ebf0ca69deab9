//! Time of `dehaze` on a full sensor frame (2448x2048, 5 MP): a sample's Stokes planes
//! upsampled by pixel replication, so the scene keeps its layout (sky on top, haze growing
//! with depth) at the size the target is stated for. Prints one JSON object: the best of
//! `--runs` seconds for the polarization method (defaults), the dark channel (defaults) and
//! the dark channel as the OpenCV reference computes it (`denoise_radius = 0`, see
//! tools/dehaze_dcp_reference.py). `--s0-out FILE` writes the upsampled S0 as raw
//! little-endian f32 for that reference. Driven by tools/bench_dehaze.py.
//!
//! `cargo run --release -p polar-dehaze --example dehaze_bench -- SAMPLE_DIR [--runs N] [--s0-out FILE]`

use std::path::PathBuf;
use std::time::Instant;

use polar_dehaze::{DehazeOptions, Method, dehaze};
use polar_image::LinearStokesImage;
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::{Observation, StokesPlanes};

/// The binaries' allocator, so the times are what `polar-vision run` sees.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

const WIDTH: usize = 2448;
const HEIGHT: usize = 2048;

fn upsampled(sample: &std::path::Path) -> Observation {
    let s: LinearStokesImage = polar_io::read_exr(
        sample.join(polar_io::files::STOKES),
        polar_io::LINEAR_STOKES_CHANNELS,
    )
    .expect("a sample directory with stokes.exr");
    let (w, h) = s.size();
    let mut big = LinearStokesImage::new(WIDTH, HEIGHT);
    for (k, px) in big.pixels_mut().iter_mut().enumerate() {
        let (x, y) = (k % WIDTH * w / WIDTH, k / WIDTH * h / HEIGHT);
        *px = s.pixels()[y * w + x];
    }
    Observation::new(
        StokesPlanes::from_linear_stokes(&big),
        CameraModel::Orthographic,
    )
}

fn best_seconds(obs: &Observation, opts: &DehazeOptions, runs: usize) -> f64 {
    (0..runs.max(1))
        .map(|_| {
            let t = Instant::now();
            dehaze(obs, opts).expect("dehaze");
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let mut args = std::env::args_os().skip(1);
    let (mut sample, mut runs, mut s0_out) = (None, 3, None);
    while let Some(a) = args.next() {
        match a.to_str() {
            Some("--runs") => {
                runs = args
                    .next()
                    .and_then(|v| v.to_str()?.parse().ok())
                    .expect("--runs N")
            }
            Some("--s0-out") => s0_out = args.next().map(PathBuf::from),
            _ => sample = Some(PathBuf::from(a)),
        }
    }
    let obs =
        upsampled(&sample.expect("usage: dehaze_bench SAMPLE_DIR [--runs N] [--s0-out FILE]"));
    if let Some(path) = s0_out {
        let bytes: Vec<u8> = obs
            .planes
            .s0
            .as_slice()
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        std::fs::write(&path, bytes).expect("--s0-out");
    }
    let polarization = DehazeOptions::default();
    let dark = DehazeOptions {
        method: Method::DarkChannel,
        ..DehazeOptions::default()
    };
    let reference = DehazeOptions {
        denoise_radius: 0,
        ..dark
    };
    println!(
        "{{\"width\": {WIDTH}, \"height\": {HEIGHT}, \"threads\": {}, \"polarization_s\": {:.4}, \"dark_channel_s\": {:.4}, \"dark_channel_as_reference_s\": {:.4}}}",
        rayon::current_num_threads(),
        best_seconds(&obs, &polarization, runs),
        best_seconds(&obs, &dark, runs),
        best_seconds(&obs, &reference, runs),
    );
}
