//! Cost of the phase functions a renderer calls per medium vertex: `eval` (plane matrix
//! plus the two frame rotations) and `sample`, over batches of 1024 direction pairs,
//! for Rayleigh (the anchor), Henyey–Greenstein and tabulated Mie; and the one-off cost
//! of building a Mie table.
//!
//! Run: `cargo bench -p polar-optics --bench phase`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::Vector3;
use num_complex::Complex64;
use polar_optics::scatter::{MieTable, PhaseFunction};
use std::hint::black_box;

const N: usize = 1024;

/// `N` unit directions spread over the sphere (a golden-angle spiral, shifted by `seed`).
fn directions(seed: f64) -> Vec<Vector3<f64>> {
    (0..N)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / N as f64;
            let phi = 2.399_963 * i as f64 + seed;
            let r = (1.0 - z * z).sqrt();
            Vector3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let (k_in, k_out) = (directions(0.0), directions(1.3));
    let us: Vec<[f64; 2]> = (0..N)
        .map(|i| [(i as f64 + 0.5) / N as f64, ((i * 7) % N) as f64 / N as f64])
        .collect();
    let cases = [
        ("rayleigh", PhaseFunction::Rayleigh),
        ("hg", PhaseFunction::henyey_greenstein(0.8, 0.3).unwrap()),
        (
            "mie_x10",
            PhaseFunction::mie(10.0, Complex64::new(1.33, 0.0)).unwrap(),
        ),
        (
            "mie_x1000",
            PhaseFunction::mie(1000.0, Complex64::new(1.33, 0.0)).unwrap(),
        ),
    ];
    let mut g = c.benchmark_group("phase");
    g.throughput(Throughput::Elements(N as u64));
    for (name, p) in &cases {
        g.bench_function(format!("eval_{name}"), |b| {
            b.iter(|| {
                for (a, o) in black_box(&k_in).iter().zip(black_box(&k_out)) {
                    black_box(p.eval(a, o));
                }
            })
        });
        g.bench_function(format!("sample_{name}"), |b| {
            b.iter(|| {
                for (a, u) in black_box(&k_in).iter().zip(black_box(&us)) {
                    black_box(p.sample(a, *u));
                }
            })
        });
    }
    g.finish();
    let mut t = c.benchmark_group("mie_table_new");
    t.sample_size(10);
    for x in [10.0, 100.0] {
        t.bench_function(format!("x{x}"), |b| {
            b.iter(|| black_box(MieTable::new(black_box(x), Complex64::new(1.33, 0.0))))
        });
    }
    t.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
