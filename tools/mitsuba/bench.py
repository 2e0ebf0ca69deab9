#!/usr/bin/env python3
"""Time-to-equal-error of our renderer against Mitsuba 3 (llvm_ad_mono_polarized),
both on the same number of threads (default 2), on the cross-check scenes.

For each scene and several spp values, both renderers are timed and their
error measured against a converged Mitsuba reference:

    error = S0 relative RMSE over the object pixels (as in crosscheck.py),

with the reference's own noise removed: the reference is the mean R of two
independent renders R1, R2, and E|X - T|^2 = E|X - R|^2 - E|R1 - R2|^2 / 4
(T the truth, X independent of R). Monte Carlo error falls as t^-1/2, so each
renderer's points are fitted with error = c / sqrt(t) and the time ratio at
equal error is (c_mitsuba / c_ours)^2 (> 1: ours is faster).

Timings: Mitsuba is timed warm (scene loaded, kernel compiled by a 1-spp
render first: only mi.render); ours is the renderer's own render time from
meta.json "seconds" when it writes it, else the wall time of the process.

    tools/.venv/bin/python tools/mitsuba/bench.py OUT [--refs DIR] [--threads 2]
        [--spp 16,64,256,1024] [--scenes a,b] [--ours-exe PATH] [--ours-only-if-available]

Writes OUT/bench.json and OUT/bench.png (error vs time, both renderers).
"""

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import ours  # noqa: E402
import render_refs  # noqa: E402
import scenes  # noqa: E402


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", type=Path, help="output dir: bench.json, bench.png, our renders")
    ap.add_argument("--refs", type=Path, default=None, help="Mitsuba reference cache (default: OUT/refs)")
    ap.add_argument("--threads", type=int, default=2, help="threads for both renderers (default 2)")
    ap.add_argument("--spp", type=lambda t: [int(v) for v in t.split(",")], default=[16, 64, 256, 1024],
                    help="comma-separated spp values for both renderers")
    ap.add_argument("--ref-spp", type=int, default=None, help=f"reference spp (default per scene: {scenes.REFERENCE_SPP})")
    ap.add_argument("--scenes", type=render_refs.parse_scene_list, default=scenes.SCENES)
    ap.add_argument("--ours-exe", type=Path, default=None, help="our render_scene executable (default: cargo build)")
    ap.add_argument("--ours-only-if-available", action="store_true",
                    help="when our renderer is not there yet, bench Mitsuba alone, say so and exit 0")
    return ap.parse_args()


class Reference:
    """Two independent converged Mitsuba renders of one scene."""

    def __init__(self, mi, refs, name, spp):
        r1, r2 = (scenes.read_stokes_exr(mi, render_refs.ensure_reference(mi, refs / f"seed{s}", name, spp, s))
                  for s in (0, 1))
        self.mask = scenes.object_mask(name)
        self.pixels = self.mask.size
        self.s0 = 0.5 * (r1[..., 0] + r2[..., 0])[self.mask]
        self.noise_mse = float(np.mean((r1[..., 0] - r2[..., 0])[self.mask] ** 2)) / 4
        self.stokes = 0.5 * (r1 + r2)

    def error(self, stokes):
        """S0 relative RMSE against the truth, reference noise removed (NaN if below it)."""
        mse = float(np.mean((stokes[..., 0][self.mask] - self.s0) ** 2)) - self.noise_mse
        return float(np.sqrt(mse) / self.s0.mean()) if mse > 0 else float("nan")

    def floor(self):
        """The reference's own relative error: errors near it are not measurable."""
        return float(np.sqrt(self.noise_mse) / self.s0.mean())


def bench_mitsuba(mi, name, spp_list, ref):
    """[(spp, seconds, error)] for Mitsuba, warm."""
    scene = mi.load_dict(scenes.scene_dict(mi, name, 1), optimize=False)
    scenes.render_stokes(mi, scene, 1, seed=99)  # compile the kernels
    rows = []
    for i, spp in enumerate(spp_list):
        t0 = time.perf_counter()
        stokes = scenes.render_stokes(mi, scene, spp, seed=100 + i)
        rows.append((spp, time.perf_counter() - t0, ref.error(stokes)))
    return rows


def bench_ours(exe, name, spp_list, ref, out, threads):
    """[(spp, seconds, error)] for our renderer, and the timing source."""
    rows, source = [], None
    for spp in spp_list:
        stokes, seconds, source = ours.render(exe, name, out / "ours" / f"{name}-{spp}", spp, threads)
        rows.append((spp, seconds, ref.error(stokes)))
    return rows, source


