//! Ray-geometry queries: primitives (triangles, analytic spheres) in a
//! compressed-wide BVH built once per scene with obvhs (PLOC builder), traversed
//! for the closest hit and, for shadow rays, for any hit.
//!
//! obvhs works in `f32`; the BVH only culls, and every primitive test (and the
//! final hit) is done in `f64` in the scene's own primitive list, which is
//! reordered once after the build to obvhs's primitive order.

use crate::math::Vec3;
use crate::scene::{Geometry, Scene};
use glam::Vec3A;
use obvhs::{
    Boundable, BvhBuildParams, aabb::Aabb, cwbvh::CwBvh, cwbvh::builder::build_cwbvh, ray::Ray,
    ray::RayHit,
};

/// One primitive of one shape.
#[derive(Clone, Debug)]
pub(crate) enum Primitive {
    /// Triangle `index` of a mesh shape, with its vertex positions.
    Triangle {
        /// Owning shape.
        shape: u32,
        /// Triangle index within the mesh.
        index: u32,
        /// Vertex positions.
        p: [Vec3; 3],
    },
    /// An analytic sphere shape.
    Sphere {
        /// Owning shape.
        shape: u32,
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f64,
    },
}

/// A surface point found by a ray.
#[derive(Clone, Debug)]
pub(crate) struct SurfaceHit {
    /// Position.
    pub p: Vec3,
    /// Geometric normal on the front side (winding order / outward).
    pub ng: Vec3,
    /// Shading normal (interpolated or exact), in the same hemisphere as `ng`.
    pub ns: Vec3,
    /// Texture coordinates (zero on a sphere whose material has no texture).
    pub uv: [f64; 2],
    /// Index of the shape hit.
    pub shape: usize,
}

impl Boundable for Primitive {
    fn aabb(&self) -> Aabb {
        let (lo, hi) = match self {
            Primitive::Triangle { p, .. } => {
                (p[0].inf(&p[1]).inf(&p[2]), p[0].sup(&p[1]).sup(&p[2]))
            }
            Primitive::Sphere { center, radius, .. } => {
                (center.add_scalar(-radius), center.add_scalar(*radius))
            }
        };
        // Pad outward so that rounding to f32 never shrinks the box.
        let pad = |v: Vec3, s: f64| {
            let c = v.map(|c| (c + s * 1e-6 * (1.0 + c.abs())) as f32);
            Vec3A::new(c.x, c.y, c.z)
        };
        Aabb::new(pad(lo, -1.0), pad(hi, 1.0))
    }
}

impl Primitive {
    /// Shape index.
    pub fn shape(&self) -> usize {
        match self {
            Primitive::Triangle { shape, .. } | Primitive::Sphere { shape, .. } => *shape as usize,
        }
    }

    /// Surface area.
    pub fn area(&self) -> f64 {
        match self {
            Primitive::Triangle { p, .. } => 0.5 * (p[1] - p[0]).cross(&(p[2] - p[0])).norm(),
            Primitive::Sphere { radius, .. } => 4.0 * std::f64::consts::PI * radius * radius,
        }
    }

