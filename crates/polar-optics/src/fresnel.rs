//! Fresnel equations for dielectrics and conductors with a complex relative
//! index `η = n + ik`, as amplitudes and as Mueller matrices in the s/p frame.
//!
//! Frames: `s = normalize(n × k_in)` is shared by the incident, reflected and
//! transmitted beams; each beam's `p = k × s`, so `(s, p, k)` is right-handed and
//! the Stokes x axis is `s`. With this choice the p amplitude follows Hecht,
//! `r_p = (η cos θi − cos θt)/(η cos θi + cos θt)`, and normal incidence is
//! isotropic in the lab frame (`r_p = −r_s` there because `p_out = −p_in`).

use crate::block::BlockDiagonal;
use crate::mueller::Mueller;
use crate::stokes::Stokes;
use num_complex::Complex64;

/// Complex Fresnel amplitudes at one angle of incidence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FresnelAmplitudes {
    /// s (perpendicular) reflection amplitude.
    pub r_s: Complex64,
    /// p (parallel) reflection amplitude.
    pub r_p: Complex64,
    /// s transmission amplitude (ratio of electric fields).
    pub t_s: Complex64,
    /// p transmission amplitude (ratio of electric fields).
    pub t_p: Complex64,
    /// `η cos θt = sqrt(η² − sin² θi)` on the branch with `Im ≥ 0` (decaying wave).
    pub eta_cos_t: Complex64,
    /// The cosine of the angle of incidence used, clamped to `[0, 1]`.
    pub cos_i: f64,
}

