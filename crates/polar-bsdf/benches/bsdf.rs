//! Cost of `eval` and `sample` per BSDF (the inner loop of the path tracer).
//! Run: `cargo bench -p polar-bsdf`.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use polar_bsdf::Material;
use std::hint::black_box;

fn materials() -> Vec<(&'static str, Material)> {
    [
        ("lambertian", "type = 'lambertian'\nalbedo = 0.5"),
        ("smooth_conductor", "type = 'conductor'\nmetal = 'au'"),
        (
            "rough_conductor",
            "type = 'conductor'\nmetal = 'au'\nroughness = [0.1, 0.3]",
        ),
        ("smooth_dielectric", "type = 'dielectric'\nior = 1.5"),
        (
            "rough_dielectric",
            "type = 'dielectric'\nior = 1.5\nroughness = 0.2",
        ),
        ("plastic", "type = 'plastic'\nalbedo = 0.5\nroughness = 0.1"),
    ]
    .into_iter()
    .map(|(name, text)| (name, toml::from_str(text).expect("valid material")))
    .collect()
}

fn bench(c: &mut Criterion) {
    let wo = Vector3::new(0.3, -0.2, 0.93).normalize();
    let wi = Vector3::new(-0.4, 0.1, 0.91).normalize();
    for (name, material) in materials() {
        let bsdf = material.bsdf([0.5, 0.5]);
        c.bench_function(&format!("{name}/eval"), |b| {
            b.iter(|| black_box(&bsdf).eval(black_box(&wo), &wi))
        });
        let mut u = 0.1_f64;
        c.bench_function(&format!("{name}/sample"), |b| {
            b.iter(|| {
                u = (u + 0.618_033_988_749_895).fract();
                black_box(&bsdf).sample(black_box(&wo), [u, 1.0 - u, (3.0 * u).fract()])
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
