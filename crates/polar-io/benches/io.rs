//! Read/write throughput at the real sensor size (2448x2048): the bundled real 8-bit frame,
//! a 16-bit mosaic, and a 4-channel float32 Stokes EXR.
//! Run: `cargo bench -p polar-io --bench io`.

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use polar_image::{Gray, Image, StokesImage};
use polar_io::{
    STOKES_CHANNELS, read_exr, read_gray_png, read_mosaic, write_exr, write_gray16_png,
};

const W: usize = 2448;
const H: usize = 2048;

fn bench_io(c: &mut Criterion) {
    let real =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/real/camera_IMX250MZR.png");
    let dir = std::env::temp_dir().join(format!("polar-io-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Noise-like 12-bit data: compresses like a real sensor frame, not like a constant.
    let mosaic = Gray::from_vec(
        W,
        H,
        (0..W * H)
            .map(|i| ((i as u32).wrapping_mul(2654435761) >> 20) as u16)
            .collect(),
    )
    .unwrap();
    let stokes: StokesImage = Image::from_vec(
        W,
        H,
        (0..W * H * 4)
            .map(|i| ((i as f32) * 0.001).sin().abs())
            .collect(),
    )
    .unwrap();
    let png16 = dir.join("raw16.png");
    let exr = dir.join("stokes.exr");
    write_gray16_png(&png16, &mosaic).unwrap();
    write_exr(&exr, &stokes, STOKES_CHANNELS).unwrap();

    let mut g = c.benchmark_group("io_2448x2048");
    g.sample_size(10);
    g.bench_function("read_real_png8", |b| b.iter(|| read_mosaic(&real).unwrap()));
    g.bench_function("read_png16", |b| b.iter(|| read_gray_png(&png16).unwrap()));
    g.bench_function("write_png16", |b| {
        b.iter(|| write_gray16_png(&png16, &mosaic).unwrap())
    });
    g.bench_function("read_stokes_exr", |b| {
        b.iter(|| -> StokesImage { read_exr(&exr, STOKES_CHANNELS).unwrap() })
    });
    g.bench_function("write_stokes_exr", |b| {
        b.iter(|| write_exr(&exr, &stokes, STOKES_CHANNELS).unwrap())
    });
    g.finish();
    std::fs::remove_dir_all(&dir).unwrap();
}

criterion_group!(benches, bench_io);
criterion_main!(benches);
