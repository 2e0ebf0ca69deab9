//! Helpers shared by the renderer's integration tests (each test file uses a subset).
#![allow(dead_code)]

use polar_render::{Camera, FirstHit, Polarization, RenderOptions, RenderOutput, Scene, render};

/// World vectors.
pub type V3 = nalgebra::Vector3<f64>;

/// A square camera on +z at `distance` looking at the origin.
pub fn camera(distance: f64, fov_deg: f64, size: usize) -> Camera {
    Camera {
        position: V3::new(0.0, 0.0, distance),
        look_at: V3::zeros(),
        up: V3::y(),
        fov_deg,
        width: size,
        height: size,
    }
}

/// Renders silently, with the cheapest exact model or the one forced, with the ground
/// truth (and with a medium the clear view).
pub fn run(scene: &Scene, model: Option<Polarization>) -> RenderOutput {
    let opts = RenderOptions {
        force_model: model,
        ground_truth: true,
        clear: true,
        ..Default::default()
    };
    render(scene, &opts, &|_, _| {}).expect("render")
}

/// Renders silently with the cheapest exact model, with the ground truth, the clear and
/// the dehazed view.
pub fn run_dehazed(scene: &Scene) -> RenderOutput {
    let opts = RenderOptions {
        ground_truth: true,
        clear: true,
        dehazed: true,
        ..Default::default()
    };
    render(scene, &opts, &|_, _| {}).expect("render")
}

/// The ground truth of a render made with it.
pub fn truth(o: &RenderOutput) -> &FirstHit {
    o.ground_truth.as_ref().expect("ground truth")
}

/// Renders on a pool of `threads` threads.
pub fn run_on_threads(scene: &Scene, threads: usize) -> RenderOutput {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
        .install(|| run(scene, None))
}

/// The bits of every Stokes value (and of the clear view when there is one), for exact comparisons.
pub fn bits(o: &RenderOutput) -> Vec<u32> {
    let clear = o.clear.as_ref().map(|c| c.as_slice()).unwrap_or_default();
    o.stokes
        .as_slice()
        .iter()
        .chain(clear)
        .map(|v| v.to_bits())
        .collect()
}
