//! The Sobol sampler against the independent one on two cross-check scenes: both are
//! unbiased, and Sobol's pixel error at equal spp is lower by a stated margin.
//! Run with `cargo test -p polar-render --release`.

use polar_render::{SamplerKind, Scene, load_scene};
use std::path::Path;

mod common;
use common::run;

/// A cross-check scene (datasets-synth/scenes/crosscheck) at 32×32 pixels.
fn crosscheck(name: &str) -> Scene {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets-synth/scenes/crosscheck");
    let mut scene = load_scene(&dir.join(format!("{name}.toml"))).expect("scene");
    scene.camera.width = 32;
    scene.camera.height = 32;
    scene
}

/// S0 of `scene` rendered with `sampler` at `spp` samples per pixel under `seed`.
fn s0(scene: &Scene, sampler: SamplerKind, spp: u32, seed: u64) -> Vec<f64> {
    let mut s = scene.clone();
    s.settings.sampler = sampler;
    s.settings.spp = spp;
    s.settings.seed = seed;
    let out = run(&s, None);
    out.stokes
        .pixels()
        .iter()
        .map(|p| f64::from(p[0]))
        .collect()
}

/// Root mean square of `a − b`.
fn rmse(a: &[f64], b: &[f64]) -> f64 {
    let sum: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    (sum / a.len() as f64).sqrt()
}

/// At 64 spp, Sobol's RMSE against a 4096-spp reference (Sobol, another seed) is below
/// `1 / margin` of independent sampling's. The image mean agrees with the reference's
/// within 4 standard errors: per-pixel scrambles make the pixel errors independent,
/// so the standard error of their mean is `sqrt(Σ e²) / n`, e the residuals themselves
/// (which also carry the reference's noise).
fn sobol_beats_independent(name: &str, margin: f64) {
    let scene = crosscheck(name);
    let reference = s0(&scene, SamplerKind::Sobol, 4096, 1);
    let sobol = s0(&scene, SamplerKind::Sobol, 64, 2);
    let independent = s0(&scene, SamplerKind::Independent, 64, 2);
    let (e_sobol, e_ind) = (rmse(&sobol, &reference), rmse(&independent, &reference));
    assert!(
        e_sobol * margin < e_ind,
        "{name}: RMSE Sobol {e_sobol:.3e}, independent {e_ind:.3e}, want a ratio > {margin}"
    );
    let n = reference.len() as f64;
    let residual: Vec<f64> = sobol.iter().zip(&reference).map(|(x, r)| x - r).collect();
    let mean = residual.iter().sum::<f64>() / n;
    let se = residual.iter().map(|e| e * e).sum::<f64>().sqrt() / n;
    assert!(
        mean.abs() < 4.0 * se,
        "{name}: mean residual {mean:.3e} ± {se:.3e}"
    );
}

#[test]
fn sobol_beats_independent_on_a_smooth_conductor() {
    // Delta BSDF under a constant environment: only the 2-D pixel footprint is
    // integrated, where a (0,2)-sequence converges far faster than independent points.
    sobol_beats_independent("conductor", 4.0);
}

#[test]
fn sobol_beats_independent_on_a_rough_conductor() {
    // GGX α = 0.2 with a sun and an environment: light, BSDF and deeper bounces use
    // the aligned draws after the camera's, so this checks their alignment.
    sobol_beats_independent("roughconductor", 3.0);
}
