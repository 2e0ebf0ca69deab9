//! Cost of one aligned draw of the Sobol sampler against the independent one: a
//! path's camera draw and two bounces (light and BSDF `next_3d` each).
//! `cargo bench -p polar-render --bench sampler`

use criterion::{Criterion, criterion_group, criterion_main};
use polar_render::SamplerKind;
use polar_render::sampler::PixelStreams;
use std::hint::black_box;

fn draws(c: &mut Criterion) {
    let mut group = c.benchmark_group("sampler: camera + 2 bounces (5 draws)");
    for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
        let streams = PixelStreams::new(1, 2, kind);
        let mut sample = 0;
        group.bench_function(format!("{kind:?}"), |b| {
            b.iter(|| {
                sample = (sample + 1) & 0xffff;
                let mut s = streams.sample(black_box(sample));
                let mut sum = s.next_2d()[0];
                for _ in 0..4 {
                    sum += s.next_3d()[1];
                }
                sum
            })
        });
    }
    group.finish();
}

criterion_group!(benches, draws);
criterion_main!(benches);
