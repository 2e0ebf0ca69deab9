//! Degenerate directions (normal incidence, exactly grazing, just above and
//! below the horizon, along the polarizer axis) and extreme random numbers
//! never give NaN, infinite or negative results.

mod common;

use common::*;

fn special_directions() -> Vec<V3> {
    let mut dirs = vec![V3::z(), -V3::z(), V3::x(), V3::y(), -V3::x()];
    for z in [1e-12_f64, -1e-12, 1e-6, -1e-6] {
        dirs.push(V3::new((1.0_f64 - z * z).sqrt(), 0.0, z));
    }
    dirs.push(dir(0.3, 45.0));
    dirs.push(dir(179.9, 10.0));
    dirs.push(V3::new(0.3_f64.cos(), 0.3_f64.sin(), 0.0));
    dirs
}

#[test]
fn degenerate_directions_give_finite_results() {
    let us = [0.0, 0.5, 1.0 - f64::EPSILON];
    for (name, bsdf) in all_bsdfs() {
        for wo in special_directions() {
            for wi in special_directions() {
                let m = bsdf.eval(&wo, &wi);
                let pdf = bsdf.pdf(&wo, &wi);
                assert!(
                    m.iter().all(|v| v.is_finite()),
                    "{name}: eval({wo:?}, {wi:?}) = {m}"
                );
                assert!(
                    m[(0, 0)] >= 0.0,
                    "{name}: negative intensity at {wo:?}, {wi:?}"
                );
                assert!(
                    pdf.is_finite() && pdf >= 0.0,
                    "{name}: pdf {pdf} at {wo:?}, {wi:?}"
                );
            }
            for u0 in us {
                for u1 in us {
                    for u2 in us {
                        let Some(s) = bsdf.sample(&wo, [u0, u1, u2]) else {
                            continue;
                        };
                        let ok = s.weight.iter().all(|v| v.is_finite())
                            && s.weight[(0, 0)] >= 0.0
                            && s.pdf.is_finite()
                            && s.pdf > 0.0
                            && (s.wi.norm() - 1.0).abs() < 1e-9
                            && s.eta.is_finite()
                            && s.eta > 0.0;
                        assert!(
                            ok,
                            "{name}: sample at wo={wo:?} u={:?}: {s:?}",
                            [u0, u1, u2]
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn is_delta_exactly_when_eval_is_zero_everywhere() {
    // A renderer skips light sampling on `is_delta`: that must lose nothing
    // (exact zeros), and smooth-lobed BSDFs must not claim it.
    for (name, bsdf) in delta_only() {
        assert!(bsdf.is_delta(), "{name}");
        for wo in special_directions() {
            for wi in special_directions() {
                assert_eq!(
                    bsdf.eval(&wo, &wi),
                    polar_optics::Mueller::zeros(),
                    "{name}"
                );
            }
        }
    }
    for (name, bsdf) in smooth_lobed() {
        assert!(!bsdf.is_delta(), "{name}");
    }
}
