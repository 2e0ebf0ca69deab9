//! Physical validation of the renderer on scenes with known answers.
//! Run with `cargo test -p polar-render --release`.

use polar_bsdf::{
    ConductorParams, DielectricParams, LambertianParams, Material, PlasticParams, Roughness,
    Texture,
};
use polar_optics::stokes::{aolp, dolp};
use polar_render::{
    Camera, Emission, Geometry, Light, RenderOptions, RenderOutput, Scene, Shape, render,
};
use std::f64::consts::PI;

mod common;
use common::{V3, camera};

fn sphere_scene(cam: Camera, material: Material, env: f64) -> Scene {
    let mut scene = Scene::new(cam);
    let m = scene.add_material("sphere", material);
    scene.shapes.push(Shape::new(
        Geometry::Sphere {
            center: V3::zeros(),
            radius: 1.0,
        },
        m,
    ));
    scene
        .lights
        .push(Light::Environment(Emission::unpolarized(env)));
    scene
}

fn run(scene: &Scene) -> RenderOutput {
    render(scene, &RenderOptions::default(), &|_, _| {}).expect("render")
}

/// Camera ray through image point `(x, y)` (pixel units) of a camera on +z looking at the origin.
fn ray_dir(cam: &Camera, x: f64, y: f64) -> V3 {
    let t = (0.5 * cam.fov_deg.to_radians()).tan();
    let sx = (2.0 * x / cam.width as f64 - 1.0) * t;
    let sy = (1.0 - 2.0 * y / cam.height as f64) * t * cam.height as f64 / cam.width as f64;
    V3::new(sx, sy, -1.0).normalize()
}

/// Cosine of incidence where the ray from `o` along `d` meets the unit sphere at the origin.
fn sphere_cos(o: &V3, d: &V3) -> Option<f64> {
    let b = o.dot(d);
    let disc = b * b - (o.norm_squared() - 1.0);
    (disc > 0.0).then(|| {
        let p = o + d * (-b - disc.sqrt());
        -d.dot(&p)
    })
}

/// Cosines of incidence on the unit sphere of an `n × n` grid of sub-pixel rays of
/// pixel `(x, y)` (camera `cam`), if every ray meets the sphere at a cosine of at
/// least 0.3 (steeper footprints vary too much within the pixel to predict).
fn footprint_cosines(cam: &Camera, x: usize, y: usize, n: usize) -> Option<Vec<f64>> {
    (0..n * n)
        .map(|k| {
            let (sx, sy) = (
                (0.5 + (k % n) as f64) / n as f64,
                (0.5 + (k / n) as f64) / n as f64,
            );
            sphere_cos(&cam.position, &ray_dir(cam, x as f64 + sx, y as f64 + sy))
                .filter(|c| *c >= 0.3)
        })
        .collect()
}

#[test]
fn white_furnace_lambertian_sphere_is_invisible() {
    // Albedo-1 Lambertian sphere in a uniform environment of radiance 1: every pixel has S0 = 1.
    // Light sampling draws the environment with the Lambertian's own cosine-weighted sampling, so
    // both estimators (MIS weight 1/2 each) return exactly 1/2 on the convex sphere and the only
    // error is float rounding: tolerance 1e-6 (f32 output).
    let mat = Material::Lambertian(LambertianParams {
        albedo: Texture::Constant(1.0),
    });
    let mut scene = sphere_scene(camera(4.0, 40.0, 24), mat, 1.0);
    scene.settings.spp = 4;
    let out = run(&scene);
    assert_eq!(out.model, polar_render::Polarization::None);
    for p in out.stokes.pixels() {
        assert!((f64::from(p[0]) - 1.0).abs() < 1e-6, "S0 = {}", p[0]);
        assert_eq!(&p[1..], &[0.0; 3]);
    }
}

