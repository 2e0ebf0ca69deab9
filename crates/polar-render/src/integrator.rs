//! Unidirectional path tracing of Mueller/Stokes radiance with next-event
//! estimation, multiple importance sampling (power heuristic, Veach 1997),
//! Russian roulette and, at the camera vertex of glass and plastic and at every
//! smooth-glass vertex before Russian roulette, both outcomes of the lobe choice
//! traced (see [`radiance`]), generic over the [`Transport`] representation.
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

use crate::geometry::{RAY_EPSILON, SurfaceHit};
use crate::math::Vec3;
use crate::sampler::Sampler;
use crate::settings::{MAX_SPLIT_DEPTH, RR_DEPTH};
use crate::tracking::Flight;
use crate::transport::Transport;
use crate::world::{LightSample, PickedLight, World};
use polar_bsdf::{Bsdf, BsdfSample, cosine_hemisphere, cosine_hemisphere_pdf};
use polar_optics::frame::{double_angle, rotate_stokes};
use polar_optics::scatter::PhaseFunction;
use polar_optics::{Mueller, Polarization, Stokes, rotate_stokes_basis, stokes_basis};

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
/// `stokes_basis(k)` into the frame with x axis `x()` (nothing to do, and `x` not
/// asked, when unpolarized). Inlined: returned through memory, the vector was
/// read back before its stores were done (a store-forwarding stall).
#[inline]
fn into_frame(s: &Stokes, k: &Vec3, x: impl FnOnce() -> Vec3) -> Stokes {
    if s[1] == 0.0 && s[2] == 0.0 && s[3] == 0.0 {
        *s
    } else {
        rotate_stokes_basis(k, &stokes_basis(k), &x()) * s
    }
}

/// The power heuristic with exponent 2.
fn power_heuristic(a: f64, b: f64) -> f64 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 { a2 / (a2 + b2) } else { 0.0 }
}

/// Offset of a new ray origin off the surface, relative to the scene scale.
fn spawn(hit: &SurfaceHit, d: &Vec3) -> Vec3 {
    let eps = RAY_EPSILON * (1.0 + hit.p.amax());
    hit.p + hit.ng * eps.copysign(hit.ng.dot(d))
}

/// Where the last bounce sampled its direction from, for MIS on emitters it hits.
#[derive(Clone, Copy)]
enum Bounce {
    /// Camera ray or a delta lobe: emission counts fully.
    Specular,
    /// A smooth lobe (or a phase function) with solid-angle density `pdf` at point
    /// `p`; light sampling would have drawn its direction toward the environment
    /// with density `environment` ([`Vertex::environment_density`]).
    Smooth { pdf: f64, p: Vec3, environment: f64 },
}

impl Bounce {
    /// MIS weight of emission reached by this bounce against light sampling, whose
    /// density `light_pdf(p, environment)` (given the bounce's point and
    /// environment density) is asked only after a smooth bounce.
    fn mis_weight(&self, light_pdf: impl FnOnce(&Vec3, f64) -> f64) -> f64 {
        match self {
            Bounce::Specular => 1.0,
            Bounce::Smooth {
                pdf,
                p,
                environment,
            } => power_heuristic(*pdf, light_pdf(p, *environment)),
        }
    }
}

/// A scattering vertex: a surface point with its BSDF (in the shading frame), or
/// a point in the medium with its phase function. Directions `wi` are world
/// vectors toward where the light comes from.
#[expect(
    clippy::large_enum_variant,
    reason = "one vertex per bounce, on the stack: boxing the surface would allocate per bounce"
)]
enum Vertex<'a> {
    Surface {
        hit: SurfaceHit,
        bsdf: Bsdf,
        frame: Frame,
        /// Local direction toward the camera side.
        wo: Vec3,
    },
    Medium {
        p: Vec3,
        phase: &'a PhaseFunction,
        /// Propagation direction of the light leaving toward the camera side.
        k_out: Vec3,
    },
}

/// A sampled continuation of the path.
struct Continuation {
    /// World direction of the new ray.
    wi: Vec3,
    /// x axis of the input basis of `weight` (the next `path_x`).
    in_x: Vec3,
    /// Mueller matrix divided by the density (and the cosine, for surfaces).
    weight: Mueller,
    pdf: f64,
    is_delta: bool,
    /// Relative index crossed, `n(wi side) / n(wo side)` (1 unless refracted).
    eta: f64,
}

