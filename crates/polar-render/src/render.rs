//! The render driver: rayon over tiles, per-pixel seeded samples, the film
//! (Stokes in the per-pixel camera frame) and the first-hit ground truth.

use crate::Error;
use crate::integrator::{SplitPaths, radiance};
use crate::sampler::PixelStreams;
use crate::scene::{Light, Scene};
use crate::transport::{Full, Linear, Scalar, Transport};
use crate::world::World;
use polar_bsdf::Material;
use polar_image::{Gray, NormalImage, StokesImage};
use polar_io::{GroundTruth, MaterialLabel, Sample, TRANSPARENT_MASK_ON};
use polar_optics::{Polarization, Stokes};
use pulp::{Arch, Simd, WithSimd};
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
    /// Also compute [`RenderOutput::ground_truth`] (one more ray per pixel, through its
    /// centre, and with a medium the optical depth along it).
    pub ground_truth: bool,
    /// With a medium, also render [`RenderOutput::clear`] (one more render of the
    /// view); ignored without a medium.
    pub clear: bool,
    /// With a medium, also render [`RenderOutput::dehazed`] (one more render of the
    /// view); ignored without a medium.
    pub dehazed: bool,
}

/// Everything a render produces.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// Stokes `S0..S3` per pixel in the conventions' camera frame.
    pub stokes: StokesImage,
    /// The first-hit ground truth; `None` unless asked for ([`RenderOptions::ground_truth`]).
    pub ground_truth: Option<FirstHit>,
    /// S0 of the same view rendered without the participating medium (same
    /// seed and samples); `None` unless asked for ([`RenderOptions::clear`]) and the
    /// scene has a medium.
    pub clear: Option<Gray<f32>>,
    /// S0 of the same view (same seed) with the medium removed from the camera
    /// segment of every path only: from the camera to the first surface (or on to
    /// the environment) there is neither extinction nor in-scattering, while the
    /// light reaching that surface still crosses the medium (attenuated sun,
    /// skylight scattered by the haze). What dehazing recovers: the hazy image is
    /// `t · dehazed + airlight` with `t` the camera segment's transmittance.
    /// `None` unless asked for ([`RenderOptions::dehazed`]) and the scene has a medium.
    pub dehazed: Option<Gray<f32>>,
    /// The transport model used.
    pub model: Polarization,
    /// Wall-clock seconds of the render (BVH build and ground truth included; the
    /// renders behind `clear` and `dehazed` excluded).
    pub seconds: f64,
    /// Samples per pixel.
    pub spp: u32,
}

impl RenderOutput {
    /// The render as the files of a sample directory (`conventions.md`): `stokes.exr` and
    /// whatever of `gt/` was rendered; the caller adds `meta.json` and any sensor files.
    pub fn into_sample(self) -> Sample {
        let (hit, clear, dehazed) = (self.ground_truth, self.clear, self.dehazed);
        let gt = match hit {
            Some(h) => GroundTruth {
                normal: Some(h.normal),
                depth: Some(h.depth),
                material: Some(h.material),
                transparent: Some(h.transparent),
                clear,
                transmission: h.transmission,
                dehazed,
            },
            None => GroundTruth {
                clear,
                dehazed,
                ..GroundTruth::default()
            },
        };
        Sample {
            stokes: Some(self.stokes),
            gt,
            ..Sample::default()
        }
    }
}

/// Ground truth of the first hit along each pixel's central ray: the `gt/` images of
/// docs/conventions.md that do not need another render.
#[derive(Clone, Debug)]
pub struct FirstHit {
    /// Camera-frame unit normal of the first hit, facing the camera; 0 where no surface.
    pub normal: NormalImage,
    /// Distance along the viewing axis (camera -z) to the first hit; 0 where no surface.
    pub depth: Gray<f32>,
    /// Material labels ([`MaterialLabel`] values).
    pub material: Gray<u8>,
    /// [`TRANSPARENT_MASK_ON`] on transparent objects, else 0.
    pub transparent: Gray<u8>,
    /// Transmittance `exp(−∫ σ_t ds)` of the medium along each pixel's central ray
    /// up to its first surface (to the medium's exit if none), computed exactly;
    /// `None` when the scene has no medium.
    pub transmission: Option<Gray<f32>>,
}

