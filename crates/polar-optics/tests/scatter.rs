//! Phase matrices: normalisation, sampling against the pdf, Rayleigh's polarization
//! in the plane and world frames, realizability of depolarized Henyey–Greenstein and Mie,
//! and the hard cases (forward/backward scattering, rounding outside [−1, 1],
//! `|g| → 1`, `g = 0`, depolarization 0 and 1, bad parameters).

use nalgebra::Vector3;
use num_complex::Complex64;
use polar_optics::frame::{basis_angle, scattering_axis};
use polar_optics::scatter::{MieTable, PhaseFunction};
use polar_optics::stokes::{aolp, dolp, linear, unpolarized};
use polar_optics::validity::is_realizable;
use polar_optics::{Mueller, OpticsError, Stokes, stokes_basis};
use polar_testkit::{chi2_critical, pearson};
use std::f64::consts::PI;
use std::sync::Arc;

type V3 = Vector3<f64>;

/// SplitMix64: a small seeded generator, enough for histograms.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn sphere(&mut self) -> V3 {
        let z = 2.0 * self.next() - 1.0;
        let phi = 2.0 * PI * self.next();
        let r = (1.0 - z * z).sqrt();
        V3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

fn hg(g: f64, d: f64) -> PhaseFunction {
    PhaseFunction::henyey_greenstein(g, d).unwrap()
}

fn mie(x: f64, n: f64, k: f64) -> PhaseFunction {
    let p = PhaseFunction::mie(x, Complex64::new(n, k)).unwrap();
    assert_eq!(
        p,
        PhaseFunction::Mie(Arc::new(MieTable::new(x, Complex64::new(n, k)).unwrap()))
    );
    p
}

/// Every configuration under test, by name, including the extreme asymmetries.
fn phase_functions() -> Vec<(String, PhaseFunction)> {
    let mut v = vec![("rayleigh".to_string(), PhaseFunction::Rayleigh)];
    for g in [0.0, 0.3, -0.6, 0.9, 0.999, -0.999] {
        for d in [0.0, 0.4, 1.0] {
            v.push((format!("hg g={g} d={d}"), hg(g, d)));
        }
    }
    for (x, n, k) in [(0.5, 1.33, 0.0), (10.0, 1.5, 0.01), (40.0, 1.33, 0.0)] {
        v.push((format!("mie x={x} m={n}+{k}i"), mie(x, n, k)));
    }
    v
}

/// `θ(t) = π (1 − cos πt)/2`: dense near both poles, where the peaks of `|g| → 1` lie.
fn theta_of(t: f64) -> f64 {
    0.5 * PI * (1.0 - (PI * t).cos())
}

/// `∫ f(cos θ) dΩ` over `t ∈ [t0, t1]` by the midpoint rule in `t` (`n` points).
fn integrate(f: impl Fn(f64) -> f64, t0: f64, t1: f64, n: usize) -> f64 {
    let h = (t1 - t0) / n as f64;
    (0..n)
        .map(|i| {
            let t = t0 + (i as f64 + 0.5) * h;
            let theta = theta_of(t);
            let dtheta = 0.5 * PI * PI * (PI * t).sin();
            f(theta.cos()) * 2.0 * PI * theta.sin() * dtheta * h
        })
        .sum()
}

#[test]
fn m00_integrates_to_one_and_mean_cosine_matches() {
    for (name, p) in phase_functions() {
        // 2e5 points put ≥ 7000 inside the narrowest peak (g = 0.999, width ~0.045 rad):
        // midpoint error well below 1e-8; 1e-7 leaves room for the sum's rounding.
        let norm = integrate(|mu| p.plane_matrix(mu)[(0, 0)], 0.0, 1.0, 200_000);
        assert!((norm - 1.0).abs() < 1e-7, "{name}: ∫M00 dΩ = {norm}");
        let g = integrate(|mu| p.pdf(mu) * mu, 0.0, 1.0, 200_000);
        // Mie: the table's <cos θ> against the series value, within its interpolation error.
        let tol = if p.couples_circular() { 1e-4 } else { 1e-7 };
        assert!(
            (g - p.mean_cosine()).abs() < tol,
            "{name}: <cos> = {g} vs {}",
            p.mean_cosine()
        );
    }
}

