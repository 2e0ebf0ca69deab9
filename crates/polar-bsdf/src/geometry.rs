//! Local-frame geometry shared by the BSDFs: mirror and refraction directions,
//! cosine-weighted hemisphere sampling, and the one recipe that turns an s/p
//! Fresnel Mueller matrix into the implicit Stokes bases of the BSDF interface.

use nalgebra::Vector3;
use polar_optics::frame::{double_angle, rotate_columns, rotate_rows};
use polar_optics::fresnel::fresnel_amplitudes;
use polar_optics::{BlockDiagonal, Mueller, Stokes, rotate_stokes, stokes_basis};
use std::f64::consts::{FRAC_1_PI, PI};

/// Local-frame vector.
pub(crate) type V3 = Vector3<f64>;

/// Below this squared length a cross product is treated as degenerate.
const DEGENERATE_SQ: f64 = 1e-24;

/// Mirror direction of `w` about the unit normal `m`: `2 (w·m) m − w`.
#[inline(always)]
pub(crate) fn reflect(w: &V3, m: &V3) -> V3 {
    2.0 * w.dot(m) * m - w
}

/// Mirror direction of `w` about the macro normal `z`.
pub(crate) fn reflect_z(w: &V3) -> V3 {
    V3::new(-w.x, -w.y, w.z)
}

/// Refraction of `w` (pointing away from the surface, `w·m > 0`) through the
/// interface with normal `m`, where `etap = n_other / n_w` (Snell). `None` under
/// total internal reflection.
#[inline(always)]
pub(crate) fn refract(w: &V3, m: &V3, etap: f64) -> Option<V3> {
    let cos_w = w.dot(m);
    let sin2_t = (1.0 - cos_w * cos_w).max(0.0) / (etap * etap);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(-w / etap + (cos_w / etap - cos_t) * m)
}

/// Cosine-weighted direction on the upper hemisphere (local frame, `z` up) from a point
/// `u` of the unit square: Malley's method, projecting Shirley and Chiu's concentric map
/// of the square onto the disk. That map keeps areas and has low distortion, so
/// stratified and low-discrepancy points stay well spread on the hemisphere (pbrt-v4's
/// `SampleCosineHemisphere`). The one cosine warp of the workspace (BSDFs and the
/// renderer's light sampling).
#[inline(always)]
pub fn cosine_hemisphere(u: [f64; 2]) -> V3 {
    let (a, b) = (2.0 * u[0] - 1.0, 2.0 * u[1] - 1.0);
    let (r, phi) = if a == 0.0 && b == 0.0 {
        (0.0, 0.0)
    } else if a.abs() > b.abs() {
        (a, 0.25 * PI * (b / a))
    } else {
        (b, 0.5 * PI - 0.25 * PI * (a / b))
    };
    let (x, y) = (r * phi.cos(), r * phi.sin());
    V3::new(x, y, (1.0 - x * x - y * y).max(0.0).sqrt())
}

/// Solid-angle density of [`cosine_hemisphere`]: `cos θ / π` (0 below the horizon).
#[inline(always)]
pub fn cosine_hemisphere_pdf(w: &V3) -> f64 {
    w.z.max(0.0) * FRAC_1_PI
}

/// The s axis of the plane of incidence spanned by `normal` and `k`: `normal × k`,
/// *not normalized* (it only feeds basis rotations, whose `double_angle` is
/// invariant to the length of its axes: a square root and a division saved);
/// any axis perpendicular to `k` when they are collinear (normal incidence,
/// where the Fresnel matrix is isotropic).
#[inline(always)]
pub(crate) fn s_axis(normal: &V3, k: &V3) -> V3 {
    let c = normal.cross(k);
    if c.norm_squared() > DEGENERATE_SQ {
        c
    } else {
        stokes_basis(k)
    }
}

/// The two basis changes that take a matrix with input x axis `s_in` (light
/// along `k_in`) and output x axis `s_out` (light along `k_out`) into the
/// interface's bases `stokes_basis(k_in)` and `stokes_basis(k_out)`, as
/// `(cos 2θ, sin 2θ)`: `(output, input)` for `rotator(output) · M · rotator(input)`.
#[inline(always)]
fn bsdf_rotations(k_in: &V3, s_in: &V3, k_out: &V3, s_out: &V3) -> ((f64, f64), (f64, f64)) {
    (
        double_angle(k_out, s_out, &stokes_basis(k_out)),
        double_angle(k_in, &stokes_basis(k_in), s_in),
    )
}

