#!/usr/bin/env python3
"""Checks the polarized Rayleigh phase function plugin (rayleigh_phase.py)
inside Mitsuba 3's `volpath`, with virtual experiments (results: README.md).

1. The plugin alone: an unpolarized beam scattered by 90 (45) degrees has
   DoLP 1 (1/3), polarized along the normal of the scattering plane; M[0, 0]
   equals Mitsuba's own (scalar) `rayleigh`; `sample` returns value / pdf with
   pdf = M[0, 0], and its directions follow 1 + mu^2 (mean mu^2 = 2/5).
2. A ball of the medium (radius 0.5) lit by a collimated beam (directional
   emitter), seen by an orthographic camera along -z, so that every camera ray
   sees the same scattering angle (90 or 45 degrees). The scattering plane is
   turned by PHI = 30 degrees about the optical axis, so a mirrored or rotated
   Stokes frame cannot pass. The Stokes vectors are summed over the image.
   a) single scattering (volpath max_depth = 2): DoLP 1 and 1/3 exactly, AoLP
      perpendicular to the scattering plane in the conventions' camera frame
      (120 degrees here); the scalar `rayleigh` gives the same S0 with DoLP 0;
   b) all orders (max_depth = -1): multiple scattering lowers the DoLP by
      O(tau), tau = the ball's optical diameter (0.1 here); the AoLP stays
      exactly perpendicular (the ball is symmetric about the scattering plane).

    tools/.venv/bin/python tools/mitsuba/rayleigh_check.py [--spp 256] [--threads 2]
Exits non-zero when a check fails.
"""

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rayleigh_phase  # noqa: E402
import scenes  # noqa: E402

PHI_DEG = 30.0  # azimuth of the scattering plane about the optical axis
RADIUS = 0.5
SIGMA_T = 0.1  # pure scattering (albedo 1): optical diameter tau = 0.1
TAU = 2 * RADIUS * SIGMA_T
# Tolerances.
# Plugin and single scattering: float32 arithmetic only (every sample carries
# the same Stokes direction, so there is no Monte Carlo noise in DoLP or AoLP).
DOLP_EXACT_TOL = 1e-4
AOLP_EXACT_TOL_DEG = 0.01
# All orders: the multiply scattered light is a fraction f <= 1 - exp(-tau)
# of S0 (it must meet a second scatterer within one optical diameter), and
# whatever its polarization it moves the DoLP by at most 2 f (measured: 0.015
# at 90 degrees, 0.004 at 45). The AoLP is exact by symmetry up to noise
# (0.02 degrees between seeds at 256 spp).
DOLP_MULTI_TOL = 2 * (1 - np.exp(-TAU))
AOLP_MULTI_TOL_DEG = 0.2
S0_SAME_TOL = 1e-3  # our M[0, 0] against Mitsuba's rayleigh, same random numbers


def beam_direction(theta_deg):
    """k_in: the direction the beam travels, at theta from k_out = +z (toward the camera)."""
    t, p = np.radians(theta_deg), np.radians(PHI_DEG)
    return np.array([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])


def expected(theta_deg):
    """(DoLP, AoLP in the conventions' frame) of single Rayleigh scattering."""
    mu = np.cos(np.radians(theta_deg))
    n = np.cross(beam_direction(theta_deg), [0.0, 0.0, 1.0])
    x_ref, y_ref = scenes.reference_frame(np.array([0.0, 0.0, -1.0]))
    return (1 - mu**2) / (1 + mu**2), np.mod(np.arctan2(n @ y_ref, n @ x_ref), np.pi)


def check_plugin(mi, dr):
    """Part 1: the plugin's matrices, pdf and sampling."""
    ok = True
    phase = mi.load_dict({"type": rayleigh_phase.PLUGIN})
    scalar = mi.load_dict({"type": "rayleigh"})
    ctx = mi.PhaseFunctionContext()
    mei = dr.zeros(mi.MediumInteraction3f)
    mei.wi = mi.Vector3f(0.0, 0.0, 1.0)
    print(f"{'angle':>6} {'DoLP':>9} {'expected':>9} {'AoLP':>9} {'expected':>9} {'M00':>10} {'rayleigh':>10}  (plugin, unpolarized beam)")
    for theta in (90.0, 45.0, 120.0, 0.0, 180.0):
        wo = mi.Vector3f(-beam_direction(theta))
        m, pdf = phase.eval_pdf(ctx, mei, wo)
        m = np.array(m).reshape(4, 4)
        s = m[:, 0]  # the Mueller matrix applied to (1, 0, 0, 0), frame stokes_basis(+z)
        basis = np.array(mi.mueller.stokes_basis(mi.Vector3f(0.0, 0.0, 1.0))).ravel()
        psi = 0.5 * np.arctan2(s[2], s[1])  # from basis toward y = k x basis (Mitsuba's frame)
        field = np.cos(psi) * basis + np.sin(psi) * np.cross([0.0, 0.0, 1.0], basis)
        x_ref, y_ref = scenes.reference_frame(np.array([0.0, 0.0, -1.0]))  # the camera ray d = -k_out
        aolp = np.mod(np.arctan2(field @ y_ref, field @ x_ref), np.pi)
        dolp = np.hypot(s[1], s[2]) / s[0]
        want_dolp, want_aolp = expected(theta)
        ref = float(np.ravel(scalar.eval_pdf(ctx, mei, wo)[0])[0])
        good = abs(dolp - want_dolp) < DOLP_EXACT_TOL and abs(s[0] - ref) < 1e-6 and abs(float(np.ravel(pdf)[0]) - s[0]) < 1e-6
        if want_dolp > 0.01:
            good &= np.degrees(abs(scenes.angle_diff(aolp, want_aolp))) < AOLP_EXACT_TOL_DEG
        print(f"{theta:6.0f} {dolp:9.6f} {want_dolp:9.6f} {np.degrees(aolp):9.3f} {np.degrees(want_aolp):9.3f} "
              f"{s[0]:10.6f} {ref:10.6f}  {'ok' if good else 'FAIL'}")
        ok &= good
    n = 1 << 18
    sampler = mi.load_dict({"type": "independent"})
    sampler.seed(0, n)
    mei = dr.zeros(mi.MediumInteraction3f, n)
    mei.wi = dr.normalize(mi.Vector3f(0.3, -0.2, 0.9))
    wo, weight, pdf = phase.sample(ctx, mei, sampler.next_1d(), sampler.next_2d())
    value, pdf_eval = phase.eval_pdf(ctx, mei, wo)
    err_w = float(np.abs(np.array(weight) - np.array(value) / np.array(pdf)).max())
    err_pdf = float(np.abs(np.array(pdf) - np.array(pdf_eval)).max())
    mu2 = np.array(dr.dot(wo, mei.wi)) ** 2
    z = (mu2.mean() - 0.4) / (mu2.std() / np.sqrt(n))
    good = err_w < 1e-5 and err_pdf < 1e-6 and abs(z) < 5
    print(f"sample: max |weight - value/pdf| {err_w:.1e}, max |pdf - eval pdf| {err_pdf:.1e}, "
          f"mean mu^2 {mu2.mean():.5f} (2/5, {z:+.1f} sigma)  {'ok' if good else 'FAIL'}")
    return ok & good


