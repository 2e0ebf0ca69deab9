//! Polarization behaviour of the BSDFs against closed-form Fresnel optics, and
//! the honesty of each BSDF's [`Polarization`] class.

mod common;

use common::*;
use num_complex::Complex64;
use polar_bsdf::microfacet::Ggx;
use polar_bsdf::{Bsdf, Conductor, Dielectric, Plastic, Sheet, SheetKind};
use polar_optics::Polarization;
use polar_optics::frame::basis_angle;
use polar_optics::fresnel_amplitudes;
use polar_optics::mueller::couples_circular;
use polar_optics::stokes::{aolp, dolp, linear, unpolarized};
use polar_optics::{Mueller, Stokes, stokes_basis};

/// Exact optics in double precision: agreement to 1e-9 leaves room for the
/// frame rotations' rounding only.
const TOL: f64 = 1e-9;

/// The physical direction of the linear polarization of `s` travelling along `k`.
fn field_axis(k: &V3, s: &Stokes) -> V3 {
    let x = stokes_basis(k);
    let y = k.cross(&x);
    let psi = aolp(s[0], s[1], s[2]);
    x * psi.cos() + y * psi.sin()
}

/// Linear light of unit intensity polarized along `axis`, travelling along `k`, in the BSDF basis.
fn polarized_along(k: &V3, axis: &V3) -> Stokes {
    linear(1.0, basis_angle(k, &stokes_basis(k), axis))
}

/// The s axis of the plane containing the macro normal and `k`.
fn s_axis(k: &V3) -> V3 {
    V3::z().cross(k).normalize()
}

/// Output Stokes of a delta lobe chosen by `u0`, for input `input`.
fn delta_output(bsdf: &Bsdf, wo: &V3, u0: f64, input: impl Fn(&V3) -> Stokes) -> (V3, Stokes) {
    let s = bsdf.sample(wo, [u0, 0.5, 0.5]).expect("delta sample");
    assert!(s.is_delta);
    (s.wi, s.weight * s.pdf * input(&s.wi))
}

#[test]
fn brewster_reflection_is_fully_s_polarized() {
    let eta = 1.5_f64;
    let brewster = eta.atan().to_degrees();
    let glass = Bsdf::Dielectric(Dielectric {
        eta,
        roughness: None,
        importance: None,
    });
    let plastic = Bsdf::Plastic(Plastic {
        eta,
        roughness: None,
        albedo: 0.5,
        specular_prob: 0.5,
    });
    for (name, bsdf) in [("glass", glass), ("smooth plastic", plastic)] {
        for phi in [0.0, 30.0, 135.0, 270.0] {
            let wo = dir(brewster, phi);
            let (_, out) = delta_output(&bsdf, &wo, 0.0, |_| unpolarized(1.0));
            let d = dolp(out[0], out[1], out[2]);
            assert!((d - 1.0).abs() < TOL, "{name} phi {phi}: DoLP {d}");
            let along_s = field_axis(&wo, &out).dot(&s_axis(&wo)).abs();
            assert!(
                (along_s - 1.0).abs() < TOL,
                "{name} phi {phi}: field not along s ({along_s})"
            );
            let (r_s, _) =
                fresnel_amplitudes(brewster.to_radians().cos(), eta.into()).reflectance();
            assert!(
                (out[0] - 0.5 * r_s).abs() < TOL,
                "{name}: S0 {} vs R_s/2 {}",
                out[0],
                0.5 * r_s
            );
        }
    }
}

#[test]
fn conductor_turns_45_degree_linear_light_circular() {
    let eta = gold();
    let bsdf = Bsdf::Conductor(Conductor {
        eta,
        roughness: None,
    });
    for theta in [30.0, 60.0, 80.0] {
        let wo = dir(theta, 75.0);
        // Input linear at 45° between s and p of its own plane of incidence.
        let (_, out) = delta_output(&bsdf, &wo, 0.5, |wi| {
            let k = -wi;
            let s = s_axis(&k);
            polarized_along(&k, &(s + k.cross(&s)).normalize())
        });
        // In the s/p frame the input is (1, 0, 1, 0), so S0 = (|r_s|² + |r_p|²)/2
        // and S3 = Im(r_s conj(r_p)); rotations leave both unchanged.
        let f = fresnel_amplitudes(theta.to_radians().cos(), eta);
        let (r_s, r_p) = f.reflectance();
        let s3 = (f.r_s * f.r_p.conj()).im;
        assert!(
            (out[0] - 0.5 * (r_s + r_p)).abs() < TOL,
            "theta {theta}: S0 {}",
            out[0]
        );
        assert!(
            (out[3] - s3).abs() < TOL,
            "theta {theta}: S3 {} vs {s3}",
            out[3]
        );
        assert!(
            out[3].abs() / out[0] > 0.1,
            "theta {theta}: only {} circular",
            out[3] / out[0]
        );
    }
}

