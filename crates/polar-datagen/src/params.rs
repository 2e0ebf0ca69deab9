//! Seeded parameter sampling: a sample's parameters are a pure function of the suite seed,
//! the family and the sample index, so any thread or shard draws the same sample.

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use serde::{Deserialize, Serialize};

use crate::suite::{Family, FamilyKind, NoiseLevel, SizeName, Suite};

/// SplitMix64 finaliser (Steele et al. 2014): a bijective 64-bit mix used to decorrelate seeds.
fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// FNV-1a hash of a name: stable across platforms and Rust versions (unlike `DefaultHasher`).
fn fnv1a(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01B3)
    })
}

/// The seed of sample `index` of family `family`: splitmix64(splitmix64(seed ^ fnv1a(family)) ^ index).
pub fn sample_seed(suite_seed: u64, family: &str, index: u32) -> u64 {
    splitmix64(splitmix64(suite_seed ^ fnv1a(family)) ^ u64::from(index))
}

/// The id of sample `index` of a family: `<family>-<index, 5 digits>`.
pub fn sample_id(family: &str, index: u32) -> String {
    format!("{family}-{index:05}")
}

/// Everything that determines one sample; recorded verbatim in `meta.json` and the manifest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SampleParams {
    /// Sample id, also its directory name.
    pub id: String,
    /// Family name.
    pub family: String,
    /// Family kind.
    pub kind: FamilyKind,
    /// Index within the family.
    pub index: u32,
    /// Seed of the parameter draw, the renderer and the sensor noise.
    pub seed: u64,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Sensor noise level.
    pub noise: NoiseLevel,
    /// Camera placement.
    pub camera: CameraParams,
    /// Lighting.
    pub light: LightParams,
    /// Ground or backdrop.
    pub background: BackgroundParams,
    /// Objects in the scene.
    pub objects: Vec<ObjectParams>,
    /// The participating medium (haze family only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub haze: Option<HazeParams>,
}

/// A slab of haze over the ground: a homogeneous medium with a Henyey-Greenstein phase
/// matrix with Rayleigh-like polarization, scaled by `1 - depolarization`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HazeParams {
    /// Extinction coefficient sigma_t, 1/m.
    pub extinction: f64,
    /// Single-scattering albedo sigma_s / sigma_t.
    pub albedo: f64,
    /// Henyey-Greenstein asymmetry g.
    pub asymmetry: f64,
    /// Depolarization of the phase matrix, in [0, 1].
    pub depolarization: f64,
    /// Distance of the farthest object from the camera, m.
    pub scene_depth: f64,
}

/// A camera on a sphere around the scene centre, looking at it, up = +y.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraParams {
    /// Distance to the scene centre, m.
    pub distance: f64,
    /// Elevation above the ground plane, degrees.
    pub elevation_deg: f64,
    /// Horizontal field of view, degrees.
    pub fov_deg: f64,
}

/// One directional key light plus a uniform environment.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LightParams {
    /// Elevation of the light direction, degrees.
    pub elevation_deg: f64,
    /// Azimuth of the light direction, degrees (0 = from the camera side).
    pub azimuth_deg: f64,
    /// Radiance scale of the key light.
    pub intensity: f64,
    /// Uniform environment radiance.
    pub ambient: f64,
}

/// The ground plane (opaque families) or backdrop (transparent family).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BackgroundParams {
    /// `plain` or `checker`.
    pub pattern: String,
    /// Pattern repetitions across the plane.
    pub scale: f64,
    /// The two albedos of the pattern (equal for `plain`).
    pub albedo: [f64; 2],
}

/// One object: shape, material and pose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObjectParams {
    /// Shape and its parameters.
    pub shape: ShapeParams,
    /// Material and its parameters.
    pub material: MaterialParams,
    /// Centre, m (y up, ground at y = 0).
    pub position: [f64; 3],
    /// Euler angles x, y, z, degrees.
    pub rotation_deg: [f64; 3],
    /// Radius of the bounding sphere, m.
    pub size: f64,
}