def ball_scene(mi, theta_deg, max_depth, spp, phase=rayleigh_phase.PLUGIN, res=32):
    """The medium ball under a unit collimated beam, orthographic camera on +z."""
    to_world = mi.ScalarTransform4f().look_at(origin=[0.0, 0.0, 5.0], target=[0.0, 0.0, 0.0], up=[0.0, 1.0, 0.0])
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "stokes", "integrator": {"type": "volpath", "max_depth": max_depth}},
        "sensor": {
            "type": "orthographic",
            "to_world": to_world @ mi.ScalarTransform4f().scale([RADIUS, RADIUS, 1.0]),
            "film": {"type": "hdrfilm", "width": res, "height": res, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "ball": {
            "type": "sphere", "radius": RADIUS, "bsdf": {"type": "null"},
            "interior": {"type": "homogeneous", "sigma_t": SIGMA_T, "albedo": 1.0, "phase": {"type": phase}},
        },
        "sun": {"type": "directional", "direction": beam_direction(theta_deg).tolist(), "irradiance": 1.0},
    }, optimize=False)


def summed_stokes(mi, scene, spp):
    """The Stokes vector summed over the image (float64)."""
    return scenes.render_stokes(mi, scene, spp, seed=7).reshape(-1, 4).astype(np.float64).sum(0)


def check_renders(mi, spp):
    """Part 2: single scattering and all orders in volpath."""
    ok = True
    print(f"\nball of tau = {TAU}, beam at phi = {PHI_DEG:.0f} deg, {spp} spp; Stokes summed over the image")
    print(f"{'angle':>6} {'orders':>7} {'DoLP':>9} {'expected':>9} {'tol':>7} {'AoLP':>9} {'expected':>9} {'tol':>6}")
    for theta in (90.0, 45.0):
        want_dolp, want_aolp = expected(theta)
        single = None
        for orders, depth, dolp_tol, aolp_tol in (("1", 2, DOLP_EXACT_TOL, AOLP_EXACT_TOL_DEG),
                                                  ("all", -1, DOLP_MULTI_TOL, AOLP_MULTI_TOL_DEG)):
            s = summed_stokes(mi, ball_scene(mi, theta, depth, spp), spp)
            single = s if single is None else single
            dolp = np.hypot(s[1], s[2]) / s[0]
            aolp = np.mod(0.5 * np.arctan2(s[2], s[1]), np.pi)
            daolp = np.degrees(abs(scenes.angle_diff(aolp, want_aolp)))
            good = abs(dolp - want_dolp) <= dolp_tol and daolp <= aolp_tol
            print(f"{theta:6.0f} {orders:>7} {dolp:9.5f} {want_dolp:9.5f} {dolp_tol:7.4f} {np.degrees(aolp):9.3f} "
                  f"{np.degrees(want_aolp):9.3f} {aolp_tol:6.2f}  {'ok' if good else 'FAIL'}")
            ok &= good
        print(f"{'':6} multiple scattering adds {100 * (s[0] / single[0] - 1):.1f}% to S0")
        scalar = summed_stokes(mi, ball_scene(mi, theta, 2, spp, phase="rayleigh"), spp)
        rel = abs(scalar[0] / single[0] - 1)
        good = rel < S0_SAME_TOL and np.hypot(scalar[1], scalar[2]) == 0.0
        print(f"{'':6} Mitsuba's `rayleigh`, single scattering: S0 differs by {rel:.1e}, DoLP "
              f"{np.hypot(scalar[1], scalar[2]) / scalar[0]:.3f} (scalar fallback)  {'ok' if good else 'FAIL'}")
        ok &= good
    return ok


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--threads", type=int, default=None)
    args = ap.parse_args()
    mi, dr = scenes.setup_mitsuba(args.threads)
    ok = check_plugin(mi, dr)
    ok &= check_renders(mi, args.spp)
    print("\nall checks passed" if ok else "\nSOME CHECKS FAILED")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