#[test]
fn specular_sphere_dolp_and_aolp_follow_fresnel() {
    // A black-backed smooth plastic (albedo 0, n = 1.5) reflects only the specular Fresnel part of a
    // uniform unpolarized environment: DoLP = |Rs - Rp| / (Rs + Rp) at the viewing angle, and the
    // light is s-polarized, i.e. AoLP is tangential to the sphere's outline.
    let mat = Material::Plastic(PlasticParams {
        albedo: Texture::Constant(0.0),
        ior: 1.5,
        ext_ior: 1.0,
        roughness: Roughness::Isotropic(0.0),
    });
    let cam = camera(20.0, 6.5, 64);
    let mut scene = sphere_scene(cam.clone(), mat, 1.0);
    scene.settings.spp = 64;
    let out = run(&scene);
    assert_eq!(out.model, polar_render::Polarization::Linear);
    let (mut worst_dolp, mut worst_aolp, mut max_dolp, mut checked) =
        (0.0_f64, 0.0_f64, 0.0_f64, 0);
    let (mut sum_err, mut sum_abs) = (0.0, 0.0);
    for y in 0..cam.height {
        for x in 0..cam.width {
            // Prediction: mean Stokes over an 8x8 grid of sub-pixel rays; pixels whose footprint
            // is not wholly on the sphere are skipped.
            let Some(cosines) = footprint_cosines(&cam, x, y, 8) else {
                continue;
            };
            let s = out.stokes.pixel(x, y).map(f64::from);
            let mut pred = [0.0; 2];
            for c in &cosines {
                let (rs, rp) =
                    polar_optics::fresnel_amplitudes(*c, num_complex::Complex64::new(1.5, 0.0))
                        .reflectance();
                pred[0] += 0.5 * (rs + rp) / 64.0;
                pred[1] += 0.5 * (rs - rp) / 64.0;
            }
            let predicted = pred[1].abs() / pred[0];
            let got = dolp(s[0], s[1], s[2]);
            worst_dolp = worst_dolp.max((got - predicted).abs());
            sum_err += got - predicted;
            sum_abs += (got - predicted).abs();
            max_dolp = max_dolp.max(got);
            // Tangential direction in the image: perpendicular to the radius from the image centre.
            let (dx, dy) = (x as f64 + 0.5 - 32.0, 32.0 - (y as f64 + 0.5));
            if got > 0.1 && dx.hypot(dy) > 6.0 {
                let tangential = (dy.atan2(dx) + 0.5 * PI).rem_euclid(PI);
                let diff =
                    (aolp(s[0], s[1], s[2]) - tangential + 0.5 * PI).rem_euclid(PI) - 0.5 * PI;
                worst_aolp = worst_aolp.max(diff.abs());
            }
            checked += 1;
        }
    }
    assert!(checked > 1200, "only {checked} sphere pixels");
    // 64 jittered samples against the 64-ray grid mean. Measured: mean |dDoLP| 0.0017, mean signed
    // -0.0003, worst 0.018 (a steep pixel near cos = 0.3). The mean bounds catch any bias
    // (e.g. a wrong Fresnel sign or frame) at a quarter of the smallest plausible error.
    let (mean_err, mean_abs) = (sum_err / checked as f64, sum_abs / checked as f64);
    assert!(
        mean_err.abs() < 0.001 && mean_abs < 0.004 && worst_dolp < 0.03,
        "dDoLP mean {mean_err} mean abs {mean_abs} worst {worst_dolp}"
    );
    // Where the pixel is more than 6 px from the centre its footprint spans under 10 deg of polar
    // angle; the per-pixel frame is tilted by under 0.1 deg at this 6.5 deg fov. Measured worst 0.6 deg.
    assert!(
        worst_aolp.to_degrees() < 1.0,
        "worst AoLP error {} deg",
        worst_aolp.to_degrees()
    );
    // Brewster's angle (56.3 deg) lies on the sphere: DoLP reaches ~1 there.
    assert!(max_dolp > 0.98, "max DoLP {max_dolp}");
}

/// S0 of single camera samples (one per pixel, seeds 0..4) through a lossless
/// glass sphere (n = 1.5) in a uniform unpolarized environment of radiance 1, seen
/// from distance 4 with field of view `fov_deg` on `size`² pixels, as pairs: the
/// sample with paths of up to `max_depth` vertices, and the same sample (same
/// seed, so the same jitter) with `max_depth` 1, which is exactly the front
/// reflection's share `R00` (both outcomes of the camera vertex's choice are
/// traced; the transmitted path is cut at the back of the sphere). Only the camera
/// vertex splits (`split_depth` 1), so that the transmitted path is one path.
fn glass_sphere_samples(fov_deg: f64, size: usize, max_depth: u32) -> Vec<(f64, f64)> {
    let mat = Material::Dielectric(DielectricParams {
        ior: 1.5,
        ext_ior: 1.0,
        roughness: Roughness::Isotropic(0.0),
    });
    let mut scene = sphere_scene(camera(4.0, fov_deg, size), mat, 1.0);
    scene.settings.spp = 1;
    scene.settings.split_depth = 1;
    let s0 = |scene: &Scene| {
        let out = run(scene);
        assert_eq!(out.model, polar_render::Polarization::Full);
        out.stokes
            .pixels()
            .iter()
            .map(|p| f64::from(p[0]))
            .collect::<Vec<_>>()
    };
    (0..4)
        .flat_map(|seed| {
            scene.settings.seed = seed;
            scene.settings.max_depth = max_depth;
            let full = s0(&scene);
            scene.settings.max_depth = 1;
            full.into_iter().zip(s0(&scene)).collect::<Vec<_>>()
        })
        .collect()
}