/// Re-expresses a Mueller matrix given with input x axis `s_in` (light along
/// `k_in`) and output x axis `s_out` (light along `k_out`) in the interface's
/// bases: `stokes_basis(k_in)` and `stokes_basis(k_out)`.
pub(crate) fn to_bsdf_bases(m: &Mueller, k_in: &V3, s_in: &V3, k_out: &V3, s_out: &V3) -> Mueller {
    let (out, inp) = bsdf_rotations(k_in, s_in, k_out, s_out);
    rotate_columns(&rotate_rows(m, out), inp)
}

/// [`to_bsdf_bases`] of the rank-one matrix `col · rowᵀ` (a depolarizing element
/// between two polarizing ones): rotating the two vectors instead of the product's
/// rows and columns takes 8 multiplications instead of 32. The row is a column
/// rotated by `−θ`: `(rowᵀ · R(θ))ᵀ = R(−θ) · row`.
#[inline(always)]
pub(crate) fn rank_one_to_bsdf_bases(
    col: &Stokes,
    row: &Stokes,
    k_in: &V3,
    s_in: &V3,
    k_out: &V3,
    s_out: &V3,
) -> Mueller {
    let (out, (ci, si)) = bsdf_rotations(k_in, s_in, k_out, s_out);
    rotate_stokes(col, out) * rotate_stokes(row, (ci, -si)).transpose()
}

/// Fresnel reflection at the (micro)normal `m` of light arriving along `-wi` and
/// leaving along `wo`, for relative index `eta = n_transmitted / n_incident`
/// (complex for conductors), in the BSDF bases.
#[inline(always)]
pub(crate) fn reflection(eta: num_complex::Complex64, m: &V3, wo: &V3, wi: &V3) -> Mueller {
    let f = fresnel_amplitudes(wi.dot(m).abs(), eta).reflection_block();
    from_sp_frame(&f, m, wo, wi)
}

/// Re-expresses a block-diagonal matrix `f` given in the s/p frame of the plane
/// of incidence at the (micro)normal `m` (light arriving along `-wi`, leaving
/// along `wo`; x = s on both sides) in the BSDF bases, without forming `f` as 4×4.
/// Inlined into the BSDFs: as a call, the smooth dielectric scene rendered 3% slower.
#[inline(always)]
pub(crate) fn from_sp_frame(f: &BlockDiagonal, m: &V3, wo: &V3, wi: &V3) -> Mueller {
    let k_in = -wi;
    let s = s_axis(m, &k_in);
    let (out, inp) = bsdf_rotations(&k_in, &s, wo, &s);
    f.rotated(out, inp)
}

/// Column 0 of [`from_sp_frame`] (light leaving along `wo`, any `wi` in the
/// plane of `m` and `wo`) from column 0 `c` in the s/p frame at `m`: the output
/// of the interface for unpolarized input, which only needs the output rotation.
#[inline(always)]
pub(crate) fn sp_column_to_wo_basis(c: &Stokes, m: &V3, wo: &V3) -> Stokes {
    rotate_stokes(c, double_angle(wo, &s_axis(m, wo), &stokes_basis(wo)))
}

/// Fresnel transmission (energy-flux units, no radiance scaling) at the
/// (micro)normal `m` of light arriving along `-wi` and leaving along `wo`, for the
/// real relative index `eta = n_wo_side / n_wi_side`, in the BSDF bases.
pub(crate) fn transmission(eta: f64, m: &V3, wo: &V3, wi: &V3) -> Mueller {
    let f = fresnel_amplitudes(wi.dot(m).abs(), eta.into()).transmission_block();
    from_sp_frame(&f, m, wo, wi)
}

/// A Mueller matrix that only keeps intensity: `value` at (0, 0), zero elsewhere
/// (an ideal depolarizer with gain `value`).
pub(crate) fn depolarizer(value: f64) -> Mueller {
    let mut m = Mueller::zeros();
    m[(0, 0)] = value;
    m
}