impl Continuation {
    /// The continuation along a BSDF sample at a surface with shading frame `frame`.
    #[inline(always)]
    fn of(frame: &Frame, s: BsdfSample) -> Self {
        Self {
            wi: frame.to_world(&s.wi),
            in_x: frame.to_world(&stokes_basis(&-s.wi)),
            weight: s.weight,
            pdf: s.pdf,
            is_delta: s.is_delta,
            eta: s.eta,
        }
    }
}

impl Vertex<'_> {
    fn p(&self) -> Vec3 {
        match self {
            Vertex::Surface { hit, .. } => hit.p,
            Vertex::Medium { p, .. } => *p,
        }
    }

    /// The shading frame about whose normal light sampling draws environment directions
    /// cosine-weighted: at a surface whose sampling chooses between lobes (plastic,
    /// glass), where a light sample drawn from that sampling would draw the choice
    /// again, bringing back the noise the split at the camera vertex removes.
    /// Elsewhere (`None`) the environment is sampled
    /// with the vertex's own distribution ([`NextEvent::environment`]).
    fn cosine_environment(&self) -> Option<&Frame> {
        match self {
            Vertex::Surface { bsdf, frame, .. } if bsdf.chooses_lobes() => Some(frame),
            _ => None,
        }
    }

    /// Density with which light sampling draws environment direction `wi` from
    /// this vertex, whose own sampling has density `pdf` for it (the density of
    /// [`Self::cosine_environment`], or `pdf`).
    fn environment_density(&self, wi: &Vec3, pdf: f64) -> f64 {
        self.cosine_environment()
            .map_or(pdf, |frame| cosine_hemisphere_pdf(&frame.to_local(wi)))
    }

    /// No light sampling at a vertex whose every lobe is a delta.
    fn is_delta(&self) -> bool {
        match self {
            Vertex::Surface { bsdf, .. } => bsdf.is_delta(),
            Vertex::Medium { .. } => false,
        }
    }

    /// The x axis of the output basis of this vertex's matrices (light leaving along `-d`).
    fn out_x(&self) -> Vec3 {
        match self {
            Vertex::Surface { frame, wo, .. } => frame.to_world(&stokes_basis(wo)),
            Vertex::Medium { k_out, .. } => stokes_basis(k_out),
        }
    }

    /// The Mueller matrix for light from `wi` (input basis [`Self::in_x`]), its
    /// sampling density and the input basis x axis.
    #[inline(always)]
    fn eval(&self, wi: &Vec3) -> (Mueller, f64, Vec3) {
        match self {
            Vertex::Surface {
                bsdf, frame, wo, ..
            } => {
                let wi = frame.to_local(wi);
                let in_x = frame.to_world(&stokes_basis(&-wi));
                (bsdf.eval(wo, &wi), bsdf.pdf(wo, &wi), in_x)
            }
            Vertex::Medium { phase, k_out, .. } => (
                phase.eval(&-wi, k_out),
                phase.pdf(-wi.dot(k_out)),
                stokes_basis(&-wi),
            ),
        }
    }

    /// Samples the direction the path continues in. Inlined into the path loop, so
    /// that its result is not written to memory and read back.
    #[inline(always)]
    fn sample(&self, u: [f64; 3]) -> Option<Continuation> {
        match self {
            Vertex::Surface {
                bsdf, frame, wo, ..
            } => bsdf.sample(wo, u).map(|s| Continuation::of(frame, s)),
            Vertex::Medium { phase, k_out, .. } => {
                // The density depends on k_in · k_out only: sampling about k_out gives k_in.
                // (u[1], u[2]) is the draw's 2-D point (Sampler::next_3d).
                let (k_in, pdf) = phase.sample(k_out, [u[1], u[2]]);
                (pdf > 0.0).then(|| Continuation {
                    wi: -k_in,
                    in_x: stokes_basis(&k_in),
                    weight: phase.eval(&k_in, k_out) / pdf,
                    pdf,
                    is_delta: false,
                    eta: 1.0,
                })
            }
        }
    }

    /// Both outcomes of a surface's lobe choice where a split can trace both
    /// ([`Bsdf::lobe_outcomes`], with the 2-D point `u`): each with its
    /// probability, `None` where it brings no light.
    #[inline(always)]
    fn lobe_outcomes(&self, u: [f64; 2]) -> Option<[Option<(f64, Continuation)>; 2]> {
        match self {
            Vertex::Surface {
                bsdf, frame, wo, ..
            } => bsdf.lobe_outcomes(wo, u).map(|lobes| {
                lobes.map(|l| {
                    l.sample
                        .map(|s| (l.probability, Continuation::of(frame, s)))
                })
            }),
            Vertex::Medium { .. } => None,
        }
    }

    /// A surface whose BSDF chooses between lobes (what [`Self::aim`] acts on).
    fn chooses_lobes(&self) -> bool {
        matches!(self, Vertex::Surface { bsdf, .. } if bsdf.chooses_lobes())
    }

    /// Makes a surface's lobe choice follow what the camera measures, given the
    /// first row `t` of the throughput in the path frame and the rotation of
    /// this vertex's output basis into it: as a row, `t · rotator(θ)` is `t`
    /// rotated by `−θ` (see [`Bsdf::with_importance`]).
    fn aim(&mut self, t: &Stokes, (cos2, sin2): (f64, f64)) {
        debug_assert!(self.chooses_lobes());
        if let Vertex::Surface { bsdf, wo, .. } = self {
            *bsdf = bsdf.with_importance(wo, &rotate_stokes(t, (cos2, -sin2)));
        }
    }

    /// Origin of a ray leaving the vertex along `wi` (off the surface).
    fn spawn(&self, wi: &Vec3) -> Vec3 {
        match self {
            Vertex::Surface { hit, .. } => spawn(hit, wi),
            Vertex::Medium { p, .. } => *p,
        }
    }
}