/// What the transmitted path of each sample of [`glass_sphere_samples`] brings,
/// relative to its share `1 − R00`: `(S0 − R00) / (1 − R00)`. Pixels that see
/// the environment (`R00 = 1`) or where the sphere reflects more than 90 % are
/// left out (there the f32 output's rounding, 1e-7 of S0, would be amplified
/// beyond 1e-6).
fn transmitted_path_s0(fov_deg: f64, size: usize, max_depth: u32) -> Vec<f64> {
    glass_sphere_samples(fov_deg, size, max_depth)
        .into_iter()
        .filter(|&(_, r)| r < 0.9)
        .map(|(s, r)| (s - r) / (1.0 - r))
        .collect()
}

#[test]
fn glass_sphere_in_a_constant_environment_has_no_lobe_choice_variance() {
    // Every path that escapes the lossless sphere brings S0 = 1 exactly when the
    // camera vertex traces both its reflection (R00) and its transmission (1 − R00)
    // and each later Fresnel lobe is chosen for the S0 it brings to the camera
    // (polar-bsdf `with_importance`), however polarized the path is: the transmitted
    // path brings 1 − R00 exactly. max_depth 4 stays below Russian roulette, so it
    // brings that or, still inside at the depth limit (near the outline), 0.
    // Choosing by unpolarized reflectance gave neither on 81% of these pixels
    // (measured with 48 seeds, before the split); f32 output: 1e-6 after the division.
    let s0 = transmitted_path_s0(25.0, 16, 4);
    for v in &s0 {
        assert!(v.abs() < 1e-6 || (v - 1.0).abs() < 1e-6, "S0 = {v}");
    }
    let escaped = s0.iter().filter(|&&v| v > 0.5).count();
    assert!(
        escaped * 100 > 95 * s0.len(),
        "only {escaped} of {} paths escaped",
        s0.len()
    );
}

#[test]
fn glass_front_reflection_is_traced_not_drawn() {
    // With max_depth 1 a camera sample through the sphere's front brings its
    // reflection alone: R00 of the incidence angle at the jittered point, the same
    // for any seed up to the angle's spread over the pixel. Drawing reflection or
    // transmission instead would give 1 or 0. A pixel spans 1.6 deg of view, under
    // 9 deg of incidence where R00 < 0.05 (incidence below 45 deg), over which R00
    // changes by under 0.01 (0.040 at normal incidence, 0.050 at 45 deg).
    let r: Vec<f64> = glass_sphere_samples(25.0, 16, 1)
        .into_iter()
        .map(|(_, r)| r)
        .collect();
    let (a, b) = r.split_at(256); // seeds 0 and 1 of the 16 x 16 image
    let front: Vec<f64> = a
        .iter()
        .zip(b)
        .filter(|(ra, rb)| ra.max(**rb) < 0.05)
        .map(|(ra, rb)| (ra - rb).abs())
        .collect();
    assert!(front.len() > 100, "only {} front pixels", front.len());
    let worst = front.iter().copied().fold(0.0, f64::max);
    assert!(worst < 0.01, "R00 differs by {worst} between two seeds");
    let lowest = r.iter().copied().fold(1.0, f64::min);
    assert!(
        lowest > 0.04 - 1e-6,
        "S0 {lowest} below R00 at normal incidence"
    );
}

