#!/usr/bin/env python3
"""BSDF-level cross-check of polar-bsdf against Mitsuba 3 (llvm_ad_mono_polarized).

For random direction pairs it compares the full 4x4 Mueller matrices of
`eval` (rough conductor, isotropic and anisotropic; pplastic) and of the delta
lobes returned by `sample` (smooth conductor; smooth dielectric reflection,
transmission and total internal reflection). Both renderers express the matrix
in the same implicit local-frame Stokes bases (incident: stokes_basis(-wi),
outgoing: stokes_basis(wo)), so no conversion is applied: a sign or frame error
on either side shows up directly.

Direction names follow polar-bsdf: `wo` toward the viewer (Mitsuba's si.wi),
`wi` toward the light (Mitsuba's wo).

Usage: tools/.venv/bin/python tools/bsdf_crosscheck.py
       (builds and runs `cargo run --release -p polar-bsdf --example bsdf_eval`)
Exit status 1 when any case differs by more than the tolerance below.
"""

import json
import os
import subprocess
import sys

import drjit as dr
import mitsuba as mi
import numpy as np

mi.set_variant("llvm_ad_mono_polarized")

# Mitsuba computes in float32: agreement to 2e-4 of the largest entry of the
# matrix leaves room for single-precision rounding through Fresnel, D and G.
TOLERANCE = 2e-4
PAIRS = 300
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

AU = {"eta": 0.43, "k": 2.455}  # polar-bsdf's Metal::Au (Johnson & Christy, 548.6 nm)

CASES = [
    # name, Mitsuba dict, polar-bsdf TOML, mode ("eval" or ("sample", u0)), sides of wo
    ("rough_conductor_iso",
     {"type": "roughconductor", "distribution": "ggx", "alpha": 0.2, **AU},
     "type = 'conductor'\nmetal = 'au'\nroughness = 0.2", "eval", False),
    ("rough_conductor_aniso",
     {"type": "roughconductor", "distribution": "ggx", "alpha_u": 0.1, "alpha_v": 0.3, **AU},
     "type = 'conductor'\nmetal = 'au'\nroughness = [0.1, 0.3]", "eval", False),
    ("pplastic",
     {"type": "pplastic", "diffuse_reflectance": {"type": "uniform", "value": 0.5},
      "alpha": 0.2, "distribution": "ggx", "int_ior": 1.5, "ext_ior": 1.0},
     "type = 'plastic'\nalbedo = 0.5\nior = 1.5\nroughness = 0.2", "eval", False),
    ("smooth_conductor", {"type": "conductor", **AU},
     "type = 'conductor'\nmetal = 'au'", ("sample", 0.5), False),
    ("smooth_dielectric_reflection", {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0},
     "type = 'dielectric'\nior = 1.5", ("sample", 0.0), True),
    ("smooth_dielectric_transmission", {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0},
     "type = 'dielectric'\nior = 1.5", ("sample", 0.9999), True),
    # Thin sheets agree at normal incidence only ("normal": wo = +-z): Mitsuba's
    # polarizer angle turns the other way (ours at +30 deg is its theta = -30),
    # its retarder the same way; off normal, Mitsuba measures the angle from the
    # unprojected tangent and scales the retardance by |cos theta|, while
    # polar-bsdf projects the axis onto the wavefront and keeps the retardance.
    ("polarizer_30deg_normal", {"type": "polarizer", "theta": -30.0},
     "type = 'polarizer'\nangle_deg = 30.0", ("sample", 0.5), "normal"),
    ("quarter_wave_30deg_normal", {"type": "retarder", "theta": 30.0, "delta": 90.0},
     "type = 'retarder'\nangle_deg = 30.0\nretardance_deg = 90.0", ("sample", 0.5), "normal"),
]


