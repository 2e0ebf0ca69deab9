//! Participating media with known answers: Beer–Lambert transmittance, the
//! furnace, single Rayleigh scattering, grid vs homogeneous, model equivalence,
//! determinism and the dehazed ground truth. Run with `cargo test -p polar-render --release`.

use polar_bsdf::{LambertianParams, Material, Texture};
use polar_optics::scatter::PhaseFunction;
use polar_optics::stokes::{aolp, dolp};
use polar_render::{
    Camera, DensityGrid, Emission, Geometry, Light, Medium, Polarization, RenderOptions, Scene,
    Shape, render,
};
use std::f64::consts::PI;

mod common;
use common::{V3, bits, camera, run, run_dehazed, run_on_threads, truth};

/// The medium filling `[-1, 1]³`.
fn unit_box(sigma_s: f64, sigma_a: f64, phase: PhaseFunction) -> Medium {
    Medium {
        bounds_min: V3::repeat(-1.0),
        bounds_max: V3::repeat(1.0),
        sigma_s,
        sigma_a,
        phase,
        density: None,
    }
}

/// A constant grid of `value` (resolution 3 × 2 × 2, so that interpolation is exercised).
fn constant_grid(value: f64) -> DensityGrid {
    DensityGrid {
        resolution: [3, 2, 2],
        values: vec![value; 12],
    }
}

fn scene_with(cam: Camera, medium: Medium, spp: u32) -> Scene {
    let mut scene = Scene::new(cam);
    scene.medium = Some(medium);
    scene.settings.spp = spp;
    scene
}

fn mean(values: impl Iterator<Item = f64>) -> (f64, usize) {
    let (sum, n) = values.fold((0.0, 0), |(s, n), v| (s + v, n + 1));
    (sum / n as f64, n)
}

/// Path length through the box `[-1, 1]³` of the central ray of pixel `(x, y)` of a
/// camera on +z whose rays all cross the faces z = ±1: `2 / cos(angle to the axis)`.
fn central_length(cam: &Camera, x: usize, y: usize) -> f64 {
    let t = (0.5 * cam.fov_deg.to_radians()).tan();
    let sx = (2.0 * (x as f64 + 0.5) / cam.width as f64 - 1.0) * t;
    let sy = (1.0 - 2.0 * (y as f64 + 0.5) / cam.height as f64) * t;
    2.0 * (1.0 + sx * sx + sy * sy).sqrt()
}

#[test]
fn beer_lambert_transmittance_of_a_homogeneous_box() {
    // Absorption only (σ_a = 0.5, no scattering), environment 1: every pixel sees
    // exp(−σ_a L), analytically (no randomness beyond the pixel jitter: a narrow 2° fov
    // changes L by < 1e-3 across a pixel). The ground truth is the exact value at the centre.
    let cam = camera(5.0, 2.0, 8);
    let mut scene = scene_with(cam.clone(), unit_box(0.0, 0.5, PhaseFunction::Rayleigh), 4);
    scene
        .lights
        .push(Light::Environment(Emission::unpolarized(1.0)));
    let out = run(&scene, None);
    assert_eq!(out.model, Polarization::None, "nothing scatters");
    let tr = truth(&out).transmission.as_ref().expect("transmission");
    for y in 0..8 {
        for x in 0..8 {
            let expected = (-0.5 * central_length(&cam, x, y)).exp();
            let s0 = f64::from(out.stokes.pixel(x, y)[0]);
            assert!((s0 - expected).abs() < 1e-4, "S0 {s0} vs {expected}");
            let t = f64::from(tr.pixel(x, y)[0]);
            assert!(
                (t - expected).abs() < 1e-6,
                "transmission {t} vs {expected}"
            );
        }
    }
}