#[test]
fn russian_roulette_inside_glass_weighs_the_throughput_by_eta_squared() {
    // The sphere with Russian roulette on (from depth 5): inside glass the
    // throughput's S0 is 1/n² of what an escaping path brings, so the survival
    // probability must be T00·η² (clamped to 0.95), not T00; the transmitted path
    // of a split camera vertex carries its share 1 − R00, divided out for the
    // survival. Then every transmitted path brings 0 (cut at max_depth or killed)
    // or 0.95^-k after k roulette survivals, relative to its share; with T00
    // alone a survivor inside the glass would weigh n² = 2.25 instead (S0 = 2.368
    // seen), and without the share divided out it would survive less and
    // weigh more. The outline's near-total internal reflection gives the deep
    // paths (at least 50 asked; 144 measured over the 4 seeds). f32 output: 1e-5.
    let survivals = |s0: f64| (0..=10).find(|&k| (s0 * 0.95f64.powi(k) - 1.0).abs() < 1e-5);
    let mut deep = 0;
    for v in transmitted_path_s0(31.0, 160, 15) {
        let k = survivals(v);
        assert!(v.abs() < 1e-5 || k.is_some(), "S0 = {v}");
        deep += usize::from(k.is_some_and(|k| k > 0));
    }
    assert!(deep >= 50, "only {deep} paths survived a roulette");
}

/// Directional reflectance of `material` for unpolarized light from every direction,
/// seen at `cos θo`: `(A00, |(A10, A20)|)` with `A = ∫ f cos θi dωi`, by the midpoint
/// rule on a `n × n` grid in `(cos θi, φi)` (the BSDF's evaluation only, none of its sampling).
fn directional_reflectance(material: &Material, cos_o: f64, n: usize) -> (f64, f64) {
    let bsdf = material.bsdf([0.0, 0.0]);
    let wo = V3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
    let cell = 2.0 * PI / (n * n) as f64;
    let mut a = [0.0; 3];
    for i in 0..n {
        let mu = (i as f64 + 0.5) / n as f64;
        let r = (1.0 - mu * mu).sqrt();
        for j in 0..n {
            let phi = 2.0 * PI * (j as f64 + 0.5) / n as f64;
            let f = bsdf.eval(&wo, &V3::new(r * phi.cos(), r * phi.sin(), mu));
            for (k, ak) in a.iter_mut().enumerate() {
                *ak += f[(k, 0)] * cell;
            }
        }
    }
    (a[0], a[1].hypot(a[2]))
}

#[test]
fn constant_environment_on_smooth_lobes_matches_quadrature() {
    // A rough conductor and a rough plastic sphere in a uniform unpolarized environment of
    // radiance 1 (no other light): each pixel's S0 and DoLP are those of the directional
    // reflectance at its viewing angle, integrated here from the BSDF's evaluation. The renderer
    // samples the environment with the BSDF's own distribution and weighs both samples by MIS, so
    // this checks that pairing: with a weight of 1 instead of 1/2 for the light sample S0 is 1.5x
    // (seen: mean +50 %); DoLP checks the polarized part of both samples' weights. Single
    // scattering only (max_depth 1): the sphere is convex.
    let rough = |a: f64| Roughness::Isotropic(a);
    let materials = [
        Material::Conductor(ConductorParams {
            metal: None,
            n: Some(0.2),
            k: Some(3.0),
            roughness: rough(0.2),
        }),
        Material::Plastic(PlasticParams {
            albedo: Texture::Constant(0.5),
            ior: 1.5,
            ext_ior: 1.0,
            roughness: rough(0.1),
        }),
    ];
    let cam = camera(20.0, 6.5, 32);
    for material in materials {
        // The reflectance on 24 viewing angles, interpolated linearly in cos θo.
        let cos_table: Vec<f64> = (0..24).map(|i| 0.25 + 0.75 * i as f64 / 23.0).collect();
        let table: Vec<(f64, f64)> = cos_table
            .iter()
            .map(|&c| directional_reflectance(&material, c, 800))
            .collect();
        let predict = |c: f64| {
            let t = ((c - 0.25) / 0.75 * 23.0).clamp(0.0, 22.999);
            let (i, f) = (t as usize, t.fract());
            let (a, b) = (table[i], table[i + 1]);
            (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1))
        };
        let mut scene = sphere_scene(cam.clone(), material.clone(), 1.0);
        scene.settings.spp = 256;
        scene.settings.max_depth = 1;
        let out = run(&scene);
        let (mut checked, mut sum_rel, mut worst_rel, mut sum_dolp) = (0, 0.0, 0.0_f64, 0.0);
        for y in 0..cam.height {
            for x in 0..cam.width {
                // The pixel's prediction: the mean over a 4x4 grid of sub-pixel rays, all on the
                // sphere with cos θo >= 0.3.
                let Some(cosines) = footprint_cosines(&cam, x, y, 4) else {
                    continue;
                };
                let (s0, pol) = cosines.iter().fold((0.0, 0.0), |(s, p), &c| {
                    let (a, b) = predict(c);
                    (s + a / 16.0, p + b / 16.0)
                });
                let s = out.stokes.pixel(x, y).map(f64::from);
                let rel = (s[0] - s0) / s0;
                sum_rel += rel;
                worst_rel = worst_rel.max(rel.abs());
                sum_dolp += (dolp(s[0], s[1], s[2]) - pol / s0).abs();
                checked += 1;
            }
        }
        assert!(checked > 400, "only {checked} sphere pixels");
        // 256 spp against a 4x4-ray footprint mean and an 800² quadrature. Measured (conductor,
        // plastic): mean relative S0 difference 6e-5, 3e-4; worst pixel 0.003, 0.016 (plastic's
        // diffuse noise near cos = 0.3); mean |dDoLP| 7e-5, 6e-4. The bounds are 5-10x those.
        let (mean_rel, mean_dolp) = (sum_rel / checked as f64, sum_dolp / checked as f64);
        assert!(
            mean_rel.abs() < 0.003 && worst_rel < 0.03 && mean_dolp < 0.003,
            "{material:?}: S0 mean rel {mean_rel} worst {worst_rel}, mean |dDoLP| {mean_dolp}"
        );
    }
}

