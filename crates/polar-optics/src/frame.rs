//! Stokes reference frames: the step most polarized renderers get wrong, so it
//! lives here once. Frames are implicit: a frame is the x axis of the Stokes
//! basis for a given propagation direction `k`, with `y = k × x`.

use crate::mueller::{Mueller, rotator};
use nalgebra::Vector3;

/// A canonical x axis perpendicular to the propagation direction `k` (unit),
/// continuous except near one pole (Duff et al. 2017, "Building an orthonormal basis, revisited").
pub fn stokes_basis(k: &Vector3<f64>) -> Vector3<f64> {
    let sign = 1.0_f64.copysign(k.z);
    let a = -1.0 / (sign + k.z);
    let b = k.x * k.y * a;
    Vector3::new(1.0 + sign * k.x * k.x * a, sign * b, -sign * k.x)
}

/// The signed angle from `current` to `target` (both unit, perpendicular to `k`),
/// measured from x toward `y = k × x`.
pub fn basis_angle(k: &Vector3<f64>, current: &Vector3<f64>, target: &Vector3<f64>) -> f64 {
    let sin = current.cross(target).dot(k);
    let cos = current.dot(target);
    sin.atan2(cos)
}

/// Mueller matrix that re-expresses a Stokes vector travelling along `k` from the
/// frame with x axis `current` into the frame with x axis `target`.
pub fn rotate_stokes_basis(
    k: &Vector3<f64>,
    current: &Vector3<f64>,
    target: &Vector3<f64>,
) -> Mueller {
    rotator(basis_angle(k, current, target))
}

/// Re-expresses a Mueller matrix `m` whose input is in frame `in_current` (for
/// light along `in_k`) and whose output is in `out_current` (along `out_k`) so
/// that it takes input in `in_target` and gives output in `out_target`.
pub fn rotate_mueller_basis(
    m: &Mueller,
    in_k: &Vector3<f64>,
    in_current: &Vector3<f64>,
    in_target: &Vector3<f64>,
    out_k: &Vector3<f64>,
    out_current: &Vector3<f64>,
    out_target: &Vector3<f64>,
) -> Mueller {
    rotate_stokes_basis(out_k, out_current, out_target)
        * m
        * rotate_stokes_basis(in_k, in_target, in_current)
}