#[test]
fn beer_lambert_by_ratio_tracking_on_a_grid() {
    // σ_a = 1 times a constant density 0.5: ratio tracking against the majorant 0.5 is a
    // Bernoulli estimate of e^{−1} (every tentative collision zeroes it), std 0.48 per
    // sample; 16² pixels × 64 spp = 16384 samples give a std of the image mean 0.0038:
    // allow 4 sigma. A ramp density (0.2 … 1 along z, majorant 1) gives fractional weights;
    // it is checked against the exact optical depth of the ground truth.
    let cam = camera(5.0, 2.0, 16);
    let mut medium = unit_box(0.0, 1.0, PhaseFunction::Rayleigh);
    medium.density = Some(constant_grid(0.5));
    let mut scene = scene_with(cam.clone(), medium, 64);
    scene
        .lights
        .push(Light::Environment(Emission::unpolarized(1.0)));
    let out = run(&scene, None);
    let (m, _) = mean(out.stokes.pixels().iter().map(|p| f64::from(p[0])));
    let expected = (-1.0_f64).exp();
    assert!((m - expected).abs() < 0.015, "mean S0 {m} vs {expected}");
    let tr = truth(&out).transmission.as_ref().expect("transmission");
    assert!(
        (f64::from(tr.pixel(8, 8)[0]) - (-0.5 * central_length(&cam, 8, 8)).exp()).abs() < 1e-6
    );

    let ramp = DensityGrid {
        resolution: [1, 1, 5],
        values: vec![0.2, 0.4, 0.6, 0.8, 1.0],
    };
    scene.medium.as_mut().expect("medium").density = Some(ramp);
    let out = run(&scene, None);
    let tr = truth(&out).transmission.as_ref().expect("transmission");
    // Exact: the clamped trilinear ramp over z ∈ [−1, 1] integrates to 1.2 (0.2 · 0.2 + 0.8 ·
    // 1.2 + 1 · 0.2), times the 1/cos stretch of the oblique ray.
    let (got, n) = mean(out.stokes.pixels().iter().map(|p| f64::from(p[0])));
    let (want, _) = mean(tr.pixels().iter().map(|p| f64::from(p[0])));
    let centre = f64::from(tr.pixel(8, 8)[0]);
    let exact = (-1.2 * central_length(&cam, 8, 8) / 2.0).exp();
    assert!(
        (centre - exact).abs() < 1e-6,
        "optical depth: {centre} vs {exact}"
    );
    // The weights lie in [0, 1]: std per sample <= 0.5, so 4 sigma of the mean is 2/sqrt(N).
    let tolerance = 2.0 / ((n * 64) as f64).sqrt();
    assert!(
        (got - want).abs() < tolerance,
        "ratio tracking {got} vs {want} ± {tolerance}"
    );
}

/// `(mean, standard error)` of the values.
fn mean_and_se(values: &[f64]) -> (f64, f64) {
    let (m, n) = mean(values.iter().copied());
    let var = values.iter().map(|d| (d - m).powi(2)).sum::<f64>() / (n - 1) as f64;
    (m, (var / n as f64).sqrt())
}

fn furnace(phase: PhaseFunction) {
    // An albedo-1 medium (σ_s = 1, optical thickness 2 across the box) in a uniform
    // environment of radiance 1 is in equilibrium: every pixel has S0 = 1 and no
    // polarization. 16² pixels × 32 spp. S0: the mean over the image within 4 standard
    // errors (estimated from the pixels) of 1 and within 2% of it. Polarization: the
    // image means of S1, S2 and of the radial and tangential components (a pattern
    // about the image centre, which plain means would cancel) within 4 standard errors of 0.
    let size = 16;
    let mut scene = scene_with(camera(4.0, 40.0, size), unit_box(1.0, 0.0, phase), 32);
    scene.settings.max_depth = 256;
    scene
        .lights
        .push(Light::Environment(Emission::unpolarized(1.0)));
    let out = run(&scene, None);
    let s0: Vec<f64> = out
        .stokes
        .pixels()
        .iter()
        .map(|p| f64::from(p[0]))
        .collect();
    let (m, se) = mean_and_se(&s0);
    assert!((m - 1.0).abs() < (4.0 * se).min(0.02), "mean S0 {m} ± {se}");
    let mut components = [const { Vec::new() }; 4];
    for (i, p) in out.stokes.pixels().iter().enumerate() {
        let (dx, dy) = ((i % size) as f64 - 7.5, 7.5 - (i / size) as f64);
        let phi2 = 2.0 * dy.atan2(dx);
        let (s1, s2) = (f64::from(p[1]), f64::from(p[2]));
        let radial = s1 * phi2.cos() + s2 * phi2.sin();
        let tangential = s2 * phi2.cos() - s1 * phi2.sin();
        for (c, v) in components.iter_mut().zip([s1, s2, radial, tangential]) {
            c.push(v);
        }
    }
    for (name, c) in ["S1", "S2", "radial", "tangential"].iter().zip(&components) {
        let (m, se) = mean_and_se(c);
        assert!(m.abs() < 4.0 * se, "{name}: mean {m} ± {se}");
    }
}

