//! The per-sample work with the real renderer: scene -> `polar_render::render` -> sensor ->
//! files of the sample format (`conventions.md`), written into the given directory.

use std::path::Path;

use polar_image::{Gray, StokesImage};
use polar_io::{BitDepth, MosaicPng};
use polar_render::{Polarization, RenderOptions, RenderOutput, Scene};
use polar_sensor::SensorModel;
use serde::Serialize;

use crate::Error;
use crate::params::SampleParams;
use crate::run::{SampleWorker, WorkReport};
use crate::scene::build_scene;
use crate::suite::NoiseLevel;

/// Fraction of the full well that the 99th percentile of S0 reaches (auto-exposure headroom)
/// unless the noise level sets its own [`NoiseLevel::exposure`].
const EXPOSURE_TARGET: f64 = 0.8;
/// Percentile of S0 used for auto-exposure: ignores a few specular highlights.
const EXPOSURE_QUANTILE: f64 = 0.99;

/// Renders samples with polar-render and polar-sensor.
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderWorker;

impl SampleWorker for RenderWorker {
    fn produce(&self, params: &SampleParams, dir: &Path) -> Result<WorkReport, Error> {
        let scene = build_scene(params);
        let out = render(&scene, &params.id)?;
        let record = serde_json::to_value(params).map_err(|e| Error::Sample {
            id: params.id.clone(),
            message: format!("parameters to JSON: {e}"),
        })?;
        let report = WorkReport {
            model: out.model,
            render_seconds: out.seconds,
        };
        write_sample(dir, &scene, out, &params.noise, &record, &params.id)?;
        Ok(report)
    }
}

/// Renders a scene with its ground truth (with a medium also the clear and dehazed views,
/// see [`RenderOutput::clear`] and [`RenderOutput::dehazed`]), mapping errors to the sample id.
pub fn render(scene: &Scene, id: &str) -> Result<RenderOutput, Error> {
    let opts = RenderOptions {
        ground_truth: true,
        clear: true,
        dehazed: true,
        ..RenderOptions::default()
    };
    polar_render::render(scene, &opts, &|_, _| {}).map_err(|e| Error::Sample {
        id: id.to_owned(),
        message: e.to_string(),
    })
}

/// The sensor of a noise level with auto-exposure for `stokes`, seeded by `seed`: the
/// quantum efficiency of [`SensorModel::imx250mzr`], the rest from the noise level.
pub fn sensor_model(noise: &NoiseLevel, stokes: &StokesImage, seed: u64) -> SensorModel {
    let quantum_efficiency = SensorModel::imx250mzr().quantum_efficiency;
    let max_dn = f64::from((1u32 << noise.bits) - 1);
    let s0 = stokes.channel(0);
    let level = polar_image::quantile(s0.as_slice().iter().copied(), EXPOSURE_QUANTILE)
        .map_or(0.0, f64::from);
    let electrons_per_unit = if level > 0.0 {
        noise.exposure.unwrap_or(EXPOSURE_TARGET) * noise.full_well_e / level
    } else {
        1.0
    };
    SensorModel {
        photons_per_unit: electrons_per_unit / quantum_efficiency,
        extinction_ratio: noise.extinction_ratio.unwrap_or(f64::INFINITY),
        quantum_efficiency,
        gain: noise.full_well_e / max_dn,
        read_noise: noise.read_noise_e,
        full_well: noise.full_well_e,
        bit_depth: u32::from(noise.bits),
        black_level: 0,
        shot_noise: noise.shot_noise,
        seed: seed ^ 0x5e45_0a5e_5e45_0a5e,
    }
}

#[derive(Serialize)]
struct Meta<'a> {
    width: usize,
    height: usize,
    generator: String,
    renderer: RendererMeta,
    sensor: SensorMeta<'a>,
    camera: CameraMeta,
    spp: u32,
    seconds: f64,
    scene: &'a serde_json::Value,
}

#[derive(Serialize)]
struct RendererMeta {
    name: &'static str,
    model: Polarization,
    spp: u32,
    max_depth: u32,
    split_depth: u32,
    seed: u64,
}

#[derive(Serialize)]
struct SensorMeta<'a> {
    noise: &'a NoiseLevel,
    photons_per_unit: f64,
    quantum_efficiency: f64,
    gain_e_per_dn: f64,
    bit_depth: u32,
    black_level: u16,
    saturated_pixels: usize,
    seed: u64,
}

#[derive(Serialize)]
struct CameraMeta {
    position: [f64; 3],
    look_at: [f64; 3],
    up: [f64; 3],
    fov_deg: f64,
    fov_axis: &'static str,
}

fn io_err(id: &str) -> impl Fn(polar_io::Error) -> Error + '_ {
    move |e| Error::Sample {
        id: id.to_owned(),
        message: e.to_string(),
    }
}