/// Procedural shapes (meshes from [`crate::mesh`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum ShapeParams {
    /// Unit sphere.
    Sphere,
    /// Superquadric with exponents e1 (latitude) and e2 (longitude).
    Superquadric {
        /// Latitude exponent.
        e1: f64,
        /// Longitude exponent.
        e2: f64,
    },
    /// Sphere with smooth radial bumps.
    Blob {
        /// Bump amplitude, fraction of the radius.
        amplitude: f64,
        /// Angular frequency of the bumps.
        frequency: f64,
        /// Phases of the bump pattern.
        phase: [f64; 3],
    },
    /// Torus in the local xz plane.
    Torus {
        /// Tube radius / ring radius.
        minor_ratio: f64,
    },
    /// Extruded star polygon.
    Extrusion {
        /// Number of points.
        sides: u32,
        /// Inner radius / outer radius of the star (1 = regular polygon).
        inner_ratio: f64,
        /// Depth, fraction of the size.
        depth: f64,
    },
    /// Flat box (a glass pane).
    Slab {
        /// Thickness, m.
        thickness: f64,
    },
}

/// Materials, mapped to the renderer's BSDFs by the scene builder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum MaterialParams {
    /// Rough dielectric coat over a diffuse base.
    Dielectric {
        /// Index of refraction.
        ior: f64,
        /// GGX alpha.
        roughness: f64,
        /// Diffuse albedo.
        albedo: f64,
    },
    /// Rough conductor.
    Metal {
        /// Metal name (complex index from polar-bsdf's table).
        metal: String,
        /// GGX alpha.
        roughness: f64,
    },
    /// Dielectric with a two-albedo checker texture.
    Textured {
        /// Index of refraction.
        ior: f64,
        /// GGX alpha.
        roughness: f64,
        /// The two albedos.
        albedo: [f64; 2],
        /// Checker repetitions.
        scale: f64,
    },
    /// Smooth or rough glass (refracting).
    Glass {
        /// Index of refraction.
        ior: f64,
        /// GGX alpha.
        roughness: f64,
    },
}

/// Draws from the family's effective ranges; the draw order is fixed, so the result depends
/// only on the seed.
struct Draw<'a> {
    rng: Pcg64,
    family: &'a Family,
}

