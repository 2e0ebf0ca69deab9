#!/usr/bin/env python3
"""Checks, with virtual optical experiments, in which frame Mitsuba 3's
`stokes` integrator writes S0..S3 (see README.md for the results).

1. Image orientation: a small emitter at world +x (+y) must show on the right
   (top) of the image: the displayed image is not mirrored.
2. Linear polarizer sheet (Mitsuba `polarizer` on a rectangle filling the
   view, unpolarized environment behind it), turned by rotating the *shape*
   by phi about the optical axis (counterclockwise as the camera sees it).
   The AoLP measured at every pixel is compared with the prediction in three
   candidate frames:
     conventions  x_ref = normalize(d x u), y_ref = x_ref x d  (must match)
     projected    x = camera right projected perpendicular to d, y = x x d
     mirrored     the conventions frame with y_ref flipped (clockwise angles)
   The transmitted field direction is computed with the same tilted-polarizer
   model Mitsuba uses (Korger et al. 2013: the absorbing axis, the shape's V
   direction, projected perpendicular to the ray; the field is perpendicular to
   it and to the ray), so the only unknown is the output frame.
3. The polarizer's `theta` parameter with the shape unrotated: which way does
   it turn the measured AoLP?
4. S3 sign: polarizer at +45 degrees then a quarter-wave retarder with its fast
   axis along image +x (Mitsuba `retarder`, fast axis = the shape's U
   direction). The y field component is delayed by a quarter period, so the
   field turns from +x to +y: counterclockwise for an observer facing the
   source, i.e. left-handed, S3 = -S0 in the conventions.

    tools/.venv/bin/python tools/mitsuba/polarizer_check.py [--spp 16]
Exits non-zero when a check fails.
"""

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import scenes  # noqa: E402

# Tolerances. Every pixel's value is the mean over its footprint while the
# prediction uses the pixel centre: the AoLP varies by < 0.01 degrees across
# a pixel here, so 0.05 degrees is a generous float32 + footprint margin. A
# wrong frame is off by > 1 degree at the corners (printed), far above it.
AOLP_TOL_DEG = 0.05
WRONG_FRAME_MIN_DEG = 1.0
S3_TOL = 1e-3  # S3/S0 of an ideal quarter-wave plate is exactly -1 at normal incidence


def sheet(mi, bsdf, z, phi_deg=0.0):
    """A 6 x 6 rectangle at depth z facing the camera, turned by phi about +z."""
    to_world = (
        mi.ScalarTransform4f()
        .translate([0.0, 0.0, z])
        .rotate(axis=[0.0, 0.0, 1.0], angle=phi_deg)
        .scale([3.0, 3.0, 1.0])
    )
    return {"type": "rectangle", "to_world": to_world, "bsdf": bsdf}


def render(mi, shapes, spp):
    """Renders `shapes` under a unit unpolarized environment; returns S0..S3."""
    scene = {
        "type": "scene",
        "integrator": scenes.stokes_integrator(),
        "sensor": scenes.sensor_dict(mi, spp),
        "env": {"type": "constant", "radiance": 1.0},
    }
    scene.update(shapes)
    return scenes.render_stokes(mi, mi.load_dict(scene, optimize=False), spp)


def predicted_aolp(phi_deg, frame):
    """AoLP (H, W) behind a polarizer sheet turned by phi, in `frame`."""
    d = scenes.pixel_rays()
    f = -d  # light travels from the sheet toward the camera
    p = np.radians(phi_deg)
    absorb = np.array([-np.sin(p), np.cos(p), 0.0])  # the shape's V axis
    a = absorb - (f @ absorb)[..., None] * f
    e = np.cross(f, a / np.linalg.norm(a, axis=-1, keepdims=True))
    x, y = candidate_frame(d, frame)
    return np.mod(np.arctan2((e * y).sum(-1), (e * x).sum(-1)), np.pi)


def candidate_frame(d, frame):
    """(x, y) axes per pixel of one of the candidate output frames."""
    x_ref, y_ref = scenes.reference_frame(d)
    if frame == "conventions":
        return x_ref, y_ref
    if frame == "mirrored":
        return x_ref, -y_ref
    right = scenes.camera_basis()[0]
    x = right - (d @ right)[..., None] * d
    x /= np.linalg.norm(x, axis=-1, keepdims=True)
    return x, np.cross(x, d)