/// Next-event estimation at one vertex: every sun, and one light with extent (MIS
/// against the vertex's own sampling), each attenuated by the medium. `to_path`
/// takes a matrix of the vertex into the path frame.
struct NextEvent<'a, 'w, R, P> {
    world: &'a World<'w>,
    vertex: &'a Vertex<'a>,
    throughput: Option<&'a R>,
    to_path: &'a P,
}

impl<R: Transport, P: Fn(&Mueller) -> R> NextEvent<'_, '_, R, P> {
    /// Adds the suns and an emissive shape; returns the light draw's 2-D point
    /// when it picked the environment, which [`Self::environment`] samples once
    /// the continuation's numbers are drawn. Delta vertices skip the light's
    /// random numbers, so the streams do not depend on it.
    #[inline(always)]
    fn suns_and_shapes(&self, sampler: &mut Sampler, sum: &mut Stokes) -> Option<[f64; 2]> {
        if self.vertex.is_delta() {
            sampler.skip_3d();
            return None;
        }
        let u_light = sampler.next_3d();
        for sun in self.world.sun_samples() {
            let (f, _, in_x) = self.vertex.eval(&sun.wi);
            self.deliver(&sun, &f, in_x, 1.0, sampler, sum);
        }
        match self.world.sample_light(&self.vertex.p(), u_light)? {
            PickedLight::Area(ls) => {
                let (f, pdf, in_x) = self.vertex.eval(&ls.wi);
                self.deliver(&ls, &f, in_x, power_heuristic(ls.pdf, pdf), sampler, sum);
                None
            }
            PickedLight::Environment(u) => Some(u),
        }
    }

    /// Adds the environment, sampled from the light draw's point `u_light` or the
    /// continuation's numbers `u_scatter` (see [`Vertex::environment_density`]).
    ///
    /// Where the vertex samples it with its own distribution, the light sample
    /// takes the continuation's 2-D point with its second number shifted by ½
    /// (modulo 1), and its `f / pdf` is the BSDF sample's own weight (no
    /// evaluation). For visible-normal sampling (Heitz 2018: radius, then angle on
    /// the projected disk) that is the continuation's disk point mirrored through
    /// the centre, an antithetic pair: the polarization a microfacet tilted across
    /// the plane of incidence brings is odd in the tilt and cancels between the two
    /// to first order.
    #[inline(always)]
    fn environment(
        &self,
        u_light: [f64; 2],
        u_scatter: &[f64; 3],
        sampler: &mut Sampler,
        sum: &mut Stokes,
    ) {
        let (wi, f, in_x, pdf, w) = match self.vertex.cosine_environment() {
            Some(frame) => {
                let local = cosine_hemisphere(u_light);
                let wi = frame.to_world(&local);
                let pdf = self.world.environment_pdf(cosine_hemisphere_pdf(&local));
                if pdf <= 0.0 {
                    return;
                }
                let (f, bsdf_pdf, in_x) = self.vertex.eval(&wi);
                (wi, f, in_x, pdf, power_heuristic(pdf, bsdf_pdf))
            }
            None => {
                let [u0, u1, u2] = *u_scatter;
                let Some(c) = self
                    .vertex
                    .sample([u0, u1, half_shift(u2)])
                    .filter(|c| !c.is_delta)
                else {
                    return;
                };
                let pdf = self.world.environment_pdf(c.pdf);
                // f = weight · c.pdf: the sample's weight is f over its own density.
                let w = power_heuristic(pdf, c.pdf) * c.pdf;
                (c.wi, c.weight, c.in_x, pdf, w)
            }
        };
        let Some(stokes) = self.world.environment(&-wi) else {
            return;
        };
        let ls = LightSample {
            wi,
            dist: f64::INFINITY,
            stokes,
            pdf,
        };
        self.deliver(&ls, &f, in_x, w, sampler, sum);
    }

