//! Renders a scene file and writes `stokes.exr`, the ground truth under `gt/`
//! (with a medium also `gt/clear.exr`, `gt/transmission.exr` and `gt/dehazed.exr`) and
//! `meta.json` (with the render time in `seconds`) into OUT_DIR.
//!
//! `cargo run --release -p polar-render --example render_scene -- SCENE OUT_DIR [--spp N] [--model none|linear|full] [--sampler sobol|independent]`

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
    let usage = "usage: render_scene SCENE OUT_DIR [--spp N] [--model none|linear|full] [--sampler sobol|independent]";
    let (mut positional, mut spp, mut model, mut sampler) = (Vec::new(), None, None, None);
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
            clear: true,
            dehazed: true,
        },
        &|done, total| {
            eprint!("\r{done}/{total} tiles");
        },
    )?;
    eprintln!();
    std::fs::create_dir_all(out.join("gt"))?;
    polar_io::write_exr(
        out.join("stokes.exr"),
        &out_img.stokes,
        polar_io::STOKES_CHANNELS,
    )?;
    polar_io::write_exr(
        out.join("gt/normal.exr"),
        &out_img.normal,
        polar_io::RGB_CHANNELS,
    )?;
    polar_io::write_exr(
        out.join("gt/depth.exr"),
        &out_img.depth,
        polar_io::Y_CHANNEL,
    )?;
    polar_io::write_gray8_png(out.join("gt/material.png"), &out_img.material)?;
    polar_io::write_gray8_png(out.join("gt/transparent.png"), &out_img.transparent)?;
    for (name, image) in [
        (polar_io::files::GT_CLEAR, &out_img.clear),
        (polar_io::files::GT_TRANSMISSION, &out_img.transmission),
        (polar_io::files::GT_DEHAZED, &out_img.dehazed),
    ] {
        if let Some(image) = image {
            polar_io::write_exr(out.join(name), image, polar_io::Y_CHANNEL)?;
        }
    }
    let meta = serde_json::json!({
        "width": scene.camera.width,
        "height": scene.camera.height,
        "scene": scene_path.display().to_string(),
        "renderer": "polar-render",
        "model": format!("{:?}", out_img.model),
        "spp": out_img.spp,
        "sampler": format!("{:?}", scene.settings.sampler),
        "seconds": out_img.seconds,
    });
    std::fs::write(out.join("meta.json"), serde_json::to_string_pretty(&meta)?)?;
    eprintln!(
        "{:?} transport, {} spp, {:.3} s",
        out_img.model, out_img.spp, out_img.seconds
    );
    Ok(())
}
