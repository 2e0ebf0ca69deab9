//! The scene as the renderer sees it, built from a scene file
//! ([`crate::scene_file`]) or in code (the procedural dataset generator).
//!
//! Units: world distances are arbitrary but consistent; radiance and
//! irradiance are monochromatic. Emitted Stokes vectors are given relative to
//! `S0` in the implicit frame `x = polar_optics::stokes_basis(k)` of the
//! propagation direction `k` (as Mitsuba 3 does for its polarized emitters).

use crate::Error;
use crate::math::Vec3;
use crate::medium::Medium;
use crate::settings::{MAX_SPLIT_DEPTH, RenderSettings};
use crate::shapes::{TriangleMesh, check_mesh};
use polar_bsdf::Material;
use polar_optics::OpticsError;
use polar_optics::sky::RayleighSky;
use polar_sensor::SensorSettings;
use std::path::Path;

/// Largest image side in pixels a scene may ask for (the area is further bounded by
/// [`polar_io::MAX_PIXELS`]), so a mistyped size is refused instead of exhausting memory.
pub const MAX_IMAGE_SIDE: usize = 16384;
/// Largest samples per pixel: far above converged renders (a few thousand), low enough that
/// a mistyped value is refused instead of rendering for years.
pub const MAX_SPP: u32 = 1 << 20;
/// Largest `max_depth` (scattering events per path): Russian roulette ends paths long before
/// it in real scenes, while a lossless scene would otherwise trace a path for hours.
pub const MAX_PATH_DEPTH: u32 = 1024;

/// Pinhole camera; `fov_deg` is the horizontal field of view (Mitsuba's
/// default `fov_axis = "x"`). The image is `width × height`, row 0 on top.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Centre of projection.
    pub position: Vec3,
    /// A point the optical axis passes through.
    pub look_at: Vec3,
    /// Up direction (need not be orthogonal to the view direction).
    pub up: Vec3,
    /// Horizontal field of view in degrees, in `(0, 180)`.
    pub fov_deg: f64,
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
}

/// Emitted radiance with an optional polarization state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    /// Radiance `S0` (for a sun: irradiance on a surface facing it).
    pub value: f64,
    /// `(S1, S2, S3) / S0` in the implicit frame of the propagation direction;
    /// zero (unpolarized) by default.
    pub polarization: [f64; 3],
}

impl Emission {
    /// Unpolarized emission of strength `value`.
    pub fn unpolarized(value: f64) -> Self {
        Self {
            value,
            polarization: [0.0; 3],
        }
    }

    /// The emitted Stokes vector.
    pub fn stokes(&self) -> polar_optics::Stokes {
        let [s1, s2, s3] = self.polarization;
        polar_optics::Stokes::new(1.0, s1, s2, s3) * self.value
    }
}

/// A light that is not a shape: area lights are shapes with an [`Emission`].
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// Constant radiance arriving from every direction (infinitely far).
    Environment(Emission),
    /// A directional light: light arrives *from* `direction` (unit, pointing
    /// toward the sun), so it travels along `-direction`.
    Sun {
        /// Direction toward the sun (normalised on use).
        direction: Vec3,
        /// Irradiance on a surface facing the sun, with its polarization.
        emission: Emission,
    },
    /// A polarized single-scattering Rayleigh sky (`polar_optics::sky`): an
    /// environment whose Stokes radiance depends on the direction (zero below
    /// the horizon), together with its sun, a directional light of irradiance
    /// `sun_irradiance · e^{−τ/μ0}`. It counts as the environment (at most one).
    Sky(RayleighSky),
}

/// The scene-file key (under the light) that a sky error is about: the field named
/// in the error (`"|up|"` → `up`, `"sun_direction . up"` → `sun_direction`).
pub(crate) fn sky_key(e: &OpticsError) -> &'static str {
    match e {
        OpticsError::OutOfRange { name, .. } => name
            .trim_start_matches('|')
            .split(['|', ' '])
            .next()
            .unwrap_or(name),
        _ => "sky",
    }
}

/// The geometry of a shape.
#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    /// An analytic sphere (exact normals and silhouette, like Mitsuba's `sphere`).
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius, > 0.
        radius: f64,
    },
    /// A triangle mesh.
    Mesh(TriangleMesh),
}

/// A shape: geometry, its material and, for area lights, its emission.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    /// The geometry.
    pub geometry: Geometry,
    /// Index into [`Scene::materials`]; `None` is a black absorber.
    pub material: Option<usize>,
    /// Emission from the front side (outward normal), making the shape an area light.
    pub emission: Option<Emission>,
    /// `true` for floors, walls and the like: label 0 in the ground truth
    /// even though they have normals and depth (see the conventions).
    pub background: bool,
}