impl Draw<'_> {
    fn num(&mut self, key: &str) -> f64 {
        let [lo, hi] = self.family.range(key);
        if lo < hi {
            self.rng.random_range(lo..hi)
        } else {
            lo
        }
    }

    fn int(&mut self, key: &str) -> u32 {
        let [lo, hi] = self.family.range(key);
        // Values are validated within limits >= 0; rounding ends inclusive.
        self.rng.random_range(lo.round() as u32..=hi.round() as u32)
    }

    fn pick(&mut self, key: &str) -> String {
        let list = self.family.choices(key);
        let i = self.rng.random_range(0..list.len().max(1));
        list.get(i).cloned().unwrap_or_default()
    }

    fn unit(&mut self) -> f64 {
        self.rng.random_range(0.0..1.0)
    }

    fn shape(&mut self, name: &str) -> ShapeParams {
        match name {
            "superquadric" => ShapeParams::Superquadric {
                e1: self.num("superquadric_exponent"),
                e2: self.num("superquadric_exponent"),
            },
            "blob" => ShapeParams::Blob {
                amplitude: self.num("blob_amplitude"),
                frequency: self.num("blob_frequency"),
                phase: [0; 3].map(|_| self.unit() * std::f64::consts::TAU),
            },
            "torus" => ShapeParams::Torus {
                minor_ratio: self.num("torus_minor_ratio"),
            },
            "extrusion" => ShapeParams::Extrusion {
                sides: self.int("extrusion_sides"),
                inner_ratio: 0.45 + 0.55 * self.unit(),
                depth: self.num("extrusion_depth"),
            },
            "slab" => ShapeParams::Slab {
                thickness: self.num("thickness"),
            },
            _ => ShapeParams::Sphere,
        }
    }

    fn material(&mut self) -> MaterialParams {
        match self.family.kind {
            FamilyKind::Transparent => MaterialParams::Glass {
                ior: self.num("glass_ior"),
                roughness: self.num("glass_roughness"),
            },
            FamilyKind::Material => match self.pick("material").as_str() {
                "metal" => MaterialParams::Metal {
                    metal: self.pick("metal"),
                    roughness: self.num("roughness"),
                },
                "textured" => MaterialParams::Textured {
                    ior: self.num("ior"),
                    roughness: self.num("roughness"),
                    albedo: [self.num("albedo"), self.num("albedo")],
                    scale: self.num("texture_scale"),
                },
                _ => self.dielectric(),
            },
            _ => self.dielectric(),
        }
    }

    fn dielectric(&mut self) -> MaterialParams {
        MaterialParams::Dielectric {
            ior: self.num("ior"),
            roughness: self.num("roughness"),
            albedo: self.num("albedo"),
        }
    }

    fn objects(&mut self) -> Vec<ObjectParams> {
        let n = self.int("objects");
        let mut objects: Vec<ObjectParams> = (0..n)
            .map(|_| {
                let name = self.pick("shape");
                let shape = self.shape(&name);
                let material = self.material();
                let size = self.num("object_size");
                let rotation_deg = [0; 3].map(|_| self.unit() * 360.0);
                ObjectParams {
                    shape,
                    material,
                    position: [0.0, size, 0.0],
                    rotation_deg,
                    size,
                }
            })
            .collect();
        // Side by side along x, centred, touching the ground, 10 % gaps.
        let total: f64 = objects.iter().map(|o| 2.2 * o.size).sum();
        let mut x = -total / 2.0;
        for o in &mut objects {
            o.position[0] = x + 1.1 * o.size;
            x += 2.2 * o.size;
        }
        objects
    }

    fn haze(&mut self) -> HazeParams {
        HazeParams {
            extinction: self.num("density"),
            albedo: self.num("haze_albedo"),
            asymmetry: self.num("haze_asymmetry"),
            depolarization: self.num("haze_depolarization"),
            scene_depth: self.num("scene_depth"),
        }
    }

    /// Objects standing on the ground at depths spread geometrically from the camera distance
    /// to `depth` (equal steps in log depth: as many near as far objects on screen), each at a
    /// random lateral place in the field of view and 15 % of the view's width tall.
    fn objects_in_depth(&mut self, camera: &CameraParams, depth: f64) -> Vec<ObjectParams> {
        let n = self.int("objects").max(1);
        let near = camera.distance.min(depth);
        let half_field = (0.5 * camera.fov_deg.to_radians()).tan();
        (0..n)
            .map(|i| {
                let t = (f64::from(i) + self.unit()) / f64::from(n);
                let z = near * (depth / near).powf(t);
                let size = 0.15 * z * half_field;
                let x = (2.0 * self.unit() - 1.0) * 0.8 * z * half_field;
                let name = self.pick("shape");
                ObjectParams {
                    shape: self.shape(&name),
                    material: self.dielectric(),
                    position: [x, size, -z],
                    rotation_deg: [0; 3].map(|_| self.unit() * 360.0),
                    size,
                }
            })
            .collect()
    }

    fn background(&mut self) -> BackgroundParams {
        match self.family.kind {
            FamilyKind::Transparent => {
                let pattern = self.pick("background");
                let scale = self.num("texture_scale");
                BackgroundParams {
                    pattern,
                    scale,
                    albedo: [0.1 + 0.2 * self.unit(), 0.6 + 0.3 * self.unit()],
                }
            }
            _ => {
                let a = 0.2 + 0.4 * self.unit();
                BackgroundParams {
                    pattern: "plain".into(),
                    scale: 1.0,
                    albedo: [a, a],
                }
            }
        }
    }
}