#[test]
fn furnace_rayleigh_medium_keeps_energy() {
    furnace(PhaseFunction::Rayleigh);
}

#[test]
fn furnace_henyey_greenstein_medium_keeps_energy() {
    furnace(PhaseFunction::henyey_greenstein(0.7, 0.5).expect("hg"));
}

/// A Rayleigh box `[-1, 1]³` seen from `position` (2° fov) and lit by a sun at scattering
/// angle `theta` whose scattering plane holds the central view direction `d` and the
/// image direction at angle `psi` from `x_ref` toward `y_ref` (the conventions' frame):
/// sun direction `cos θ d + sin θ e`, so `k_in · k_out = cos θ`. Single scattering is then
/// polarized along `d × e`, at AoLP `psi + 90°`.
fn single_scattering_scene(
    position: V3,
    theta: f64,
    psi: f64,
    sigma_s: f64,
    max_depth: u32,
) -> Scene {
    let cam = Camera {
        position,
        ..camera(5.0, 2.0, 16)
    };
    let d = -position.normalize();
    let x_ref = d.cross(&cam.up).normalize();
    let e = x_ref * psi.cos() + x_ref.cross(&d) * psi.sin();
    let mut scene = scene_with(cam, unit_box(sigma_s, 0.0, PhaseFunction::Rayleigh), 32);
    scene.settings.max_depth = max_depth;
    scene.lights.push(Light::Sun {
        direction: d * theta.cos() + e * theta.sin(),
        emission: Emission::unpolarized(1.0),
    });
    scene
}

#[test]
fn single_rayleigh_scattering_dolp_and_aolp() {
    // τ ≈ 0.04 along the view (σ_s = 0.02): single scattering dominates and has
    // DoLP = sin²θ / (1 + cos²θ) exactly for every sample, polarized perpendicular to the
    // scattering plane. Multiple scattering (a fraction ~τ of the light, less polarized)
    // lowers the DoLP by at most ~τ; the 2° fov moves θ by < 1°, changing the DoLP by
    // < 0.016 at 45° (first order, averaging out). Tolerance 0.04 on the image DoLP and 1°
    // on the AoLP. An oblique view and tilted planes, so that no frame is axis-aligned.
    let position = V3::new(0.35, 0.45, 0.82).normalize() * 5.0;
    for (theta_deg, psi_deg) in [(90.0_f64, 20.0_f64), (45.0, 70.0), (135.0, 150.0)] {
        let (theta, psi) = (theta_deg.to_radians(), psi_deg.to_radians());
        let out = run(
            &single_scattering_scene(position, theta, psi, 0.02, 8),
            None,
        );
        let s = out
            .stokes
            .pixels()
            .iter()
            .fold([0.0; 3], |a, p| [0, 1, 2].map(|c| a[c] + f64::from(p[c])));
        let expected = theta.sin().powi(2) / (1.0 + theta.cos().powi(2));
        let got = dolp(s[0], s[1], s[2]);
        assert!(
            (got - expected).abs() < 0.04,
            "θ {theta_deg}: DoLP {got} vs {expected}"
        );
        let want = (psi + 0.5 * PI).rem_euclid(PI);
        let diff = (aolp(s[0], s[1], s[2]) - want + 0.5 * PI).rem_euclid(PI) - 0.5 * PI;
        assert!(
            diff.abs() < 1f64.to_radians(),
            "θ {theta_deg}: AoLP off by {} deg",
            diff.to_degrees()
        );
    }
}

