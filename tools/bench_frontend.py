#!/usr/bin/env python3
"""Front-end speed, side by side in one run: polanalyser's chain vs polar-sensor on a full frame.

polanalyser chain (float64, as polanalyser computes it):
  demosaicing(COLOR_PolarMono) + calcStokes(4 polarizer Mueller matrices) + cvtStokesToDoLP + cvtStokesToAoLP
polar-sensor (f32): raw -> S0, S1, S2, DoLP, AoLP, fused, caller-allocated planes
  (crates/polar-sensor/examples/bench_frontend.rs, built with cargo --release).
Both: best of N runs after a warm-up (the least disturbed by other processes).
The Rust example is built twice: the default build (x86-64 baseline code, whose hot
row kernels are also compiled for AVX2+FMA and AVX-512 and picked at run time by CPU
feature detection; OpenCV dispatches at run time too) and with `-C target-cpu=native`.
The SIMD target picked at run time and the machine load (1-minute load average,
before and after) are printed with the table.
The Rust side also measures memory bandwidth (memcpy and a STREAM-scale loop) and
reports the fused chain against the bytes it must move.

Colour (same run): a 2448x2048 colour mosaic (IMX250MYR layout, made from the bundled mono
frames as in tools/polanalyser_goldens.py) through polanalyser's colour chain
  demosaicing(COLOR_PolarRGB) + calcStokes + cvtStokesToDoLP + cvtStokesToAoLP (per colour)
and through polar-sensor's `stokes_planes_rgb_into` (the example with --pattern=rgb).

Whole process (`--process N`): `polar-vision stokes FRAME --out DIR` spawned as a user
runs it (release build), median of N runs, with the default `residual` and with
`--demosaic bilinear`, in the same run as polanalyser's chain; reports the split the
program prints (compute = read + demosaic + products, outputs) and its `--timings` stages
(read, exposure checks, demosaic + products, validity mask, each output file), the bytes its
outputs take on disk and its peak resident memory per input pixel (from GNU time); and a
floor row: the same number of bytes written as seven files into a fresh folder on the same
file system from this process, with no compute and no encoding.

Usage: tools/.venv/bin/python tools/bench_frontend.py [FRAME.png] [--reps N] [--process N] [--no-native]
"""

import argparse
import json
import os
import re
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np
import polanalyser as pa
from polanalyser_goldens import colour_frame

ROOT = Path(__file__).resolve().parent.parent


def best_time(reps, f):
    f()
    times = []
    for _ in range(reps):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def polanalyser_chain(raw, muellers):
    imgs = pa.demosaicing(raw, pa.COLOR_PolarMono)
    stokes = pa.calcStokes(imgs, muellers)
    with np.errstate(divide="ignore", invalid="ignore"):
        dolp = pa.cvtStokesToDoLP(stokes)
    aolp = pa.cvtStokesToAoLP(stokes)
    return stokes, dolp, aolp


def polanalyser_rgb_chain(raw, muellers):
    imgs = pa.demosaicing(raw, pa.COLOR_PolarRGB)
    stokes = pa.calcStokes(imgs, muellers)  # (h, w, 3 colours, 3)
    with np.errstate(divide="ignore", invalid="ignore"):
        dolp = pa.cvtStokesToDoLP(stokes)
    aolp = pa.cvtStokesToAoLP(stokes)
    return stokes, dolp, aolp


def run_process(exe, frame, extra):
    """One `polar-vision stokes` run into a fresh folder: (wall s, stderr split line,
    output bytes on disk, peak RSS in bytes or None).

    The peak comes from GNU time (/usr/bin/time) around the binary: a child's ru_maxrss
    from wait4 would include this Python process's own resident set, which the child
    inherits at fork and reports until it exits (so it measured ~98 B/px instead of ~25)."""
    gnu_time = Path("/usr/bin/time")
    with tempfile.TemporaryDirectory() as tmp:
        out, rss_file = Path(tmp) / "out", Path(tmp) / "rss"
        cmd = [str(exe), "stokes", frame, "--out", str(out), "--timings", *extra]
        if gnu_time.is_file():
            cmd = [str(gnu_time), "-f", "%M", "-o", str(rss_file), *cmd]
        t = time.perf_counter()
        proc = subprocess.run(cmd, stderr=subprocess.PIPE, text=True)
        wall = time.perf_counter() - t
        if proc.returncode != 0:
            raise SystemExit(f"polar-vision stokes {frame} {' '.join(extra)} failed:\n{proc.stderr}")
        size = sum(f.stat().st_size for f in out.rglob("*") if f.is_file())
        peak = int(rss_file.read_text().split()[-1]) * 1024 if rss_file.is_file() else None
    split = re.search(r"in ([0-9.]+) ms, outputs in ([0-9.]+) ms", proc.stderr)
    stages = re.search(r"^timings: (.*)$", proc.stderr, re.MULTILINE)
    return wall, split.groups() if split else ("?", "?"), size, peak, stages.group(1) if stages else "?"


