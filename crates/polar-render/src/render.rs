//! The render driver: rayon over tiles, per-pixel seeded samples, the film
//! (Stokes in the per-pixel camera frame) and the first-hit ground truth.

use crate::Error;
use crate::integrator::radiance;
use crate::sampler::PixelStreams;
use crate::scene::Scene;
use crate::transport::{Full, Linear, Scalar, Transport, emission_polarization};
use crate::world::World;
use polar_bsdf::Polarization;
use polar_image::{Gray, Image, StokesImage};
use polar_optics::Stokes;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Tile edge in pixels (the unit of parallel work and of progress reports).
const TILE: usize = 16;

/// Options that do not change the image.
#[derive(Clone, Debug, Default)]
pub struct RenderOptions {
    /// Transport model to use instead of the cheapest exact one; must not be
    /// cheaper than the scene needs (that would be inexact).
    pub force_model: Option<Polarization>,
}

/// Everything a render produces.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// Stokes `S0..S3` per pixel in the conventions' camera frame.
    pub stokes: StokesImage,
    /// Camera-frame unit normal of the first hit, facing the camera; 0 where no surface.
    pub normal: Image<f32, 3>,
    /// Distance along the viewing axis (camera -z) to the first hit; 0 where no surface.
    pub depth: Gray<f32>,
    /// Material labels: 0 background, 1 opaque dielectric, 2 metal, 3 transparent.
    pub material: Gray<u8>,
    /// 255 on transparent objects, else 0.
    pub transparent: Gray<u8>,
    /// S0 of the same view rendered without the participating medium (same
    /// seed and samples); `None` when the scene has no medium.
    pub clear: Option<Gray<f32>>,
    /// Transmittance `exp(−∫ σ_t ds)` of the medium along each pixel's central ray
    /// up to its first surface (to the medium's exit if none), computed exactly;
    /// `None` when the scene has no medium.
    pub transmission: Option<Gray<f32>>,
    /// The transport model used.
    pub model: Polarization,
    /// Wall-clock seconds of the render (BVH build included; the medium-free
    /// render behind `clear` excluded).
    pub seconds: f64,
    /// Samples per pixel.
    pub spp: u32,
}

/// The cheapest exact model for `scene`: the maximum over the materials on its
/// shapes, the polarization of its emitters and its medium's phase function.
pub fn required_model(scene: &Scene) -> Polarization {
    let materials = scene
        .shapes
        .iter()
        .filter_map(|s| s.material)
        .map(|m| scene.materials[m].1.bsdf([0.5, 0.5]).polarization());
    let emitters = scene
        .shapes
        .iter()
        .filter_map(|s| s.emission)
        .map(|e| emission_polarization(&e.polarization));
    let lights = scene.lights.iter().map(|l| match l {
        crate::Light::Environment(e) | crate::Light::Sun { emission: e, .. } => {
            emission_polarization(&e.polarization)
        }
        crate::Light::Sky(_) => Polarization::Linear,
    });
    let medium = scene.medium.iter().map(|m| m.polarization());
    materials
        .chain(emitters)
        .chain(lights)
        .chain(medium)
        .max()
        .unwrap_or(Polarization::None)
}

/// Per-pixel results of one tile.
struct TileResult {
    x0: usize,
    y0: usize,
    w: usize,
    stokes: Vec<[f32; 4]>,
    gt: Vec<GroundTruth>,
}

#[derive(Clone, Copy, Default)]
struct GroundTruth {
    normal: [f32; 3],
    depth: f32,
    label: u8,
    /// Transmittance of the medium along the central ray (1 without a medium).
    transmission: f32,
}