#[test]
fn pdf_is_m00_and_sample_reports_it() {
    let mut rng = Rng(3);
    for (name, p) in phase_functions() {
        for _ in 0..2000 {
            let k_in = rng.sphere();
            let (k_out, pdf) = p.sample(&k_in, [rng.next(), rng.next()]);
            assert!(
                (k_out.norm() - 1.0).abs() < 1e-12,
                "{name}: |k_out| = {}",
                k_out.norm()
            );
            let mu = k_in.dot(&k_out);
            // Relative 1e-9: k_in·k_out differs from the sampled cosine by rounding,
            // amplified by d ln p/dμ ≤ 3/(1 − |g|)² ≈ 3e6 at g = 0.999.
            assert!(
                (p.pdf(mu) - pdf).abs() <= 1e-9 * pdf,
                "{name}: {} vs {pdf}",
                p.pdf(mu)
            );
            let m00 = p.eval(&k_in, &k_out)[(0, 0)];
            assert!(
                (m00 - pdf).abs() <= 1e-9 * pdf,
                "{name}: M00 {m00} vs pdf {pdf}"
            );
        }
    }
}

#[test]
fn sampling_inverts_the_closed_form_cdf() {
    // Rayleigh F(μ) = (μ³ + 3μ + 4)/8; HG F(μ) = (1 − g²)/(2g) (1/√(1 + g² − 2gμ) − 1/(1 + g)).
    // 1e-12: a few ulps of the Cardano / HG inversions, amplified by 1/(1 + |g|)... at most ~2.
    let hg_cdf = |g: f64, mu: f64| {
        (1.0 - g * g) / (2.0 * g) * (1.0 / (1.0 + g * g - 2.0 * g * mu).sqrt() - 1.0 / (1.0 + g))
    };
    for i in 0..=1000 {
        let u = i as f64 / 1000.0;
        let mu = PhaseFunction::Rayleigh.sample_cos_theta(u);
        assert!(
            ((mu.powi(3) + 3.0 * mu + 4.0) / 8.0 - u).abs() < 1e-12,
            "u {u}: μ {mu}"
        );
        for g in [0.3, -0.6, 0.9] {
            let mu = hg(g, 0.0).sample_cos_theta(u);
            assert!((hg_cdf(g, mu) - u).abs() < 1e-12, "g {g} u {u}: μ {mu}");
        }
    }
    assert_eq!(PhaseFunction::Rayleigh.sample_cos_theta(0.0), -1.0);
    assert_eq!(PhaseFunction::Rayleigh.sample_cos_theta(1.0), 1.0);
}

const T_BINS: usize = 60;
const PHI_BINS: usize = 12;
const SAMPLES: usize = 200_000;
/// Chi-square test of `sample` against `pdf` over (t, φ) bins, φ measured about `k_in`
/// from `stokes_basis(k_in)`; Wilson–Hilferty quantile at 1 − 1e-3.
#[test]
fn chi_square_sampling_against_pdf() {
    let k_ins = [V3::z(), -V3::z(), V3::new(0.48, -0.6, 0.64)];
    for (name, p) in phase_functions() {
        for (case, k_in) in k_ins.iter().enumerate() {
            let mut rng = Rng(17 + case as u64);
            let x = stokes_basis(k_in);
            let y = k_in.cross(&x);
            let mut observed = vec![0.0; T_BINS * PHI_BINS];
            for _ in 0..SAMPLES {
                let (k, _) = p.sample(k_in, [rng.next(), rng.next()]);
                let theta = k.dot(k_in).clamp(-1.0, 1.0).acos();
                let t = (1.0 - 2.0 * theta / PI).clamp(-1.0, 1.0).acos() / PI;
                let tb = ((t * T_BINS as f64) as usize).min(T_BINS - 1);
                let phi = k.dot(&y).atan2(k.dot(&x)).rem_euclid(2.0 * PI);
                let pb = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
                observed[tb * PHI_BINS + pb] += 1.0;
            }
            let expected: Vec<f64> = (0..T_BINS * PHI_BINS)
                .map(|b| {
                    let t0 = (b / PHI_BINS) as f64 / T_BINS as f64;
                    let mass = integrate(|mu| p.pdf(mu), t0, t0 + 1.0 / T_BINS as f64, 400);
                    mass / PHI_BINS as f64 * SAMPLES as f64
                })
                .collect();
            let (stat, dof) = pearson(&observed, &expected);
            let critical = chi2_critical(dof);
            assert!(
                stat < critical,
                "{name} k_in {k_in:?}: chi2 {stat:.1} >= {critical:.1} (dof {dof})"
            );
        }
    }
}

