//! From sample parameters to a `polar_render::Scene`: camera on a sphere around the objects,
//! a sun plus a uniform sky, a ground plane (and a textured backdrop for glass), objects in a row;
//! for haze, a low camera looking over objects spread in depth through a slab of haze under a
//! polarized Rayleigh sky.

use polar_bsdf::{
    Checkerboard, ConductorParams, DielectricParams, LambertianParams, Material, Metal,
    PlasticParams, Roughness, Texture,
};
use polar_optics::scatter::PhaseFunction;
use polar_optics::sky::RayleighSky;
use polar_render::Vec3;
use polar_render::shapes::{cube, rectangle, superquadric, torus, transform};
use polar_render::{Camera, Emission, Geometry, Light, Medium, Scene, Shape};

use crate::mesh::{blob, extrusion};
use crate::params::{HazeParams, MaterialParams, ObjectParams, SampleParams, ShapeParams};
use crate::suite::FamilyKind;

/// Tessellation of curved meshes: 48 segments keep the chord error below 0.1 % of the radius.
const SEGMENTS: u32 = 48;
/// Half-size of the ground and backdrop planes, m.
const PLANE: f64 = 30.0;
/// Path length limit: glass needs entry, exit and the backdrop bounce.
const MAX_DEPTH: u32 = 12;

/// Unit vector at `elevation` above the ground (y up) and `azimuth` around y from +z, degrees.
fn direction(elevation_deg: f64, azimuth_deg: f64) -> Vec3 {
    let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    Vec3::new(a.sin() * e.cos(), e.sin(), a.cos() * e.cos())
}

/// The camera: on a sphere around the objects, or for haze at eye height (the size of the
/// nearest object) looking toward the far end, pitched down by `elevation_deg`.
fn camera(p: &SampleParams) -> Camera {
    let (position, look_at) = match &p.haze {
        Some(h) => {
            let eye = Vec3::new(0.0, 0.15 * p.camera.distance * tan_half(p), 0.0);
            (
                eye,
                eye + h.scene_depth * direction(-p.camera.elevation_deg, 180.0),
            )
        }
        None => {
            let height = p.objects.iter().map(|o| o.size).fold(0.5, f64::max);
            let target = Vec3::new(0.0, height, 0.0);
            let position = target + p.camera.distance * direction(p.camera.elevation_deg, 0.0);
            (position, target)
        }
    };
    Camera {
        position,
        look_at,
        up: Vec3::y(),
        fov_deg: p.camera.fov_deg,
        width: p.width as usize,
        height: p.height as usize,
    }
}

fn tan_half(p: &SampleParams) -> f64 {
    (0.5 * p.camera.fov_deg.to_radians()).tan()
}

/// Haze fills a box three scene depths wide and deep around the camera and half a scene
/// depth high, so that every view ray crosses at least one scene depth of it.
fn haze_medium(h: &HazeParams) -> Medium {
    let d = h.scene_depth;
    Medium {
        bounds_min: Vec3::new(-3.0 * d, -0.01 * d, -3.0 * d),
        bounds_max: Vec3::new(3.0 * d, 0.5 * d, 3.0 * d),
        sigma_s: h.albedo * h.extinction,
        sigma_a: (1.0 - h.albedo) * h.extinction,
        phase: PhaseFunction::HenyeyGreenstein {
            g: h.asymmetry,
            depolarization: h.depolarization,
        },
        density: None,
    }
}

/// Vertical optical depth of the Rayleigh sky over haze: the Earth's at 550 nm.
const SKY_OPTICAL_DEPTH: f64 = 0.1;

/// A sun and a uniform sky (`ambient`); for haze, outdoors, the polarized single-scattering
/// Rayleigh sky with its own (attenuated) sun instead.
fn lights(p: &SampleParams) -> Vec<Light> {
    let sun = direction(p.light.elevation_deg, p.light.azimuth_deg);
    if p.haze.is_some() {
        let sky = RayleighSky {
            sun_direction: sun,
            up: Vec3::y(),
            optical_depth: SKY_OPTICAL_DEPTH,
            sun_irradiance: p.light.intensity,
        };
        return vec![Light::Sky(sky)];
    }
    vec![
        Light::Environment(Emission::unpolarized(p.light.ambient)),
        Light::Sun {
            direction: sun,
            emission: Emission::unpolarized(p.light.intensity),
        },
    ]
}

/// Builds the scene of one sample.
pub fn build_scene(p: &SampleParams) -> Scene {
    let mut scene = Scene::new(camera(p));
    scene.settings.spp = p.spp;
    scene.settings.seed = p.seed;
    scene.settings.max_depth = MAX_DEPTH;
    scene.lights.extend(lights(p));
    add_ground(&mut scene, p);
    scene.medium = p.haze.as_ref().map(haze_medium);
    for (i, o) in p.objects.iter().enumerate() {
        let m = scene.add_material(&format!("object{i}"), material(&o.material));
        scene.shapes.push(Shape::new(geometry(o), m));
    }
    scene
}