/// Renders `scene` with the cheapest exact transport (or `opts.force_model`),
/// using the current rayon thread pool. `progress(done, total)` is called after each tile
/// (with a medium, a second round follows for the medium-free `clear` render).
/// The result is bit-identical for the same scene and seed whatever the thread count.
pub fn render(
    scene: &Scene,
    opts: &RenderOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<RenderOutput, Error> {
    scene.validate()?;
    let required = required_model(scene);
    let model = opts.force_model.unwrap_or(required);
    if model < required {
        return Err(Error::ModelTooCheap {
            requested: model,
            required,
        });
    }
    let start = Instant::now();
    let tiles = render_with(scene, model, progress);
    let seconds = start.elapsed().as_secs_f64();
    let mut out = assemble(scene, tiles, model, seconds);
    if scene.medium.is_some() {
        let clear_scene = Scene {
            medium: None,
            ..scene.clone()
        };
        let clear_model = opts.force_model.unwrap_or(required_model(&clear_scene));
        let clear = assemble(
            &clear_scene,
            render_with(&clear_scene, clear_model, progress),
            clear_model,
            0.0,
        );
        out.clear = Some(clear.stokes.channel(0));
    }
    Ok(out)
}

/// Renders the tiles of a validated scene with transport `model`.
fn render_with(
    scene: &Scene,
    model: Polarization,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Vec<TileResult> {
    let world = World::new(scene);
    match model {
        Polarization::None => render_tiles::<Scalar>(&world, progress),
        Polarization::Linear => render_tiles::<Linear>(&world, progress),
        Polarization::Full => render_tiles::<Full>(&world, progress),
    }
}

fn render_tiles<R: Transport>(
    world: &World,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Vec<TileResult> {
    let (w, h) = (world.scene.camera.width, world.scene.camera.height);
    let origins: Vec<(usize, usize)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let done = AtomicUsize::new(0);
    origins
        .par_iter()
        .map(|&(x0, y0)| {
            let tile = render_tile::<R>(world, x0, y0);
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, origins.len());
            tile
        })
        .collect()
}

fn render_tile<R: Transport>(world: &World, x0: usize, y0: usize) -> TileResult {
    let cam = &world.scene.camera;
    let (tw, th) = (TILE.min(cam.width - x0), TILE.min(cam.height - y0));
    let settings = &world.scene.settings;
    let mut tile = TileResult {
        x0,
        y0,
        w: tw,
        stokes: Vec::with_capacity(tw * th),
        gt: Vec::with_capacity(tw * th),
    };
    for y in y0..y0 + th {
        for x in x0..x0 + tw {
            let streams =
                PixelStreams::new(settings.seed, (y * cam.width + x) as u64, settings.sampler);
            let mut sum = Stokes::zeros();
            for s in 0..settings.spp {
                let mut sampler = streams.sample(u64::from(s));
                let [jx, jy] = sampler.next_2d();
                let d = world.camera.direction(x as f64 + jx, y as f64 + jy);
                sum += radiance::<R>(world, &d, &mut sampler);
            }
            let mean = sum / f64::from(settings.spp);
            tile.stokes.push([
                mean[0] as f32,
                mean[1] as f32,
                mean[2] as f32,
                mean[3] as f32,
            ]);
            tile.gt.push(ground_truth(world, x, y));
        }
    }
    tile
}

/// First-hit ground truth along the ray through the pixel centre.
fn ground_truth(world: &World, x: usize, y: usize) -> GroundTruth {
    let d = world.camera.direction(x as f64 + 0.5, y as f64 + 0.5);
    let o = world.camera.position;
    let hit = world.intersect(&o, &d);
    let t_hit = hit.as_ref().map_or(f64::INFINITY, |h| (h.p - o).norm());
    let transmission = world.scene.medium.as_ref().map_or(1.0, |m| {
        (-crate::tracking::optical_depth(m, &o, &d, t_hit)).exp() as f32
    });
    let Some(hit) = hit else {
        return GroundTruth {
            transmission,
            ..GroundTruth::default()
        };
    };
    let shape = &world.scene.shapes[hit.shape];
    let n = if hit.ns.dot(&d) > 0.0 {
        -hit.ns
    } else {
        hit.ns
    };
    let n = world.camera.to_camera(&n);
    let label = match (shape.background, shape.material) {
        (false, Some(m)) => world.scene.materials[m].1.label(),
        _ => 0,
    };
    GroundTruth {
        normal: [n.x as f32, n.y as f32, n.z as f32],
        depth: world.camera.depth(&hit.p) as f32,
        label,
        transmission,
    }
}

fn assemble(
    scene: &Scene,
    tiles: Vec<TileResult>,
    model: Polarization,
    seconds: f64,
) -> RenderOutput {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let mut stokes = StokesImage::new(w, h);
    let mut normal = Image::<f32, 3>::new(w, h);
    let mut depth = Gray::<f32>::new(w, h);
    let mut material = Gray::<u8>::new(w, h);
    let mut transparent = Gray::<u8>::new(w, h);
    let mut transmission = Gray::<f32>::new(w, h);
    for t in tiles {
        for (i, (s, g)) in t.stokes.iter().zip(&t.gt).enumerate() {
            let p = (t.y0 + i / t.w) * w + t.x0 + i % t.w;
            stokes.pixels_mut()[p] = *s;
            normal.pixels_mut()[p] = g.normal;
            depth.pixels_mut()[p] = [g.depth];
            material.pixels_mut()[p] = [g.label];
            transparent.pixels_mut()[p] = [if g.label == 3 { 255 } else { 0 }];
            transmission.pixels_mut()[p] = [g.transmission];
        }
    }
    RenderOutput {
        stokes,
        normal,
        depth,
        material,
        transparent,
        clear: None,
        transmission: scene.medium.is_some().then_some(transmission),
        model,
        seconds,
        spp: scene.settings.spp,
    }
}
