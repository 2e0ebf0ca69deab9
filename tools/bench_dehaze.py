#!/usr/bin/env python3
"""Dehazing speed on a 5 MP frame, side by side in one run: polar-dehaze (polarization and
dark channel) against the OpenCV dark-channel reference (tools/dehaze_dcp_reference.py).

The frame: datasets-synth/scenes/hazy_outdoor.toml rendered by `polar-datagen render`
(or SAMPLE_DIR if given), its Stokes planes upsampled to 2448x2048 by pixel replication
(crates/polar-dehaze/examples/bench.rs, which also writes the S0 the reference reads).
Both sides on 2 threads, best of N runs; the machine load is printed with the table.

Usage: tools/.venv/bin/python tools/bench_dehaze.py [SAMPLE_DIR] [--runs N]
"""

import argparse
import json
import os
import subprocess
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

import dehaze_dcp_reference as reference

ROOT = Path(__file__).resolve().parent.parent
THREADS = 2


def cargo_exe(args, name):
    """Builds with cargo (release) and returns the path of executable `name`."""
    out = subprocess.run(
        ["cargo", "build", "--release", "--locked", "--message-format=json", *args],
        cwd=ROOT, check=True, capture_output=True, text=True,
    ).stdout
    for line in out.splitlines():
        msg = json.loads(line)
        if msg.get("reason") == "compiler-artifact" and msg.get("executable") and msg["target"]["name"] == name:
            return msg["executable"]
    raise SystemExit(f"cargo built no executable named {name}")


def best(f, runs):
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sample", nargs="?", type=Path, help="a sample directory with stokes.exr (default: render hazy_outdoor.toml)")
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    bench = cargo_exe(["-p", "polar-dehaze", "--example", "dehaze_bench"], "dehaze_bench")
    with tempfile.TemporaryDirectory() as tmp:
        sample = args.sample
        if sample is None:
            sample = Path(tmp) / "hazy"
            datagen = cargo_exe(["-p", "polar-datagen"], "polar-datagen")
            scene = ROOT / "datasets-synth/scenes/hazy_outdoor.toml"
            subprocess.run([datagen, "render", str(scene), "--out", str(sample), "--spp", "16"], check=True, capture_output=True)
        s0_path = Path(tmp) / "s0.bin"
        load_before = os.getloadavg()[0]
        env = dict(os.environ, RAYON_NUM_THREADS=str(THREADS))
        ours = json.loads(subprocess.run(
            [bench, str(sample), "--runs", str(args.runs), "--s0-out", str(s0_path)],
            env=env, check=True, capture_output=True, text=True,
        ).stdout)
        w, h = ours["width"], ours["height"]
        s0 = reference.read_plane(s0_path, w, h)
    cv2.setNumThreads(THREADS)
    t_ref = best(lambda: reference.dehaze_dcp(s0), args.runs)
    load_after = os.getloadavg()[0]
    print(f"{w}x{h} ({w * h / 1e6:.2f} MP), {THREADS} threads, best of {args.runs}; "
          f"load average {load_before:.1f} before, {load_after:.1f} after; OpenCV {cv2.__version__}")
    print()
    print("| method | s | vs OpenCV dark channel |")
    print("|---|---|---|")
    print(f"| OpenCV + numpy dark channel (tools/dehaze_dcp_reference.py) | {t_ref:.3f} | 1.0x |")
    for key, label in [
        ("dark_channel_as_reference_s", "ours, dark channel as the reference (no denoising)"),
        ("dark_channel_s", "ours, dark channel (defaults)"),
        ("polarization_s", "ours, polarization (defaults)"),
    ]:
        print(f"| {label} | {ours[key]:.3f} | {t_ref / ours[key]:.1f}x |")
    print()
    print(f"target: polarization under 0.5 s: {'met' if ours['polarization_s'] < 0.5 else 'NOT met'}")


if __name__ == "__main__":
    main()
