//! The scene file: versioned TOML (`version = 1`), documented in
//! `datasets-synth/scenes/README.md`. Parsing is strict (unknown keys are
//! errors) and every error names the file, the key and the reason.

use crate::Error;
use crate::math::Vec3;
use crate::medium::{DensityGrid, Medium, check_resolution, phase_key};
use crate::sampler::SamplerKind;
use crate::scene::{Camera, Emission, Geometry, Light, Scene, Shape, sky_key};
use crate::settings::RenderSettings;
use crate::shapes;
use num_complex::Complex64;
use polar_optics::scatter::PhaseFunction;
use polar_optics::sky::RayleighSky;
use polar_sensor::SensorSettings;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The scene-file format version this crate reads.
pub const SCENE_VERSION: u32 = 1;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    /// Checked before the schema is applied (see [`parse_scene`]).
    #[serde(rename = "version")]
    _version: u32,
    camera: CameraDesc,
    #[serde(default)]
    render: RenderDesc,
    #[serde(default)]
    materials: BTreeMap<String, polar_bsdf::Material>,
    #[serde(default)]
    shapes: Vec<ShapeDesc>,
    #[serde(default)]
    lights: Vec<LightDesc>,
    medium: Option<MediumDesc>,
    #[serde(default)]
    sensor: SensorSettings,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MediumDesc {
    bounds_min: [f64; 3],
    bounds_max: [f64; 3],
    sigma_s: f64,
    #[serde(default)]
    sigma_a: f64,
    phase: PhaseDesc,
    density: Option<DensityDesc>,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
enum PhaseDesc {
    Rayleigh {},
    Hg {
        g: f64,
        #[serde(default = "one")]
        depolarization: f64,
    },
    Mie {
        size_parameter: f64,
        ior: [f64; 2],
    },
}

/// Largest Mie size parameter a scene file may ask for: the table's cost grows as
/// `x²` and its accuracy is measured up to `x = 1000` (`polar_optics::scatter::MieTable`).
const MAX_SIZE_PARAMETER: f64 = 1000.0;

fn one() -> f64 {
    1.0
}

/// A density grid (`resolution` + `values`) or a height fog (`height_falloff`,
/// optional `up` and `resolution`); which keys go together is checked in [`density`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DensityDesc {
    resolution: Option<[usize; 3]>,
    values: Option<Vec<f64>>,
    height_falloff: Option<f64>,
    up: Option<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraDesc {
    position: [f64; 3],
    look_at: [f64; 3],
    up: [f64; 3],
    fov_deg: f64,
    width: usize,
    height: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RenderDesc {
    #[serde(default = "default_spp")]
    spp: u32,
    #[serde(default)]
    seed: u64,
    #[serde(default = "default_max_depth")]
    max_depth: u32,
    #[serde(default = "default_split_depth")]
    split_depth: u32,
    #[serde(default)]
    sampler: SamplerKind,
}

fn default_spp() -> u32 {
    RenderSettings::default().spp
}

fn default_max_depth() -> u32 {
    RenderSettings::default().max_depth
}

fn default_split_depth() -> u32 {
    RenderSettings::default().split_depth
}

impl Default for RenderDesc {
    fn default() -> Self {
        let s = RenderSettings::default();
        Self {
            spp: s.spp,
            seed: s.seed,
            max_depth: s.max_depth,
            split_depth: s.split_depth,
            sampler: s.sampler,
        }
    }
}

#[derive(Deserialize, Clone, Copy, PartialEq, Debug)]
#[serde(rename_all = "snake_case")]
enum ShapeType {
    Sphere,
    TessellatedSphere,
    Rectangle,
    Cube,
    Disk,
    Torus,
    Superquadric,
    Mesh,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum Scale {
    Uniform(f64),
    Axes([f64; 3]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ShapeDesc {
    #[serde(rename = "type")]
    kind: ShapeType,
    material: Option<String>,
    emission: Option<f64>,
    emission_polarization: Option<[f64; 3]>,
    #[serde(default)]
    background: bool,
    center: Option<[f64; 3]>,
    radius: Option<f64>,
    file: Option<PathBuf>,
    translate: Option<[f64; 3]>,
    rotate_deg: Option<[f64; 3]>,
    scale: Option<Scale>,
    segments: Option<u32>,
    minor_radius: Option<f64>,
    exponents: Option<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
enum LightDesc {
    Environment {
        radiance: f64,
        polarization: Option<[f64; 3]>,
    },
    Sun {
        direction: [f64; 3],
        irradiance: f64,
        polarization: Option<[f64; 3]>,
    },
    Sky {
        sun_direction: [f64; 3],
        #[serde(default = "y_up")]
        up: [f64; 3],
        optical_depth: f64,
        sun_irradiance: f64,
    },
}

fn y_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

/// Reads and validates a scene file; mesh paths are relative to the file's directory.
pub fn load_scene(path: &Path) -> Result<Scene, Error> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
        file: path.to_owned(),
        reason: e.to_string(),
    })?;
    parse_scene(&text, path)
}

/// Parses scene-file text; `path` names the file in errors and anchors relative mesh paths.
pub fn parse_scene(text: &str, path: &Path) -> Result<Scene, Error> {
    let file = path.to_owned();
    // Read the version first, so that a future format gets a clear message, not a key error.
    let version = toml::from_str::<toml::Table>(text)
        .map_err(|e| Error::Parse {
            file: file.clone(),
            message: e.to_string(),
        })?
        .get("version")
        .and_then(toml::Value::as_integer);
    match version {
        Some(v) if v == i64::from(SCENE_VERSION) => {}
        Some(v) => {
            return Err(invalid(
                path,
                "version",
                format!("unsupported version {v}; this build reads version {SCENE_VERSION}"),
            ));
        }
        None => {
            return Err(invalid(
                path,
                "version",
                format!("missing integer `version` (expected {SCENE_VERSION})"),
            ));
        }
    }
    let desc: SceneFile = toml::from_str(text).map_err(|e| Error::Parse {
        file: file.clone(),
        message: e.to_string(),
    })?;
    let base = path.parent().unwrap_or(Path::new("."));
    build(desc, path, base)
}

fn invalid(file: &Path, key: impl Into<String>, reason: impl Into<String>) -> Error {
    Error::Invalid {
        file: file.to_owned(),
        key: key.into(),
        reason: reason.into(),
    }
}

fn build(desc: SceneFile, file: &Path, base: &Path) -> Result<Scene, Error> {
    let c = &desc.camera;
    let camera = Camera {
        position: c.position.into(),
        look_at: c.look_at.into(),
        up: c.up.into(),
        fov_deg: c.fov_deg,
        width: c.width,
        height: c.height,
    };
    let mut scene = Scene::new(camera);
    scene.settings = RenderSettings {
        spp: desc.render.spp,
        seed: desc.render.seed,
        max_depth: desc.render.max_depth,
        split_depth: desc.render.split_depth,
        sampler: desc.render.sampler,
    };
    desc.sensor
        .check()
        .map_err(|reason| invalid(file, "sensor", reason))?;
    scene.sensor = desc.sensor;
    let names: Vec<String> = desc.materials.keys().cloned().collect();
    for (name, m) in desc.materials {
        scene.add_material(&name, m);
    }
    for (i, s) in desc.shapes.iter().enumerate() {
        scene
            .shapes
            .push(shape(s, &format!("shapes[{i}]"), &names, file, base)?);
    }
    for (i, l) in desc.lights.into_iter().enumerate() {
        scene.lights.push(match l {
            LightDesc::Sky {
                sun_direction,
                up,
                optical_depth,
                sun_irradiance,
            } => Light::Sky(
                RayleighSky::new(
                    sun_direction.into(),
                    up.into(),
                    optical_depth,
                    sun_irradiance,
                )
                .map_err(|e| {
                    invalid(file, format!("lights[{i}].{}", sky_key(&e)), e.to_string())
                })?,
            ),
            LightDesc::Environment {
                radiance,
                polarization,
            } => Light::Environment(Emission {
                value: radiance,
                polarization: polarization.unwrap_or_default(),
            }),
            LightDesc::Sun {
                direction,
                irradiance,
                polarization,
            } => Light::Sun {
                direction: direction.into(),
                emission: Emission {
                    value: irradiance,
                    polarization: polarization.unwrap_or_default(),
                },
            },
        });
    }
    scene.medium = desc.medium.map(|m| medium(m, file)).transpose()?;
    scene.validate_as(file)?;
    Ok(scene)
}

fn medium(m: MediumDesc, file: &Path) -> Result<Medium, Error> {
    let phase = match m.phase {
        PhaseDesc::Rayleigh {} => Ok(PhaseFunction::Rayleigh),
        PhaseDesc::Hg { g, depolarization } => PhaseFunction::henyey_greenstein(g, depolarization),
        PhaseDesc::Mie {
            size_parameter,
            ior: [n, k],
        } => {
            if size_parameter > MAX_SIZE_PARAMETER {
                return Err(invalid(
                    file,
                    "medium.phase.size_parameter",
                    format!(
                        "{size_parameter} exceeds {MAX_SIZE_PARAMETER} (use `hg` for large particles)"
                    ),
                ));
            }
            PhaseFunction::mie(size_parameter, Complex64::new(n, k))
        }
    }
    .map_err(|e| invalid(file, format!("medium.{}", phase_key(&e)), e.to_string()))?;
    let (lo, hi) = (Vec3::from(m.bounds_min), Vec3::from(m.bounds_max));
    let density = m.density.map(|d| density(d, &lo, &hi, file)).transpose()?;
    Ok(Medium {
        bounds_min: lo,
        bounds_max: hi,
        sigma_s: m.sigma_s,
        sigma_a: m.sigma_a,
        phase,
        density,
    })
}

/// The grid of `[medium.density]`: given values, or a height fog sampled on a grid.
fn density(d: DensityDesc, lo: &Vec3, hi: &Vec3, file: &Path) -> Result<DensityGrid, Error> {
    let key = |k: &str| format!("medium.density.{k}");
    match (d.values, d.height_falloff) {
        (Some(values), None) => {
            if d.up.is_some() {
                return Err(invalid(
                    file,
                    key("up"),
                    "only for a height fog (`height_falloff`)",
                ));
            }
            let resolution = d
                .resolution
                .ok_or_else(|| invalid(file, key("resolution"), "required with `values`"))?;
            Ok(DensityGrid { resolution, values })
        }
        (None, Some(falloff)) => {
            if !(falloff > 0.0 && falloff.is_finite()) {
                return Err(invalid(
                    file,
                    key("height_falloff"),
                    format!("must be positive and finite, got {falloff}"),
                ));
            }
            let up = Vec3::from(d.up.unwrap_or([0.0, 1.0, 0.0]));
            if !(up.iter().all(|c| c.is_finite()) && up.norm() > 0.0) {
                return Err(invalid(
                    file,
                    key("up"),
                    format!("must be finite and non-zero, got {:?}", up.as_slice()),
                ));
            }
            if let Some(r) = d.resolution {
                check_resolution(r).map_err(|e| invalid(file, key("resolution"), e))?;
            }
            if !(lo.iter().chain(hi.iter()).all(|c| c.is_finite())) {
                return Err(invalid(file, "medium.bounds_min", "bounds must be finite"));
            }
            Ok(DensityGrid::height_fog(lo, hi, &up, falloff, d.resolution))
        }
        (Some(_), Some(_)) => Err(invalid(
            file,
            key("values"),
            "give either `values` (a grid) or `height_falloff` (a height fog), not both",
        )),
        (None, None) => Err(invalid(
            file,
            "medium.density",
            "needs `resolution` and `values`, or `height_falloff`",
        )),
    }
}

/// Keys each shape type accepts besides the common ones.
fn allowed_keys(kind: ShapeType) -> &'static [&'static str] {
    const PLACED: [&str; 3] = ["translate", "rotate_deg", "scale"];
    match kind {
        ShapeType::Sphere => &["center", "radius"],
        ShapeType::Rectangle | ShapeType::Cube => &PLACED,
        ShapeType::TessellatedSphere | ShapeType::Disk => {
            &["translate", "rotate_deg", "scale", "segments"]
        }
        ShapeType::Torus => &[
            "translate",
            "rotate_deg",
            "scale",
            "segments",
            "minor_radius",
        ],
        ShapeType::Superquadric => &["translate", "rotate_deg", "scale", "segments", "exponents"],
        ShapeType::Mesh => &["translate", "rotate_deg", "scale", "file"],
    }
}

/// Shape `key` of a scene file: its keys checked against its type, its mesh placed, its
/// material looked up by name.
fn shape(
    s: &ShapeDesc,
    key: &str,
    materials: &[String],
    file: &Path,
    base: &Path,
) -> Result<Shape, Error> {
    check_shape_keys(s, key, file)?;
    let placement = shapes::transform(
        s.translate.unwrap_or_default(),
        s.rotate_deg.unwrap_or_default(),
        match s.scale {
            None => [1.0; 3],
            Some(Scale::Uniform(k)) => [k; 3],
            Some(Scale::Axes(a)) => a,
        },
    );
    let geometry = match shape_mesh(s, key, file, base)? {
        Some(m) => Geometry::Mesh(m.transformed(&placement)),
        None => Geometry::Sphere {
            center: s.center.unwrap_or_default().into(),
            radius: s.radius.ok_or_else(|| required(s, key, "radius", file))?,
        },
    };
    let material = match &s.material {
        None => None,
        Some(name) => Some(materials.iter().position(|m| m == name).ok_or_else(|| {
            invalid(
                file,
                format!("{key}.material"),
                format!("no material named `{name}` (defined: {materials:?})"),
            )
        })?),
    };
    if s.emission_polarization.is_some() && s.emission.is_none() {
        return Err(invalid(
            file,
            format!("{key}.emission_polarization"),
            "given without `emission`",
        ));
    }
    Ok(Shape {
        geometry,
        material,
        emission: s.emission.map(|value| Emission {
            value,
            polarization: s.emission_polarization.unwrap_or_default(),
        }),
        background: s.background,
    })
}

/// An error unless every key given for shape `key` is one its type uses.
fn check_shape_keys(s: &ShapeDesc, key: &str, file: &Path) -> Result<(), Error> {
    let given = [
        ("center", s.center.is_some()),
        ("radius", s.radius.is_some()),
        ("file", s.file.is_some()),
        ("translate", s.translate.is_some()),
        ("rotate_deg", s.rotate_deg.is_some()),
        ("scale", s.scale.is_some()),
        ("segments", s.segments.is_some()),
        ("minor_radius", s.minor_radius.is_some()),
        ("exponents", s.exponents.is_some()),
    ];
    let allowed = allowed_keys(s.kind);
    match given.iter().find(|(k, set)| *set && !allowed.contains(k)) {
        Some((k, _)) => Err(invalid(
            file,
            format!("{key}.{k}"),
            format!("not used by shape type {:?}; allowed: {allowed:?}", s.kind),
        )),
        None => Ok(()),
    }
}

/// The error for a key that shape `key`'s type requires and the file lacks.
fn required(s: &ShapeDesc, key: &str, k: &str, file: &Path) -> Error {
    invalid(
        file,
        format!("{key}.{k}"),
        format!("required for shape type {:?}", s.kind),
    )
}

/// The untransformed mesh of shape `key` (`None` for an analytic sphere); a mesh file is
/// found relative to `base`.
fn shape_mesh(
    s: &ShapeDesc,
    key: &str,
    file: &Path,
    base: &Path,
) -> Result<Option<shapes::TriangleMesh>, Error> {
    let segments = s.segments.unwrap_or(64).max(3);
    if segments > shapes::MAX_SEGMENTS {
        return Err(invalid(
            file,
            format!("{key}.segments"),
            format!("{segments} is more than {}", shapes::MAX_SEGMENTS),
        ));
    }
    Ok(match s.kind {
        ShapeType::Sphere => None,
        ShapeType::TessellatedSphere => Some(shapes::uv_sphere(segments)),
        ShapeType::Rectangle => Some(shapes::rectangle()),
        ShapeType::Cube => Some(shapes::cube()),
        ShapeType::Disk => Some(shapes::disk(segments)),
        ShapeType::Torus => {
            let minor = s
                .minor_radius
                .ok_or_else(|| required(s, key, "minor_radius", file))?;
            // At or above the major radius 1 the tube crosses the axis and the surface
            // intersects itself.
            if !(minor > 0.0 && minor < 1.0) {
                return Err(invalid(
                    file,
                    format!("{key}.minor_radius"),
                    format!("{minor} must be in (0, 1) (the major radius is 1)"),
                ));
            }
            Some(shapes::torus(minor, segments))
        }
        ShapeType::Superquadric => {
            let [e1, e2] = s
                .exponents
                .ok_or_else(|| required(s, key, "exponents", file))?;
            Some(shapes::superquadric(e1, e2, segments))
        }
        ShapeType::Mesh => {
            let rel = s
                .file
                .as_ref()
                .ok_or_else(|| required(s, key, "file", file))?;
            let mesh = shapes::load_mesh(&base.join(rel))
                .map_err(|e| invalid(file, format!("{key}.file"), e.to_string()))?;
            Some(mesh)
        }
    })
}