    /// Nearest intersection in `(tmin, tmax)` as `(t, b1, b2)` (barycentrics for triangles).
    #[inline(always)]
    pub fn intersect(&self, o: &Vec3, d: &Vec3, tmin: f64, tmax: f64) -> Option<(f64, f64, f64)> {
        match self {
            Primitive::Triangle { p, .. } => {
                // Möller–Trumbore (1997).
                let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
                let pv = d.cross(&e2);
                let det = e1.dot(&pv);
                if det == 0.0 || !det.is_finite() {
                    return None;
                }
                let inv = 1.0 / det;
                let s = o - p[0];
                let b1 = s.dot(&pv) * inv;
                let q = s.cross(&e1);
                let b2 = d.dot(&q) * inv;
                let t = e2.dot(&q) * inv;
                (b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 && t > tmin && t < tmax)
                    .then_some((t, b1, b2))
            }
            Primitive::Sphere { center, radius, .. } => {
                // Stable quadratic for |d| = 1: t = -b ± sqrt(r² - |f - b d|²) with f = o - c, b = f·d.
                let f = o - center;
                let b = f.dot(d);
                let c = f.norm_squared() - radius * radius;
                // From outside (c > 0) moving away (b > 0) both roots are negative (product
                // c, sum −2b): no hit at t ≥ 0, known before the square root and division
                // (rays leaving a convex sphere after reflection, shadow rays from it).
                if c > 0.0 && b > 0.0 && tmin >= 0.0 {
                    return None;
                }
                let disc = radius * radius - (f - b * d).norm_squared();
                if disc < 0.0 {
                    return None;
                }
                let root = disc.sqrt();
                let q = -b - root.copysign(b);
                let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (c / q, q) };
                let (t0, t1) = (t0.min(t1), t0.max(t1));
                [t0, t1]
                    .into_iter()
                    .find(|t| *t > tmin && *t < tmax)
                    .map(|t| (t, 0.0, 0.0))
            }
        }
    }

    /// Uniformly samples a point on the surface: `(position, front normal)`.
    pub fn sample_point(&self, u: [f64; 2]) -> (Vec3, Vec3) {
        match self {
            Primitive::Triangle { p, .. } => {
                let s = u[0].sqrt();
                let (b1, b2) = (s * (1.0 - u[1]), s * u[1]);
                let pos = p[0] * (1.0 - b1 - b2) + p[1] * b1 + p[2] * b2;
                (pos, (p[1] - p[0]).cross(&(p[2] - p[0])).normalize())
            }
            Primitive::Sphere { center, radius, .. } => {
                let z = 1.0 - 2.0 * u[0];
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = std::f64::consts::TAU * u[1];
                let n = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                (center + *radius * n, n)
            }
        }
    }
}

/// A ray's closest primitive: its index, distance and barycentric coordinates.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PrimHit {
    pub prim: usize,
    pub t: f64,
    pub b1: f64,
    pub b2: f64,
}

/// The scene's primitives and their BVH.
pub(crate) struct Accel {
    /// `None` for at most [`BRUTE_FORCE_MAX`] primitives, which rays test one by one.
    bvh: Option<CwBvh>,
    /// Primitives in obvhs's order (index = obvhs primitive id).
    pub prims: Vec<Primitive>,
}

/// Up to this many primitives a ray tests each directly: a BVH traversal (f32
/// ray set-up, node tests) costs more than a few analytic tests. Measured on
/// the one-sphere cross-check scenes: see docs/performance-notes.md.
const BRUTE_FORCE_MAX: usize = 4;

/// Self-intersection guard for rays leaving a surface, relative to the scene scale.
pub(crate) const RAY_EPSILON: f64 = 1e-7;

impl Accel {
    /// Collects the primitives of `scene` and builds the BVH (medium-quality PLOC preset).
    pub fn build(scene: &Scene) -> Self {
        let mut prims = Vec::new();
        for (s, shape) in scene.shapes.iter().enumerate() {
            let shape_id = s as u32;
            match &shape.geometry {
                Geometry::Sphere { center, radius } => prims.push(Primitive::Sphere {
                    shape: shape_id,
                    center: *center,
                    radius: *radius,
                }),
                Geometry::Mesh(m) => {
                    prims.extend(
                        m.triangles
                            .iter()
                            .enumerate()
                            .map(|(i, t)| Primitive::Triangle {
                                shape: shape_id,
                                index: i as u32,
                                p: t.map(|v| m.positions[v as usize]),
                            }),
                    )
                }
            }
        }
        if prims.len() <= BRUTE_FORCE_MAX {
            return Self { bvh: None, prims };
        }
        let bvh = build_cwbvh(
            &prims,
            BvhBuildParams::medium_build(),
            &mut Default::default(),
        );
        let prims = bvh
            .primitive_indices
            .iter()
            .map(|&i| prims[i as usize].clone())
            .collect();
        Self {
            bvh: Some(bvh),
            prims,
        }
    }