#[test]
fn plastic_diffuse_light_is_polarized_in_the_exit_plane() {
    let eta = 1.5_f64;
    let plastic = |albedo| Plastic {
        eta,
        roughness: Some(Ggx::new(0.3, 0.3)),
        albedo,
        specular_prob: 0.5,
    };
    // The diffuse lobe alone: the plastic minus its albedo-free (specular) self.
    let (full, specular) = (Bsdf::Plastic(plastic(0.7)), Bsdf::Plastic(plastic(0.0)));
    for theta in [20.0, 60.0, 85.0] {
        let wo = dir(theta, 210.0);
        let out = (full.eval(&wo, &V3::z()) - specular.eval(&wo, &V3::z())) * unpolarized(1.0);
        // The exit refraction sees unpolarized light inside: DoLP = (T_p − T_s)/(T_p + T_s).
        let (t_s, t_p) = fresnel_amplitudes(theta.to_radians().cos(), eta.into()).transmittance();
        let expected = (t_p - t_s) / (t_p + t_s);
        let d = dolp(out[0], out[1], out[2]);
        assert!(
            (d - expected).abs() < TOL,
            "theta {theta}: DoLP {d} vs {expected}"
        );
        let along_s = field_axis(&wo, &out).dot(&s_axis(&wo)).abs();
        assert!(
            along_s < 1e-6,
            "theta {theta}: diffuse polarization not in the exit plane ({along_s})"
        );
        let (t_in_s, t_in_p) = fresnel_amplitudes(1.0, eta.into()).transmittance();
        let s0 = 0.7 / std::f64::consts::PI * 0.5 * (t_in_s + t_in_p) * 0.5 * (t_s + t_p);
        assert!(
            (out[0] - s0).abs() < TOL,
            "theta {theta}: S0 {} vs {s0}",
            out[0]
        );
    }
}

#[test]
fn polarizer_sheet_transmits_along_its_projected_axis() {
    let angle = 0.3_f64;
    let sheet = Bsdf::Sheet(Sheet {
        kind: SheetKind::Polarizer,
        angle,
    });
    let axis = V3::new(angle.cos(), angle.sin(), 0.0);
    let mut rng = rng(3);
    for _ in 0..50 {
        let wo = sphere(&mut rng);
        let (wi, out) = delta_output(&sheet, &wo, 0.5, |_| unpolarized(1.0));
        assert_eq!(wi, -wo);
        let projected = (axis - axis.dot(&wo) * wo).normalize();
        assert!((out[0] - 0.5).abs() < TOL && (dolp(out[0], out[1], out[2]) - 1.0).abs() < TOL);
        assert!(
            (field_axis(&wo, &out).dot(&projected).abs() - 1.0).abs() < TOL,
            "wo {wo:?}"
        );
        // Malus: light along the axis passes, light across it is blocked.
        let (_, pass) = delta_output(&sheet, &wo, 0.5, |_| polarized_along(&wo, &projected));
        let (_, block) = delta_output(&sheet, &wo, 0.5, |_| {
            polarized_along(&wo, &wo.cross(&projected))
        });
        assert!(
            (pass[0] - 1.0).abs() < TOL && block[0].abs() < TOL,
            "{pass:?} {block:?}"
        );
    }
}

#[test]
fn quarter_wave_sheet_at_45_degrees_makes_circular_light() {
    let sheet = Bsdf::Sheet(Sheet {
        kind: SheetKind::Retarder {
            retardance: std::f64::consts::FRAC_PI_2,
        },
        angle: 0.0,
    });
    // Viewed along +z the BSDF basis is the tangent frame itself.
    let wo = V3::z();
    assert!((stokes_basis(&wo) - V3::x()).norm() < TOL);
    let (_, out) = delta_output(&sheet, &wo, 0.5, |_| {
        linear(1.0, std::f64::consts::FRAC_PI_4)
    });
    // polar-optics' convention: fast axis along x turns +45° light into S3 = −1.
    assert!(
        (out - Stokes::new(1.0, 0.0, 0.0, -1.0)).norm() < TOL,
        "{out:?}"
    );
}

/// All the Mueller matrices a BSDF produces for random directions: `eval` for
/// random pairs and sample weights for random `wo`.
fn matrices(bsdf: &Bsdf, seed: u64) -> Vec<Mueller> {
    let mut rng = rng(seed);
    let mut out = Vec::new();
    for _ in 0..500 {
        let (wo, wi) = if two_sided(bsdf) {
            (sphere(&mut rng), sphere(&mut rng))
        } else {
            (hemisphere(&mut rng), hemisphere(&mut rng))
        };
        out.push(bsdf.eval(&wo, &wi));
        out.extend(bsdf.sample(&wo, u3(&mut rng)).map(|s| s.weight));
    }
    out
}

#[test]
fn polarization_class_is_honest() {
    let extra = [
        (
            "half_wave",
            Bsdf::Sheet(Sheet {
                kind: SheetKind::Retarder {
                    retardance: std::f64::consts::PI,
                },
                angle: 0.4,
            }),
        ),
        (
            "plastic_eta_below_one",
            Bsdf::Plastic(Plastic {
                eta: 0.7,
                roughness: None,
                albedo: 0.5,
                specular_prob: 0.5,
            }),
        ),
        (
            "conductor_real_index",
            Bsdf::Conductor(Conductor {
                eta: Complex64::new(1.8, 0.0),
                roughness: None,
            }),
        ),
    ];
    for (name, bsdf) in all_bsdfs().into_iter().chain(extra) {
        let class = bsdf.polarization();
        let ms = matrices(&bsdf, 11);
        for m in &ms {
            // Relative tolerance for rounding in the frame rotations.
            let tol = 1e-12 * m.abs().max().max(1e-300);
            match class {
                Polarization::None => {
                    let off = (0..16)
                        .filter(|&i| i != 0)
                        .map(|i| m[i].abs())
                        .fold(0.0, f64::max);
                    assert!(off <= tol, "{name}: class None but polarizes: {m}");
                }
                Polarization::Linear => assert!(
                    !couples_circular(m, tol),
                    "{name}: class Linear but couples S3: {m}"
                ),
                Polarization::Full => {}
            }
        }
        if class == Polarization::Full && name != "conductor_real_index" {
            // Not a lazy over-claim: some configuration really couples S3 (a
            // conductor of real index is a documented over-claim).
            assert!(
                ms.iter().any(|m| couples_circular(m, 1e-6)),
                "{name}: class Full but never couples S3"
            );
        }
    }
}
