//! Transport-model equivalence, determinism across thread counts and the
//! ground-truth buffers. Run with `cargo test -p polar-render --release`.

use polar_bsdf::{DielectricParams, LambertianParams, Material, PlasticParams, Roughness, Texture};
use polar_render::{
    Camera, Emission, Geometry, Light, Polarization, RenderOptions, RenderOutput, Scene, Shape,
    render,
};

mod common;
use common::{V3, bits, run, run_on_threads, truth};

fn lambertian(albedo: f64) -> Material {
    Material::Lambertian(LambertianParams {
        albedo: Texture::Constant(albedo),
    })
}

/// A sphere on a floor, lit by an environment, a sun and a small area light; 32x24 pixels.
fn scene(object: Material) -> Scene {
    let camera = Camera {
        position: V3::new(0.0, 1.0, 5.0),
        look_at: V3::zeros(),
        up: V3::y(),
        fov_deg: 45.0,
        width: 32,
        height: 24,
    };
    let mut scene = Scene::new(camera);
    scene.settings.spp = 8;
    scene.settings.seed = 7;
    let m = scene.add_material("object", object);
    let floor = scene.add_material("floor", lambertian(0.5));
    scene.shapes.push(Shape::new(
        Geometry::Sphere {
            center: V3::zeros(),
            radius: 1.0,
        },
        m,
    ));
    let place = |t, r, s| polar_render::shapes::transform(t, r, s);
    let plane = polar_render::shapes::rectangle().transformed(&place(
        [0.0, -1.0, 0.0],
        [-90.0, 0.0, 0.0],
        [4.0; 3],
    ));
    scene.shapes.push(Shape {
        background: true,
        ..Shape::new(Geometry::Mesh(plane), floor)
    });
    let lamp = polar_render::shapes::rectangle().transformed(&place(
        [0.0, 3.0, 0.0],
        [90.0, 0.0, 0.0],
        [0.5; 3],
    ));
    scene.shapes.push(Shape {
        geometry: Geometry::Mesh(lamp),
        material: None,
        emission: Some(Emission::unpolarized(10.0)),
        background: true,
    });
    scene
        .lights
        .push(Light::Environment(Emission::unpolarized(0.3)));
    scene.lights.push(Light::Sun {
        direction: V3::new(1.0, 1.0, 1.0),
        emission: Emission::unpolarized(2.0),
    });
    scene
}

/// Largest difference over all pixels and the first `channels` channels, relative to max(1, |value|).
fn max_rel_diff(a: &RenderOutput, b: &RenderOutput, channels: usize) -> f64 {
    let pairs = a.stokes.pixels().iter().zip(b.stokes.pixels());
    pairs
        .flat_map(|(p, q)| {
            (0..channels)
                .map(move |c| f64::from((p[c] - q[c]).abs()) / f64::from(p[c].abs().max(1.0)))
        })
        .fold(0.0, f64::max)
}

#[test]
fn scalar_transport_matches_full_on_an_unpolarizing_scene() {
    let s = scene(lambertian(0.8));
    let cheap = run(&s, None);
    assert_eq!(cheap.model, Polarization::None);
    let full = run(&s, Some(Polarization::Full));
    // Same seed, same decisions: only float rounding of the zero blocks can differ (f32 output).
    assert!(
        max_rel_diff(&cheap, &full, 4) < 1e-6,
        "{}",
        max_rel_diff(&cheap, &full, 4)
    );
    assert!(
        full.stokes
            .pixels()
            .iter()
            .all(|p| p[1] == 0.0 && p[2] == 0.0 && p[3] == 0.0)
    );
    assert!(
        cheap.stokes.pixels().iter().any(|p| p[0] > 0.1),
        "image is black"
    );
}

