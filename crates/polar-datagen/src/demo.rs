//! The built-in demo scene and single-scene rendering (`demo` and `render` commands): one
//! sample directory, committed atomically, plus quick-look pictures.

use std::path::{Path, PathBuf};

use polar_io::{StagedDir, files};
use polar_render::Polarization;
use polar_sensor::{SensorModel, SensorSettings};

use crate::Error;
use crate::params::{
    BackgroundParams, CameraParams, LightParams, MaterialParams, ObjectParams, SampleParams,
    ShapeParams,
};
use crate::sample::{render, write_pictures, write_sample};
use crate::scene::build_scene;
use crate::store;
use crate::suite::{FamilyKind, NoiseLevel};

/// The noise of the Sony IMX250MZR preset ([`SensorModel::imx250mzr`]).
pub fn realistic_noise() -> NoiseLevel {
    let p = SensorModel::imx250mzr();
    NoiseLevel {
        name: "realistic".into(),
        full_well_e: p.full_well,
        read_noise_e: p.read_noise,
        bits: u8::try_from(p.bit_depth).expect("the preset's bit depth is at most 16"),
        shot_noise: p.shot_noise,
        extinction_ratio: Some(p.extinction_ratio),
        exposure: None,
    }
}

fn object(
    shape: ShapeParams,
    material: MaterialParams,
    size: f64,
    rotation_deg: [f64; 3],
) -> ObjectParams {
    ObjectParams {
        shape,
        material,
        position: [0.0, size, 0.0],
        rotation_deg,
        size,
    }
}

/// The demo: a plastic sphere, a gold superquadric, a glass sphere and a checkered torus on a
/// grey floor before a checkered backdrop, lit by a low sun and a dim sky.
pub fn demo_params(width: u32, height: u32, spp: u32) -> SampleParams {
    let mut objects = vec![
        object(
            ShapeParams::Sphere,
            MaterialParams::Dielectric {
                ior: 1.5,
                roughness: 0.05,
                albedo: 0.6,
            },
            0.45,
            [0.0; 3],
        ),
        object(
            ShapeParams::Superquadric { e1: 0.5, e2: 0.5 },
            MaterialParams::Metal {
                metal: "gold".into(),
                roughness: 0.15,
            },
            0.45,
            [20.0, 30.0, 0.0],
        ),
        object(
            ShapeParams::Sphere,
            MaterialParams::Glass {
                ior: 1.5,
                roughness: 0.0,
            },
            0.45,
            [0.0; 3],
        ),
        object(
            ShapeParams::Torus { minor_ratio: 0.35 },
            MaterialParams::Textured {
                ior: 1.45,
                roughness: 0.2,
                albedo: [0.15, 0.75],
                scale: 4.0,
            },
            0.45,
            [0.0, 25.0, 0.0],
        ),
    ];
    for (i, o) in objects.iter_mut().enumerate() {
        o.position[0] = (i as f64 - 1.5) * 1.0;
    }
    SampleParams {
        id: "demo".into(),
        family: "demo".into(),
        kind: FamilyKind::Transparent,
        index: 0,
        seed: 1,
        width,
        height,
        spp,
        noise: realistic_noise(),
        camera: CameraParams {
            distance: 4.2,
            elevation_deg: 15.0,
            fov_deg: 45.0,
        },
        light: LightParams {
            elevation_deg: 35.0,
            azimuth_deg: 60.0,
            intensity: 3.0,
            ambient: 0.2,
        },
        background: BackgroundParams {
            pattern: "checker".into(),
            scale: 24.0,
            albedo: [0.2, 0.7],
        },
        objects,
        haze: None,
    }
}

/// The last component of `--out`: the name of the sample directory (`.` or `..` name none).
fn sample_name(dir: &Path) -> Result<String, Error> {
    dir.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .ok_or_else(|| Error::Option {
            option: "--out",
            message: format!(
                "{} does not name a sample directory; give one, e.g. --out {}",
                dir.display(),
                dir.join("sample").display()
            ),
        })
}

