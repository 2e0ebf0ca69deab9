//! Speed-up of "model only what a scene needs": the same scene rendered with the
//! cheapest exact transport and with the more expensive ones.
//! `cargo bench -p polar-render --bench models`

use criterion::{Criterion, criterion_group, criterion_main};
use polar_bsdf::{LambertianParams, Material, PlasticParams, Roughness, Texture};
use polar_render::{
    Camera, Emission, Geometry, Light, Polarization, RenderOptions, Scene, Shape, render,
};

type V3 = nalgebra::Vector3<f64>;

/// A sphere on a floor under an environment and a sun, 64x64 at 4 spp.
fn scene(material: Material) -> Scene {
    let camera = Camera {
        position: V3::new(0.0, 1.0, 5.0),
        look_at: V3::zeros(),
        up: V3::y(),
        fov_deg: 40.0,
        width: 64,
        height: 64,
    };
    let mut scene = Scene::new(camera);
    scene.settings.spp = 4;
    let m = scene.add_material("object", material);
    let floor = scene.add_material(
        "floor",
        Material::Lambertian(LambertianParams {
            albedo: Texture::Constant(0.5),
        }),
    );
    scene.shapes.push(Shape::new(
        Geometry::Sphere {
            center: V3::zeros(),
            radius: 1.0,
        },
        m,
    ));
    let plane = polar_render::shapes::rectangle().transformed(&polar_render::shapes::transform(
        [0.0, -1.0, 0.0],
        [-90.0, 0.0, 0.0],
        [5.0; 3],
    ));
    scene.shapes.push(Shape {
        background: true,
        ..Shape::new(Geometry::Mesh(plane), floor)
    });
    scene
        .lights
        .push(Light::Environment(Emission::unpolarized(0.5)));
    scene.lights.push(Light::Sun {
        direction: V3::new(1.0, 1.0, 1.0),
        emission: Emission::unpolarized(4.0),
    });
    scene
}

fn bench(c: &mut Criterion) {
    let lambert = scene(Material::Lambertian(LambertianParams {
        albedo: Texture::Constant(0.8),
    }));
    let plastic = scene(Material::Plastic(PlasticParams {
        albedo: Texture::Constant(0.5),
        ior: 1.5,
        ext_ior: 1.0,
        roughness: Roughness::Isotropic(0.1),
    }));
    let mut group = c.benchmark_group("models");
    group.sample_size(10);
    let cases = [
        ("lambertian/none", &lambert, Polarization::None),
        ("lambertian/linear", &lambert, Polarization::Linear),
        ("lambertian/full", &lambert, Polarization::Full),
        ("plastic/linear", &plastic, Polarization::Linear),
        ("plastic/full", &plastic, Polarization::Full),
    ];
    for (name, scene, model) in cases {
        let opts = RenderOptions {
            force_model: Some(model),
            ..Default::default()
        };
        group.bench_function(name, |b| {
            b.iter(|| render(scene, &opts, &|_, _| {}).expect("render"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