CORNERS = {"centre": (63, 63), "top-left": (0, 0), "top-right": (0, 127), "bottom-left": (127, 0), "bottom-right": (127, 127)}


def check_orientation(mi, spp):
    """Bright spots placed at world +x and +y land right of and above the centre."""
    ok = True
    for axis, pos in (("+x", [0.8, 0.0, 0.0]), ("+y", [0.0, 0.8, 0.0])):
        shapes = {"dot": {"type": "sphere", "center": pos, "radius": 0.1, "emitter": {"type": "area", "radiance": 100.0}}}
        s0 = render(mi, shapes, spp)[..., 0]
        row, col = np.unravel_index(np.argmax(s0), s0.shape)
        good = col > 70 and abs(row - 63.5) < 4 if axis == "+x" else row < 57 and abs(col - 63.5) < 4
        print(f"emitter at world {axis}: brightest pixel row {row}, col {col} -> {'ok' if good else 'FAIL'}")
        ok &= good
    return ok


def check_polarizer(mi, spp, phis):
    """Shape-rotated polarizer: measured AoLP against the three candidate frames."""
    ok = True
    print(f"\n{'phi':>5} {'pixel':>12} {'measured':>9} {'conv.':>8} {'proj.':>8} {'mirr.':>8}   (AoLP, degrees)")
    for phi in phis:
        measured = scenes.aolp(render(mi, {"sheet": sheet(mi, {"type": "polarizer"}, 0.0, phi)}, spp))
        preds = {f: predicted_aolp(phi, f) for f in ("conventions", "projected", "mirrored")}
        for name, (r, c) in CORNERS.items():
            vals = [measured[r, c]] + [preds[f][r, c] for f in preds]
            print(f"{phi:5.0f} {name:>12} " + " ".join(f"{round(np.degrees(v), 3) % 180:8.3f}" for v in vals))
        errs = {f: np.degrees(np.abs(scenes.angle_diff(measured, p))).max() for f, p in preds.items()}
        print("      max |measured - predicted| over all pixels: " + ", ".join(f"{f} {e:.3f}" for f, e in errs.items()))
        ok &= errs["conventions"] <= AOLP_TOL_DEG
        ok &= min(errs["projected"], errs["mirrored"]) >= WRONG_FRAME_MIN_DEG or phi % 90 == 0
    return ok


def check_theta(mi, spp, theta):
    """Which way the `theta` parameter turns the AoLP at the image centre."""
    s = render(mi, {"sheet": sheet(mi, {"type": "polarizer", "theta": theta}, 0.0)}, spp)
    got = np.degrees(scenes.aolp(s)[63, 63])
    turned = np.degrees(scenes.angle_diff(np.radians(got), 0.0))
    print(f"\npolarizer theta = {theta}, shape unrotated: AoLP at centre {got:.3f} deg (turned by {turned:+.3f})")
    return abs(abs(turned) - theta) < AOLP_TOL_DEG, turned


def check_s3(mi, spp):
    """Polarizer at +45 then a quarter-wave plate with fast axis +x: S3/S0 = -1."""
    shapes = {
        "polarizer": sheet(mi, {"type": "polarizer"}, 0.0, 45.0),
        "qwp": sheet(mi, {"type": "retarder", "delta": 90.0}, 1.0),
    }
    s = render(mi, shapes, spp)
    s3 = s[63, 63, 3] / s[63, 63, 0]
    print(f"\npolarizer at +45 deg, then quarter-wave plate (fast axis +x): S3/S0 at centre = {s3:+.4f} (expected -1)")
    return abs(s3 + 1.0) < S3_TOL


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spp", type=int, default=16, help="samples per pixel (the sheets are noise-free)")
    ap.add_argument("--threads", type=int, default=None)
    args = ap.parse_args()
    mi, _ = scenes.setup_mitsuba(args.threads)
    ok = check_orientation(mi, args.spp)
    ok &= check_polarizer(mi, args.spp, [0.0, 30.0, 60.0, 125.0])
    theta_ok, turned = check_theta(mi, args.spp, 30.0)
    print(f"-> the theta parameter turns the axis {'clockwise' if turned < 0 else 'counterclockwise'} on the image, "
          f"shape rotation counterclockwise")
    ok &= theta_ok
    ok &= check_s3(mi, args.spp)
    print("\nall checks passed" if ok else "\nSOME CHECKS FAILED")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