    fn f32_ray(o: &Vec3, d: &Vec3, tmax: f64) -> Ray {
        let v = |v: &Vec3| Vec3A::new(v.x as f32, v.y as f32, v.z as f32);
        Ray::new(v(o), v(d), 0.0, tmax.min(f64::from(f32::MAX)) as f32)
    }

    /// Closest primitive hit along the unit direction `d` in `(tmin, tmax)`: `(primitive, t, b1, b2)`.
    #[inline(always)]
    pub fn closest(&self, o: &Vec3, d: &Vec3, tmin: f64, tmax: f64) -> Option<PrimHit> {
        let Some(bvh) = &self.bvh else {
            return self.closest_brute_force(o, d, tmin, tmax);
        };
        let mut hit = RayHit::none();
        // The closest candidate in f64, kept as found (no second intersection test).
        let mut best: Option<PrimHit> = None;
        bvh.ray_traverse(Self::f32_ray(o, d, tmax), &mut hit, |ray, id| {
            let limit = f64::from(ray.tmax).min(tmax);
            let Some((t, b1, b2)) = self.prims[id].intersect(o, d, tmin, limit * (1.0 + 1e-6))
            else {
                return f32::INFINITY;
            };
            if t < tmax && best.as_ref().is_none_or(|b| t < b.t) {
                best = Some(PrimHit {
                    prim: id,
                    t,
                    b1,
                    b2,
                });
            }
            t as f32
        });
        best
    }

    /// [`Self::closest`] by testing every primitive (small scenes).
    #[inline(always)]
    fn closest_brute_force(&self, o: &Vec3, d: &Vec3, tmin: f64, tmax: f64) -> Option<PrimHit> {
        let mut best: Option<PrimHit> = None;
        for (prim, p) in self.prims.iter().enumerate() {
            let limit = best.as_ref().map_or(tmax, |b| b.t);
            if let Some((t, b1, b2)) = p.intersect(o, d, tmin, limit) {
                best = Some(PrimHit { prim, t, b1, b2 });
            }
        }
        best
    }

    /// `true` when nothing blocks the segment from `o` along `d` over `(tmin, tmax)`.
    #[inline(always)]
    pub fn unoccluded(&self, o: &Vec3, d: &Vec3, tmin: f64, tmax: f64) -> bool {
        let Some(bvh) = &self.bvh else {
            return self
                .prims
                .iter()
                .all(|p| p.intersect(o, d, tmin, tmax).is_none());
        };
        bvh.ray_traverse_miss(Self::f32_ray(o, d, tmax), |_, id| {
            self.prims[id]
                .intersect(o, d, tmin, tmax)
                .map_or(f32::INFINITY, |_| 0.0)
        })
    }

