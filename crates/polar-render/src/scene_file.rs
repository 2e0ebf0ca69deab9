//! The scene file: versioned TOML (`version = 1`), documented in
//! `datasets-synth/scenes/README.md`. Parsing is strict (unknown keys are
//! errors) and every error names the file, the key and the reason.

use crate::Error;
use crate::scene::{Camera, Emission, Geometry, Light, RenderSettings, Scene, Shape};
use crate::shapes;
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
    sensor: Option<toml::Table>,
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
}

fn default_spp() -> u32 {
    RenderSettings::default().spp
}

fn default_max_depth() -> u32 {
    RenderSettings::default().max_depth
}

impl Default for RenderDesc {
    fn default() -> Self {
        let s = RenderSettings::default();
        Self {
            spp: s.spp,
            seed: s.seed,
            max_depth: s.max_depth,
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
    };
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
    for l in desc.lights {
        scene.lights.push(match l {
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
    scene.validate_as(file)?;
    Ok(scene)
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

fn shape(
    s: &ShapeDesc,
    key: &str,
    materials: &[String],
    file: &Path,
    base: &Path,
) -> Result<Shape, Error> {
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
    if let Some((k, _)) = given.iter().find(|(k, set)| *set && !allowed.contains(k)) {
        return Err(invalid(
            file,
            format!("{key}.{k}"),
            format!("not used by shape type {:?}; allowed: {allowed:?}", s.kind),
        ));
    }
    let require = |v: Option<f64>, k: &str| {
        v.ok_or_else(|| {
            invalid(
                file,
                format!("{key}.{k}"),
                format!("required for shape type {:?}", s.kind),
            )
        })
    };
    let segments = s.segments.unwrap_or(64).max(3);
    let scale = match s.scale {
        None => [1.0; 3],
        Some(Scale::Uniform(k)) => [k; 3],
        Some(Scale::Axes(a)) => a,
    };
    let placement = shapes::transform(
        s.translate.unwrap_or_default(),
        s.rotate_deg.unwrap_or_default(),
        scale,
    );
    let mesh = match s.kind {
        ShapeType::Sphere => None,
        ShapeType::TessellatedSphere => Some(shapes::uv_sphere(segments)),
        ShapeType::Rectangle => Some(shapes::rectangle()),
        ShapeType::Cube => Some(shapes::cube()),
        ShapeType::Disk => Some(shapes::disk(segments)),
        ShapeType::Torus => Some(shapes::torus(
            require(s.minor_radius, "minor_radius")?,
            segments,
        )),
        ShapeType::Superquadric => {
            let [e1, e2] = s.exponents.ok_or_else(|| {
                invalid(
                    file,
                    format!("{key}.exponents"),
                    "required for shape type Superquadric",
                )
            })?;
            Some(shapes::superquadric(e1, e2, segments))
        }
        ShapeType::Mesh => {
            let rel = s.file.as_ref().ok_or_else(|| {
                invalid(file, format!("{key}.file"), "required for shape type Mesh")
            })?;
            let path = base.join(rel);
            let mesh = shapes::load_mesh(&path)
                .map_err(|e| invalid(file, format!("{key}.file"), e.to_string()))?;
            Some(mesh)
        }
    };
    let geometry = match mesh {
        Some(m) => Geometry::Mesh(m.transformed(&placement)),
        None => Geometry::Sphere {
            center: s.center.unwrap_or_default().into(),
            radius: require(s.radius, "radius")?,
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
    let emission = s.emission.map(|value| Emission {
        value,
        polarization: s.emission_polarization.unwrap_or_default(),
    });
    if s.emission_polarization.is_some() && emission.is_none() {
        return Err(invalid(
            file,
            format!("{key}.emission_polarization"),
            "given without `emission`",
        ));
    }
    Ok(Shape {
        geometry,
        material,
        emission,
        background: s.background,
    })
}