def fit_c(rows):
    """c of error = c / sqrt(t), least squares in log space over measurable points."""
    pts = [(t, e) for _, t, e in rows if np.isfinite(e) and t > 0]
    return float(np.exp(np.mean([np.log(e) + 0.5 * np.log(t) for t, e in pts]))) if pts else float("nan")


def print_rows(name, label, rows, pixels):
    for spp, t, e in rows:
        rate = spp * pixels / t / 1e6
        print(f"{name:<16}{label:<10}{spp:>7}{t:>10.3f}{rate:>12.2f}{100 * e:>12.3f}%")


def plot(path, results):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(results), figsize=(4.2 * len(results), 4), constrained_layout=True, squeeze=False)
    for ax, (name, res) in zip(axes[0], results.items()):
        for label, style in (("mitsuba", "o-"), ("ours", "s-")):
            rows = res.get(label)
            if not rows:
                continue
            t = np.array([r[1] for r in rows])
            ax.loglog(t, [r[2] for r in rows], style, label=f"{label} (c={res['c_' + label]:.3g})")
            tt = np.geomspace(t.min(), t.max(), 20)
            ax.loglog(tt, res["c_" + label] / np.sqrt(tt), ":", color=ax.lines[-1].get_color())
        ax.axhline(res["floor"], color="gray", lw=0.8, label="reference noise")
        ratio = res.get("speedup")
        ax.set_title(name + (f"  (speed-up {ratio:.2f}x)" if ratio else ""))
        ax.set_xlabel("render time (s, 2 threads)")
        ax.set_ylabel("S0 relative RMSE")
        ax.legend(fontsize=8)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main():
    args = parse_args()
    mi, dr = scenes.setup_mitsuba(args.threads)
    args.out.mkdir(parents=True, exist_ok=True)
    refs = args.refs or args.out / "refs"
    exe, why = args.ours_exe, None
    if exe is None:
        gaps = ours.missing(args.scenes)
        why = "missing " + ", ".join(gaps) if gaps else None
        exe = None if gaps else ours.build()
    results = {}
    references = {n: Reference(mi, refs, n, args.ref_spp or scenes.REFERENCE_SPP[n]) for n in args.scenes}
    print(f"\n{'scene':<16}{'renderer':<10}{'spp':>7}{'seconds':>10}{'Msamples/s':>12}{'S0 error':>13}")
    for name, ref in references.items():
        res = {"floor": ref.floor(), "mitsuba": bench_mitsuba(mi, name, args.spp, ref)}
        print_rows(name, "mitsuba", res["mitsuba"], ref.pixels)
        if exe is not None:
            try:
                res["ours"], res["ours_timing"] = bench_ours(exe, name, args.spp, ref, args.out, args.threads)
                print_rows(name, "ours", res["ours"], ref.pixels)
            except ours.RenderFailed as err:
                print(f"{name}: OUR RENDERER FAILED, Mitsuba only:\n{err}")
        for label in ("mitsuba", "ours"):
            if label in res:
                res["c_" + label] = fit_c(res[label])
        if "ours" in res:
            res["speedup"] = (res["c_mitsuba"] / res["c_ours"]) ** 2
        results[name] = res
    print(f"\nreference noise floor (S0 rel. error of the reference itself): "
          + ", ".join(f"{n} {100 * r['floor']:.2f}%" for n, r in results.items()))
    if exe is not None:
        print("\ntime-to-equal-error, Mitsuba time / our time (fit error = c / sqrt(t)):")
        for n, r in results.items():
            if "speedup" in r:
                print(f"  {n:<16}{r['speedup']:6.2f}x   (our timing: {r['ours_timing']})")
        speedups = [r["speedup"] for r in results.values() if np.isfinite(r.get("speedup", np.nan))]
        if speedups:
            print(f"  {'geometric mean':<16}{np.exp(np.mean(np.log(speedups))):6.2f}x")
    meta = {"threads": args.threads, "spp": args.spp, "mitsuba": render_refs.scenes_version(), "scenes": results}
    (args.out / "bench.json").write_text(json.dumps(meta, indent=2) + "\n")
    plot(args.out / "bench.png", results)
    print(f"\nwrote {args.out / 'bench.json'} and {args.out / 'bench.png'}")
    if exe is None:
        print(f"\nOUR RENDERER IS NOT AVAILABLE YET: {why}. Only Mitsuba was benchmarked.")
        sys.exit(0 if args.ours_only_if_available else 2)


if __name__ == "__main__":
    main()