#[test]
fn rayleigh_dolp_is_sin2_over_1_plus_cos2_in_the_plane_frame() {
    let r = PhaseFunction::Rayleigh;
    for i in 0..=180 {
        let theta = (i as f64).to_radians();
        let s = r.plane_matrix(theta.cos()) * unpolarized(1.0);
        let expected = theta.sin().powi(2) / (1.0 + theta.cos().powi(2));
        // Closed form in a few operations: 1e-14.
        assert!((dolp(s[0], s[1], s[2]) - expected).abs() < 1e-14, "θ {i}°");
        // Perpendicular to the scattering plane: along x = e_⊥, so S1 ≥ 0, S2 = S3 = 0.
        assert!(s[1] >= 0.0 && s[2] == 0.0 && s[3] == 0.0, "θ {i}°: {s:?}");
    }
    let at = |deg: f64| {
        let s = r.plane_matrix(deg.to_radians().cos()) * unpolarized(1.0);
        dolp(s[0], s[1], s[2])
    };
    assert!((at(90.0) - 1.0).abs() < 1e-15);
    assert!((at(45.0) - 1.0 / 3.0).abs() < 1e-15);
    assert!(at(0.0).abs() < 1e-15 && at(180.0).abs() < 1e-15);
}

/// The polarization angle of an axis `a` (perpendicular to `k`) in the frame `stokes_basis(k)`.
fn angle_in_basis(k: &V3, a: &V3) -> f64 {
    basis_angle(k, &stokes_basis(k), a)
}

/// Difference of two polarization angles modulo π, in `[0, π/2]`.
fn angle_gap(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(PI);
    d.min(PI - d)
}

#[test]
fn world_eval_of_unpolarized_light_is_polarized_perpendicular_to_the_scattering_plane() {
    let mut rng = Rng(11);
    for _ in 0..3000 {
        let (k_in, k_out) = (rng.sphere(), rng.sphere());
        let mu = k_in.dot(&k_out);
        let s = PhaseFunction::Rayleigh.eval(&k_in, &k_out) * unpolarized(1.0);
        let expected = (1.0 - mu * mu) / (1.0 + mu * mu);
        // 1e-12: the two frame rotations add a few ulps per entry.
        assert!((dolp(s[0], s[1], s[2]) - expected).abs() < 1e-12);
        if expected > 1e-6 {
            let normal = k_in.cross(&k_out).normalize();
            let want = angle_in_basis(&k_out, &normal);
            // 1e-6 rad: AoLP = ½ atan2 loses precision only as DoLP → 0 (excluded).
            assert!(
                angle_gap(aolp(s[0], s[1], s[2]), want) < 1e-6,
                "k_in {k_in:?} k_out {k_out:?}"
            );
        }
    }
}

#[test]
fn world_eval_is_the_dipole_pattern_for_linear_input() {
    // A dipole driven along e_⊥ radiates e_⊥-polarized light with |S1|² = 1 (amplitude
    // diag(1, cos θ) on (E_⊥, E_∥)); driven along e_∥ it radiates ∝ cos²θ, along
    // y_out = k_out × e_⊥. Intensities per unit input: 2·3/(16π) and 2·3/(16π)·cos²θ.
    let norm = 3.0 / (8.0 * PI);
    let mut rng = Rng(12);
    for _ in 0..2000 {
        let (k_in, k_out) = (rng.sphere(), rng.sphere());
        let mu = k_in.dot(&k_out);
        let m = PhaseFunction::Rayleigh.eval(&k_in, &k_out);
        let e_perp = scattering_axis(&k_in, &k_out);
        for (axis_in, axis_out, gain) in [
            (e_perp, e_perp, 1.0),
            (k_in.cross(&e_perp), k_out.cross(&e_perp), mu * mu),
        ] {
            let s = m * linear(1.0, angle_in_basis(&k_in, &axis_in));
            assert!(
                (s[0] - norm * gain).abs() < 1e-12,
                "{} vs {}",
                s[0],
                norm * gain
            );
            if gain > 1e-6 {
                let want = angle_in_basis(&k_out, &axis_out);
                assert!(angle_gap(aolp(s[0], s[1], s[2]), want) < 1e-6);
                assert!((dolp(s[0], s[1], s[2]) - 1.0).abs() < 1e-9);
            }
        }
    }
}