/// The cheapest exact model for `scene`: the maximum over the materials on its
/// shapes, the polarization of its emitters and its medium's phase function.
pub fn required_model(scene: &Scene) -> Polarization {
    let materials = scene
        .shapes
        .iter()
        .filter_map(|s| s.material)
        .map(|m| scene.materials[m].material.polarization());
    let emitters = scene
        .shapes
        .iter()
        .filter_map(|s| s.emission)
        .map(|e| Polarization::of_emission(&e.polarization));
    let lights = scene.lights.iter().map(|l| match l {
        Light::Environment(e) | Light::Sun { emission: e, .. } => {
            Polarization::of_emission(&e.polarization)
        }
        Light::Sky(_) => Polarization::Linear,
    });
    let medium = scene.medium.iter().map(|m| m.polarization());
    Polarization::cheapest_exact(materials.chain(emitters).chain(lights).chain(medium))
}

/// Per-pixel results of one tile.
struct TileResult {
    x0: usize,
    y0: usize,
    w: usize,
    stokes: Vec<[f32; 4]>,
    /// Empty unless the pass computes ground truth.
    gt: Vec<PixelTruth>,
}

/// What one render pass computes besides the Stokes image.
#[derive(Clone, Copy, Default)]
struct Pass {
    /// Take the medium off the camera segment of every path (the dehazed ground truth).
    camera_segment_clear: bool,
    /// Compute the first-hit ground truth of every pixel.
    ground_truth: bool,
}

/// The first-hit ground truth of one pixel.
#[derive(Clone, Copy, Default)]
struct PixelTruth {
    normal: [f32; 3],
    depth: f32,
    label: MaterialLabel,
    /// Transmittance of the medium along the central ray (1 without a medium).
    transmission: f32,
}

/// Renders `scene` with the cheapest exact transport (or `opts.force_model`),
/// using the current rayon thread pool. `progress(done, total)` is called after each tile
/// (with a medium, one more round follows for each of the `clear` and `dehazed` renders
/// asked for).
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
    let pass = Pass {
        ground_truth: opts.ground_truth,
        ..Pass::default()
    };
    let tiles = render_with(scene, model, pass, progress);
    let seconds = start.elapsed().as_secs_f64();
    let (stokes, ground_truth) = assemble(scene, tiles, pass);
    let mut out = RenderOutput {
        stokes,
        ground_truth,
        clear: None,
        dehazed: None,
        model,
        seconds,
        spp: scene.settings.spp,
    };
    if scene.medium.is_some() {
        if opts.clear {
            out.clear = Some(render_clear(scene, opts, progress));
        }
        if opts.dehazed {
            let pass = Pass {
                camera_segment_clear: true,
                ..Pass::default()
            };
            let tiles = render_with(scene, model, pass, progress);
            out.dehazed = Some(assemble(scene, tiles, pass).0.channel(0));
        }
    }
    Ok(out)
}

/// S0 of `scene` rendered without its medium ([`RenderOutput::clear`]).
fn render_clear(
    scene: &Scene,
    opts: &RenderOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Gray<f32> {
    let clear_scene = Scene {
        medium: None,
        ..scene.clone()
    };
    let model = opts.force_model.unwrap_or(required_model(&clear_scene));
    let pass = Pass::default();
    let tiles = render_with(&clear_scene, model, pass, progress);
    assemble(&clear_scene, tiles, pass).0.channel(0)
}

/// Renders the tiles of a validated scene with transport `model`, on the best
/// SIMD target of the CPU.
fn render_with(
    scene: &Scene,
    model: Polarization,
    pass: Pass,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Vec<TileResult> {
    render_on(scene, model, pass, Arch::new(), progress)
}

/// [`render_with`] on the SIMD target `arch`.
fn render_on(
    scene: &Scene,
    model: Polarization,
    pass: Pass,
    arch: Arch,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Vec<TileResult> {
    let world = World::new(scene);
    let world = if pass.camera_segment_clear {
        world.with_camera_segment_clear()
    } else {
        world
    };
    let gt = pass.ground_truth;
    match model {
        Polarization::None => render_tiles::<Scalar>(&world, gt, arch, progress),
        Polarization::Linear => render_tiles::<Linear>(&world, gt, arch, progress),
        Polarization::Full => render_tiles::<Full>(&world, gt, arch, progress),
    }
}

/// The tiles of `world` in parallel; `ground_truth`: also each pixel's first-hit truth.
fn render_tiles<R: Transport>(
    world: &World,
    ground_truth: bool,
    arch: Arch,
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
            let tile = arch.dispatch(TileOp::<R> {
                world,
                origin: (x0, y0),
                ground_truth,
                transport: std::marker::PhantomData,
            });
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, origins.len());
            tile
        })
        .collect()
}