impl Shape {
    /// A non-emitting object shape with material `material`.
    pub fn new(geometry: Geometry, material: usize) -> Self {
        Self {
            geometry,
            material: Some(material),
            emission: None,
            background: false,
        }
    }
}

/// A material with the name the scene gives it (for error messages).
#[derive(Clone, Debug, PartialEq)]
pub struct NamedMaterial {
    /// The name, e.g. the key under `[materials]` in a scene file.
    pub name: String,
    /// The material.
    pub material: Material,
}

/// A complete scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The camera.
    pub camera: Camera,
    /// Sampling settings.
    pub settings: RenderSettings,
    /// Named materials; shapes refer to them by index.
    pub materials: Vec<NamedMaterial>,
    /// Shapes.
    pub shapes: Vec<Shape>,
    /// Environment and sun lights.
    pub lights: Vec<Light>,
    /// The participating medium, if any (at most one).
    pub medium: Option<Medium>,
    /// Sensor noise settings (not used by the renderer; for the sensor model that
    /// turns its Stokes image into a raw frame).
    pub sensor: SensorSettings,
}

impl Scene {
    /// An empty scene seen by `camera`, with default settings.
    pub fn new(camera: Camera) -> Self {
        Self {
            camera,
            settings: RenderSettings::default(),
            materials: Vec::new(),
            shapes: Vec::new(),
            lights: Vec::new(),
            medium: None,
            sensor: SensorSettings::default(),
        }
    }

    /// Adds a named material and returns its index for [`Shape::material`].
    pub fn add_material(&mut self, name: &str, material: Material) -> usize {
        self.materials.push(NamedMaterial {
            name: name.to_owned(),
            material,
        });
        self.materials.len() - 1
    }
}

/// The camera's values, as `(key, reason)` on failure.
fn validate_camera(c: &Camera) -> Result<(), (String, String)> {
    for (k, v) in [
        ("camera.position", &c.position),
        ("camera.look_at", &c.look_at),
        ("camera.up", &c.up),
    ] {
        if !finite(v) {
            return Err((k.into(), format!("not finite: {:?}", v.as_slice())));
        }
    }
    if !(c.fov_deg > 0.0 && c.fov_deg < 180.0) {
        return Err((
            "camera.fov_deg".into(),
            format!("must be in (0, 180), got {}", c.fov_deg),
        ));
    }
    if let Err((k, r)) = check_image_size(c.width, c.height) {
        return Err((format!("camera.{k}"), r));
    }
    let view = c.look_at - c.position;
    if view.norm() == 0.0 || view.cross(&c.up).norm() <= 1e-9 * view.norm() * c.up.norm() {
        return Err((
            "camera.up".into(),
            "look_at equals position, or up is parallel to the view direction".into(),
        ));
    }
    Ok(())
}

/// Where a scene came from, for error messages of scenes built in code.
const BUILT_IN_CODE: &str = "<scene built in code>";

impl Scene {
    /// Checks every value (camera, settings, materials, shapes, lights, medium); errors
    /// name the key and the reason.
    pub fn validate(&self) -> Result<(), Error> {
        self.validate_as(Path::new(BUILT_IN_CODE))
    }

    /// [`Self::validate`], naming `file` in errors.
    pub(crate) fn validate_as(&self, file: &Path) -> Result<(), Error> {
        let bad = |(key, reason): (String, String)| Error::Invalid {
            file: file.to_owned(),
            key,
            reason,
        };
        validate_camera(&self.camera).map_err(bad)?;
        self.validate_settings().map_err(bad)?;
        for NamedMaterial { name, material } in &self.materials {
            if let Err(polar_bsdf::Error::InvalidParameter { field, reason }) = material.validate()
            {
                return Err(bad((format!("materials.{name}.{field}"), reason)));
            }
        }
        for (i, s) in self.shapes.iter().enumerate() {
            self.validate_shape(s)
                .map_err(|(k, r)| bad((format!("shapes[{i}].{k}"), r)))?;
        }
        self.validate_lights().map_err(bad)?;
        if let Some(m) = &self.medium {
            m.validate()
                .map_err(|(k, r)| bad((format!("medium.{k}"), r)))?;
        }
        Ok(())
    }