/// Checks that `dir` can become a sample directory: named, absent, empty or an earlier
/// sample (has meta.json), with a writable parent. Called before rendering.
pub fn check_sample_target(dir: &Path) -> Result<(), Error> {
    sample_name(dir)?;
    if dir.exists() {
        let empty = std::fs::read_dir(dir)
            .map_err(Error::io(dir))?
            .next()
            .is_none();
        if !empty && !dir.join(polar_io::files::META).exists() {
            return Err(Error::OutputNotWritable {
                path: dir.to_owned(),
                source: std::io::Error::other(
                    "exists and is not a sample directory (no meta.json); refusing to replace it",
                ),
            });
        }
    }
    store::ensure_writable(&parent_of(dir))
}

fn parent_of(dir: &Path) -> PathBuf {
    dir.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), Path::to_owned)
}

/// Renders the demo into `out` (a sample directory with `pictures/`); returns the transport
/// model used.
pub fn run_demo(out: &Path, width: u32, height: u32, spp: u32) -> Result<Polarization, Error> {
    let params = demo_params(width, height, spp);
    let scene = build_scene(&params);
    let record = serde_json::to_value(&params).map_err(|e| Error::Sample {
        id: params.id.clone(),
        message: format!("parameters to JSON: {e}"),
    })?;
    render_into(out, &scene, &params.noise, &record)
}

/// The noise level of a scene's `[sensor]` settings (checked when the scene was parsed);
/// absent keys take the realistic values.
pub fn noise_from_settings(s: &SensorSettings) -> NoiseLevel {
    let r = realistic_noise();
    NoiseLevel {
        name: "scene".into(),
        full_well_e: s.full_well_e.unwrap_or(r.full_well_e),
        read_noise_e: s.read_noise_e.unwrap_or(r.read_noise_e),
        bits: s.bits.unwrap_or(r.bits),
        shot_noise: s.shot_noise.unwrap_or(r.shot_noise),
        extinction_ratio: s.extinction_ratio.or(r.extinction_ratio),
        exposure: None,
    }
}

/// Loads a scene file for `render`, with `--spp` and `--seed` applied, and checks everything
/// a sample needs before any rendering: the scene, an even image size and the `[sensor]` table.
pub fn load_render_scene(
    file: &Path,
    spp: Option<u32>,
    seed: Option<u64>,
) -> Result<(polar_render::Scene, NoiseLevel), Error> {
    let mut scene = polar_render::load_scene(file)?;
    let noise = noise_from_settings(&scene.sensor);
    let c = &scene.camera;
    for (key, v) in [("camera.width", c.width), ("camera.height", c.height)] {
        if !v.is_multiple_of(2) {
            return Err(polar_render::Error::Invalid {
                file: file.to_owned(),
                key: key.into(),
                reason: format!("{v} must be even (the mosaic has 2x2 polarizer super-pixels)"),
            }
            .into());
        }
    }
    scene.settings.spp = spp.unwrap_or(scene.settings.spp);
    scene.settings.seed = seed.unwrap_or(scene.settings.seed);
    Ok((scene, noise))
}

/// Renders `scene` into the sample directory `out`, atomically (sibling staging dir, rename).
pub fn render_into(
    out: &Path,
    scene: &polar_render::Scene,
    noise: &NoiseLevel,
    record: &serde_json::Value,
) -> Result<Polarization, Error> {
    check_sample_target(out)?;
    let name = sample_name(out)?;
    let staged = StagedDir::new(out, files::META)?;
    let result = render(scene, &name)?;
    let model = result.model;
    write_pictures(&staged.path().join(files::vision::PICTURES), &result.stokes)?;
    write_sample(staged.path(), scene, result, noise, record, &name)?;
    staged.commit()?;
    Ok(model)
}
