//! Unidirectional path tracing of Mueller/Stokes radiance with next-event
//! estimation, multiple importance sampling (power heuristic, Veach 1997) and
//! Russian roulette, generic over the [`Transport`] representation.
//!
//! Frames: a camera path carries the throughput `T` together with a frame: `T`
//! maps Stokes light arriving along the current ray (travelling along `-d`) in
//! the frame with x axis `path_x` (a world vector perpendicular to `d`) to
//! Stokes at the camera in the conventions' per-pixel frame (`path_x = x_ref`
//! on the primary ray, so the film needs no further rotation). A BSDF matrix
//! comes with input basis `stokes_basis(-wi)` and output basis
//! `stokes_basis(wo)` of local vectors: its output is rotated once into
//! `path_x` (one rotation per vertex, shared by light and BSDF sampling), and
//! its input basis, taken to world space, becomes the next `path_x`. This is the
//! calculus of re-expressing every matrix in world-implicit bases with
//! `rotate_mueller_basis` (Mitsuba 3) with a quarter of the rotations. Emitted
//! Stokes (implicit frame of its direction) is rotated only when polarized.

use crate::geometry::SurfaceHit;
use crate::sampler::Sampler;
use crate::scene::Vec3;
use crate::transport::Transport;
use crate::world::World;
use polar_bsdf::Polarization;
use polar_optics::frame::{double_angle, rotate_rows};
use polar_optics::{Mueller, Stokes, rotate_stokes_basis, stokes_basis};

/// Orthonormal shading frame: `z = n`, `x = stokes_basis(n)`, `y = z × x`.
struct Frame {
    x: Vec3,
    y: Vec3,
    z: Vec3,
}

impl Frame {
    fn new(n: Vec3) -> Self {
        let x = stokes_basis(&n);
        Self {
            y: n.cross(&x),
            x,
            z: n,
        }
    }

    fn to_local(&self, v: &Vec3) -> Vec3 {
        Vec3::new(v.dot(&self.x), v.dot(&self.y), v.dot(&self.z))
    }

    fn to_world(&self, v: &Vec3) -> Vec3 {
        self.x * v.x + self.y * v.y + self.z * v.z
    }
}

/// Re-expresses Stokes `s` travelling along `k` from the implicit frame
/// `stokes_basis(k)` into the frame with x axis `x` (nothing to do when unpolarized).
fn into_frame(s: &Stokes, k: &Vec3, x: &Vec3) -> Stokes {
    if s[1] == 0.0 && s[2] == 0.0 && s[3] == 0.0 {
        *s
    } else {
        rotate_stokes_basis(k, &stokes_basis(k), x) * s
    }
}

/// Russian roulette starts at this bounce (Mitsuba's default `rr_depth`): earlier,
/// it mostly kills glass paths whose throughput is still near 1, adding variance.
const RR_DEPTH: u32 = 5;

/// The power heuristic with exponent 2.
fn power_heuristic(a: f64, b: f64) -> f64 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 { a2 / (a2 + b2) } else { 0.0 }
}

/// Offset of a new ray origin off the surface, relative to the scene scale.
fn spawn(hit: &SurfaceHit, d: &Vec3) -> Vec3 {
    let eps = crate::geometry::RAY_EPSILON * (1.0 + hit.p.amax());
    hit.p + hit.ng * eps.copysign(hit.ng.dot(d))
}

/// Where the last bounce sampled its direction from, for MIS on emitters it hits.
enum Bounce {
    /// Camera ray or a delta lobe: emission counts fully.
    Specular,
    /// A smooth lobe with solid-angle density `pdf` at point `p` with shading normal `n`.
    Smooth { pdf: f64, p: Vec3, n: Vec3 },
}

