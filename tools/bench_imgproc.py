#!/usr/bin/env python3
"""Side-by-side timing of polar-imgproc against OpenCV / scikit-image on a 2448x2048 frame.

Uses a real IMX250MZR frame (tests/data/real/camera_IMX250MZR.png) as float32 in [0, 1],
a degraded copy (blur + seeded noise) for the two-image ops and guided filter, its Otsu
mask for labelling. OpenCV runs with cv2.setNumThreads(2); the Rust example
(`cargo run --release -p polar-imgproc --example bench_imgproc`) uses rayon on the same
2 cores (RAYON_NUM_THREADS=2). Each time is the best of REPS runs after one warm-up (the least
disturbed by other load on a shared machine).

    tools/.venv/bin/python tools/bench_imgproc.py [--reps 7]
"""

import argparse
import os
import subprocess
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np
from skimage.filters import threshold_otsu
from skimage.measure import label as sk_label
from skimage.metrics import peak_signal_noise_ratio, structural_similarity

ROOT = Path(__file__).resolve().parent.parent


def timed(reps, f):
    f()
    t = []
    for _ in range(reps):
        s = time.perf_counter()
        f()
        t.append((time.perf_counter() - s) * 1e3)
    return float(np.min(t))


def reference_times(img, deg, mask, img8, reps):
    ell7 = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (7, 7))
    rect5, rect15 = np.ones((5, 5), np.uint8), np.ones((15, 15), np.uint8)
    ssim_reps = max(1, reps // 3)
    ops = {
        "gaussian_5x5": ("cv2.GaussianBlur 5x5", lambda: cv2.GaussianBlur(img, (5, 5), 0)),
        "gaussian_sigma2": ("cv2.GaussianBlur sigma 2", lambda: cv2.GaussianBlur(img, (0, 0), 2.0)),
        "box_5x5": ("cv2.boxFilter 5x5", lambda: cv2.boxFilter(img, -1, (5, 5))),
        "box_31x31": ("cv2.boxFilter 31x31", lambda: cv2.boxFilter(img, -1, (31, 31))),
        "sobel_dx_k3": ("cv2.Sobel dx k3", lambda: cv2.Sobel(img, cv2.CV_32F, 1, 0, ksize=3)),
        "sobel_dy_k5": ("cv2.Sobel dy k5", lambda: cv2.Sobel(img, cv2.CV_32F, 0, 1, ksize=5)),
        "scharr_dx": ("cv2.Scharr dx", lambda: cv2.Scharr(img, cv2.CV_32F, 1, 0)),
        "erode_rect_5x5": ("cv2.erode rect 5", lambda: cv2.erode(img, rect5)),
        "dilate_rect_15x15": ("cv2.dilate rect 15", lambda: cv2.dilate(img, rect15)),
        "erode_ellipse_7x7": ("cv2.erode ellipse 7", lambda: cv2.erode(img, ell7)),
        "open_rect_5x5": ("cv2.morphologyEx open 5", lambda: cv2.morphologyEx(img, cv2.MORPH_OPEN, rect5)),
        "median_f32_k3": ("cv2.medianBlur f32 3", lambda: cv2.medianBlur(img, 3)),
        "median_f32_k5": ("cv2.medianBlur f32 5", lambda: cv2.medianBlur(img, 5)),
        "median_u8_k5": ("cv2.medianBlur u8 5", lambda: cv2.medianBlur(img8, 5)),
        "median_u8_k9": ("cv2.medianBlur u8 9", lambda: cv2.medianBlur(img8, 9)),
        "guided_r8": ("cv2.ximgproc.guidedFilter r8", lambda: cv2.ximgproc.guidedFilter(img, deg, 8, 1e-3)),
        "otsu_f32": ("skimage threshold_otsu", lambda: threshold_otsu(img)),
        "label_c8": ("skimage label conn 2", lambda: sk_label(mask, connectivity=2)),
        "label_stats_c8": ("cv2.connectedComponentsWithStats 8",
                           lambda: cv2.connectedComponentsWithStats(mask, connectivity=8)),
        "psnr": ("skimage PSNR", lambda: peak_signal_noise_ratio(img, deg, data_range=1.0)),
        "ssim": ("skimage SSIM gaussian", lambda: structural_similarity(
            img, deg, data_range=1.0, gaussian_weights=True, sigma=1.5, use_sample_covariance=False)),
    }
    return {k: (name, timed(ssim_reps if k == "ssim" else reps, f)) for k, (name, f) in ops.items()}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=3,
                    help="alternate reference and Rust runs this many times, keeping each op's best")
    args = ap.parse_args()
    cv2.setNumThreads(2)
    frame = cv2.imread(str(ROOT / "tests/data/real/camera_IMX250MZR.png"), cv2.IMREAD_GRAYSCALE)
    img = (frame.astype(np.float32) / 255.0)
    rng = np.random.default_rng(7)
    deg = (cv2.GaussianBlur(img, (5, 5), 1.0) + 0.02 * rng.standard_normal(img.shape)).astype(np.float32)
    mask = (img > threshold_otsu(img)).astype(np.uint8) * 255
    h, w = img.shape
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        img.astype("<f4").tofile(d / "img.f32")
        deg.astype("<f4").tofile(d / "degraded.f32")
        mask.tofile(d / "mask.u8")
        frame.tofile(d / "img.u8")
        (d / "size.txt").write_text(f"{w} {h}\n")
        env = dict(os.environ, RAYON_NUM_THREADS="2")
        env.setdefault("CARGO_TARGET_DIR", str(ROOT / "target"))
        cmd = ["cargo", "run", "--quiet", "--release", "-p", "polar-imgproc", "--example", "bench_imgproc",
               "--", str(d), str(args.reps)]
        build = ["cargo", "build", "--quiet", "--release", "-p", "polar-imgproc", "--example", "bench_imgproc"]
        subprocess.run(build, cwd=ROOT, env=env, check=True)
        ref, ours = {}, {}
        for _ in range(args.rounds):
            for k, (name, t) in reference_times(img, deg, mask, frame, args.reps).items():
                ref[k] = (name, min(t, ref.get(k, (name, float("inf")))[1]))
            out = subprocess.run(cmd, cwd=ROOT, env=env, check=True, capture_output=True, text=True).stdout
            for line in out.splitlines():
                k, v = line.split()
                ours[k] = min(float(v), ours.get(k, float("inf")))
    print(f"{w}x{h} float32, 2 threads, best of {args.reps} runs x {args.rounds} alternating rounds (ms)")
    print(f"{'op':<20} {'reference':<36} {'ref ms':>9} {'rust ms':>9} {'speedup':>8}")
    for k, (name, t) in ref.items():
        r = ours.get(k, float("nan"))
        print(f"{k:<20} {name:<36} {t:9.2f} {r:9.2f} {t / r:7.2f}x")


if __name__ == "__main__":
    main()