    /// Adds light sample `ls` through this vertex's matrix `f` (input basis x axis
    /// `in_x`) with MIS weight `w`, if the light is visible.
    #[inline(always)]
    fn deliver(
        &self,
        ls: &LightSample,
        f: &Mueller,
        in_x: Vec3,
        w: f64,
        sampler: &mut Sampler,
        sum: &mut Stokes,
    ) {
        if f[(0, 0)] <= 0.0 {
            return;
        }
        let p = self.vertex.p();
        let origin = self.vertex.spawn(&ls.wi);
        let tmax = if ls.dist.is_finite() {
            (ls.dist - (origin - p).norm()) * (1.0 - 1e-7)
        } else {
            f64::INFINITY
        };
        if !self.world.accel.unoccluded(&origin, &ls.wi, 0.0, tmax) {
            return;
        }
        let tr = self.world.transmittance(&origin, &ls.wi, tmax, sampler);
        let le = R::from_stokes(&into_frame(&ls.stokes, &-ls.wi, || in_x));
        // T · (F · le): two matrix–vector products instead of a matrix product.
        add(
            sum,
            self.throughput,
            &(self.to_path)(f).apply(&le),
            tr * w / ls.pdf,
        );
    }
}

/// `(x + ½) mod 1`, exactly (for `x` on the `2^-53` grid of `[0, 1)`; NaN stays NaN).
fn half_shift(x: f64) -> f64 {
    if x < 0.5 { x + 0.5 } else { x - 0.5 }
}

/// `sum += t · le · w`, with `t = None` the identity (exactly: `I · le = le`).
fn add<R: Transport>(sum: &mut Stokes, t: Option<&R>, le: &R::Stokes, w: f64) {
    let le = t.map_or(*le, |t| t.apply(le));
    *sum += R::to_stokes(&le) * w;
}

/// A camera path between two vertices: the ray it follows and what it carries.
#[derive(Clone, Copy)]
struct PathState<R> {
    o: Vec3,
    d: Vec3,
    /// `None` while it is the identity (products with it are copies).
    throughput: Option<R>,
    /// The path frame's x axis; `None` for the film frame of the primary ray.
    path_x: Option<Vec3>,
    bounce: Bounce,
    /// Product of the squared relative indices crossed: η² of the current medium.
    eta2: f64,
    depth: u32,
    /// The product of the probabilities of this path's outcomes of the lobe choices
    /// whose outcomes were all traced ([`Bsdf::lobe_outcomes`]), 1 without any: its
    /// throughput already holds it, Russian roulette divides it out.
    share: f64,
}

/// What one segment and vertex of a path lead to.
enum Step<R> {
    /// The path goes on.
    Continue,
    /// The path goes on, and so does this second one split off at its vertex.
    Split(PathState<R>),
    /// The path has ended.
    End,
}

impl<R: Transport> PathState<R> {
    fn camera(world: &World, d0: &Vec3) -> Self {
        Self {
            o: world.camera.position,
            d: *d0,
            throughput: None,
            path_x: None,
            bounce: Bounce::Specular,
            eta2: 1.0,
            depth: 0,
            share: 1.0,
        }
    }

