#!/usr/bin/env python3
"""Golden data from polanalyser/OpenCV for the polar-sensor front end, and a full-frame check.

Default mode writes small JSON fixtures to crates/polar-sensor/tests/data/:
  bilinear_u8.json, bilinear_u16.json   random mosaics (every DN pattern, borders included)
  real_crop_u8.json                     a 48x32 crop of a bundled real IMX250MZR frame
Each holds the raw mosaic and polanalyser's outputs: the four demosaiced images
(COLOR_PolarMono), calcLinearStokes S0..S2, cvtStokesToDoLP, cvtStokesToAoLP and
applyColorToAoLP(aolp, value=dolp) converted to RGB. Undefined values (NaN) are null.
  rgb_u8.json, rgb_u16.json             random colour mosaics (IMX250MYR layout)
  rgb_real_crop_u8.json                 a 32x24 crop of a colour frame made from the bundled
                                        real frames (see colour_frame)
The colour fixtures hold, per colour C in R, G, B, the keys "C.i0" ... "C.aolp" of
polanalyser's COLOR_PolarRGB chain (no picture: ours is of the luminance).

--check runs the real `polar-vision stokes` binary (cargo build --release) on each
bundled real frame and compares its stokes.exr / dolp.exr / aolp.exr / aolp.png
with polanalyser on the full frame, and with `--pattern rgb` on the full-size colour frame
(colour_frame) per colour, reading the channels S0.R ... S2.B with Mitsuba's Bitmap;
exits non-zero if a tolerance is exceeded.

Run with the pinned venv: tools/.venv/bin/python tools/polanalyser_goldens.py [--check]
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
from importlib.metadata import version
from pathlib import Path

import cv2
import numpy as np
import polanalyser as pa

ROOT = Path(__file__).resolve().parent.parent
FIXTURES = ROOT / "crates" / "polar-sensor" / "tests" / "data"
REAL = ROOT / "tests" / "data" / "real"
ANGLES = np.deg2rad([0, 45, 90, 135])
# The IMX250MYR layout of docs/conventions.md, written out here independently of the Rust
# code: polarizer index (into ANGLES) per [y % 2][x % 2], colour per 2x2 block
# [(y // 2) % 2][(x // 2) % 2] as an index into OpenCV's B, G, R order (R G / G B).
ANGLE_AT = np.array([[2, 1], [3, 0]])
BGR_AT = np.array([[2, 1], [1, 0]])
COLORS = {"R": 2, "G": 1, "B": 0}  # our channel name -> index in OpenCV's BGR

# Tolerances of --check (full frame, bilinear).
STOKES_REL_TOL = 1e-4  # max |ours - polanalyser| / max |polanalyser| per S0, S1, S2
DOLP_ABS_TOL = 1e-5  # f32 vs f64 rounding of sqrt(S1^2+S2^2)/S0
AOLP_ABS_TOL = 1e-5  # radians, circular difference modulo pi
PICTURE_DN_TOL = 1  # aolp.png vs applyColorToAoLP, per channel ...
PICTURE_FLIP_FRACTION = 1e-4  # ... except where f32 vs f64 AoLP/DoLP truncate to a neighbouring hue/value bin


def polanalyser_chain(raw):
    """polanalyser's chain: demosaicing, calcLinearStokes, DoLP, AoLP (float64)."""
    imgs = pa.demosaicing(raw, pa.COLOR_PolarMono)
    stokes = pa.calcLinearStokes(np.stack(imgs), ANGLES)
    with np.errstate(divide="ignore", invalid="ignore"):
        dolp = pa.cvtStokesToDoLP(stokes)
    aolp = pa.cvtStokesToAoLP(stokes)
    return imgs, stokes, dolp, aolp


