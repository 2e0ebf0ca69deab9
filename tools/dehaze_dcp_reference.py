#!/usr/bin/env python3
"""Independent reference of polar-dehaze's dark-channel-prior baseline (He, Sun, Tang,
CVPR 2009 / TPAMI 2011) on one channel (S0), with OpenCV and numpy.

Same steps and parameters as crates/polar-dehaze/src/dark_channel.rs + refine.rs:
  scale = nearest-rank 0.99 quantile of the valid S0 (S0 > 0, finite), as
          polar_sensor::Observation::s0_scale; I = S0 / scale
  dark0 = cv2.erode(I, ones(patch, patch))            (min filter, border ignored)
  A     = max I over valid pixels whose dark0 >= the k-th largest valid dark0,
          k = max(1, n // 1000)                        (He et al.'s 0.1 %)
  t     = 1 - omega * cv2.erode(I / A, ones(patch, patch))
  t     = cv2.ximgproc.guidedFilter(I, t, radius, eps), clipped to [t0, 1]
  J     = max((I - A) / t + A, 0) * scale
Defaults: patch 15, omega 0.95, t0 0.1 (He et al.), radius 15, eps 1e-3; the Rust side is
compared with the same radius (GuidedRadius::Pixels(15): its default radius is a share of
the image size) and denoise_radius = 0 (its optional noise-weighted denoising of S0 is not
part of He et al.'s method).

Input: a float32 S0 plane as .npy, or as raw little-endian float32 .bin with --width and
--height. Output: raw little-endian float32 .bin (or .npy by extension) of t and J.
--synthetic W H writes a deterministic closed-form hazy S0 to the input path first
(the golden input of crates/polar-dehaze/tests/golden/).

Pinned: numpy==2.4.6, opencv-contrib-python-headless==5.0.0.93 (tools/requirements.txt).
Regenerate the goldens:
  python tools/dehaze_dcp_reference.py crates/polar-dehaze/tests/golden/dcp_s0.bin \
      --synthetic 64 48 --width 64 --height 48 \
      --out-t crates/polar-dehaze/tests/golden/dcp_t.bin \
      --out-radiance crates/polar-dehaze/tests/golden/dcp_radiance.bin
"""

import argparse
import math
import pathlib

import cv2
import numpy as np


def synthetic(width, height):
    """Closed-form hazy S0: textured radiance with dark pixels, depth growing upwards,
    A_inf = 0.9, beta z from 0.1 (bottom) to 3 (top), times 1000 (an arbitrary unit)."""
    y, x = np.mgrid[0:height, 0:width].astype(np.float64)
    radiance = 0.35 + 0.25 * np.sin(x / 3.1) * np.cos(y / 4.7)
    radiance[((x // 5) + (y // 5)) % 3 == 0] = 0.02
    optical_depth = 0.1 + 2.9 * (1.0 - y / (height - 1)) ** 2
    t = np.exp(-optical_depth)
    s0 = radiance * t + 0.9 * (1.0 - t)
    return (1000.0 * s0).astype(np.float32)


def read_plane(path, width, height):
    path = pathlib.Path(path)
    if path.suffix == ".npy":
        return np.load(path).astype(np.float32)
    data = np.fromfile(path, dtype="<f4")
    if width is None or height is None or data.size != width * height:
        raise SystemExit(f"{path}: {data.size} floats; pass --width and --height that match")
    return data.reshape(height, width)


def write_plane(path, plane):
    path = pathlib.Path(path)
    if path.suffix == ".npy":
        np.save(path, plane.astype(np.float32))
    else:
        plane.astype("<f4").tofile(path)


def s0_scale(s0):
    """polar_sensor::Observation::s0_scale: nearest rank, index round((n - 1) q), half away from 0."""
    valid = s0[np.isfinite(s0) & (s0 > 0)]
    if valid.size == 0:
        return np.float32(1.0)
    v = np.sort(valid)
    k = int(math.floor((v.size - 1) * 0.99 + 0.5))
    return np.float32(v[k]) if v[k] > 0 else np.float32(1.0)


def dehaze_dcp(s0, patch=15, omega=0.95, t0=0.1, radius=15, eps=1e-3):
    s0 = np.where(np.isfinite(s0), s0, 0).astype(np.float32)
    valid = s0 > 0
    scale = s0_scale(s0)
    img = (s0 / scale).astype(np.float32)
    kernel = np.ones((patch, patch), np.uint8)
    dark0 = cv2.erode(img, kernel)
    vals = dark0[valid]
    if vals.size == 0:
        t = np.ones_like(img)
        return t, img * scale
    k = min(max(1, img.size // 1000), vals.size)
    thr = np.sort(vals)[vals.size - k]
    a = np.float32(img[valid & (dark0 >= thr)].max())
    if not a > 0:
        t = np.ones_like(img)
        return t, img * scale
    dark = cv2.erode((img / a).astype(np.float32), kernel)
    t = (np.float32(1.0) - np.float32(omega) * dark).astype(np.float32)
    if radius > 0:
        t = cv2.ximgproc.guidedFilter(img, t, radius, eps)
    t = np.clip(t, np.float32(t0), np.float32(1.0)).astype(np.float32)
    j = np.maximum((img - a) / t + a, np.float32(0.0)) * scale
    return t, j.astype(np.float32)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("input", help="S0 plane, .npy or raw float32 .bin")
    ap.add_argument("--width", type=int)
    ap.add_argument("--height", type=int)
    ap.add_argument("--synthetic", type=int, nargs=2, metavar=("W", "H"),
                    help="first write the closed-form synthetic S0 to INPUT")
    ap.add_argument("--out-t", required=True)
    ap.add_argument("--out-radiance", required=True)
    ap.add_argument("--patch", type=int, default=15)
    ap.add_argument("--omega", type=float, default=0.95)
    ap.add_argument("--t0", type=float, default=0.1)
    ap.add_argument("--radius", type=int, default=15)
    ap.add_argument("--eps", type=float, default=1e-3)
    args = ap.parse_args()
    if args.synthetic:
        write_plane(args.input, synthetic(*args.synthetic))
    s0 = read_plane(args.input, args.width, args.height)
    t, j = dehaze_dcp(s0, args.patch, args.omega, args.t0, args.radius, args.eps)
    write_plane(args.out_t, t)
    write_plane(args.out_radiance, j)
    print(f"{args.input}: {s0.shape[1]}x{s0.shape[0]}, t in [{t.min():.4f}, {t.max():.4f}], "
          f"radiance in [{j.min():.4g}, {j.max():.4g}], cv2 {cv2.__version__}, numpy {np.__version__}")


if __name__ == "__main__":
    main()
