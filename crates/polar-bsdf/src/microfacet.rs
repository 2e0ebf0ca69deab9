//! The anisotropic GGX (Trowbridge–Reitz) microfacet distribution with Smith
//! masking, as in Walter et al. 2007 and Heitz 2014, and visible-normal sampling
//! (Heitz 2018, "Sampling the GGX Distribution of Visible Normals").
//!
//! Masking–shadowing is Smith's *separable* form `G = G1(wo) G1(wi)`, the form
//! Mitsuba 3 uses, so that the cross-check compares like with like.

use crate::geometry::V3;
use std::f64::consts::PI;

/// Smallest roughness used for a rough lobe; below it GGX is numerically a delta.
pub const MIN_ALPHA: f64 = 1e-4;

/// GGX distribution in the local shading frame; `alpha_x` acts along the tangent x.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    /// Roughness (slope scale) along the tangent x.
    pub alpha_x: f64,
    /// Roughness along y = z × x.
    pub alpha_y: f64,
}

impl Ggx {
    /// A distribution with both roughnesses clamped to at least [`MIN_ALPHA`].
    pub fn new(alpha_x: f64, alpha_y: f64) -> Self {
        Self {
            alpha_x: alpha_x.max(MIN_ALPHA),
            alpha_y: alpha_y.max(MIN_ALPHA),
        }
    }

    /// Normal distribution `D(m) = 1 / (π αx αy (mx²/αx² + my²/αy² + mz²)²)`; 0 for `mz ≤ 0`.
    pub fn d(&self, m: &V3) -> f64 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let e = (m.x / self.alpha_x).powi(2) + (m.y / self.alpha_y).powi(2) + m.z * m.z;
        1.0 / (PI * self.alpha_x * self.alpha_y * e * e)
    }

    /// Smith `Λ(v) = (sqrt(1 + (αx² vx² + αy² vy²) / vz²) − 1) / 2`.
    fn lambda(&self, v: &V3) -> f64 {
        let t2 = ((self.alpha_x * v.x).powi(2) + (self.alpha_y * v.y).powi(2)) / (v.z * v.z);
        0.5 * ((1.0 + t2).sqrt() - 1.0)
    }

    /// Smith masking `G1(v, m) = 1 / (1 + Λ(v))`, 0 unless `v` sees the front of
    /// `m` from the same side as the macro surface (`(v·m)(v·z) > 0`).
    #[inline(always)]
    pub fn g1(&self, v: &V3, m: &V3) -> f64 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        1.0 / (1.0 + self.lambda(v))
    }

    /// Separable masking–shadowing `G1(wo, m) G1(wi, m)`.
    #[inline(always)]
    pub fn g(&self, wo: &V3, wi: &V3, m: &V3) -> f64 {
        self.g1(wo, m) * self.g1(wi, m)
    }

    /// A microfacet normal (with `mz > 0`) drawn from the visible normals seen
    /// from `v` (or from `-v` when `v` lies below the surface), Heitz 2018.
    #[inline(always)]
    pub fn sample_visible(&self, v: &V3, u: [f64; 2]) -> V3 {
        let v = if v.z < 0.0 { -v } else { *v };
        let vh = V3::new(self.alpha_x * v.x, self.alpha_y * v.y, v.z).normalize();
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = if len2 > 0.0 {
            V3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
        } else {
            V3::x()
        };
        let t2 = vh.cross(&t1);
        let r = u[0].sqrt();
        let (sin_phi, cos_phi) = (2.0 * PI * u[1]).sin_cos();
        let p1 = r * cos_phi;
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * sin_phi;
        let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
        V3::new(self.alpha_x * nh.x, self.alpha_y * nh.y, nh.z.max(0.0)).normalize()
    }

    /// Density of [`Self::sample_visible`] over microfacet normals:
    /// `G1(v, m) |v·m| D(m) / |vz|`.
    #[inline(always)]
    pub fn pdf_visible(&self, v: &V3, m: &V3) -> f64 {
        if v.z == 0.0 {
            return 0.0;
        }
        self.g1(v, m) * v.dot(m).abs() * self.d(m) / v.z.abs()
    }
}