#[test]
fn single_rayleigh_scattering_radiance_is_normalised() {
    // Direct light only (max_depth 1): a camera ray crossing z ∈ [−1, 1] near x = 0 at
    // θ = 90° sees L = E σ_s p(90°) ∫₀² e^{−σ_s s} e^{−σ_s · 1} ds with p(90°) = 3/(16π)
    // (the sun path from x = 1 to x = 0 has length 1). σ_s = 0.25: about 40% of the samples
    // scatter; 16² × 32 samples give a relative std of the mean ~1%: allow 4%.
    let sigma = 0.25;
    let out = run(
        &single_scattering_scene(V3::new(0.0, 0.0, 5.0), 0.5 * PI, 0.0, sigma, 1),
        None,
    );
    let (got, _) = mean(out.stokes.pixels().iter().map(|p| f64::from(p[0])));
    let expected =
        sigma * 3.0 / (16.0 * PI) * (-sigma).exp() * (1.0 - (-2.0 * sigma).exp()) / sigma;
    assert!(
        (got / expected - 1.0).abs() < 0.04,
        "S0 {got} vs {expected}"
    );
}

/// A Lambertian sphere in a Rayleigh box under an environment and a sun.
fn hazy_sphere(density: Option<DensityGrid>) -> Scene {
    let mut medium = unit_box(0.4, 0.1, PhaseFunction::Rayleigh);
    medium.bounds_min = V3::repeat(-2.0);
    medium.bounds_max = V3::repeat(2.0);
    medium.density = density;
    let mut scene = scene_with(camera(5.0, 40.0, 16), medium, 32);
    let m = scene.add_material(
        "white",
        Material::Lambertian(LambertianParams {
            albedo: Texture::Constant(0.8),
        }),
    );
    scene.shapes.push(Shape::new(
        Geometry::Sphere {
            center: V3::zeros(),
            radius: 0.8,
        },
        m,
    ));
    scene
        .lights
        .push(Light::Environment(Emission::unpolarized(0.5)));
    scene.lights.push(Light::Sun {
        direction: V3::new(1.0, 1.0, 0.5),
        emission: Emission::unpolarized(2.0),
    });
    scene
}

#[test]
fn constant_grid_matches_homogeneous_medium() {
    // Delta tracking on a constant grid samples the same distances as the analytic
    // homogeneous case but from other random numbers: compare statistically. For S0, S1
    // and S2 the per-pixel differences have a mean that must lie within 4 standard errors
    // (estimated from the differences themselves) of zero.
    let a = run(&hazy_sphere(None), None);
    let b = run(&hazy_sphere(Some(constant_grid(1.0))), None);
    for c in 0..3 {
        let diffs: Vec<f64> = a
            .stokes
            .pixels()
            .iter()
            .zip(b.stokes.pixels())
            .map(|(p, q)| f64::from(p[c] - q[c]))
            .collect();
        let (m, se) = mean_and_se(&diffs);
        assert!(
            m.abs() < 4.0 * se + 1e-9,
            "channel {c}: mean diff {m}, se {se}"
        );
    }
    let ta = truth(&a).transmission.as_ref().expect("transmission");
    let tb = truth(&b).transmission.as_ref().expect("transmission");
    for (p, q) in ta.pixels().iter().zip(tb.pixels()) {
        assert!((p[0] - q[0]).abs() < 1e-6);
    }
}

#[test]
fn linear_transport_matches_full_in_a_rayleigh_medium() {
    let s = hazy_sphere(None);
    let cheap = run(&s, None);
    assert_eq!(cheap.model, Polarization::Linear);
    let full = run(&s, Some(Polarization::Full));
    let worst = cheap
        .stokes
        .pixels()
        .iter()
        .zip(full.stokes.pixels())
        .flat_map(|(p, q)| (0..4).map(move |c| (p[c] - q[c]).abs() / p[c].abs().max(1.0)))
        .fold(0.0_f32, f32::max);
    // Same seed, same decisions: only rounding differs.
    assert!(worst < 1e-5, "{worst}");
    assert!(
        full.stokes
            .pixels()
            .iter()
            .any(|p| p[1].hypot(p[2]) > 0.02 * p[0]),
        "the medium must polarize"
    );
}