def random_dirs(rng, n, two_sided):
    """Unit vectors with |cos theta| in [0.05, 1] (upper hemisphere unless
    two-sided); exactly +-z when two_sided is "normal"."""
    if two_sided == "normal":
        return np.stack([np.zeros(n), np.zeros(n), rng.choice([-1.0, 1.0], n)], axis=1)
    z = rng.uniform(0.05, 1.0, n)
    if two_sided:
        z *= rng.choice([-1.0, 1.0], n)
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def vec3(a):
    return mi.Vector3f(*(np.ascontiguousarray(a[:, i], dtype=np.float32) for i in range(3)))


def mueller_rows(m, n):
    """Mitsuba MuellerMatrix (per lane) -> array (n, 4, 4), [row][column]."""
    lanes = [[np.broadcast_to(np.asarray(m[i][j]).ravel(), (n,)) for j in range(4)] for i in range(4)]
    return np.array(lanes).transpose(2, 0, 1)


def mitsuba_matrices(bsdf_dict, mode, wo, wi):
    n = len(wo)
    bsdf = mi.load_dict(bsdf_dict)
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    si.wi = vec3(wo)
    ctx = mi.BSDFContext()
    if mode == "eval":
        return mueller_rows(bsdf.eval(ctx, si, vec3(wi)), n), wi
    u0 = mi.Float(np.full(n, mode[1], dtype=np.float32))
    bs, weight = bsdf.sample(ctx, si, u0, mi.Point2f(0.5, 0.5))
    lanes = lambda v: np.broadcast_to(np.asarray(v).ravel(), (n,))  # noqa: E731 (constants come back as 1 lane)
    pdf = lanes(bs.pdf)
    wi_mi = np.stack([lanes(c) for c in (bs.wo.x, bs.wo.y, bs.wo.z)], axis=1)
    return mueller_rows(weight, n) * pdf[:, None, None], wi_mi


def ours(toml, mode, wo, wi):
    if mode == "eval":
        items = [{"material": toml, "wo": list(a), "wi": list(b)} for a, b in zip(wo, wi)]
    else:
        items = [{"material": toml, "wo": list(a), "u": [mode[1], 0.5, 0.5]} for a in wo]
    cmd = ["cargo", "run", "-q", "--release", "-p", "polar-bsdf", "--example", "bsdf_eval"]
    out = subprocess.run(cmd, input=json.dumps(items), capture_output=True, text=True, cwd=ROOT, check=True)
    res = json.loads(out.stdout)
    return np.array([r["m"] for r in res]).reshape(-1, 4, 4), np.array([r["wi"] for r in res])


def main():
    rng = np.random.default_rng(2026)
    failed = False
    print(f"{'case':32s} {'pairs':>5s} {'max rel err':>12s} {'mean rel err':>12s} {'max |M00|':>10s}")
    for name, bsdf_dict, toml, mode, two_sided in CASES:
        wo = random_dirs(rng, PAIRS, two_sided)
        wi = random_dirs(rng, PAIRS, False)
        m_mi, wi_mi = mitsuba_matrices(bsdf_dict, mode, wo, wi)
        m_us, wi_us = ours(toml, mode, wo, wi)
        # Where both sampled a direction it must be the same one.
        both = (np.abs(m_mi[:, 0, 0]) > 0) & (np.abs(m_us[:, 0, 0]) > 0)
        dir_err = np.abs(wi_mi[both] - wi_us[both]).max() if both.any() else 0.0
        scale = np.maximum(np.abs(m_mi).max(axis=(1, 2)), np.abs(m_us).max(axis=(1, 2)))
        scale = np.where(scale > 0, scale, 1.0)
        rel = np.abs(m_mi - m_us).max(axis=(1, 2)) / scale
        ok = rel.max() <= TOLERANCE and dir_err <= 1e-5
        failed |= not ok
        print(f"{name:32s} {PAIRS:5d} {rel.max():12.2e} {rel.mean():12.2e} {np.abs(m_us[:, 0, 0]).max():10.3g}"
              + ("" if ok else f"   FAIL (direction error {dir_err:.1e})"))
        if not ok:
            k = int(np.argmax(rel))
            print(f"  worst: wo={wo[k]} wi={wi[k]}\n  mitsuba=\n{m_mi[k]}\n  ours=\n{m_us[k]}")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