/// Fresnel amplitudes for incidence cosine `cos_i` and relative index
/// `eta = n_t / n_i` (complex `n + ik`, `k ≥ 0`, for conductors).
///
/// `η cos θt` is computed as `sqrt(η² − sin²θi)` with the branch `Im ≥ 0`, which
/// is both the physical decaying wave for conductors and the evanescent wave of
/// total internal reflection; no division by `η` occurs, so `k → 0` and large
/// `k` are stable. With `c = cos θi`, `w = η cos θt` (Born & Wolf §1.5.2, Hecht (4.42)):
/// `r_s = (c − w)/(c + w)`, `r_p = (η² c − w)/(η² c + w)`, `t_s = 2c/(c + w)`,
/// `t_p = 2ηc/(η² c + w)`.
///
/// Edge cases (all without NaN): `cos_i` is clamped to `[0, 1]` (grazing `cos_i = 0`
/// gives `r_s = r_p = −1`); index matching `η = 1` returns `r = 0`, `t = 1` exactly;
/// `|η| > 1e30` or infinite is the perfect-conductor limit `r_s = −1`, `r_p = +1`
/// (`−1` at exactly grazing), `t = 0` (relative error `~1/|η|`, below `f64` precision),
/// so that `|η²|²` never overflows in the complex divisions. Undefined inputs give
/// NaN amplitudes: a NaN or infinite `cos_i`, or a NaN component of `eta`.
///
/// Inlined across crates (BSDF sampling's hot path): a caller that keeps only
/// the reflection amplitudes then skips the transmission ones.
#[inline(always)]
pub fn fresnel_amplitudes(cos_i: f64, eta: Complex64) -> FresnelAmplitudes {
    let zero = Complex64::new(0.0, 0.0);
    let one = Complex64::new(1.0, 0.0);
    if !cos_i.is_finite() || eta.is_nan() {
        let nan = Complex64::new(f64::NAN, f64::NAN);
        return FresnelAmplitudes {
            r_s: nan,
            r_p: nan,
            t_s: nan,
            t_p: nan,
            eta_cos_t: nan,
            cos_i: f64::NAN,
        };
    }
    let cos_i = cos_i.clamp(0.0, 1.0);
    let ci = Complex64::new(cos_i, 0.0);
    if eta == one {
        return FresnelAmplitudes {
            r_s: zero,
            r_p: zero,
            t_s: one,
            t_p: one,
            eta_cos_t: ci,
            cos_i,
        };
    }
    if eta.norm_sqr() > PERFECT_CONDUCTOR * PERFECT_CONDUCTOR {
        let r_p = if cos_i > 0.0 { one } else { -one };
        let eta_cos_t = Complex64::new(0.0, f64::INFINITY);
        return FresnelAmplitudes {
            r_s: -one,
            r_p,
            t_s: zero,
            t_p: zero,
            eta_cos_t,
            cos_i,
        };
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    if eta.im == 0.0 && cos_i > 0.0 && eta.re * eta.re > sin2_i {
        return real_amplitudes(cos_i, eta.re, sin2_i);
    }
    complex_amplitudes(cos_i, eta, sin2_i)
}

/// [`fresnel_amplitudes`] for a real index without total internal reflection, off
/// grazing (glass below the critical angle): the same formulas in real arithmetic, one
/// square root and two divisions instead of a complex square root and two complex
/// reciprocals. Equal to [`complex_amplitudes`] up to rounding (`1/x` rounds once where
/// the complex reciprocal `x/x²` rounds twice; the square roots agree exactly).
#[inline]
fn real_amplitudes(cos_i: f64, eta: f64, sin2_i: f64) -> FresnelAmplitudes {
    let w = (eta * eta - sin2_i).sqrt();
    let eta2_ci = eta * eta * cos_i;
    let (inv_s, inv_p) = (1.0 / (cos_i + w), 1.0 / (eta2_ci + w));
    let real = |x: f64| Complex64::new(x, 0.0);
    FresnelAmplitudes {
        r_s: real((cos_i - w) * inv_s),
        r_p: real((eta2_ci - w) * inv_p),
        t_s: real(2.0 * cos_i * inv_s),
        t_p: real(2.0 * eta * cos_i * inv_p),
        eta_cos_t: real(w),
        cos_i,
    }
}

/// [`fresnel_amplitudes`] in complex arithmetic (conductors, total internal reflection,
/// grazing incidence) for `cos_i` in `[0, 1]` and `sin2_i = 1 − cos_i²`.
#[inline(always)]
fn complex_amplitudes(cos_i: f64, eta: Complex64, sin2_i: f64) -> FresnelAmplitudes {
    let zero = Complex64::new(0.0, 0.0);
    let one = Complex64::new(1.0, 0.0);
    let ci = Complex64::new(cos_i, 0.0);
    let mut d = eta * eta - sin2_i;
    // Keep the branch cut on the correct side for real negative arguments (TIR).
    if d.im == 0.0 {
        d.im = 0.0;
    }
    let eta_cos_t = principal_sqrt(d);
    if cos_i == 0.0 {
        // Grazing: r = −1 exactly, as the quotients give it (the reciprocals below round).
        return FresnelAmplitudes {
            r_s: -one,
            r_p: -one,
            t_s: zero,
            t_p: zero,
            eta_cos_t,
            cos_i,
        };
    }
    let eta2_ci = eta * eta * cos_i;
    // r and t of one polarization share their denominator: one reciprocal each.
    let (inv_s, inv_p) = (recip(ci + eta_cos_t), recip(eta2_ci + eta_cos_t));
    let r_s = (ci - eta_cos_t) * inv_s;
    let r_p = (eta2_ci - eta_cos_t) * inv_p;
    let t_s = 2.0 * ci * inv_s;
    let t_p = 2.0 * eta * ci * inv_p;
    FresnelAmplitudes {
        r_s,
        r_p,
        t_s,
        t_p,
        eta_cos_t,
        cos_i,
    }
}

/// `1 / z` with one real division (num-complex's division has two); like it,
/// through `|z|²`, which the `|η| ≤ 1e30` bound keeps finite.
#[inline]
fn recip(z: Complex64) -> Complex64 {
    let k = 1.0 / z.norm_sqr();
    Complex64::new(z.re * k, -z.im * k)
}

/// The principal square root without trigonometry (num-complex goes through
/// polar form: atan2 and sin_cos): with `m = |z|`, `√z = (√((m+a)/2), sign(b) √((m−a)/2))`
/// for `z = a + ib`, taking the larger part first and the other as `b / 2t`
/// (no cancellation). `b = +0` on the negative real axis gives `+i√|a|`.
#[inline]
fn principal_sqrt(z: Complex64) -> Complex64 {
    let (a, b) = (z.re, z.im);
    // |z| directly where the squares neither overflow nor lose precision to
    // underflow (libm's hypot guards against both, at several times the cost).
    let m2 = a * a + b * b;
    let m = if (1e-290..1e290).contains(&m2) {
        m2.sqrt()
    } else {
        a.hypot(b)
    };
    if m == 0.0 {
        return Complex64::new(0.0, b);
    }
    if a >= 0.0 {
        let t = (0.5 * (m + a)).sqrt();
        Complex64::new(t, b / (2.0 * t))
    } else {
        let t = (0.5 * (m - a)).sqrt();
        Complex64::new(b.abs() / (2.0 * t), t.copysign(b))
    }
}

/// Above this `|η|` the interface is treated as a perfect conductor: the error is
/// `~1/|η|`, and the complex division by `η² cos θi + w` squares `|η|²`, which
/// overflows near `|η| = 1e77`.
const PERFECT_CONDUCTOR: f64 = 1e30;

impl FresnelAmplitudes {
    /// Power reflectances `(R_s, R_p)`.
    #[inline(always)]
    pub fn reflectance(&self) -> (f64, f64) {
        (self.r_s.norm_sqr(), self.r_p.norm_sqr())
    }

    /// Power transmittances `(T_s, T_p) = Re(η cos θt)/cos θi · |t|²` (energy flux
    /// across the interface, real `η` only); 0 at grazing incidence and under TIR.
    #[inline(always)]
    pub fn transmittance(&self) -> (f64, f64) {
        let f = self.flux_factor();
        (f * self.t_s.norm_sqr(), f * self.t_p.norm_sqr())
    }

    /// `Re(η cos θt) / cos θi`, the ratio of flux densities; 0 where `cos θi = 0`.
    fn flux_factor(&self) -> f64 {
        if self.cos_i > 0.0 {
            self.eta_cos_t.re.max(0.0) / self.cos_i
        } else {
            0.0
        }
    }

    /// Mueller matrix of specular reflection in the s/p frames (x = s).
    pub fn reflection_mueller(&self) -> Mueller {
        self.reflection_block().to_mueller()
    }

    /// [`Self::reflection_mueller`] in block-diagonal form, for the fast path.
    #[inline]
    pub fn reflection_block(&self) -> BlockDiagonal {
        BlockDiagonal::from_diagonal_jones(self.r_s, self.r_p)
    }

    /// First column of [`Self::reflection_mueller`], unpolarized unit light
    /// reflected: `((R_s + R_p)/2, (R_s − R_p)/2, 0, 0)` (what a lobe choice needs).
    #[inline(always)]
    pub fn reflected_unpolarized(&self) -> Stokes {
        let (r_s, r_p) = self.reflectance();
        Stokes::new(0.5 * (r_s + r_p), 0.5 * (r_s - r_p), 0.0, 0.0)
    }

    /// Phase retardance of reflection `arg(r_s) − arg(r_p)` wrapped to `(−π, π]`.
    /// Under total internal reflection (`η < 1`, `sin θi > η`) it obeys
    /// `tan(δ/2) = cos θi sqrt(sin²θi − η²) / sin²θi` (Born & Wolf §1.5.4).
    pub fn reflection_phase(&self) -> f64 {
        (self.r_s * self.r_p.conj()).arg()
    }

    /// Mueller matrix of specular transmission in the s/p frames (x = s), in
    /// units of energy flux (so that `R + T = 1` for a lossless dielectric).
    /// A renderer carrying radiance must further scale by `1/η²`.
    pub fn transmission_mueller(&self) -> Mueller {
        self.transmission_block().to_mueller()
    }

    /// First column of [`Self::transmission_mueller`], unpolarized unit light
    /// transmitted: `((T_s + T_p)/2, (T_s − T_p)/2, 0, 0)`. It is also the first row
    /// (the matrix is symmetric), so it is all a depolarizing lobe between two
    /// refractions needs, without the `S2, S3` block.
    #[inline(always)]
    pub fn transmitted_unpolarized(&self) -> Stokes {
        let (t_s, t_p) = self.transmittance();
        Stokes::new(0.5 * (t_s + t_p), 0.5 * (t_s - t_p), 0.0, 0.0)
    }

    /// [`Self::transmission_mueller`] in block-diagonal form, for the fast path.
    #[inline]
    pub fn transmission_block(&self) -> BlockDiagonal {
        let f = self.flux_factor().sqrt();
        BlockDiagonal::from_diagonal_jones(self.t_s * f, self.t_p * f)
    }
}

/// Mueller matrix of specular reflection in the s/p frames: shorthand for
/// `fresnel_amplitudes(cos_i, eta).reflection_mueller()`.
pub fn reflection_mueller(cos_i: f64, eta: Complex64) -> Mueller {
    fresnel_amplitudes(cos_i, eta).reflection_mueller()
}

/// Mueller matrix of specular transmission in the s/p frames (energy-flux units).
pub fn transmission_mueller(cos_i: f64, eta: Complex64) -> Mueller {
    fresnel_amplitudes(cos_i, eta).transmission_mueller()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transmitted_unpolarized_is_the_first_column_and_row() {
        // Two roundings apart (|t √f|² against f |t|²): 1e-15.
        for (cos_i, eta) in [(0.9, 1.5), (0.3, 1.5), (0.7, 1.0 / 1.5), (0.05, 2.4)] {
            let f = fresnel_amplitudes(cos_i, Complex64::new(eta, 0.0));
            let (m, s) = (f.transmission_mueller(), f.transmitted_unpolarized());
            assert!((m.column(0) - s).amax() < 1e-15, "cos {cos_i}, eta {eta}");
            assert!(
                (m.row(0).transpose() - s).amax() < 1e-15,
                "cos {cos_i}, eta {eta}"
            );
        }
    }

    #[test]
    fn reflected_unpolarized_is_the_first_column_and_completes_transmission() {
        // Column 0 of R plus flux T is unpolarized unit light for a lossless
        // interface (R_s + T_s = R_p + T_p = 1), also under TIR (no transmission);
        // 1e-15: a few roundings of numbers of order 1.
        for (cos_i, eta) in [(0.9, 1.5), (0.3, 1.5), (0.7, 1.0 / 1.5), (0.2, 1.0 / 1.5)] {
            let f = fresnel_amplitudes(cos_i, Complex64::new(eta, 0.0));
            let r = f.reflected_unpolarized();
            assert!((f.reflection_mueller().column(0) - r).amax() < 1e-15);
            let sum = r + f.transmitted_unpolarized();
            assert!(
                (sum - Stokes::x()).amax() < 1e-15,
                "cos {cos_i}, eta {eta}: {sum}"
            );
        }
    }

    #[test]
    fn flux_transmission_is_the_same_from_both_sides() {
        // Stokes relations: T_s, T_p and (without TIR, real amplitudes) t_s t_p are
        // symmetric, so the s/p-frame matrix is too; 1e-12: the other side's cosine,
        // from Snell's law, carries the rounding of 1 − cos² (2e-13 at cos 0.01).
        for eta in [1.5_f64, 1.0 / 1.5, 2.4] {
            for cos_1 in [1.0, 0.9, 0.5, 0.2, 0.01] {
                let sin2_2 = (1.0 - cos_1 * cos_1) / (eta * eta);
                if sin2_2 >= 1.0 {
                    continue;
                }
                let cos_2 = (1.0 - sin2_2).sqrt();
                let a = transmission_mueller(cos_1, Complex64::new(eta, 0.0));
                let b = transmission_mueller(cos_2, Complex64::new(1.0 / eta, 0.0));
                assert!((a - b).amax() < 1e-12, "eta {eta}, cos {cos_1}: {a} {b}");
            }
        }
    }

    #[test]
    fn real_index_fast_path_matches_the_complex_formulas() {
        // Glass from outside and inside below the critical angle, near index matching, and
        // Brewster's angle (r_p = 0, hence an absolute tolerance): 4e-16, about two ulps of
        // amplitudes of magnitude <= 2 (the complex reciprocal rounds twice, 1/x once).
        for eta in [1.5_f64, 1.0 / 1.5, 2.4, 1.0001, 0.9999, 1.33] {
            let brewster = 1.0 / (1.0 + eta * eta).sqrt();
            for cos_i in [1.0, 0.999, 0.9, brewster, 0.5, 0.2, 0.01, 1e-6] {
                let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
                if eta * eta <= sin2_i {
                    continue;
                }
                let (r, c) = (
                    real_amplitudes(cos_i, eta, sin2_i),
                    complex_amplitudes(cos_i, Complex64::new(eta, 0.0), sin2_i),
                );
                for (a, b) in [
                    (r.r_s, c.r_s),
                    (r.r_p, c.r_p),
                    (r.t_s, c.t_s),
                    (r.t_p, c.t_p),
                ] {
                    assert!(
                        (a - b).norm() <= 2e-16 * 2.0,
                        "eta {eta}, cos {cos_i}: {a} {b}"
                    );
                }
                assert_eq!(r.eta_cos_t, c.eta_cos_t, "eta {eta}, cos {cos_i}");
            }
        }
        // The dispatch: real index below the critical angle takes the fast path.
        let f = fresnel_amplitudes(0.5, Complex64::new(1.5, 0.0));
        assert_eq!(f, real_amplitudes(0.5, 1.5, 0.75));
    }

    #[test]
    fn principal_sqrt_matches_num_complex_in_every_quadrant() {
        // Relative 1e-15: a few ulps; both signs of zero imaginary parts on both real half-axes.
        let parts = [0.0, -0.0, 1e-300, 0.04, -0.3, 2.0, -7.5, 1e20, -1e20];
        for a in parts {
            for b in parts {
                let z = Complex64::new(a, b);
                let (got, want) = (principal_sqrt(z), z.sqrt());
                assert!(
                    (got - want).norm() <= 1e-15 * want.norm(),
                    "sqrt({z}) = {got}, num-complex {want}"
                );
                assert_eq!(got.im.is_sign_negative(), want.im.is_sign_negative(), "{z}");
            }
        }
    }
}
