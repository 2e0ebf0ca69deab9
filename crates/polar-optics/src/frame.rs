//! Stokes reference frames: the step most polarized renderers get wrong, so it
//! lives here once. Frames are implicit: a frame is the x axis of the Stokes
//! basis for a given propagation direction `k`, with `y = k × x`.

use crate::mueller::{Mueller, rotator_cos_sin};
use crate::stokes::Stokes;
use nalgebra::Vector3;

/// A canonical x axis perpendicular to the propagation direction `k` (unit),
/// continuous except near one pole (Duff et al. 2017, "Building an orthonormal basis, revisited").
#[inline]
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

/// `(cos 2θ, sin 2θ)` for the [`basis_angle`] θ, without trigonometry: with
/// `c = r cos θ = current · target` and `s = r sin θ`, `cos 2θ = (c² − s²) / r²` and
/// `sin 2θ = 2cs / r²`. `(1, 0)` (no rotation) when both vanish, as `atan2(0, 0) = 0`.
#[inline]
pub fn double_angle(k: &Vector3<f64>, current: &Vector3<f64>, target: &Vector3<f64>) -> (f64, f64) {
    let s = current.cross(target).dot(k);
    let c = current.dot(target);
    let r2 = c * c + s * s;
    if r2 > 0.0 {
        ((c * c - s * s) / r2, 2.0 * c * s / r2)
    } else {
        (1.0, 0.0)
    }
}

/// Mueller matrix that re-expresses a Stokes vector travelling along `k` from the
/// frame with x axis `current` into the frame with x axis `target`.
#[inline]
pub fn rotate_stokes_basis(
    k: &Vector3<f64>,
    current: &Vector3<f64>,
    target: &Vector3<f64>,
) -> Mueller {
    let (cos2, sin2) = double_angle(k, current, target);
    rotator_cos_sin(cos2, sin2)
}

/// `rotator(θ) · s` for `(cos 2θ, sin 2θ)`: a Stokes vector (or the transpose of a
/// Mueller row, with `−θ`) re-expressed in a rotated basis; only `S1` and `S2` mix.
#[inline]
pub fn rotate_stokes(s: &Stokes, (cos2, sin2): (f64, f64)) -> Stokes {
    Stokes::new(s.x, cos2 * s.y + sin2 * s.z, cos2 * s.z - sin2 * s.y, s.w)
}

/// `rotator(θ) · m` for `(cos 2θ, sin 2θ)`: only rows 1 and 2 mix.
#[inline]
pub fn rotate_rows(m: &Mueller, (cos2, sin2): (f64, f64)) -> Mueller {
    let mut r = *m;
    for j in 0..4 {
        let (a, b) = (m[(1, j)], m[(2, j)]);
        r[(1, j)] = cos2 * a + sin2 * b;
        r[(2, j)] = cos2 * b - sin2 * a;
    }
    r
}

/// `m · rotator(θ)` for `(cos 2θ, sin 2θ)`: only columns 1 and 2 mix.
#[inline]
pub fn rotate_columns(m: &Mueller, (cos2, sin2): (f64, f64)) -> Mueller {
    let mut r = *m;
    for i in 0..4 {
        let (a, b) = (m[(i, 1)], m[(i, 2)]);
        r[(i, 1)] = cos2 * a - sin2 * b;
        r[(i, 2)] = sin2 * a + cos2 * b;
    }
    r
}

/// Re-expresses a Mueller matrix `m` whose input is in frame `in_current` (for
/// light along `in_k`) and whose output is in `out_current` (along `out_k`) so
/// that it takes input in `in_target` and gives output in `out_target`:
/// `rotate_stokes_basis(out) · m · rotate_stokes_basis(in_k, in_target, in_current)`,
/// written as row and column mixes.
#[inline]
pub fn rotate_mueller_basis(
    m: &Mueller,
    in_k: &Vector3<f64>,
    in_current: &Vector3<f64>,
    in_target: &Vector3<f64>,
    out_k: &Vector3<f64>,
    out_current: &Vector3<f64>,
    out_target: &Vector3<f64>,
) -> Mueller {
    let rows = rotate_rows(m, double_angle(out_k, out_current, out_target));
    rotate_columns(&rows, double_angle(in_k, in_target, in_current))
}