fn albedo_texture(p: &SampleParams) -> Texture {
    let b = &p.background;
    if b.pattern == "checker" {
        Texture::Checkerboard(Checkerboard {
            checkerboard: b.albedo,
            scale: b.scale,
        })
    } else {
        Texture::Constant(b.albedo[0])
    }
}

fn add_ground(scene: &mut Scene, p: &SampleParams) {
    let lambert = |albedo| Material::Lambertian(LambertianParams { albedo });
    let ground = scene.add_material("ground", lambert(Texture::Constant(p.background.albedo[0])));
    // The ground reaches past the haze box, whose far walls are then hidden behind it.
    let half = p.haze.as_ref().map_or(PLANE, |h| 4.0 * h.scene_depth);
    let floor = rectangle().transformed(&transform([0.0; 3], [-90.0, 0.0, 0.0], [half; 3]));
    scene.shapes.push(Shape {
        background: true,
        ..Shape::new(Geometry::Mesh(floor), ground)
    });
    if p.kind == FamilyKind::Transparent {
        let back = p.objects.iter().map(|o| o.size).fold(0.5, f64::max) * 2.5;
        let backdrop = scene.add_material("backdrop", lambert(albedo_texture(p)));
        let wall = rectangle().transformed(&transform(
            [0.0, PLANE / 4.0, -back],
            [0.0; 3],
            [PLANE / 4.0; 3],
        ));
        scene.shapes.push(Shape {
            background: true,
            ..Shape::new(Geometry::Mesh(wall), backdrop)
        });
    }
}

fn geometry(o: &ObjectParams) -> Geometry {
    let place = |mesh: polar_render::TriangleMesh, scale: [f64; 3]| {
        Geometry::Mesh(mesh.transformed(&transform(o.position, o.rotation_deg, scale)))
    };
    let s = o.size;
    match &o.shape {
        ShapeParams::Sphere => Geometry::Sphere {
            center: Vec3::from(o.position),
            radius: s,
        },
        ShapeParams::Superquadric { e1, e2 } => {
            // The superquadric spans [-1, 1]^3: its corners reach sqrt(3) for small exponents.
            let reach = 3f64.sqrt().powf(1.0 - e1.min(*e2).min(1.0));
            place(superquadric(*e1, *e2, SEGMENTS), [s / reach; 3])
        }
        ShapeParams::Blob {
            amplitude,
            frequency,
            phase,
        } => place(blob(*amplitude, *frequency, *phase, SEGMENTS), [s; 3]),
        ShapeParams::Torus { minor_ratio } => {
            place(torus(*minor_ratio, SEGMENTS), [s / (1.0 + minor_ratio); 3])
        }
        ShapeParams::Extrusion {
            sides,
            inner_ratio,
            depth,
        } => place(extrusion(*sides, *inner_ratio, *depth), [s; 3]),
        ShapeParams::Slab { thickness } => {
            let t = (0.5 * thickness).min(s);
            place(cube(), [s / 2f64.sqrt(), s / 2f64.sqrt(), t])
        }
    }
}

fn metal(name: &str) -> Metal {
    match name {
        "silver" => Metal::Ag,
        "aluminium" => Metal::Al,
        "copper" => Metal::Cu,
        _ => Metal::Au,
    }
}

fn material(m: &MaterialParams) -> Material {
    let plastic = |albedo, ior, roughness: f64| {
        Material::Plastic(PlasticParams {
            albedo,
            ior,
            ext_ior: 1.0,
            roughness: Roughness::Isotropic(roughness),
        })
    };
    match m {
        MaterialParams::Dielectric {
            ior,
            roughness,
            albedo,
        } => plastic(Texture::Constant(*albedo), *ior, *roughness),
        MaterialParams::Textured {
            ior,
            roughness,
            albedo,
            scale,
        } => plastic(
            Texture::Checkerboard(Checkerboard {
                checkerboard: *albedo,
                scale: *scale,
            }),
            *ior,
            *roughness,
        ),
        MaterialParams::Metal {
            metal: name,
            roughness,
        } => Material::Conductor(ConductorParams {
            metal: Some(metal(name)),
            n: None,
            k: None,
            roughness: Roughness::Isotropic(*roughness),
        }),
        MaterialParams::Glass { ior, roughness } => Material::Dielectric(DielectricParams {
            ior: *ior,
            ext_ior: 1.0,
            roughness: Roughness::Isotropic(*roughness),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::draw_params;
    use crate::suite::{SizeName, Suite};

    #[test]
    fn every_drawn_scene_of_the_standard_suite_validates() {
        let text = include_str!("../../../datasets-synth/suites/standard.toml");
        let suite = Suite::parse(text).unwrap();
        for f in &suite.families {
            for i in 0..60 {
                let p = draw_params(&suite, f, SizeName::Ci, i);
                if let Err(e) = build_scene(&p).validate() {
                    panic!("{} {e}: {:?}", p.id, p.objects);
                }
            }
        }
    }
}