#[test]
fn forward_and_backward_scattering_are_finite_and_continuous() {
    let mut rng = Rng(5);
    for (name, p) in phase_functions() {
        for _ in 0..50 {
            let k = rng.sphere();
            let nudge = rng.sphere() * 1e-7;
            for (exact, near) in [(k, (k + nudge).normalize()), (-k, (-k + nudge).normalize())] {
                let m = p.eval(&k, &exact);
                assert!(m.iter().all(|v| v.is_finite()), "{name}: {m:?}");
                // The plane is undefined at θ = 0, π and the matrix does not depend on it:
                // a neighbour 1e-7 rad away differs by O(θ²) relative to M00 (g = 0.999's
                // slope near the peak adds ~1e-7 · 3/(1-g)... it is flat at θ = 0).
                let diff = (m - p.eval(&k, &near)).amax();
                assert!(
                    diff <= 1e-6 * m[(0, 0)].abs(),
                    "{name}: jump {diff} at k_out = ±k_in"
                );
            }
        }
    }
}

#[test]
fn cos_theta_slightly_outside_the_unit_interval_is_clamped() {
    for (name, p) in phase_functions() {
        for (outside, edge) in [(1.0 + 4e-16, 1.0), (-1.0 - 4e-16, -1.0)] {
            assert_eq!(p.plane_matrix(outside), p.plane_matrix(edge), "{name}");
            assert_eq!(p.pdf(outside), p.pdf(edge), "{name}");
            assert!(p.pdf(outside).is_finite());
        }
    }
}

/// `Q Pᵀ Q` with `Q = diag(1, 1, −1, 1)`: the reciprocity relation of a phase matrix
/// (van de Hulst 1957 §5.32), which the plane matrix must equal.
fn reciprocal(p: &Mueller) -> Mueller {
    let q = Mueller::from_diagonal(&Stokes::new(1.0, 1.0, -1.0, 1.0));
    q * p.transpose() * q
}

#[test]
fn plane_matrix_obeys_reciprocity_and_m00_is_symmetric_in_the_world() {
    let mut rng = Rng(8);
    for (name, p) in phase_functions() {
        for i in 0..=36 {
            let m = p.plane_matrix((i as f64 * 5.0).to_radians().cos());
            assert_eq!(reciprocal(&m), m, "{name}");
        }
        let (k_in, k_out) = (rng.sphere(), rng.sphere());
        let (a, b) = (
            p.eval(&k_in, &k_out)[(0, 0)],
            p.eval(&-k_out, &-k_in)[(0, 0)],
        );
        assert!((a - b).abs() <= 1e-12 * a, "{name}");
    }
}

#[test]
fn every_plane_matrix_is_realizable() {
    // Mie matrices are Jones matrices (rank one) and the table interpolates them
    // linearly, a convex sum: realizable up to rounding.
    for (name, p) in phase_functions() {
        for i in 0..=72 {
            let m = p.plane_matrix((i as f64 * 2.5).to_radians().cos());
            assert!(is_realizable(&m, 1e-10), "{name} θ {}°", i as f64 * 2.5);
        }
    }
}

#[test]
fn mie_couples_circular_and_s34_is_nonzero() {
    let p = mie(10.0, 1.5, 0.01);
    assert!(p.couples_circular());
    let m = p.plane_matrix(0.5);
    assert!(m[(2, 3)].abs() > 1e-6 * m[(0, 0)] && m[(2, 3)] == -m[(3, 2)]);
}

