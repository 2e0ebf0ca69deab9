//! Renders a scene file and writes `stokes.exr` and `meta.json` (with the render time in
//! `seconds`) into OUT_DIR; with `--gt` also the ground truth under `gt/` (with a medium
//! also `gt/clear.exr`, `gt/transmission.exr` and `gt/dehazed.exr`, two more renders).
//!
//! `cargo run --release -p polar-render --example render_scene -- SCENE OUT_DIR [--spp N] [--model none|linear|full] [--sampler sobol|independent] [--gt]`

use polar_io::files;
use polar_render::{Polarization, RenderOptions, RenderOutput, SamplerKind, load_scene, render};
use std::path::{Path, PathBuf};

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
    std::fs::create_dir_all(&out)?;
    polar_io::write_exr(
        out.join(files::STOKES),
        &out_img.stokes,
        polar_io::STOKES_CHANNELS,
    )?;
    if gt {
        write_ground_truth(&out, &out_img)?;
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
    std::fs::write(out.join(files::META), serde_json::to_string_pretty(&meta)?)?;
    eprintln!(
        "{:?} transport, {} spp, {:.3} s",
        out_img.model, out_img.spp, out_img.seconds
    );
    Ok(())
}

/// Writes the ground truth of `img` (rendered with it) under `out/gt/`.
fn write_ground_truth(out: &Path, img: &RenderOutput) -> Result<(), Box<dyn std::error::Error>> {
    let truth = img
        .ground_truth
        .as_ref()
        .ok_or("rendered without ground truth")?;
    std::fs::create_dir_all(out.join(files::GT_DIR))?;
    polar_io::write_exr(
        out.join(files::GT_NORMAL),
        &truth.normal,
        polar_io::RGB_CHANNELS,
    )?;
    polar_io::write_exr(out.join(files::GT_DEPTH), &truth.depth, polar_io::Y_CHANNEL)?;
    polar_io::write_gray8_png(out.join(files::GT_MATERIAL), &truth.material)?;
    polar_io::write_gray8_png(out.join(files::GT_TRANSPARENT), &truth.transparent)?;
    for (name, image) in [
        (files::GT_CLEAR, &img.clear),
        (files::GT_TRANSMISSION, &truth.transmission),
        (files::GT_DEHAZED, &img.dehazed),
    ] {
        if let Some(image) = image {
            polar_io::write_exr(out.join(name), image, polar_io::Y_CHANNEL)?;
        }
    }
    Ok(())
}
