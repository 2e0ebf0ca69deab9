//! Block-diagonal fast path versus general 4×4 (and 3×3 linear) Mueller products.
//!
//! Run: `cargo bench -p polar-optics --bench block_mueller`.

use criterion::{Criterion, criterion_group, criterion_main};
use num_complex::Complex64;
use polar_optics::mueller::{linear_part, rotator};
use polar_optics::stokes::to_linear;
use polar_optics::{BlockDiagonal, Mueller, Stokes, fresnel_amplitudes};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let f = fresnel_amplitudes(0.6, Complex64::new(0.2, 3.3));
    let b1 = f.reflection_block();
    let b2 = fresnel_amplitudes(0.3, Complex64::new(1.5, 0.0)).transmission_block();
    let (m1, m2) = (b1.to_mueller(), b2.to_mueller());
    let general: Mueller = rotator(0.3) * m1;
    let s = Stokes::new(1.0, 0.3, -0.2, 0.1);
    let (l1, ls) = (linear_part(&m1), to_linear(&s));

    let mut g = c.benchmark_group("mueller");
    g.bench_function("full4x4 * full4x4", |b| {
        b.iter(|| black_box(m1) * black_box(m2))
    });
    g.bench_function("block * block", |b| {
        b.iter(|| black_box(b1) * black_box(b2))
    });
    g.bench_function("full4x4 * general", |b| {
        b.iter(|| black_box(m1) * black_box(general))
    });
    g.bench_function("block * general", |b| {
        b.iter(|| black_box(b1) * black_box(general))
    });
    g.bench_function("full4x4 * stokes", |b| {
        b.iter(|| black_box(m1) * black_box(s))
    });
    g.bench_function("block * stokes", |b| {
        b.iter(|| black_box(b1) * black_box(s))
    });
    g.bench_function("linear3x3 * linear stokes", |b| {
        b.iter(|| black_box(l1) * black_box(ls))
    });
    g.bench_function("detect block", |b| {
        b.iter(|| BlockDiagonal::from_mueller(black_box(&m1), 0.0))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