def polanalyser_rgb_chain(raw):
    """polanalyser's colour chain: demosaicing COLOR_PolarRGB, calcLinearStokes, DoLP, AoLP per colour."""
    imgs = pa.demosaicing(raw, pa.COLOR_PolarRGB)  # four (h, w, 3) BGR images
    stokes = pa.calcLinearStokes(np.stack(imgs), ANGLES)  # (h, w, 3 colours, 3)
    with np.errstate(divide="ignore", invalid="ignore"):
        dolp = pa.cvtStokesToDoLP(stokes)
    aolp = pa.cvtStokesToAoLP(stokes)
    return imgs, stokes, dolp, aolp


def colour_mosaic(images):
    """The colour mosaic (IMX250MYR layout) of four (h, w, 3) BGR images behind 0, 45, 90, 135 degrees."""
    h, w = images[0].shape[:2]
    y, x = np.mgrid[0:h, 0:w]
    return np.stack(images)[ANGLE_AT[y % 2, x % 2], y, x, BGR_AT[(y // 2) % 2, (x // 2) % 2]]


def colour_frame():
    """A full-size colour mosaic from the bundled mono frames: their polarizer images
    (COLOR_PolarMono) as red (carps), green (camera) and blue (carps upside down)."""
    frames = [cv2.imread(str(REAL / f), cv2.IMREAD_UNCHANGED) for f in ("carps_IMX250MZR.png", "camera_IMX250MZR.png")]
    red, green = (pa.demosaicing(f, pa.COLOR_PolarMono) for f in frames)
    blue = [img[::-1] for img in red]
    return colour_mosaic([np.dstack([b, g, r]) for r, g, b in zip(red, green, blue)])


def aolp_picture_rgb(aolp, dolp):
    """applyColorToAoLP(aolp, value=dolp) as RGB, black where DoLP/AoLP are undefined."""
    ok = np.isfinite(aolp) & np.isfinite(dolp)
    bgr = pa.applyColorToAoLP(np.where(ok, aolp, 0), value=np.where(ok, np.clip(dolp, 0, 1), 0))
    rgb = bgr[..., ::-1].copy()
    rgb[~ok] = 0
    return rgb


def as_list(a):
    return [None if not np.isfinite(v) else float(v) for v in np.asarray(a, dtype=np.float64).ravel()]


def fixture(raw, bits):
    imgs, stokes, dolp, aolp = polanalyser_chain(raw)
    h, w = raw.shape
    return {
        "source": f"polanalyser {version('polanalyser')}, OpenCV {cv2.__version__}",
        "width": w,
        "height": h,
        "bits": bits,
        "raw": raw.ravel().tolist(),
        "i0": imgs[0].ravel().tolist(),
        "i45": imgs[1].ravel().tolist(),
        "i90": imgs[2].ravel().tolist(),
        "i135": imgs[3].ravel().tolist(),
        "s0": as_list(stokes[..., 0]),
        "s1": as_list(stokes[..., 1]),
        "s2": as_list(stokes[..., 2]),
        "dolp": as_list(dolp),
        "aolp": as_list(aolp),
        "aolp_rgb": aolp_picture_rgb(aolp, dolp).ravel().tolist(),
    }


def colour_fixture(raw, bits):
    imgs, stokes, dolp, aolp = polanalyser_rgb_chain(raw)
    h, w = raw.shape
    out = {
        "source": f"polanalyser {version('polanalyser')}, OpenCV {cv2.__version__}",
        "width": w,
        "height": h,
        "bits": bits,
        "raw": raw.ravel().tolist(),
    }
    for name, c in COLORS.items():
        for key, img in zip(["i0", "i45", "i90", "i135"], imgs):
            out[f"{name}.{key}"] = img[..., c].ravel().tolist()
        for i in range(3):
            out[f"{name}.s{i}"] = as_list(stokes[..., c, i])
        out[f"{name}.dolp"] = as_list(dolp[..., c])
        out[f"{name}.aolp"] = as_list(aolp[..., c])
    return out


def write_fixtures():
    FIXTURES.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(20261123)
    raw8 = rng.integers(0, 256, (10, 12), dtype=np.uint8)
    raw8[4:6, 4:6] = 0  # a zero super-pixel: S0 = 0 in its centre, DoLP/AoLP undefined
    raw16 = rng.integers(0, 65536, (12, 16), dtype=np.uint16)
    real = cv2.imread(str(REAL / "carps_IMX250MZR.png"), cv2.IMREAD_UNCHANGED)
    crop = np.ascontiguousarray(real[800:832, 1000:1048])
    for name, raw, bits in [("bilinear_u8", raw8, 8), ("bilinear_u16", raw16, 16), ("real_crop_u8", crop, 8)]:
        path = FIXTURES / f"{name}.json"
        path.write_text(json.dumps(fixture(raw, bits)))
        print(f"wrote {path.relative_to(ROOT)} ({path.stat().st_size // 1024} KiB)")
    rgb8 = rng.integers(0, 256, (12, 16), dtype=np.uint8)
    rgb8[4:8, 4:8] = 0  # a zero 4x4 tile: S0 = 0 in some colours, DoLP/AoLP undefined
    rgb16 = rng.integers(0, 65536, (16, 20), dtype=np.uint16)
    rgb_crop = np.ascontiguousarray(colour_frame()[800:824, 1000:1032])
    for name, raw, bits in [("rgb_u8", rgb8, 8), ("rgb_u16", rgb16, 16), ("rgb_real_crop_u8", rgb_crop, 8)]:
        path = FIXTURES / f"{name}.json"
        path.write_text(json.dumps(colour_fixture(raw, bits)))
        print(f"wrote {path.relative_to(ROOT)} ({path.stat().st_size // 1024} KiB)")


def read_exr(path):
    """Named float channels of an EXR file, via Mitsuba's Bitmap (in the pinned venv)."""
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    bmp = mi.Bitmap(str(path))
    names = [bmp.struct_()[i].name for i in range(bmp.channel_count())]
    data = np.array(bmp).reshape(bmp.height(), bmp.width(), len(names))
    return {name: data[..., i] for i, name in enumerate(names)}


def build_binary():
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    subprocess.run(["cargo", "build", "--release", "--locked", "-p", "polar-vision"], cwd=ROOT, check=True)
    return target / "release" / "polar-vision"


def circular_diff(a, b):
    d = np.abs(a - b) % np.pi
    return np.minimum(d, np.pi - d)


def compare(label, ours, dolp_ours, aolp_ours, stokes, dolp, aolp, failures):
    """Our S0..S2 (dict by name), DoLP and AoLP against polanalyser's, within the tolerances above."""
    for i, name in enumerate(["S0", "S1", "S2"]):
        ref = stokes[..., i]
        rel = np.max(np.abs(ours[name] - ref)) / np.max(np.abs(ref))
        print(f"  {label}{name}: max |diff| / max |ref| = {rel:.2e} (tol {STOKES_REL_TOL:.0e})")
        if not rel <= STOKES_REL_TOL:
            failures.append(f"{label}{name} {rel:.2e}")
    defined = np.isfinite(dolp)
    if not np.array_equal(defined, np.isfinite(dolp_ours)):
        failures.append(f"{label}DoLP NaN pattern differs")
    dd = np.max(np.abs(dolp_ours[defined] - dolp[defined]), initial=0)
    # AoLP is arbitrary where S1 = S2 = 0 (polanalyser's pseudo-inverse leaves ~1e-16 there,
    # ours exact zeros): compare where the polarization is at least 1 DN.
    polarized = defined & (np.hypot(stokes[..., 1], stokes[..., 2]) >= 1)
    da = np.max(circular_diff(aolp_ours[polarized], aolp[polarized]), initial=0)
    print(f"  {label}DoLP max |diff| = {dd:.2e} (tol {DOLP_ABS_TOL:.0e}); AoLP max |diff| = {da:.2e} rad (tol {AOLP_ABS_TOL:.0e}, where |S1,S2| >= 1 DN)")
    if not dd <= DOLP_ABS_TOL:
        failures.append(f"{label}DoLP {dd:.2e}")
    if not da <= AOLP_ABS_TOL:
        failures.append(f"{label}AoLP {da:.2e}")


def check_mono(exe, frame, failures):
    raw = cv2.imread(str(frame), cv2.IMREAD_UNCHANGED)
    _, stokes, dolp, aolp = polanalyser_chain(raw)
    with tempfile.TemporaryDirectory() as out:
        subprocess.run([str(exe), "stokes", str(frame), "--out", out, "--demosaic", "bilinear"], check=True)
        ours = read_exr(Path(out) / "stokes.exr")
        our_dolp = read_exr(Path(out) / "dolp.exr")["Y"]
        our_aolp = read_exr(Path(out) / "aolp.exr")["Y"]
        picture = cv2.imread(str(Path(out) / "aolp.png"), cv2.IMREAD_UNCHANGED)[..., ::-1]
    print(f"{frame.name}:")
    compare(f"{frame.name} ", ours, our_dolp, our_aolp, stokes, dolp, aolp, failures)
    diff = np.abs(picture.astype(int) - aolp_picture_rgb(aolp, dolp).astype(int)).max(axis=-1)
    flips = np.mean(diff > PICTURE_DN_TOL)
    dp = 0 if flips <= PICTURE_FLIP_FRACTION else diff.max()
    print(f"  aolp.png: {100 * flips:.4f}% of pixels differ by more than {PICTURE_DN_TOL} DN (max {diff.max()}; tol {100 * PICTURE_FLIP_FRACTION}%)")
    if not dp <= PICTURE_DN_TOL:
        failures.append(f"{frame.name} aolp.png {dp}")


def check_colour(exe, failures):
    """`polar-vision stokes --pattern rgb` on the full-size colour frame: the channel names
    Mitsuba's reader sees, and per colour the values of polanalyser's COLOR_PolarRGB chain."""
    raw = colour_frame()
    _, stokes, dolp, aolp = polanalyser_rgb_chain(raw)
    with tempfile.TemporaryDirectory() as out:
        frame = Path(out) / "colour.png"
        cv2.imwrite(str(frame), raw)
        result = Path(out) / "out"
        subprocess.run([str(exe), "stokes", str(frame), "--out", str(result), "--demosaic", "bilinear", "--pattern", "rgb"], check=True)
        ours = read_exr(result / "stokes.exr")
        our_dolp = read_exr(result / "dolp.exr")
        our_aolp = read_exr(result / "aolp.exr")
    names = [f"S{i}.{c}" for i in range(3) for c in COLORS]
    print(f"colour frame (carps, camera, carps flipped as R, G, B): stokes.exr channels {sorted(ours)}")
    if sorted(ours) != sorted(names):
        failures.append(f"colour stokes.exr channels {sorted(ours)}, expected {sorted(names)}")
        return
    for name, c in COLORS.items():
        mine = {f"S{i}": ours[f"S{i}.{name}"] for i in range(3)}
        compare(f"colour {name} ", mine, our_dolp[name], our_aolp[name], stokes[..., c, :], dolp[..., c], aolp[..., c], failures)


def check():
    exe = build_binary()
    failures = []
    for frame in sorted(REAL.glob("*.png")):
        check_mono(exe, frame, failures)
    check_colour(exe, failures)
    if failures:
        print("FAILED:", "; ".join(failures))
        return 1
    print("all real frames match polanalyser")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--check", action="store_true", help="compare `polar-vision stokes` with polanalyser on the real frames")
    args = parser.parse_args()
    if args.check:
        sys.exit(check())
    write_fixtures()


if __name__ == "__main__":
    main()