/// Below this squared length `k_in × k_out` is treated as zero (forward or backward scattering).
const COLLINEAR_SQ: f64 = 1e-24;

/// The x axis of the scattering-plane frame: `normalize(k_in × k_out)`, the normal of the
/// plane holding both propagation directions (Bohren & Huffman's `e_⊥`, up to a sign that
/// does not change Stokes vectors). It is perpendicular to both directions, so it serves as
/// the x axis of the incident (`y = k_in × x`) and of the scattered frame (`y = k_out × x`).
/// Where `k_out = ±k_in` the plane is undefined and `stokes_basis(k_in)` is returned: every
/// phase matrix is invariant under that choice there (isotropic forward, `diag(a, a, −a, −a)`
/// backward).
#[inline]
pub fn scattering_axis(k_in: &Vector3<f64>, k_out: &Vector3<f64>) -> Vector3<f64> {
    let c = k_in.cross(k_out);
    let n2 = c.norm_squared();
    if n2 > COLLINEAR_SQ {
        c / n2.sqrt()
    } else {
        stokes_basis(k_in)
    }
}

/// Re-expresses a matrix `m` given in the scattering-plane frame (x axis
/// [`scattering_axis`] for both beams) in the implicit frames: input in
/// `stokes_basis(k_in)`, output in `stokes_basis(k_out)`. The one place every phase
/// matrix goes through.
#[inline(always)]
pub fn from_scattering_plane(m: &Mueller, k_in: &Vector3<f64>, k_out: &Vector3<f64>) -> Mueller {
    let s = scattering_axis(k_in, k_out);
    rotate_mueller_basis(
        m,
        k_in,
        &s,
        &stokes_basis(k_in),
        k_out,
        &s,
        &stokes_basis(k_out),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mueller::rotator;

    /// Unit vector from two angles.
    fn dir(theta: f64, phi: f64) -> Vector3<f64> {
        Vector3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        )
    }

    #[test]
    fn trig_free_rotations_match_the_angle_form() {
        // Axes perpendicular to k at arbitrary angles (also past ±90°, where sin 2θ changes sign);
        // 1e-14: a few ulps of the products in both forms.
        for (i, psi) in [0.0_f64, 0.4, 1.3, 1.9, 2.8, -0.7, -2.2, 3.1]
            .into_iter()
            .enumerate()
        {
            let k = dir(0.3 + 0.35 * i as f64, 1.1 * i as f64 - 2.0);
            let x = stokes_basis(&k);
            let y = k.cross(&x);
            let target = x * psi.cos() + y * psi.sin();
            let theta = basis_angle(&k, &x, &target);
            let expected = rotator(theta);
            assert!((rotate_stokes_basis(&k, &x, &target) - expected).amax() < 1e-14);
            let s = Stokes::new(1.0, 0.3, -0.4, 0.2);
            let rot = double_angle(&k, &x, &target);
            assert!((rotate_stokes(&s, rot) - expected * s).amax() < 1e-14);
            let m = Mueller::from_fn(|r, c| (r * 4 + c) as f64 * 0.1 - 0.7);
            let k2 = dir(1.0, 0.5 * i as f64);
            let x2 = stokes_basis(&k2);
            let t2 = (x2 * 0.6 + k2.cross(&x2) * 0.8).normalize();
            let full = rotate_mueller_basis(&m, &k2, &x2, &t2, &k, &x, &target);
            let product = expected * m * rotator(basis_angle(&k2, &t2, &x2));
            assert!((full - product).amax() < 1e-14, "psi {psi}");
        }
    }

    #[test]
    fn degenerate_axes_give_no_rotation() {
        let k = Vector3::z();
        assert_eq!(
            double_angle(&k, &Vector3::zeros(), &Vector3::x()),
            (1.0, 0.0)
        );
    }
}