#[test]
fn hazy_render_is_bit_identical_across_thread_counts_and_has_ground_truth() {
    let s = hazy_sphere(Some(constant_grid(0.7)));
    let one = run_on_threads(&s, 1);
    assert!(one.clear.is_some() && truth(&one).transmission.is_some());
    assert_eq!(bits(&one), bits(&run_on_threads(&s, 2)));
    // The clear view and the ground truth are options: without them, the same image.
    let lean = render(&s, &RenderOptions::default(), &|_, _| {}).expect("render");
    assert!(lean.clear.is_none() && lean.ground_truth.is_none());
    assert_eq!(bits(&lean), bits(&one)[..bits(&lean).len()]);
    // The clear image is the medium-free render of the same view.
    let mut no_medium = s.clone();
    no_medium.medium = None;
    let plain = run(&no_medium, None);
    assert!(plain.clear.is_none() && truth(&plain).transmission.is_none());
    assert_eq!(
        plain.stokes.channel(0).as_slice(),
        one.clear.as_ref().expect("clear").as_slice()
    );
}

#[test]
fn mie_medium_needs_full_transport() {
    // Mie's S34 couples circular and linear polarization: the cheapest exact model is Full,
    // and Linear is refused.
    let mut s = hazy_sphere(None);
    s.medium.as_mut().expect("medium").phase =
        PhaseFunction::mie(2.0, num_complex::Complex64::new(1.33, 0.0)).expect("mie");
    s.settings.spp = 4;
    assert_eq!(polar_render::required_model(&s), Polarization::Full);
    let err = render(
        &s,
        &RenderOptions {
            force_model: Some(Polarization::Linear),
            ..Default::default()
        },
        &|_, _| {},
    )
    .unwrap_err();
    assert!(
        matches!(err, polar_render::Error::ModelTooCheap { .. }),
        "{err}"
    );
    let out = run(&s, None);
    assert!(out.stokes.as_slice().iter().all(|v| v.is_finite()));
}

fn rayleigh_sky(tau: f64) -> polar_optics::sky::RayleighSky {
    polar_optics::sky::RayleighSky::new(V3::new(1.0, 0.6, -0.3), V3::y(), tau, 2.0).expect("sky")
}

#[test]
fn sky_light_shows_the_polarized_sky_in_the_camera_frame() {
    // Camera rays that escape see the sky's Stokes radiance for their direction, rotated
    // into the conventions' per-pixel frame. Prediction per pixel: the mean over a 16x16 grid
    // of sub-pixel rays; 256 jittered samples differ from it by the radiance's variation
    // across a 3.75° pixel over sqrt(256): measured worst 0.38% of the largest S0 (0.8% with
    // 64 samples); allow 1%.
    let cam = Camera {
        position: V3::zeros(),
        look_at: V3::new(0.3, 0.5, -1.0),
        up: V3::y(),
        fov_deg: 60.0,
        width: 16,
        height: 12,
    };
    let sky = rayleigh_sky(0.3);
    let mut scene = Scene::new(cam.clone());
    scene.settings.spp = 256;
    scene.lights.push(Light::Sky(sky.clone()));
    let out = run(&scene, None);
    assert_eq!(out.model, Polarization::Linear);
    let forward = (cam.look_at - cam.position).normalize();
    let right = forward.cross(&cam.up).normalize();
    let up = right.cross(&forward);
    let t = (0.5 * cam.fov_deg.to_radians()).tan();
    let direction = |x: f64, y: f64| {
        let sx = (2.0 * x / 16.0 - 1.0) * t;
        let sy = (1.0 - 2.0 * y / 12.0) * t * 12.0 / 16.0;
        (forward + right * sx + up * sy).normalize()
    };
    let max_s0 = out.stokes.pixels().iter().map(|p| p[0]).fold(0.0, f32::max);
    assert!(max_s0 > 0.0);
    let mut worst = 0.0_f64;
    for y in 0..12 {
        for x in 0..16 {
            let mut expected = polar_optics::Stokes::zeros();
            for k in 0..256 {
                let d = direction(
                    x as f64 + (0.5 + (k % 16) as f64) / 16.0,
                    y as f64 + (0.5 + (k / 16) as f64) / 16.0,
                );
                let x_ref = d.cross(&cam.up).normalize();
                let prop = -d;
                let basis = polar_optics::stokes_basis(&prop);
                expected += polar_optics::rotate_stokes_basis(&prop, &basis, &x_ref)
                    * sky.radiance(&prop)
                    / 256.0;
            }
            let got = out.stokes.pixel(x, y);
            for c in 0..3 {
                worst = worst.max((f64::from(got[c]) - expected[c]).abs() / f64::from(max_s0));
            }
        }
    }
    assert!(worst < 0.01, "worst difference {worst} of max S0");
}