def write_floor(size, files=7):
    """Seconds to write `size` bytes as `files` files into a fresh folder on the same file
    system as the process runs' outputs (page cache, no sync, as `stokes` writes them): the
    least any process with these outputs takes, however fast its compute and encoding."""
    chunk = os.urandom(size // files)
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        for i in range(files):
            (Path(tmp) / f"out{i}").write_bytes(chunk)
        return time.perf_counter() - t


def process_table(frame, runs, t_py, pixels):
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    subprocess.run(["cargo", "build", "--release", "--locked", "-p", "polar-vision"], cwd=ROOT, check=True, stderr=subprocess.DEVNULL)
    exe = target / "release" / "polar-vision"
    print()
    print(f"Whole process, median of {runs} runs (polanalyser compute {t_py * 1e3:.0f} ms in this run):")
    print(f"| {'command':<44} | {'wall ms':>8} | {'vs polanalyser':>14} | {'compute / outputs ms':>20} | {'MB on disk':>10} | {'peak B/px':>9} |")
    print(f"|{'-' * 46}|{'-' * 10}|{'-' * 16}|{'-' * 22}|{'-' * 12}|{'-' * 11}|")
    splits, sizes = [], []
    for label, extra in [("stokes (default: residual)", []), ("stokes --demosaic bilinear", ["--demosaic", "bilinear"])]:
        rs = [run_process(exe, frame, extra) for _ in range(runs)]
        wall = statistics.median(r[0] for r in rs)
        mid = min(rs, key=lambda r: abs(r[0] - wall))
        peaks = [r[3] for r in rs if r[3] is not None]
        peak = f"{max(peaks) / pixels:9.1f}" if peaks else f"{'?':>9}"
        print(
            f"| {label:<44} | {wall * 1e3:8.0f} | {t_py / wall:13.2f}x | {mid[1][0]:>9} / {mid[1][1]:>8} | "
            f"{mid[2] / 1e6:10.1f} | {peak} |"
        )
        splits.append((label, mid[4]))
        sizes.append(mid[2])
    floor = statistics.median(write_floor(max(sizes)) for _ in range(runs))
    print(
        f"| {'floor: the same bytes written, no compute':<44} | {floor * 1e3:8.0f} | {t_py / floor:13.2f}x | "
        f"{'-':>20} | {max(sizes) / 1e6:10.1f} | {'-':>9} |"
    )
    print()
    print("Stages of the median run (--timings; output files are encoded in parallel, so their times overlap):")
    for label, stages in splits:
        print(f"- {label}: {stages}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("frame", nargs="?", default=str(ROOT / "tests/data/real/carps_IMX250MZR.png"))
    parser.add_argument("--reps", type=int, default=10)
    parser.add_argument("--process", type=int, default=0, metavar="N", help="also time the whole polar-vision stokes process, median of N runs")
    parser.add_argument("--no-native", action="store_true", help="skip the -C target-cpu=native build (a second build of the dependencies in target/native-cpu)")
    args = parser.parse_args()

    raw = cv2.imread(args.frame, cv2.IMREAD_UNCHANGED)
    muellers = [pa.polarizer(np.deg2rad(a)) for a in (0, 45, 90, 135)]

    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    builds = {
        "default": (target, {}),
        "-C target-cpu=native": (target / "native-cpu", {"RUSTFLAGS": "-C target-cpu=native"}),
    }
    if args.no_native:
        del builds["-C target-cpu=native"]
    exes = {}
    for label, (tdir, env) in builds.items():
        subprocess.run(
            ["cargo", "build", "--release", "--locked", "-p", "polar-sensor", "--example", "bench_frontend"],
            cwd=ROOT,
            check=True,
            stderr=subprocess.DEVNULL,
            env={**os.environ, "CARGO_TARGET_DIR": str(tdir), **env},
        )
        exes[label] = tdir / "release" / "examples" / "bench_frontend"

    colour = colour_frame()
    colour_png = tempfile.NamedTemporaryFile(suffix=".png", delete=False)
    colour_png.close()
    cv2.imwrite(colour_png.name, colour)

    # Timed back to back once everything is built, so that all rows share the machine's load.
    load_before = os.getloadavg()[0]
    t_py = best_time(max(3, args.reps // 3), lambda: polanalyser_chain(raw, muellers))
    t_py_rgb = best_time(max(3, args.reps // 3), lambda: polanalyser_rgb_chain(colour, muellers))
    results, rgb_results = {}, {}
    for label, exe in exes.items():
        out = subprocess.run([str(exe), args.frame, str(args.reps), "--json"], check=True, capture_output=True, text=True)
        results[label] = json.loads(out.stdout)
        extra = ["--json", "--pattern=rgb", "--only=bilinear"]
        out = subprocess.run([str(exe), colour_png.name, str(args.reps), *extra], check=True, capture_output=True, text=True)
        rgb_results[label] = json.loads(out.stdout)
    os.unlink(colour_png.name)

    h, w = raw.shape
    first = next(iter(results.values()))
    print(f"{w}x{h} {raw.dtype} frame, {first['threads']} threads; best of N runs; OpenCV {cv2.__version__}")
    print(f"load average (1 min, {os.cpu_count()} CPUs): {load_before:.2f} before, {os.getloadavg()[0]:.2f} after")
    for label, rs in results.items():
        print(
            f"[{label}] SIMD target picked at run time: {rs['simd']}; bandwidth (read+write): memcpy {rs['memcpy_gb_s']:.2f} GB/s, STREAM-scale "
            f"{rs['stream_gb_s']:.2f} GB/s; fused chain moves {rs['bytes_moved'] / 1e6:.1f} MB -> bound {rs['bound_s'] * 1e3:.2f} ms"
        )
    print()
    print(f"| {'pipeline':<52} | {'build':<22} | {'ms':>8} | {'vs polanalyser':>14} | {'vs bound':>8} |")
    print(f"|{'-' * 54}|{'-' * 24}|{'-' * 10}|{'-' * 16}|{'-' * 10}|")
    print(
        f"| {'polanalyser demosaic+calcStokes+DoLP+AoLP (f64)':<52} | {'pip wheel':<22} | {t_py * 1e3:8.1f} | "
        f"{'1.0x':>14} | {t_py / first['bound_s']:7.1f}x |"
    )
    for name in ["bilinear", "residual", "superpixel", "newton"]:
        for label, rs in results.items():
            if name not in rs["seconds"]:
                continue
            t = rs["seconds"][name]
            bound = f"{t / rs['bound_s']:7.2f}x" if name == "bilinear" else f"{'-':>8}"
            pipeline = f"polar-sensor {name} -> S0,S1,S2,DoLP,AoLP (f32)"
            print(f"| {pipeline:<52} | {label:<22} | {t * 1e3:8.2f} | {t_py / t:13.1f}x | {bound} |")
    first_rgb = next(iter(rgb_results.values()))
    print(
        f"| {'polanalyser COLOR_PolarRGB+calcStokes+DoLP+AoLP (f64)':<52} | {'pip wheel':<22} | {t_py_rgb * 1e3:8.1f} | "
        f"{'1.0x':>14} | {t_py_rgb / first_rgb['bound_s']:7.1f}x |"
    )
    for label, rs in rgb_results.items():
        t = rs["seconds"]["bilinear"]
        pipeline = "polar-sensor rgb bilinear -> per colour (f32)"
        print(f"| {pipeline:<52} | {label:<22} | {t * 1e3:8.2f} | {t_py_rgb / t:13.1f}x | {t / rs['bound_s']:7.2f}x |")
    if args.process:
        process_table(args.frame, args.process, t_py, w * h)

if __name__ == "__main__":
    main()