    /// Follows the ray to its next vertex, adds what is emitted there and what
    /// light sampling brings, and samples the continuation (above `split_depth`, at
    /// the camera vertex of glass and plastic and at smooth glass: both outcomes of
    /// the lobe choice, the first split off).
    #[inline(always)]
    fn step(
        &mut self,
        world: &World,
        d0: &Vec3,
        sampler: &mut Sampler,
        sum: &mut Stokes,
    ) -> Step<R> {
        let max_depth = world.scene.settings.max_depth;
        let path_frame = |x: Option<Vec3>| x.unwrap_or_else(|| world.camera.film_frame(d0));
        let (o, d, depth) = (self.o, self.d, self.depth);
        let hit = world.intersect(&o, &d);
        let mut vertex = match world.flight(&o, &d, hit.as_ref(), depth == 0, sampler) {
            Flight::Scatter { t, weight, medium } => {
                self.throughput = Some(self.throughput.unwrap_or_else(R::identity).scaled(weight));
                Vertex::Medium {
                    p: o + t * d,
                    phase: &medium.phase,
                    k_out: -d,
                }
            }
            Flight::Pass { weight } => {
                if weight != 1.0 {
                    self.throughput =
                        Some(self.throughput.unwrap_or_else(R::identity).scaled(weight));
                }
                let Some(hit) = hit else {
                    if let Some(le) = world.environment(&-d) {
                        let w = self.bounce.mis_weight(|_, e| world.environment_pdf(e));
                        let le = R::from_stokes(&into_frame(&le, &-d, || path_frame(self.path_x)));
                        add(sum, self.throughput.as_ref(), &le, w);
                    }
                    return Step::End;
                };
                if let Some(le) = world.emitted(&hit, &d) {
                    let w = self.bounce.mis_weight(|p, _| world.area_pdf(&hit, p));
                    let le = R::from_stokes(&into_frame(&le, &-d, || path_frame(self.path_x)));
                    add(sum, self.throughput.as_ref(), &le, w);
                }
                let shape = &world.scene.shapes[hit.shape];
                let Some(material) = shape.material.map(|m| &world.scene.materials[m].material)
                else {
                    return Step::End;
                };
                if depth == max_depth {
                    return Step::End;
                }
                let bsdf = material.bsdf(hit.uv);
                let frame = Frame::new(shading_normal(&hit, &d, bsdf.is_two_sided()));
                Vertex::Surface {
                    bsdf,
                    wo: frame.to_local(&-d),
                    frame,
                    hit,
                }
            }
        };
        if depth == max_depth {
            return Step::End;
        }
        // The one rotation of this vertex: its output basis into the path frame
        // (none for scalar transport, which keeps only the rotation-invariant M00).
        let out_rotation = if R::MODEL == Polarization::None {
            (1.0, 0.0)
        } else {
            double_angle(&-d, &vertex.out_x(), &path_frame(self.path_x))
        };
        // An identity throughput (first vertex) sees unpolarized: the old choice.
        if R::MODEL != Polarization::None
            && vertex.chooses_lobes()
            && let Some(t) = &self.throughput
        {
            vertex.aim(&t.first_row(), out_rotation);
        }
        let to_path = |m: &Mueller| R::from_rotated(m, out_rotation);
        let light = NextEvent {
            world,
            vertex: &vertex,
            throughput: self.throughput.as_ref(),
            to_path: &to_path,
        };
        let environment = light.suns_and_shapes(sampler, sum);
        // Continue the path by sampling the BSDF or the phase function, or split it.
        let u = sampler.next_scatter(depth, vertex.chooses_lobes(), !vertex.is_delta());
        if let Some(u_light) = environment {
            light.environment(u_light, &u, sampler, sum);
        }
        if depth < world.scene.settings.split_depth
            && (depth == 0 || vertex.is_delta())
            && let Some([first, second]) = vertex.lobe_outcomes([u[1], u[2]])
        {
            // Both outcomes of the choice (its number u[0] unused): the second goes
            // on here, the first is split off.
            let split = first.map(|(p, s)| {
                let mut other = *self;
                other.follow_share(&vertex, s, p, &to_path, sampler);
                other
            });
            return match (second, split) {
                (Some((p, s)), split) => {
                    self.follow_share(&vertex, s, p, &to_path, sampler);
                    split.map_or(Step::Continue, Step::Split)
                }
                (None, Some(other)) => {
                    *self = other;
                    Step::Continue
                }
                (None, None) => Step::End,
            };
        }
        let Some(s) = vertex.sample(u) else {
            return Step::End;
        };
        if self.follow(&vertex, s, &to_path, sampler) {
            Step::Continue
        } else {
            Step::End
        }
    }

    /// Continues along an outcome `s` of a split lobe choice, weighted by its
    /// probability `p` (above Russian roulette's depth).
    #[inline(always)]
    fn follow_share(
        &mut self,
        vertex: &Vertex,
        mut s: Continuation,
        p: f64,
        to_path: &impl Fn(&Mueller) -> R,
        sampler: &mut Sampler,
    ) {
        debug_assert!(self.depth < RR_DEPTH);
        self.share *= p;
        s.weight *= p;
        self.follow(vertex, s, to_path, sampler);
    }