#[test]
fn sky_sun_lights_a_white_ground() {
    // τ = 0: the sky itself is black and its sun unattenuated, so a white Lambertian ground
    // seen from above has S0 = E μ0 / π exactly (sun by next-event estimation only).
    let sky = rayleigh_sky(0.0);
    let mut scene = Scene::new(Camera {
        position: V3::new(0.0, 3.0, 0.0),
        look_at: V3::zeros(),
        up: V3::z(),
        fov_deg: 20.0,
        width: 8,
        height: 8,
    });
    scene.settings.spp = 2;
    let m = scene.add_material(
        "white",
        Material::Lambertian(LambertianParams {
            albedo: Texture::Constant(1.0),
        }),
    );
    let ground = polar_render::shapes::rectangle().transformed(&polar_render::shapes::transform(
        [0.0; 3],
        [-90.0, 0.0, 0.0],
        [5.0; 3],
    ));
    scene.shapes.push(Shape::new(Geometry::Mesh(ground), m));
    scene.lights.push(Light::Sky(sky.clone()));
    let out = run(&scene, None);
    let expected = 2.0 * sky.sun_cosine() / PI;
    for p in out.stokes.pixels() {
        assert!(
            (f64::from(p[0]) - expected).abs() < 1e-5,
            "S0 {} vs {expected}",
            p[0]
        );
    }
    // A sky and an environment together are refused.
    scene
        .lights
        .push(Light::Environment(Emission::unpolarized(1.0)));
    let err = render(&scene, &RenderOptions::default(), &|_, _| {}).unwrap_err();
    assert!(err.to_string().contains("at most one"), "{err}");
}

#[test]
fn camera_inside_the_medium_sees_an_attenuated_lamp() {
    // Camera at the centre of an absorbing box [-2, 2]³ (σ_a = 0.4) facing an emissive
    // rectangle (radiance 1, facing the camera) 1.5 units away: S0 = transmission =
    // e^{−0.4 · 1.5 / cos} per pixel (2° fov: cos > 0.9998, checked at the centre).
    let mut medium = unit_box(0.0, 0.4, PhaseFunction::Rayleigh);
    medium.bounds_min = V3::repeat(-2.0);
    medium.bounds_max = V3::repeat(2.0);
    let mut scene = scene_with(
        Camera {
            position: V3::zeros(),
            look_at: V3::new(0.0, 0.0, -1.0),
            ..camera(0.0, 2.0, 8)
        },
        medium,
        2,
    );
    let lamp = polar_render::shapes::rectangle().transformed(&polar_render::shapes::transform(
        [0.0, 0.0, -1.5],
        [0.0; 3],
        [1.0; 3],
    ));
    scene.shapes.push(Shape {
        geometry: Geometry::Mesh(lamp),
        material: None,
        emission: Some(Emission::unpolarized(1.0)),
        background: true,
    });
    let out = run(&scene, None);
    let expected = (-0.4_f64 * 1.5).exp();
    let tr = truth(&out).transmission.as_ref().expect("transmission");
    assert!((f64::from(tr.pixel(4, 4)[0]) - expected).abs() < 1e-4);
    for (s, t) in out.stokes.pixels().iter().zip(tr.pixels()) {
        assert!(
            (s[0] - t[0]).abs() < 1e-4,
            "S0 {} vs transmission {}",
            s[0],
            t[0]
        );
    }
    // Without the medium the lamp shows its full radiance.
    let clear = out.clear.as_ref().expect("clear");
    assert!(clear.pixels().iter().all(|p| (p[0] - 1.0).abs() < 1e-6));
}