#[test]
fn linear_transport_matches_full_on_a_linearly_polarizing_scene() {
    let plastic = Material::Plastic(PlasticParams {
        albedo: Texture::Constant(0.4),
        ior: 1.5,
        ext_ior: 1.0,
        roughness: Roughness::Isotropic(0.15),
    });
    let s = scene(plastic);
    let cheap = run(&s, None);
    assert_eq!(cheap.model, Polarization::Linear);
    let full = run(&s, Some(Polarization::Full));
    assert!(
        max_rel_diff(&cheap, &full, 4) < 1e-5,
        "{}",
        max_rel_diff(&cheap, &full, 4)
    );
    // The scene does polarize (so the comparison is not vacuous) and never circularly.
    assert!(
        full.stokes
            .pixels()
            .iter()
            .any(|p| p[1].hypot(p[2]) > 0.02 * p[0])
    );
    assert!(
        full.stokes
            .pixels()
            .iter()
            .all(|p| p[3].abs() <= 1e-6 * p[0].max(1.0))
    );
}

#[test]
fn cheaper_model_than_needed_is_refused() {
    let glass = Material::Dielectric(DielectricParams {
        ior: 1.5,
        ext_ior: 1.0,
        roughness: Roughness::Isotropic(0.0),
    });
    let err = render(
        &scene(glass),
        &RenderOptions {
            force_model: Some(Polarization::Linear),
            ..Default::default()
        },
        &|_, _| {},
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            polar_render::Error::ModelTooCheap {
                required: Polarization::Full,
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn output_is_bit_identical_across_thread_counts() {
    let plastic = Material::Plastic(PlasticParams {
        albedo: Texture::Constant(0.4),
        ior: 1.5,
        ext_ior: 1.0,
        roughness: Roughness::Isotropic(0.15),
    });
    let s = scene(plastic);
    let one = run_on_threads(&s, 1);
    assert_eq!(bits(&one), bits(&run_on_threads(&s, 3)));
    let mut other_seed = s.clone();
    other_seed.settings.seed += 1;
    assert_ne!(
        bits(&one),
        bits(&run(&other_seed, None)),
        "the seed must matter"
    );
}

#[test]
fn ground_truth_buffers_follow_the_conventions() {
    let glass = Material::Dielectric(DielectricParams {
        ior: 1.5,
        ext_ior: 1.0,
        roughness: Roughness::Isotropic(0.0),
    });
    let mut s = scene(glass);
    s.camera.position = V3::new(0.0, 0.0, 5.0);
    s.camera.width = 33;
    s.camera.height = 33;
    s.settings.spp = 1;
    let out = run(&s, None);
    let gt = truth(&out);
    // Centre pixel: the sphere's front point (0, 0, 1), facing the camera, 4 units along -z.
    let n = gt.normal.pixel(16, 16);
    assert!(
        (n[0].abs() + n[1].abs()) < 1e-6 && (n[2] - 1.0).abs() < 1e-6,
        "{n:?}"
    );
    assert!((gt.depth.pixel(16, 16)[0] - 4.0).abs() < 1e-5);
    assert_eq!(gt.material.pixel(16, 16)[0], 3);
    assert_eq!(gt.transparent.pixel(16, 16)[0], 255);
    // Top corner: sky (no surface).
    assert_eq!(gt.normal.pixel(0, 0), &[0.0; 3]);
    assert_eq!(gt.depth.pixel(0, 0)[0], 0.0);
    assert_eq!(gt.material.pixel(0, 0)[0], 0);
    // Bottom row: the floor has normal and depth but is background (label 0).
    let floor = gt.normal.pixel(16, 32);
    assert!(floor[1] > 0.9, "{floor:?}");
    assert!(gt.depth.pixel(16, 32)[0] > 0.0);
    assert_eq!(gt.material.pixel(16, 32)[0], 0);
    // Normals on the sphere point right on the right side and up at the top (camera frame).
    assert!(gt.normal.pixel(24, 16)[0] > 0.5 && gt.normal.pixel(16, 8)[1] > 0.5);
    for p in gt.normal.pixels() {
        let len = p.iter().map(|c| c * c).sum::<f32>().sqrt();
        assert!(len == 0.0 || (len - 1.0).abs() < 1e-5);
    }
}
