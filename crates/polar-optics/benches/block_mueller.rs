//! Block-diagonal fast path versus general 4×4 (and 3×3 linear) Mueller products,
//! over batches of 1024 distinct matrices so per-call overhead does not dominate.
//!
//! Run: `cargo bench -p polar-optics --bench block_mueller`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use num_complex::Complex64;
use polar_optics::mueller::{linear_part, rotator};
use polar_optics::stokes::to_linear;
use polar_optics::{
    BlockDiagonal, LinearMueller, LinearStokes, Mueller, Stokes, fresnel_amplitudes,
};
use std::hint::black_box;

const N: usize = 1024;

/// `N` Fresnel reflection blocks at varied angles and indices.
fn blocks(seed: f64) -> Vec<BlockDiagonal> {
    (0..N)
        .map(|i| {
            let u = (i as f64 + seed) / N as f64;
            fresnel_amplitudes(u, Complex64::new(0.2 + u, 3.0 * u)).reflection_block()
        })
        .collect()
}

/// Runs `f` over paired inputs into a reused output buffer.
fn batch<A: Copy, B: Copy, O: Copy + Default>(
    c: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    a: &[A],
    b: &[B],
    f: impl Fn(A, B) -> O,
) {
    let mut out = vec![O::default(); N];
    c.bench_function(name, |bench| {
        bench.iter(|| {
            for ((o, &x), &y) in out.iter_mut().zip(black_box(a)).zip(black_box(b)) {
                *o = f(x, y);
            }
            black_box(&out);
        })
    });
}

fn bench(c: &mut Criterion) {
    let (b1, b2) = (blocks(0.25), blocks(0.75));
    let m1: Vec<Mueller> = b1.iter().map(BlockDiagonal::to_mueller).collect();
    let m2: Vec<Mueller> = b2.iter().map(BlockDiagonal::to_mueller).collect();
    let general: Vec<Mueller> = m2
        .iter()
        .enumerate()
        .map(|(i, m)| rotator(i as f64 * 0.01) * m)
        .collect();
    let s: Vec<Stokes> = (0..N)
        .map(|i| Stokes::new(1.0, 0.3, -0.2, 0.001 * i as f64))
        .collect();
    let l1: Vec<LinearMueller> = m1.iter().map(linear_part).collect();
    let ls: Vec<LinearStokes> = s.iter().map(to_linear).collect();

    let mut g = c.benchmark_group("mueller_x1024");
    g.throughput(Throughput::Elements(N as u64));
    batch(&mut g, "full4x4 * full4x4", &m1, &m2, |x, y| x * y);
    batch(&mut g, "block * block", &b1, &b2, |x, y| x * y);
    batch(&mut g, "full4x4 * general", &m1, &general, |x, y| x * y);
    batch(&mut g, "block * general", &b1, &general, |x, y| x * y);
    batch(&mut g, "full4x4 * stokes", &m1, &s, |x, y| x * y);
    batch(&mut g, "block * stokes", &b1, &s, |x, y| x * y);
    batch(&mut g, "linear3x3 * linear stokes", &l1, &ls, |x, y| x * y);
    batch(&mut g, "detect block", &m1, &m2, |x, _| {
        BlockDiagonal::from_mueller(&x, 0.0).is_some()
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