/// The bits of a gray image, for exact comparisons.
fn gray_bits(g: &polar_image::Gray<f32>) -> Vec<u32> {
    g.as_slice().iter().map(|v| v.to_bits()).collect()
}

#[test]
fn dehazed_equals_the_render_when_the_medium_has_zero_density() {
    // A medium that is there but never interacts (σ_s = σ_a = 0, or a grid of density 0):
    // its flights pass with weight exactly 1 and draw no random numbers, so taking the
    // camera segment out of it changes nothing: the dehazed image is the hazy S0 bit for
    // bit (tolerance 0).
    let mut zero_sigma = hazy_sphere(None);
    let medium = zero_sigma.medium.as_mut().expect("medium");
    (medium.sigma_s, medium.sigma_a) = (0.0, 0.0);
    for scene in [zero_sigma, hazy_sphere(Some(constant_grid(0.0)))] {
        let out = run_dehazed(&scene);
        let dehazed = out.dehazed.as_ref().expect("dehazed");
        assert_eq!(gray_bits(&out.stokes.channel(0)), gray_bits(dehazed));
        assert!(out.stokes.pixels().iter().any(|p| p[0] > 0.1), "a lit view");
    }
    // Only asked for, and only with a medium.
    let hazy = hazy_sphere(None);
    assert!(run(&hazy, None).dehazed.is_none());
    let mut no_medium = hazy;
    no_medium.medium = None;
    assert!(run_dehazed(&no_medium).dehazed.is_none());
}

/// Pixel columns and rows (inclusive ranges) of [`haze_slab_scene`]: the plane's interior
/// (one pixel in from its edges) and, in the same rows, pixels that see no surface.
const PLANE_COLS: (usize, usize) = (5, 11);
const SKY_COLS: (usize, usize) = (20, 32);
const ROWS: (usize, usize) = (13, 19);

/// A Lambertian square (albedo 0.5, half-width 0.1) facing the camera 9 units away, in a
/// homogeneous isotropic haze (σ_s = 0.1, σ_a = 0.01) that fills a slab 5 units deep above
/// the camera and 1000 units every other way, lit by a sun from above and behind the camera
/// (45°) and a constant environment 0.2. 33 × 33 pixels, fov 4°, camera rays nearly
/// horizontal: along every one of them the haze is lit alike (the slab is invariant along
/// x and z), so the airlight follows Koschmieder's law `A (1 − t)`.
fn haze_slab_scene(seed: u64) -> Scene {
    let cam = Camera {
        position: V3::zeros(),
        look_at: V3::new(0.0, 0.0, -1.0),
        up: V3::y(),
        fov_deg: 4.0,
        width: 33,
        height: 33,
    };
    let medium = Medium {
        bounds_min: V3::repeat(-1000.0),
        bounds_max: V3::new(1000.0, 5.0, 1000.0),
        sigma_s: 0.1,
        sigma_a: 0.01,
        phase: PhaseFunction::HenyeyGreenstein {
            g: 0.0,
            depolarization: 1.0,
        },
        density: None,
    };
    let mut scene = scene_with(cam, medium, 256);
    scene.settings.seed = seed;
    let m = scene.add_material(
        "grey",
        Material::Lambertian(LambertianParams {
            albedo: Texture::Constant(0.5),
        }),
    );
    let square = polar_render::shapes::rectangle().transformed(&polar_render::shapes::transform(
        [-0.157, 0.0, -9.0],
        [0.0; 3],
        [0.1, 0.1, 1.0],
    ));
    scene.shapes.push(Shape::new(Geometry::Mesh(square), m));
    scene
        .lights
        .push(Light::Environment(Emission::unpolarized(0.2)));
    scene.lights.push(Light::Sun {
        direction: V3::new(0.0, 1.0, 1.0),
        emission: Emission::unpolarized(3.0),
    });
    scene
}

/// Mean of `f(x, y)` over the columns `cols` of [`ROWS`].
fn region_mean(cols: (usize, usize), f: impl Fn(usize, usize) -> f64) -> f64 {
    let pixels: Vec<(usize, usize)> = (ROWS.0..=ROWS.1)
        .flat_map(|y| (cols.0..=cols.1).map(move |x| (x, y)))
        .collect();
    pixels.iter().map(|&(x, y)| f(x, y)).sum::<f64>() / pixels.len() as f64
}