    /// Continues along `s` from `vertex` (Russian roulette from [`RR_DEPTH`] on);
    /// `false` if the path ends.
    #[inline(always)]
    fn follow(
        &mut self,
        vertex: &Vertex,
        s: Continuation,
        to_path: &impl Fn(&Mueller) -> R,
        sampler: &mut Sampler,
    ) -> bool {
        let weight = to_path(&s.weight);
        let mut t = self.throughput.map_or(weight, |t| t.then(&weight));
        self.path_x = Some(s.in_x);
        self.eta2 *= s.eta * s.eta;
        self.bounce = if s.is_delta {
            Bounce::Specular
        } else {
            Bounce::Smooth {
                pdf: s.pdf,
                p: vertex.p(),
                environment: vertex.environment_density(&s.wi, s.pdf),
            }
        };
        if self.depth >= RR_DEPTH {
            // Survival T00 · η² (as Mitsuba's path tracer): a transmitted throughput is
            // 1/η² of what the light will carry out again, so T00 alone would kill
            // 56 % of the paths inside glass of n = 1.5 that all escape with S0 intact.
            // A split path's throughput holds its share: survival as if it had been chosen.
            let q = (t.m00() * self.eta2 / self.share).clamp(0.0, 0.95);
            if sampler.next_1d() >= q {
                return false;
            }
            t = t.scaled(1.0 / q);
        }
        self.throughput = Some(t);
        self.o = vertex.spawn(&s.wi);
        self.d = s.wi;
        self.depth += 1;
        true
    }
}

/// One path sample along the primary direction `d0`: the Stokes vector arriving
/// at the camera, in the per-pixel camera frame (`film_frame(d0)`).
///
/// Above `split_depth` (default 5, where Russian roulette starts) both outcomes of
/// a lobe choice are traced, each weighted by its probability
/// ([`Bsdf::lobe_outcomes`]; branched path tracing): at the camera vertex of glass
/// (smooth) and plastic, and at every smooth-glass vertex, where a split costs only
/// ray segments (no light sampling at delta vertices). The expectation over the
/// choice instead of a draw: the front reflection carries most of glass's
/// polarization, the paths inside a glass object polarize differently with each
/// internal reflection, and plastic's two lobes polarize at right angles, so a
/// drawn choice is most of their polarization noise. A split-off path is traced
/// after the one it split from, with its own stream ([`Sampler::branch`]).
///
/// Work skipped without changing a bit of the result: the film frame is only
/// computed when something polarized or a vertex needs it (a primary ray that
/// sees an unpolarized environment never does), and the throughput is `None`
/// while it is the identity (products with it are copies). The path state is a
/// struct ([`PathState`]) so that a split copies it.
#[inline(always)]
pub(crate) fn radiance<R: Transport>(
    world: &World,
    d0: &Vec3,
    sampler: &mut Sampler,
    waiting: &mut SplitPaths<R>,
) -> Stokes {
    debug_assert!(waiting.0.is_empty());
    let mut sum = Stokes::zeros();
    let mut path = PathState::<R>::camera(world, d0);
    let mut splits = 0;
    loop {
        match path.step(world, d0, sampler, &mut sum) {
            Step::Continue => {}
            Step::Split(other) => {
                waiting.0.push((other, sampler.branch(splits)));
                splits += 1;
            }
            Step::End => match waiting.0.pop() {
                Some((other, stream)) => (path, *sampler) = (other, stream),
                None => return sum,
            },
        }
    }
}

/// Paths split off and waiting to be traced, last in first out, each with its own
/// stream. A path split off at depth d splits only deeper, so at most one per
/// depth above `split_depth` waits. The caller keeps it across samples, so that
/// no sample allocates.
pub(crate) struct SplitPaths<R>(Vec<(PathState<R>, Sampler)>);

impl<R> SplitPaths<R> {
    pub(crate) fn new() -> Self {
        Self(Vec::with_capacity(MAX_SPLIT_DEPTH as usize))
    }
}

/// The shading normal, flipped toward the viewer for a two-sided BSDF
/// ([`polar_bsdf::Bsdf::is_two_sided`]); a one-sided (transmissive) one keeps its
/// orientation, which tells inside from outside.
fn shading_normal(hit: &SurfaceHit, d: &Vec3, two_sided: bool) -> Vec3 {
    if two_sided && hit.ng.dot(d) > 0.0 {
        -hit.ns
    } else {
        hit.ns
    }
}