/// One path sample along the primary direction `d0`: the Stokes vector arriving
/// at the camera, in the frame with x axis `x_ref` (the per-pixel camera frame).
pub(crate) fn radiance<R: Transport>(
    world: &World,
    d0: &Vec3,
    x_ref: &Vec3,
    sampler: &mut Sampler,
) -> Stokes {
    let settings = &world.scene.settings;
    let (mut o, mut d) = (world.camera.position, *d0);
    let mut throughput = R::identity();
    let mut path_x = *x_ref;
    let mut sum = Stokes::zeros();
    let mut bounce = Bounce::Specular;
    let mut add =
        |t: &R, le: &Stokes, w: f64| sum += R::to_stokes(&t.apply(&R::from_stokes(le))) * w;
    for depth in 0..=settings.max_depth {
        let Some(hit) = world.intersect(&o, &d) else {
            if let Some(le) = world.environment() {
                let w = match &bounce {
                    Bounce::Specular => 1.0,
                    Bounce::Smooth { pdf, n, .. } => {
                        power_heuristic(*pdf, world.environment_pdf(n, &d))
                    }
                };
                add(&throughput, &into_frame(&le, &-d, &path_x), w);
            }
            break;
        };
        if let Some(le) = world.emitted(&hit, &d) {
            let w = match &bounce {
                Bounce::Specular => 1.0,
                Bounce::Smooth { pdf, p, .. } => power_heuristic(*pdf, world.area_pdf(&hit, p)),
            };
            add(&throughput, &into_frame(&le, &-d, &path_x), w);
        }
        let shape = &world.scene.shapes[hit.shape];
        let Some(material) = shape.material.map(|m| &world.scene.materials[m].1) else {
            break;
        };
        if depth == settings.max_depth {
            break;
        }
        let bsdf = material.bsdf(hit.uv);
        let frame = Frame::new(shading_normal(&hit, &d, material.label()));
        let wo_w = -d;
        let wo = frame.to_local(&wo_w);
        // The one rotation of this vertex: BSDF output basis into the path frame.
        let out_rotation = (R::MODEL != Polarization::None)
            .then(|| double_angle(&wo_w, &frame.to_world(&stokes_basis(&wo)), &path_x));
        let to_path = |m: &Mueller| match out_rotation {
            Some(r) => R::from_mueller(&rotate_rows(m, r)),
            None => R::from_mueller(m),
        };
        let in_basis = |wi: &Vec3| frame.to_world(&stokes_basis(&-wi));

        // Next-event estimation: every sun, and one light with extent (none when
        // every lobe is a delta; the random numbers are drawn anyway, so that the
        // sample streams do not depend on it).
        let u_light = sampler.next_3d();
        let lights = (!bsdf.is_delta())
            .then(|| (world.sun_samples()).chain(world.sample_light(&hit.p, &frame.z, u_light)));
        for ls in lights.into_iter().flatten() {
            let wi = frame.to_local(&ls.wi);
            let f = bsdf.eval(&wo, &wi);
            if f[(0, 0)] <= 0.0 {
                continue;
            }
            let origin = spawn(&hit, &ls.wi);
            let tmax = if ls.dist.is_finite() {
                (ls.dist - (origin - hit.p).norm()) * (1.0 - 1e-7)
            } else {
                f64::INFINITY
            };
            if world.accel.unoccluded(&origin, &ls.wi, 0.0, tmax) {
                let w = if ls.is_delta {
                    1.0
                } else {
                    power_heuristic(ls.pdf, bsdf.pdf(&wo, &wi))
                };
                let le = into_frame(&ls.stokes, &-ls.wi, &in_basis(&wi));
                add(&throughput.then(&to_path(&f)), &le, w / ls.pdf);
            }
        }

        // Continue the path by sampling the BSDF.
        let Some(s) = bsdf.sample(&wo, sampler.next_3d()) else {
            break;
        };
        let wi_w = frame.to_world(&s.wi);
        throughput = throughput.then(&to_path(&s.weight));
        path_x = in_basis(&s.wi);
        bounce = if s.is_delta {
            Bounce::Specular
        } else {
            Bounce::Smooth {
                pdf: s.pdf,
                p: hit.p,
                n: frame.z,
            }
        };
        if depth >= RR_DEPTH {
            let q = throughput.m00().clamp(0.0, 0.95);
            if sampler.next_1d() >= q {
                break;
            }
            throughput = throughput.scaled(1.0 / q);
        }
        o = spawn(&hit, &wi_w);
        d = wi_w;
    }
    sum
}

/// The shading normal, flipped toward the viewer for opaque materials (labels 1
/// and 2) so that they are two-sided; transmissive ones keep their orientation,
/// which tells inside from outside.
fn shading_normal(hit: &SurfaceHit, d: &Vec3, label: u8) -> Vec3 {
    let opaque = matches!(label, 1 | 2);
    if opaque && hit.ng.dot(d) > 0.0 {
        -hit.ns
    } else {
        hit.ns
    }
}