#[test]
fn henyey_greenstein_with_depolarization_is_realizable() {
    // Cloude: coherency eigenvalues ≥ −1e-12·M00 (rank-one Jones cases, d = 0 at 90°,
    // have exact zeros that rounding moves by ~1e-16).
    for g in [-0.999, -0.5, 0.0, 0.3, 0.9, 0.999] {
        for d in [0.0, 0.1, 0.5, 0.9, 1.0] {
            let p = hg(g, d);
            for i in 0..=36 {
                let m = p.plane_matrix((i as f64 * 5.0).to_radians().cos());
                assert!(is_realizable(&m, 1e-12), "g {g} d {d} θ {}°", i * 5);
            }
        }
    }
    for i in 0..=36 {
        let m = PhaseFunction::Rayleigh.plane_matrix((i as f64 * 5.0).to_radians().cos());
        assert!(is_realizable(&m, 1e-12), "rayleigh θ {}°", i * 5);
    }
    // The check can fail: "negative depolarization" (built without validation) amplifies
    // S22 beyond S11 and is not a physical matrix.
    let bad = PhaseFunction::HenyeyGreenstein {
        g: 0.3,
        depolarization: -0.5,
    };
    assert!(bad.validate().is_err());
    assert!(!is_realizable(&bad.plane_matrix(0.0), 1e-12));
}

#[test]
fn hg_g_0_is_isotropic_and_samples_uniformly() {
    let p = hg(0.0, 1.0);
    for i in 0..=100 {
        let u = i as f64 / 100.0;
        assert_eq!(p.sample_cos_theta(u), 2.0 * u - 1.0);
        assert_eq!(p.pdf(2.0 * u - 1.0), 0.25 / PI);
    }
}

#[test]
fn hg_g_near_1_peaks_without_loss_of_precision() {
    for g in [0.999, -0.999, 1.0 - 1e-9] {
        let p = hg(g, 0.0);
        let peak = if g > 0.0 { 1.0 } else { -1.0 };
        // p(peak) = (1 + |g|)/(4π (1 − |g|)²) in closed form; relative 1e-12.
        let a = g.abs();
        let want = (1.0 + a) / (4.0 * PI * (1.0 - a) * (1.0 - a));
        assert!((p.pdf(peak) - want).abs() <= 1e-12 * want, "g {g}");
        assert!(p.sample_cos_theta(0.5).is_finite());
    }
}

#[test]
fn depolarization_1_keeps_intensity_only_and_0_keeps_rayleigh_structure() {
    for mu in [-1.0, -0.4, 0.0, 0.5, 1.0] {
        let m = hg(0.6, 1.0).plane_matrix(mu);
        let mut only = Mueller::zeros();
        only[(0, 0)] = m[(0, 0)];
        assert_eq!(m, only);
        // d = 0, g = 0: Rayleigh's matrix divided by its M00, times 1/(4π); 1e-15.
        let hg0 = hg(0.0, 0.0).plane_matrix(mu) / (0.25 / PI);
        let r = PhaseFunction::Rayleigh.plane_matrix(mu);
        assert!((hg0 - r / r[(0, 0)]).amax() < 1e-15, "μ {mu}");
    }
}

#[test]
fn invalid_parameters_are_rejected() {
    for (g, d, name) in [
        (1.0, 0.0, "g"),
        (-1.0, 0.0, "g"),
        (1.5, 0.0, "g"),
        (f64::NAN, 0.0, "g"),
        (0.2, -0.1, "depolarization"),
        (0.2, 1.1, "depolarization"),
        (0.2, f64::NAN, "depolarization"),
    ] {
        match PhaseFunction::henyey_greenstein(g, d) {
            Err(OpticsError::OutOfRange { name: got, .. }) => assert_eq!(got, name),
            other => panic!("g {g} d {d}: {other:?}"),
        }
    }
    assert!(PhaseFunction::Rayleigh.validate().is_ok());
}

#[test]
fn rayleigh_and_hg_do_not_couple_circular() {
    for (name, p) in phase_functions()
        .into_iter()
        .filter(|(n, _)| !n.starts_with("mie"))
    {
        assert!(!p.couples_circular(), "{name}");
        for i in 0..=18 {
            let m = p.plane_matrix((i as f64 * 10.0).to_radians().cos());
            assert!(!polar_optics::mueller::couples_circular(&m, 0.0), "{name}");
        }
    }
}