#[test]
fn dehazed_plane_in_a_haze_slab_obeys_koschmieder() {
    // Hazy image H = t · D + A (1 − t) with D the plane's radiance lit through the haze,
    // t the camera segment's transmittance (gt, exact) and A the airlight, measured on the
    // hazy pixels that see no surface. So D can be recovered from the hazy render alone,
    // (H − A (1 − t)) / t, and compared with the dehazed render. Tolerance 5 %: the
    // recovered value's Monte Carlo scatter over seeds is 1.3 % (256 spp, 49 pixels; H and
    // A noise amplified by 1/t ≈ 2.7), and the plane's own disturbance of the haze lighting
    // in front of it is below 0.2 % (half-width 0.1 ≪ mean free path 9). Wrong answers are
    // far outside: the hazy plane is 15 % brighter, the clear one (unattenuated sun, no
    // haze light) 36 %.
    let out = run_dehazed(&haze_slab_scene(7));
    let (dehazed, clear, t) = (
        out.dehazed.as_ref().expect("dehazed"),
        out.clear.as_ref().expect("clear"),
        truth(&out).transmission.as_ref().expect("transmission"),
    );
    let s0 = |img: &polar_image::Gray<f32>, x, y| f64::from(img.pixel(x, y)[0]);
    let depth = |x, y| s0(&truth(&out).depth, x, y);
    assert!(
        region_mean(PLANE_COLS, |x, y| depth(x, y).min(1.0)) == 1.0,
        "plane"
    );
    assert!(region_mean(SKY_COLS, depth) == 0.0, "sky");
    // Camera rays that meet no surface show the environment itself in the dehazed image.
    let sky = region_mean(SKY_COLS, |x, y| s0(dehazed, x, y));
    assert!((sky - 0.2).abs() < 1e-6, "dehazed sky {sky}");
    let hazy = |x, y| f64::from(out.stokes.pixel(x, y)[0]);
    let airlight = region_mean(SKY_COLS, hazy);
    let recovered = region_mean(PLANE_COLS, |x, y| {
        let t = s0(t, x, y);
        (hazy(x, y) - airlight * (1.0 - t)) / t
    });
    let plane = |img| region_mean(PLANE_COLS, |x, y| s0(img, x, y));
    let (d, c, h) = (plane(dehazed), plane(clear), region_mean(PLANE_COLS, hazy));
    let rel = |a: f64| (a - recovered).abs() / recovered;
    assert!(
        rel(d) < 0.05,
        "dehazed {d} vs (H − A (1 − t)) / t = {recovered}"
    );
    assert!(
        rel(c) > 0.2 && rel(h) > 0.1,
        "clear {c}, hazy {h}: the scene must tell them apart"
    );
}

#[test]
fn dehazed_plane_matches_the_hazy_view_from_next_to_it() {
    // The dehazed pixel is the light leaving the surface, lit through the haze: what a
    // camera 0.05 units in front of the plane sees in the hazy scene (optical depth 0.0055:
    // attenuation and airlight there change S0 by < 0.2 %). Tolerance 1.5 %: both means
    // scatter by 0.2 % over seeds (256 spp), and the plane's disturbance of the haze
    // lighting in front of it adds at most 0.3 %.
    let out = run_dehazed(&haze_slab_scene(8));
    let dehazed = out.dehazed.as_ref().expect("dehazed");
    let d = region_mean(PLANE_COLS, |x, y| f64::from(dehazed.pixel(x, y)[0]));
    let mut near = haze_slab_scene(9);
    near.camera.position = V3::new(-0.157, 0.0, -8.95);
    near.camera.look_at = V3::new(-0.157, 0.0, -9.0);
    let near = run(&near, None);
    let (n, _) = mean(near.stokes.pixels().iter().map(|p| f64::from(p[0])));
    assert!(
        (d - n).abs() < 0.015 * n,
        "dehazed {d} vs hazy from next to the plane {n}"
    );
}