#[test]
fn glass_sphere_is_traced_exactly_before_russian_roulette() {
    // Every smooth-glass vertex above split_depth (default 5) traces both outcomes, so with
    // max_depth 5 a camera ray through a lossless sphere (n = 1.5) in a uniform unpolarized
    // environment brings exactly its front reflection plus what leaves after k = 0..3 internal
    // reflections. Inside a sphere every internal incidence angle is the refraction angle and
    // every plane of incidence the same, so s and p light do not mix: with R the external
    // reflectance at the incidence angle (the internal one is equal), each brings
    // R + (1 - R)^2 (1 + R + R^2 + R^3), and S0 and DoLP follow from R_s and R_p. That checks
    // the shares of the split paths and the Mueller products and frame rotations along them
    // (the exit polarization is p, the reflection's s).
    let mat = Material::Dielectric(DielectricParams {
        ior: 1.5,
        ext_ior: 1.0,
        roughness: Roughness::Isotropic(0.0),
    });
    let cam = camera(20.0, 6.5, 32);
    let mut scene = sphere_scene(cam.clone(), mat, 1.0);
    scene.settings.spp = 16;
    scene.settings.max_depth = 5;
    let out = run(&scene);
    let brings = |r: f64| r + (1.0 - r).powi(2) * (1.0 + r + r * r + r * r * r);
    let (mut checked, mut worst_s0, mut worst_dolp) = (0, 0.0_f64, 0.0_f64);
    for y in 0..cam.height {
        for x in 0..cam.width {
            // The pixel's prediction: the mean over an 8x8 grid of sub-pixel rays, all on the
            // sphere with cos >= 0.3.
            let Some(cosines) = footprint_cosines(&cam, x, y, 8) else {
                continue;
            };
            let (mut s, mut p) = (0.0, 0.0);
            for c in &cosines {
                let (rs, rp) =
                    polar_optics::fresnel_amplitudes(*c, num_complex::Complex64::new(1.5, 0.0))
                        .reflectance();
                s += 0.5 * brings(rs) / 64.0;
                p += 0.5 * brings(rp) / 64.0;
            }
            let got = out.stokes.pixel(x, y).map(f64::from);
            worst_s0 = worst_s0.max((got[0] - (s + p)).abs());
            worst_dolp =
                worst_dolp.max((dolp(got[0], got[1], got[2]) - (s - p).abs() / (s + p)).abs());
            checked += 1;
        }
    }
    assert!(checked > 400, "only {checked} sphere pixels");
    // No noise but the pixel footprint: 16 Sobol-jittered rays against the 64-ray grid mean of a
    // smooth function. Measured: worst |dS0| 4.9e-5, worst |dDoLP| 5.0e-5; with split_depth 4
    // (the last internal vertex's choice drawn) 1.7e-3 and 1.7e-3.
    assert!(
        worst_s0 < 2e-4 && worst_dolp < 2e-4,
        "worst |dS0| {worst_s0}, worst |dDoLP| {worst_dolp}"
    );
}