/// Draws the parameters of sample `index` of `family` for the given size.
pub fn draw_params(suite: &Suite, family: &Family, size: SizeName, index: u32) -> SampleParams {
    let seed = sample_seed(suite.seed, &family.name, index);
    let levels = suite.noise_for(family);
    let noise = levels[index as usize % levels.len()].clone();
    let spec = family.size(size);
    let mut d = Draw {
        rng: Pcg64::seed_from_u64(seed),
        family,
    };
    let camera = CameraParams {
        distance: d.num("camera_distance"),
        elevation_deg: d.num("camera_elevation_deg"),
        fov_deg: d.num("fov_deg"),
    };
    let light = LightParams {
        elevation_deg: d.num("light_elevation_deg"),
        azimuth_deg: d.num("light_azimuth_deg"),
        intensity: d.num("light_intensity"),
        ambient: d.num("ambient"),
    };
    let background = d.background();
    let (objects, haze, camera) = if family.kind == FamilyKind::Haze {
        let haze = d.haze();
        (
            d.objects_in_depth(&camera, haze.scene_depth),
            Some(haze),
            camera,
        )
    } else {
        let objects = d.objects();
        // Keep every object in view: the row's half-extent plus 20 % margin within the half field.
        let extent: f64 = objects.iter().map(|o| 2.2 * o.size).sum();
        let fit = 0.6 * extent / (0.5 * camera.fov_deg.to_radians()).tan();
        let camera = CameraParams {
            distance: camera.distance.max(fit),
            ..camera
        };
        (objects, None, camera)
    };
    SampleParams {
        id: sample_id(&family.name, index),
        family: family.name.clone(),
        kind: family.kind,
        index,
        seed,
        width: spec.width,
        height: spec.height,
        spp: spec.spp,
        noise,
        camera,
        light,
        background,
        objects,
        haze,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::suite::tests::MINI;

    #[test]
    fn same_index_gives_same_params_and_different_indices_differ() {
        let s = Suite::parse(MINI).unwrap();
        let f = &s.families[0];
        let a = draw_params(&s, f, SizeName::Ci, 2);
        assert_eq!(a, draw_params(&s, f, SizeName::Ci, 2));
        assert_ne!(a.seed, draw_params(&s, f, SizeName::Ci, 3).seed);
        assert_eq!(a.id, "sfp-00002");
    }

    #[test]
    fn draws_stay_inside_the_suite_ranges() {
        let s = Suite::parse(MINI).unwrap();
        let f = &s.families[0];
        for i in 0..200 {
            let p = draw_params(&s, f, SizeName::Full, i);
            assert!((1..=3).contains(&p.objects.len()));
            for o in &p.objects {
                let MaterialParams::Dielectric { ior, roughness, .. } = o.material else {
                    panic!("not dielectric")
                };
                assert!((1.4..1.6).contains(&ior), "ior {ior}");
                assert!((0.0..0.35).contains(&roughness));
            }
        }
    }

    #[test]
    fn every_drawn_shape_parameter_has_a_range_for_its_kind() {
        // A key without a spec would silently draw 0 (e.g. a torus with no tube).
        let text = include_str!("../../../datasets-synth/suites/standard.toml");
        let s = Suite::parse(text).unwrap();
        for f in s.families.iter().filter(|f| f.kind != FamilyKind::Haze) {
            let keys: Vec<_> = crate::suite::param_specs(f.kind)
                .iter()
                .map(|p| p.key)
                .collect();
            for key in [
                "superquadric_exponent",
                "blob_amplitude",
                "torus_minor_ratio",
                "extrusion_sides",
                "object_size",
                "objects",
            ] {
                assert!(keys.contains(&key), "{} lacks {key}", f.name);
            }
            for i in 0..50 {
                for o in draw_params(&s, f, SizeName::Ci, i).objects {
                    if let ShapeParams::Torus { minor_ratio } = o.shape {
                        assert!(minor_ratio >= 0.2, "{minor_ratio}");
                    }
                }
            }
        }
    }

    #[test]
    fn haze_objects_spread_from_the_camera_distance_to_the_scene_depth() {
        let text = include_str!("../../../datasets-synth/suites/standard.toml");
        let s = Suite::parse(text).unwrap();
        let f = s
            .families
            .iter()
            .find(|f| f.kind == FamilyKind::Haze)
            .unwrap();
        for i in 0..50 {
            let p = draw_params(&s, f, SizeName::Full, i);
            let h = p.haze.expect("haze family draws a medium");
            let [lo, hi] = f.range("density");
            assert!((lo..=hi).contains(&h.extinction), "{h:?}");
            assert!((0.0..=1.0).contains(&h.albedo) && h.asymmetry.abs() < 1.0);
            let depths: Vec<f64> = p.objects.iter().map(|o| -o.position[2]).collect();
            assert!(!depths.is_empty());
            for (k, z) in depths.iter().enumerate() {
                // Strata in log depth: object k lies in the k-th of n equal log-depth bins.
                let t = (z / p.camera.distance).ln() / (h.scene_depth / p.camera.distance).ln();
                let n = depths.len() as f64;
                assert!(
                    t >= k as f64 / n - 1e-9 && t <= (k + 1) as f64 / n + 1e-9,
                    "{t}"
                );
            }
        }
        let clear = draw_params(&s, &s.families[0], SizeName::Ci, 0);
        assert!(clear.haze.is_none());
    }

    #[test]
    fn seed_is_stable_across_versions() {
        // Pinned value: changing the seed derivation silently changes every dataset.
        // Values computed independently (Python) from the formulas in the doc comments.
        assert_eq!(sample_seed(7, "sfp", 0), 0x7103_2cb8_045d_c0ee);
        assert_eq!(fnv1a(""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a("a"), 0xaf63_dc4c_8601_ec8c);
    }
}
