//! Choosing between two lobes for what the camera measures.
//!
//! Light `c_k` that lobe `k` sends along `wo` (its Mueller column for
//! unpolarized unit input, in the output basis of `wo`) reaches the camera as
//! the S0 `t · c_k`, with `t` the first row of the path throughput expressed in
//! the same basis. The unpolarized choice weighs the lobes by their own `c_k,0`;
//! polarization makes that suboptimal because `(T M)_00 ≠ T_00 M_00`. Here
//! `p_k ∝ p_k,old · (t · c_k) / c_k,0`: the old choice reweighted by how much of
//! the lobe's light the camera keeps. For glass (`p_k,old ∝ c_k,0`) this is
//! `p_k ∝ t · c_k` with transmission in flux units (no `1/η²`): with incident
//! radiance proportional to `n²` on each side (the equilibrium of a lossless
//! scene in a constant environment), the path's expected S0 is then the same
//! whichever lobe is taken, so the lobe choice adds no variance to S0.

use polar_optics::Stokes;

/// Floor of a lobe's camera response relative to its unpolarized one,
/// `t · c_k ≥ FLOOR · t_0 c_k,0`. For a physical row (`t_0 ≥ |t_1..3|`) and
/// Stokes vector `t · c ≥ 0`, zero only when the lobe sends nothing to the
/// camera; rounding in a long product of matrices can leave a residue of either
/// sign there, and the weight `M_k / p_k` of a lobe chosen with a residue-sized
/// probability would blow the residue's unphysical S1..S3 up. The floor bounds
/// that weight to `1/FLOOR` times the unpolarized one and moves every other
/// choice by a relative 1e-6 at most.
const FLOOR: f64 = 1e-6;

/// Probability of choosing the first of two lobes given `p_first`, the
/// probability without polarization, the lobes' columns `c_first` and
/// `c_second` for unpolarized input, and the camera row `t` (module doc).
/// Falls back to `p_first` when `t_0 ≤ 0` (nothing reaches the camera) or a
/// lobe's `c_0` vanishes where the old choice still picks it.
#[inline(always)]
pub(crate) fn first_lobe_probability(
    p_first: f64,
    c_first: &Stokes,
    c_second: &Stokes,
    t: &Stokes,
) -> f64 {
    let response = |p: f64, c: &Stokes| {
        if p > 0.0 {
            p / c[0] * t.dot(c).max(FLOOR * t[0] * c[0])
        } else {
            0.0
        }
    };
    let (a, b) = (
        response(p_first, c_first),
        response(1.0 - p_first, c_second),
    );
    let p = a / (a + b);
    if t[0] > 0.0 && p.is_finite() {
        p
    } else {
        p_first
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unpolarized_row_keeps_the_old_choice() {
        let (c1, c2) = (
            Stokes::new(0.2, 0.1, 0.0, 0.0),
            Stokes::new(0.8, -0.1, 0.0, 0.0),
        );
        let p = first_lobe_probability(0.2, &c1, &c2, &Stokes::new(3.0, 0.0, 0.0, 0.0));
        assert!((p - 0.2).abs() < 1e-15, "{p}");
    }

    #[test]
    fn glass_choice_is_proportional_to_the_camera_response() {
        // c1 + c2 = e0, as reflection and flux transmission of a lossless interface.
        let (c1, c2) = (
            Stokes::new(0.2, 0.1, 0.0, 0.0),
            Stokes::new(0.8, -0.1, 0.0, 0.0),
        );
        let t = Stokes::new(1.0, 0.9, 0.3, 0.0);
        let p = first_lobe_probability(0.2, &c1, &c2, &t);
        assert!((p - t.dot(&c1) / t[0]).abs() < 1e-15, "{p}");
    }

    #[test]
    fn crossed_lobe_keeps_the_floor_and_dead_row_falls_back() {
        // A fully s-polarized lobe seen through a p analyser: response 0.
        let (c1, c2) = (
            Stokes::new(0.1, 0.1, 0.0, 0.0),
            Stokes::new(0.9, -0.1, 0.0, 0.0),
        );
        let p = first_lobe_probability(0.1, &c1, &c2, &Stokes::new(1.0, -1.0, 0.0, 0.0));
        assert!(p > 0.0 && p < 1e-5, "{p}");
        let zero = first_lobe_probability(0.1, &c1, &c2, &Stokes::zeros());
        assert_eq!(zero, 0.1);
        let nan = first_lobe_probability(0.1, &c1, &c2, &Stokes::repeat(f64::NAN));
        assert_eq!(nan, 0.1);
    }
}