/// Writes meta.json, raw.png, stokes.exr, polarizers.exr (the noiseless full-resolution
/// images behind the four micro-polarizers) and gt/ (with clear.exr, transmission.exr and
/// dehazed.exr when the scene has a medium) for one render into `dir`, through
/// [`polar_io::write_sample_into`]. `scene_meta` is recorded verbatim as `meta.scene` (the
/// sample parameters or the scene file). The sensor noise is seeded from the scene's render seed.
pub fn write_sample(
    dir: &Path,
    scene: &Scene,
    out: RenderOutput,
    noise: &NoiseLevel,
    scene_meta: &serde_json::Value,
    id: &str,
) -> Result<(), Error> {
    let sample_err = |message: String| Error::Sample {
        id: id.to_owned(),
        message,
    };
    if out.ground_truth.is_none() {
        return Err(sample_err("rendered without ground truth".into()));
    }
    let model = sensor_model(noise, &out.stokes, scene.settings.seed);
    let exposed = model
        .expose(&out.stokes)
        .map_err(|e| sample_err(e.to_string()))?;
    let polarizers = model
        .polarizer_images(&out.stokes)
        .map_err(|e| sample_err(e.to_string()))?;
    let meta = meta(
        scene,
        &out,
        noise,
        &model,
        exposed.saturated_count,
        scene_meta,
    );
    let meta = match serde_json::to_value(meta) {
        Ok(serde_json::Value::Object(map)) => map,
        other => {
            return Err(sample_err(format!(
                "meta.json is not a JSON object: {other:?}"
            )));
        }
    };
    let sample = polar_io::Sample {
        meta,
        raw: Some(MosaicPng {
            image: exposed.raw,
            bit_depth: BitDepth::Sixteen,
        }),
        polarizers: Some(polarizers),
        ..out.into_sample()
    };
    polar_io::write_sample_into(dir, &sample).map_err(io_err(id))
}

fn meta<'a>(
    s: &Scene,
    out: &RenderOutput,
    noise: &'a NoiseLevel,
    model: &SensorModel,
    saturated_pixels: usize,
    scene: &'a serde_json::Value,
) -> Meta<'a> {
    let (width, height) = out.stokes.size();
    Meta {
        width,
        height,
        generator: format!("polar-datagen {}", env!("CARGO_PKG_VERSION")),
        renderer: RendererMeta {
            name: "polar-render",
            model: out.model,
            spp: out.spp,
            max_depth: s.settings.max_depth,
            split_depth: s.settings.split_depth,
            seed: s.settings.seed,
        },
        sensor: SensorMeta {
            noise,
            photons_per_unit: model.photons_per_unit,
            quantum_efficiency: model.quantum_efficiency,
            gain_e_per_dn: model.gain,
            bit_depth: model.bit_depth,
            black_level: model.black_level,
            saturated_pixels,
            seed: model.seed,
        },
        camera: CameraMeta {
            position: s.camera.position.into(),
            look_at: s.camera.look_at.into(),
            up: s.camera.up.into(),
            fov_deg: s.camera.fov_deg,
            fov_axis: "x",
        },
        spp: out.spp,
        seconds: out.seconds,
        scene,
    }
}

/// DoLP and AoLP of a Stokes image (NaN where S0 is not positive), via polar-optics.
pub fn dolp_aolp(stokes: &StokesImage) -> (Gray<f32>, Gray<f32>) {
    let (w, h) = stokes.size();
    let (mut d, mut a) = (Gray::<f32>::new(w, h), Gray::<f32>::new(w, h));
    for ((px, dv), av) in stokes
        .pixels()
        .iter()
        .zip(d.as_mut_slice())
        .zip(a.as_mut_slice())
    {
        let [s0, s1, s2, _] = *px;
        *dv = polar_optics::stokes::dolp(s0, s1, s2);
        *av = polar_optics::stokes::aolp(s0, s1, s2);
    }
    (d, a)
}

/// Writes pictures/s0.png (viridis, 0 to the 99th percentile), dolp.png (viridis, 0..1) and
/// aolp.png (hue = AoLP, value = DoLP) for a quick look.
pub fn write_pictures(dir: &Path, stokes: &StokesImage) -> Result<(), Error> {
    use polar_image::quantile;
    use polar_io::files::vision;
    use polar_sensor::picture::{aolp_hsv, colormap_indices, viridis_palette};
    std::fs::create_dir_all(dir).map_err(Error::io(dir))?;
    let s0 = stokes.channel(0);
    let top = quantile(s0.as_slice().iter().copied(), EXPOSURE_QUANTILE)
        .unwrap_or(1.0)
        .max(f32::MIN_POSITIVE);
    let (dolp, aolp) = dolp_aolp(stokes);
    let err = io_err(polar_io::files::vision::PICTURES);
    for (name, values, top) in [
        (vision::S0_PICTURE, &s0, top),
        (vision::DOLP_PICTURE, &dolp, 1.0),
    ] {
        let indices = colormap_indices(values, 0.0, top);
        polar_io::write_indexed8_png(dir.join(name), &indices, viridis_palette()).map_err(&err)?;
    }
    polar_io::write_rgb8_png(dir.join(vision::AOLP_PICTURE), &aolp_hsv(&aolp, &dolp)).map_err(err)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A noise level's exposure replaces [`EXPOSURE_TARGET`]: the photons per unit of S0
    /// scale by `exposure / EXPOSURE_TARGET`.
    #[test]
    fn exposure_scales_the_auto_exposure() {
        let mut stokes = StokesImage::new(10, 10);
        for (k, p) in stokes.pixels_mut().iter_mut().enumerate() {
            p[0] = 1.0 + k as f32;
        }
        let noise = crate::demo::realistic_noise();
        let default = sensor_model(&noise, &stokes, 1).photons_per_unit;
        let over = NoiseLevel {
            exposure: Some(2.4),
            ..noise
        };
        let ratio = sensor_model(&over, &stokes, 1).photons_per_unit / default;
        let expected = 2.4 / EXPOSURE_TARGET;
        assert!(
            (ratio - expected).abs() < 1e-12,
            "{ratio} against {expected}"
        );
    }
}
