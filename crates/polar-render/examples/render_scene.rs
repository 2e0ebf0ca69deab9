//! Renders a scene file and writes `stokes.exr` and `meta.json` (with the render time in
//! `seconds`) into OUT_DIR; with `--gt` also the ground truth under `gt/` (with a medium
//! also `gt/clear.exr`, `gt/transmission.exr` and `gt/dehazed.exr`, two more renders).
//!
//! `cargo run --release -p polar-render --example render_scene -- SCENE OUT_DIR [--spp N] [--model none|linear|full] [--sampler sobol|independent] [--gt]`

use polar_render::{Polarization, RenderOptions, SamplerKind, load_scene, render};
use std::path::PathBuf;

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: render_scene SCENE OUT_DIR [--spp N] [--model none|linear|full] [--sampler sobol|independent] [--gt]";
    let (mut positional, mut spp, mut model, mut sampler) = (Vec::new(), None, None, None);
    let mut gt = false;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--spp" => spp = Some(it.next().ok_or(usage)?.parse::<u32>()?),
            "--model" => {
                model = Some(match it.next().map(String::as_str) {
                    Some("none") => Polarization::None,
                    Some("linear") => Polarization::Linear,
                    Some("full") => Polarization::Full,
                    _ => return Err(usage.into()),
                })
            }
            "--sampler" => {
                sampler = Some(match it.next().map(String::as_str) {
                    Some("sobol") => SamplerKind::Sobol,
                    Some("independent") => SamplerKind::Independent,
                    _ => return Err(usage.into()),
                })
            }
            "--gt" => gt = true,
            _ => positional.push(PathBuf::from(a)),
        }
    }
    let [scene_path, out] = <[PathBuf; 2]>::try_from(positional).map_err(|_| usage)?;
    let mut scene = load_scene(&scene_path)?;
    if let Some(spp) = spp {
        scene.settings.spp = spp;
    }
    if let Some(sampler) = sampler {
        scene.settings.sampler = sampler;
    }
    let out_img = render(
        &scene,
        &RenderOptions {
            force_model: model,
            ground_truth: gt,
            clear: gt,
            dehazed: gt,
        },
        &|done, total| {
            eprint!("\r{done}/{total} tiles");
        },
    )?;
    eprintln!();
    eprintln!(
        "{:?} transport, {} spp, {:.3} s",
        out_img.model, out_img.spp, out_img.seconds
    );
    let serde_json::Value::Object(meta) = serde_json::json!({
        "width": scene.camera.width,
        "height": scene.camera.height,
        "scene": scene_path.display().to_string(),
        "renderer": "polar-render",
        "model": out_img.model,
        "spp": out_img.spp,
        "sampler": scene.settings.sampler,
        "seconds": out_img.seconds,
    }) else {
        return Err("meta is not a JSON object".into());
    };
    let sample = polar_io::Sample {
        meta,
        ..out_img.into_sample()
    };
    polar_io::write_sample(&out, &sample)?;
    Ok(())
}
