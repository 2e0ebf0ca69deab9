//! A scene prepared for rendering: BVH, camera, per-shape BSDF lookup and the
//! light-sampling tables.

use crate::camera::PinholeCamera;
use crate::geometry::{Accel, SurfaceHit};
use crate::math::Vec3;
use crate::sampler::Sampler;
use crate::scene::{Emission, Light, Scene};
use crate::tracking::{self, Flight};
use polar_optics::Stokes;
use polar_optics::sky::RayleighSky;

/// A light with extent, as the integrator picks it (uniformly among them; suns,
/// being delta lights, are not picked but all sampled at every vertex).
#[derive(Clone, Debug)]
enum LightRef {
    /// The environment (constant or sky), see [`Environment`].
    Environment,
    /// An emissive shape: its primitives (indices into `Accel::prims`) with an
    /// area CDF, and the total area.
    Area {
        shape: usize,
        prims: Vec<usize>,
        cdf: Vec<f64>,
        area: f64,
    },
}

/// Radiance arriving from infinitely far away.
enum Environment<'a> {
    /// The same Stokes radiance from every direction.
    Constant(Stokes),
    /// A polarized sky.
    Sky(&'a RayleighSky),
}

impl Environment<'_> {
    /// Stokes radiance propagating along `k`, in the frame `stokes_basis(k)`.
    fn radiance(&self, k: &Vec3) -> Stokes {
        match self {
            Environment::Constant(s) => *s,
            Environment::Sky(sky) => sky.radiance(k),
        }
    }
}

/// A sampled light direction.
pub(crate) struct LightSample {
    /// Unit direction from the shading point toward the light (world).
    pub wi: Vec3,
    /// Distance to the light point (infinite for environment and sun).
    pub dist: f64,
    /// Incident Stokes vector in the implicit frame of its propagation direction `-wi`.
    pub stokes: Stokes,
    /// Solid-angle density including the light choice; 1 for a sun (a delta
    /// distribution: no MIS).
    pub pdf: f64,
}

/// The prepared scene.
pub(crate) struct World<'a> {
    pub scene: &'a Scene,
    pub accel: Accel,
    pub camera: PinholeCamera,
    lights: Vec<LightRef>,
    /// Directional lights: unit direction toward the sun and its emission.
    suns: Vec<(Vec3, Emission)>,
    environment: Option<Environment<'a>>,
    /// Index in `lights` of each emissive shape (for MIS when a BSDF ray hits it).
    area_index: Vec<Option<usize>>,
    /// `true` for the dehazed ground truth: the camera segment of every path (camera to
    /// its first surface, or on to the environment) passes the medium without
    /// interacting; every later segment and every shadow ray still does.
    camera_segment_clear: bool,
}

/// What the light draw of a vertex picks among the lights with extent.
pub(crate) enum PickedLight {
    /// The environment, with the draw's 2-D point (the integrator chooses how to
    /// sample a direction toward it).
    Environment([f64; 2]),
    /// A point on an emissive shape.
    Area(LightSample),
}

impl<'a> World<'a> {
    /// Builds the BVH and light tables of a validated scene.
    pub fn new(scene: &'a Scene) -> Self {
        let accel = Accel::build(scene);
        let mut lights = Vec::new();
        let mut suns = Vec::new();
        let mut environment = None;
        for l in &scene.lights {
            match l {
                Light::Environment(e) => environment = Some(Environment::Constant(e.stokes())),
                Light::Sky(sky) => {
                    environment = Some(Environment::Sky(sky));
                    let sun = sky.sun_irradiance * sky.sun_transmittance();
                    suns.push((sky.sun_direction, Emission::unpolarized(sun)));
                }
                Light::Sun {
                    direction,
                    emission,
                } => suns.push((direction.normalize(), *emission)),
            }
        }
        if environment.is_some() {
            lights.push(LightRef::Environment);
        }
        let mut area_index = vec![None; scene.shapes.len()];
        for (s, shape) in scene.shapes.iter().enumerate() {
            if shape.emission.is_none_or(|e| e.value == 0.0) {
                continue;
            }
            let prims: Vec<usize> = (0..accel.prims.len())
                .filter(|&p| accel.prims[p].shape() == s)
                .collect();
            let cdf: Vec<f64> = prims
                .iter()
                .scan(0.0, |acc, &p| {
                    *acc += accel.prims[p].area();
                    Some(*acc)
                })
                .collect();
            let area = cdf.last().copied().unwrap_or(0.0);
            if area > 0.0 {
                area_index[s] = Some(lights.len());
                lights.push(LightRef::Area {
                    shape: s,
                    prims,
                    cdf,
                    area,
                });
            }
        }
        Self {
            camera: PinholeCamera::new(&scene.camera),
            scene,
            accel,
            lights,
            suns,
            environment,
            area_index,
            camera_segment_clear: false,
        }
    }

    /// This world with the camera segment of every path free of the medium (see
    /// [`crate::RenderOptions::dehazed`]).
    pub fn with_camera_segment_clear(self) -> Self {
        Self {
            camera_segment_clear: true,
            ..self
        }
    }