/// One tile as a `pulp` operation: `with_simd` is monomorphised per SIMD target and
/// `#[inline(always)]`, so the sample loop is compiled once for the x86-64-v2 baseline,
/// once for AVX2+FMA and once for AVX-512, and [`render_with`] runs the best the CPU
/// has. Only code inlined into the loop gets the target's instructions, hence
/// `#[inline(always)]` down the per-sample path (integrator, sampler, intersection,
/// BSDFs, Fresnel). Images are the same bit for bit on every target (Rust never
/// contracts `a * b + c` into an FMA; a test compares the targets).
struct TileOp<'a, R> {
    world: &'a World<'a>,
    origin: (usize, usize),
    ground_truth: bool,
    transport: std::marker::PhantomData<R>,
}

impl<R: Transport> WithSimd for TileOp<'_, R> {
    type Output = TileResult;

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) -> TileResult {
        render_tile::<R>(self.world, self.origin, self.ground_truth)
    }
}

/// The pixels of the tile at `(x0, y0)`; `ground_truth`: also their first-hit truth.
#[inline(always)]
fn render_tile<R: Transport>(
    world: &World,
    (x0, y0): (usize, usize),
    ground_truth: bool,
) -> TileResult {
    let cam = &world.scene.camera;
    let (tw, th) = (TILE.min(cam.width - x0), TILE.min(cam.height - y0));
    let settings = &world.scene.settings;
    let mut tile = TileResult {
        x0,
        y0,
        w: tw,
        stokes: Vec::with_capacity(tw * th),
        gt: Vec::with_capacity(if ground_truth { tw * th } else { 0 }),
    };
    for y in y0..y0 + th {
        for x in x0..x0 + tw {
            let sum = pixel_sum::<R>(world, x, y);
            let mean = sum / f64::from(settings.spp);
            tile.stokes.push([
                mean[0] as f32,
                mean[1] as f32,
                mean[2] as f32,
                mean[3] as f32,
            ]);
            if ground_truth {
                tile.gt.push(pixel_truth(world, x, y));
            }
        }
    }
    tile
}

/// The sum of the path samples of pixel `(x, y)`, in sample order.
///
/// Each camera ray is set up before the previous path is traced: its Sobol draw,
/// divisions and square root then overlap that path instead of delaying the next
/// one.
/// Inlined into the SIMD dispatch of [`TileOp`].
#[inline(always)]
fn pixel_sum<R: Transport>(world: &World, x: usize, y: usize) -> Stokes {
    let settings = &world.scene.settings;
    let pixel = (y * world.scene.camera.width + x) as u64;
    let streams = PixelStreams::new(settings.seed, pixel, settings.sampler);
    let primary = |s: u32| {
        let mut sampler = streams.sample(u64::from(s));
        let [jx, jy] = sampler.next_2d();
        let d = world.camera.direction(x as f64 + jx, y as f64 + jy);
        (d, sampler)
    };
    let mut sum = Stokes::zeros();
    let mut waiting = SplitPaths::new();
    let (mut d, mut sampler) = primary(0);
    for s in 1..settings.spp {
        let next = primary(s);
        sum += radiance::<R>(world, &d, &mut sampler, &mut waiting);
        (d, sampler) = next;
    }
    sum + radiance::<R>(world, &d, &mut sampler, &mut waiting)
}