    /// Full surface data of a hit on primitive `prim`.
    #[inline(always)]
    pub fn surface(&self, scene: &Scene, hit: PrimHit, o: &Vec3, d: &Vec3) -> SurfaceHit {
        let PrimHit { prim, t, b1, b2 } = hit;
        let p = o + t * d;
        let shape = self.prims[prim].shape();
        match &self.prims[prim] {
            Primitive::Sphere { center, .. } => {
                let n = (p - center).normalize();
                // Spherical coordinates cost an atan2 and an acos: only for textures.
                let uses_uv = scene.shapes[shape]
                    .material
                    .is_some_and(|m| scene.materials[m].material.uses_uv());
                let uv = if uses_uv {
                    let u = (n.y.atan2(n.x) / std::f64::consts::TAU).rem_euclid(1.0);
                    [u, n.z.clamp(-1.0, 1.0).acos() / std::f64::consts::PI]
                } else {
                    [0.0; 2]
                };
                SurfaceHit {
                    p,
                    ng: n,
                    ns: n,
                    uv,
                    shape,
                }
            }
            Primitive::Triangle { index, p: v, .. } => {
                let Geometry::Mesh(mesh) = &scene.shapes[shape].geometry else {
                    unreachable!("triangle of a non-mesh shape")
                };
                let tri = mesh.triangles[*index as usize].map(|i| i as usize);
                let w = [1.0 - b1 - b2, b1, b2];
                let mut ng = (v[1] - v[0]).cross(&(v[2] - v[0])).normalize();
                let ns = if mesh.normals.is_empty() {
                    ng
                } else {
                    let n: Vec3 = (0..3).map(|k| mesh.normals[tri[k]] * w[k]).sum();
                    let n = n.try_normalize(1e-12).unwrap_or(ng);
                    if n.dot(&ng) < 0.0 {
                        ng = -ng;
                    }
                    n
                };
                let uv = if mesh.uvs.is_empty() {
                    [b1, b2]
                } else {
                    [0, 1].map(|c| (0..3).map(|k| mesh.uvs[tri[k]][c] * w[k]).sum())
                };
                SurfaceHit {
                    p,
                    ng,
                    ns,
                    uv,
                    shape,
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Camera, Shape};

    fn scene(shapes: Vec<Geometry>) -> Scene {
        let mut scene = Scene::new(Camera {
            position: Vec3::new(0.0, 0.0, 5.0),
            look_at: Vec3::zeros(),
            up: Vec3::y(),
            fov_deg: 40.0,
            width: 8,
            height: 8,
        });
        scene.shapes = shapes.into_iter().map(|g| Shape::new(g, 0)).collect();
        scene
    }

    #[test]
    fn brute_force_finds_what_the_bvh_finds() {
        // Two overlapping spheres in front of a rectangle (4 primitives: tested one
        // by one); a fifth primitive, far behind the ray origins, switches on the BVH.
        let sphere = |x: f64, r: f64| Geometry::Sphere {
            center: Vec3::new(x, 0.0, 0.0),
            radius: r,
        };
        let wall = Geometry::Mesh(crate::shapes::rectangle().transformed(
            &crate::shapes::transform([0.0, 0.0, -2.0], [0.0; 3], [3.0; 3]),
        ));
        let small = scene(vec![sphere(-0.4, 1.0), sphere(0.6, 0.8), wall]);
        let mut big = small.clone();
        big.shapes.push(Shape::new(
            Geometry::Sphere {
                center: Vec3::new(0.0, 0.0, 100.0),
                radius: 1.0,
            },
            0,
        ));
        let (a, b) = (Accel::build(&small), Accel::build(&big));
        assert!(a.bvh.is_none() && b.bvh.is_some());
        let o = Vec3::new(0.1, 0.05, 5.0);
        let mut shapes_hit = [0; 3];
        for i in 0..400 {
            let (u, v) = ((i % 20) as f64 / 19.0 - 0.5, (i / 20) as f64 / 19.0 - 0.5);
            let d = Vec3::new(u, v, -1.0).normalize();
            let (ha, hb) = (
                a.closest(&o, &d, 0.0, f64::INFINITY),
                b.closest(&o, &d, 0.0, f64::INFINITY),
            );
            assert_eq!(ha.is_some(), hb.is_some(), "ray {i}");
            if let (Some(ha), Some(hb)) = (ha, hb) {
                let shape = a.prims[ha.prim].shape();
                assert_eq!(shape, b.prims[hb.prim].shape(), "ray {i}");
                // Same primitive test in f64 on both sides: the same distance.
                assert_eq!(ha.t, hb.t, "ray {i}");
                shapes_hit[shape] += 1;
                assert!(!a.unoccluded(&o, &d, 0.0, ha.t * 1.001), "ray {i}");
                assert!(a.unoccluded(&o, &d, 0.0, ha.t * 0.999), "ray {i}");
            }
        }
        assert!(shapes_hit.iter().all(|&n| n > 0), "{shapes_hit:?}");
    }
}