    /// Closest surface along a unit direction.
    #[inline(always)]
    pub fn intersect(&self, o: &Vec3, d: &Vec3) -> Option<SurfaceHit> {
        let hit = self.accel.closest(o, d, 0.0, f64::INFINITY)?;
        Some(self.accel.surface(self.scene, hit, o, d))
    }

    /// The first scattering event along `o + t d` before the surface `hit` (if any),
    /// or passing through (always `Pass` with weight 1, drawing no random numbers,
    /// without a medium, or on the `camera_segment` of a world whose camera segment
    /// is clear: the distance to the hit is only computed with one).
    #[inline(always)]
    pub fn flight(
        &self,
        o: &Vec3,
        d: &Vec3,
        hit: Option<&SurfaceHit>,
        camera_segment: bool,
        sampler: &mut Sampler,
    ) -> Flight<'a> {
        match &self.scene.medium {
            Some(m) if !(camera_segment && self.camera_segment_clear) => {
                let t_max = hit.map_or(f64::INFINITY, |h| (h.p - o).norm());
                tracking::flight(m, o, d, t_max, sampler)
            }
            _ => Flight::Pass { weight: 1.0 },
        }
    }

    /// Transmittance (or its unbiased estimate) of the segment `o + t d`, `t < t_max`.
    pub fn transmittance(&self, o: &Vec3, d: &Vec3, t_max: f64, sampler: &mut Sampler) -> f64 {
        self.scene
            .medium
            .as_ref()
            .map_or(1.0, |m| tracking::transmittance(m, o, d, t_max, sampler))
    }

    /// Environment radiance propagating along `k` (Stokes in the implicit frame of
    /// `k`), if there is an environment.
    pub fn environment(&self, k: &Vec3) -> Option<Stokes> {
        self.environment.as_ref().map(|e| e.radiance(k))
    }

    /// Emitted Stokes leaving the front side of `hit` toward `-d`.
    pub fn emitted(&self, hit: &SurfaceHit, d: &Vec3) -> Option<Stokes> {
        let e = self.scene.shapes[hit.shape].emission?;
        (hit.ng.dot(d) < 0.0).then(|| e.stokes())
    }

    fn pick_probability(&self) -> f64 {
        1.0 / self.lights.len() as f64
    }

    /// Density (solid angle, with the light choice) with which light sampling reaches
    /// the environment in a direction that the integrator's environment sampling
    /// draws with density `density`.
    pub fn environment_pdf(&self, density: f64) -> f64 {
        self.pick_probability() * density
    }

    /// Density of reaching `hit` on an emissive shape from `from` by light sampling.
    pub fn area_pdf(&self, hit: &SurfaceHit, from: &Vec3) -> f64 {
        let Some(LightRef::Area { area, .. }) = self.area_index[hit.shape].map(|i| &self.lights[i])
        else {
            return 0.0;
        };
        let to = hit.p - from;
        let cos = hit.ng.dot(&to.normalize()).abs();
        if cos == 0.0 {
            0.0
        } else {
            self.pick_probability() * to.norm_squared() / (cos * area)
        }
    }

    /// Every sun as a light sample (delta lights cost no sampling and each is
    /// taken at every vertex: lower variance than picking them with the others).
    pub fn sun_samples(&self) -> impl Iterator<Item = LightSample> + '_ {
        self.suns.iter().map(|(dir, e)| LightSample {
            wi: *dir,
            dist: f64::INFINITY,
            stokes: e.stokes(),
            pdf: 1.0,
        })
    }

    /// Picks one light with extent (environment or emissive shape) with draw `u` and
    /// samples a point on it as seen from `p` (visibility not tested); suns are in
    /// [`Self::sun_samples`].
    #[inline(always)]
    pub fn sample_light(&self, p: &Vec3, u: [f64; 3]) -> Option<PickedLight> {
        if self.lights.is_empty() {
            return None;
        }
        let pick = self.pick_probability();
        let index = ((u[0] * self.lights.len() as f64) as usize).min(self.lights.len() - 1);
        match &self.lights[index] {
            LightRef::Environment => Some(PickedLight::Environment([u[1], u[2]])),
            LightRef::Area {
                shape,
                prims,
                cdf,
                area,
            } => {
                // Reuse u[1] to pick the primitive, then rescale it for the point.
                let target = u[1] * area;
                let k = cdf.partition_point(|c| *c <= target).min(prims.len() - 1);
                let lo = if k == 0 { 0.0 } else { cdf[k - 1] };
                let v = ((target - lo) / (cdf[k] - lo)).clamp(0.0, 1.0);
                let (q, nl) = self.accel.prims[prims[k]].sample_point([v, u[2]]);
                let to = q - p;
                let dist = to.norm();
                let wi = to / dist;
                let cos = -nl.dot(&wi);
                let e = self.scene.shapes[*shape].emission?;
                (cos > 0.0 && dist > 0.0).then(|| {
                    PickedLight::Area(LightSample {
                        wi,
                        dist,
                        stokes: e.stokes(),
                        pdf: pick * dist * dist / (cos * area),
                    })
                })
            }
        }
    }
}