/// First-hit ground truth along the ray through the pixel centre.
fn pixel_truth(world: &World, x: usize, y: usize) -> PixelTruth {
    let d = world.camera.direction(x as f64 + 0.5, y as f64 + 0.5);
    let o = world.camera.position;
    let hit = world.intersect(&o, &d);
    let t_hit = hit.as_ref().map_or(f64::INFINITY, |h| (h.p - o).norm());
    let transmission = world.scene.medium.as_ref().map_or(1.0, |m| {
        (-crate::tracking::optical_depth(m, &o, &d, t_hit)).exp() as f32
    });
    let Some(hit) = hit else {
        return PixelTruth {
            transmission,
            ..PixelTruth::default()
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
        (false, Some(m)) => material_label(&world.scene.materials[m].material),
        _ => MaterialLabel::Background,
    };
    PixelTruth {
        normal: [n.x as f32, n.y as f32, n.z as f32],
        depth: world.camera.depth(&hit.p) as f32,
        label,
        transmission,
    }
}

/// The ground-truth label of an object's material (docs/conventions.md).
fn material_label(m: &Material) -> MaterialLabel {
    match m {
        Material::Lambertian(_) | Material::Plastic(_) => MaterialLabel::Dielectric,
        Material::Conductor(_) => MaterialLabel::Metal,
        Material::Dielectric(_) | Material::Polarizer(_) | Material::Retarder(_) => {
            MaterialLabel::Transparent
        }
    }
}

/// The Stokes image of `tiles`, and their ground truth if `pass` computed it.
fn assemble(scene: &Scene, tiles: Vec<TileResult>, pass: Pass) -> (StokesImage, Option<FirstHit>) {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let mut stokes = StokesImage::new(w, h);
    let mut truth = pass.ground_truth.then(|| FirstHit {
        normal: NormalImage::new(w, h),
        depth: Gray::new(w, h),
        material: Gray::new(w, h),
        transparent: Gray::new(w, h),
        transmission: scene.medium.is_some().then(|| Gray::new(w, h)),
    });
    for t in tiles {
        let index = |i: usize| (t.y0 + i / t.w) * w + t.x0 + i % t.w;
        for (i, s) in t.stokes.iter().enumerate() {
            stokes.pixels_mut()[index(i)] = *s;
        }
        if let Some(truth) = truth.as_mut() {
            for (i, g) in t.gt.iter().enumerate() {
                truth.set(index(i), g);
            }
        }
    }
    (stokes, truth)
}

impl FirstHit {
    /// Stores the truth `g` of pixel index `p`.
    fn set(&mut self, p: usize, g: &PixelTruth) {
        self.normal.pixels_mut()[p] = g.normal;
        self.depth.pixels_mut()[p] = [g.depth];
        self.material.pixels_mut()[p] = [g.label.value()];
        self.transparent.pixels_mut()[p] = [if g.label == MaterialLabel::Transparent {
            TRANSPARENT_MASK_ON
        } else {
            0
        }];
        if let Some(t) = self.transmission.as_mut() {
            t.pixels_mut()[p] = [g.transmission];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::SamplerKind;
    use crate::scene_file::load_scene;
    use std::path::Path;

    /// The bits of the Stokes image of `scene` rendered on the SIMD target `arch`.
    fn stokes_bits(scene: &Scene, arch: Arch) -> Vec<u32> {
        let model = required_model(scene);
        let tiles = render_on(scene, model, Pass::default(), arch, &|_, _| {});
        let (stokes, _) = assemble(scene, tiles, Pass::default());
        stokes.as_slice().iter().map(|v| v.to_bits()).collect()
    }

    /// Every SIMD target this CPU has (AVX2+FMA, AVX-512) renders the five
    /// cross-check scenes (32×32 pixels, 16 spp, both samplers) bit for bit like the
    /// baseline code. Tolerance 0: the transport uses only correctly rounded IEEE
    /// operations and the same libm calls on every target, and Rust never contracts
    /// `a * b + c` into an FMA. On a CPU without AVX2 there is nothing to compare.
    #[test]
    fn simd_targets_render_bit_identical_images() {
        let mut archs = Vec::new();
        #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
        {
            archs.extend(pulp::x86::V3::try_new().map(Arch::V3));
            archs.extend(pulp::x86::V4::try_new().map(Arch::V4));
        }
        let dir =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets-synth/scenes/crosscheck");
        for name in [
            "conductor",
            "roughconductor",
            "dielectric",
            "pplastic",
            "haze",
        ] {
            let mut scene = load_scene(&dir.join(format!("{name}.toml"))).expect("scene");
            (scene.camera.width, scene.camera.height) = (32, 32);
            scene.settings.spp = 16;
            for sampler in [SamplerKind::Sobol, SamplerKind::Independent] {
                scene.settings.sampler = sampler;
                let baseline = stokes_bits(&scene, Arch::Scalar);
                for &arch in &archs {
                    assert!(
                        stokes_bits(&scene, arch) == baseline,
                        "{name}, {sampler:?}: {arch:?} differs from the baseline"
                    );
                }
            }
        }
    }
}