    /// The render settings' ranges, as `(key, reason)` on failure.
    fn validate_settings(&self) -> Result<(), (String, String)> {
        for (k, v, max) in [
            ("render.spp", self.settings.spp, MAX_SPP),
            ("render.max_depth", self.settings.max_depth, MAX_PATH_DEPTH),
        ] {
            if !(1..=max).contains(&v) {
                return Err((k.into(), format!("{v} must be in 1..={max}")));
            }
        }
        if self.settings.split_depth > MAX_SPLIT_DEPTH {
            return Err((
                "render.split_depth".into(),
                format!("must be at most {MAX_SPLIT_DEPTH} (where Russian roulette starts)"),
            ));
        }
        Ok(())
    }

    /// Each light's values and at most one environment or sky, as `(key, reason)` on
    /// failure.
    fn validate_lights(&self) -> Result<(), (String, String)> {
        let mut environments = 0;
        for (i, l) in self.lights.iter().enumerate() {
            let (e, key) = match l {
                Light::Sky(sky) => {
                    environments += 1;
                    sky.validate()
                        .map_err(|e| (format!("lights[{i}].{}", sky_key(&e)), e.to_string()))?;
                    continue;
                }
                Light::Environment(e) => {
                    environments += 1;
                    (e, "radiance")
                }
                Light::Sun {
                    direction,
                    emission,
                } => {
                    if !finite(direction) || direction.norm() == 0.0 {
                        return Err((
                            format!("lights[{i}].direction"),
                            format!(
                                "must be finite and non-zero, got {:?}",
                                direction.as_slice()
                            ),
                        ));
                    }
                    (emission, "irradiance")
                }
            };
            check_emission(e).map_err(|(k, r)| {
                let k = if k == "value" { key } else { "polarization" };
                (format!("lights[{i}].{k}"), r)
            })?;
        }
        if environments > 1 {
            return Err((
                "lights".into(),
                format!("{environments} environment or sky lights; at most one is allowed"),
            ));
        }
        Ok(())
    }

    fn validate_shape(&self, s: &Shape) -> Result<(), (&'static str, String)> {
        if let Some(m) = s.material.filter(|m| *m >= self.materials.len()) {
            return Err((
                "material",
                format!("index {m} but only {} materials", self.materials.len()),
            ));
        }
        match &s.geometry {
            Geometry::Sphere { center, radius } => {
                if !finite(center) {
                    return Err(("center", format!("not finite: {:?}", center.as_slice())));
                }
                if !(*radius > 0.0 && radius.is_finite()) {
                    return Err((
                        "radius",
                        format!("must be positive and finite, got {radius}"),
                    ));
                }
            }
            Geometry::Mesh(m) => check_mesh(m).map_err(|r| ("geometry", r))?,
        }
        if let Some(e) = &s.emission {
            check_emission(e).map_err(|(k, r)| {
                (
                    if k == "value" {
                        "emission"
                    } else {
                        "emission_polarization"
                    },
                    r,
                )
            })?;
        }
        Ok(())
    }
}

/// Image width and height in `1..=`[`MAX_IMAGE_SIDE`], area at most [`polar_io::MAX_PIXELS`]:
/// `Err((key under camera, reason))`.
pub fn check_image_size(width: usize, height: usize) -> Result<(), (&'static str, String)> {
    for (k, v) in [("width", width), ("height", height)] {
        if !(1..=MAX_IMAGE_SIDE).contains(&v) {
            return Err((k, format!("{v} must be in 1..={MAX_IMAGE_SIDE} pixels")));
        }
    }
    if width * height > polar_io::MAX_PIXELS {
        return Err((
            "width",
            format!(
                "{width}x{height} = {} pixels exceeds the limit of {} pixels",
                width * height,
                polar_io::MAX_PIXELS
            ),
        ));
    }
    Ok(())
}

/// Emission must be finite, non-negative and physical (`S1² + S2² + S3² ≤ S0²`).
fn check_emission(e: &Emission) -> Result<(), (&'static str, String)> {
    if !(e.value >= 0.0 && e.value.is_finite()) {
        return Err((
            "value",
            format!("must be non-negative and finite, got {}", e.value),
        ));
    }
    let p = e.polarization;
    if !p.iter().all(|c| c.is_finite()) || p.iter().map(|c| c * c).sum::<f64>() > 1.0 + 1e-12 {
        return Err((
            "polarization",
            format!("(S1, S2, S3)/S0 = {p:?} must be finite with norm at most 1"),
        ));
    }
    Ok(())
}

fn finite(v: &Vec3) -> bool {
    v.iter().all(|c| c.is_finite())
}
