#!/usr/bin/env python3
"""Time-to-equal-error of our renderer against Mitsuba 3 (llvm_ad_mono_polarized),
both on the same number of threads (default 2), on the cross-check scenes,
each renderer with an independent and a low-discrepancy sampler.

Curves: for each scene, renderer and sampler, the render time and two errors
at several spp against a converged reference (BENCH_REFERENCE: the mean of
two renders with independent seeds, R1 and R2, over the object pixels):

    S0 error  = RMS(S0 - S0_ref) / mean(S0_ref)
    pol error = sqrt(mean((S1 - S1_ref)^2 + (S2 - S2_ref)^2)) / mean(S0_ref)

each with the reference's own noise removed from the mean square
(E|X - T|^2 = E|X - R|^2 - E|R1 - R2|^2 / 4, T the truth, X independent of R).

Time-to-equal-error: for each curve, log(time) is interpolated piecewise
linearly in log(error) between the measured points (no assumed convergence
rate: low-discrepancy samplers converge faster than t^-1/2), and the time
ratio Mitsuba / ours (> 1: ours is faster) is read at the errors Mitsuba
reaches at 64, 256 and 1024 spp, where those lie inside our measured range;
where our fastest point is already below such an error, its time bounds ours
and the ratio is a lower bound ("≥", also on a geometric mean it enters). Two
pairs: Mitsuba independent / ours independent (also with the old fit
error = c / sqrt(t), ratio (c_mitsuba / c_ours)^2, for continuity) and
Mitsuba's low-discrepancy sampler (MITSUBA_LD) / ours `sobol`.

Timings: Mitsuba is timed warm: at each spp one untimed render first (it
compiles the kernel, which for the low-discrepancy samplers depends on spp),
then one timed render (mi.render only); both renders' errors are averaged.
Ours: the renderer's own render time (meta.json "seconds"). CPU time is
recorded too (process time of Mitsuba's render; our whole process), and the
ratios are printed for both clocks: wall time is the measure on an idle
machine, CPU time the one a loaded machine distorts less (docs/performance-notes.md).

    tools/.venv/bin/python tools/mitsuba/bench.py OUT [--refs DIR] [--threads 2]
        [--spp 1,4,16,64,256,1024] [--scenes a,b] [--mitsuba-samplers a,b|all]
        [--mitsuba-only] [--ours-exe PATH] [--ours-only-if-available]

Writes OUT/bench.json, OUT/bench.png (error vs time, S0 and polarization)
and prints the tables in markdown.
"""

import argparse
import json
import resource
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import ours  # noqa: E402
import render_refs  # noqa: E402
import scenes  # noqa: E402

# Mitsuba's low-discrepancy anchor: the sampler that converged furthest in
# equal time on 4 of the 5 scenes among stratified, multijitter, orthogonal
# and ldsampler, and within 20% of the best on the fifth (pplastic, where
# orthogonal overtakes it beyond ~1 s); measured with `--mitsuba-samplers all
# --mitsuba-only`, README.md "Mitsuba's sampler".
MITSUBA_LD = "multijitter"
# Our samplers (render_scene --sampler); without the flag, the scene file's.
OURS_SAMPLERS = ["independent", "sobol"]
# Reference per scene: (sampler, spp per pass, passes), the float64 mean of
# the passes, twice (seeds 0 and 1). Passes of at most 1024 spp: one Mitsuba
# pass of many samples drifts in float32 (docs/performance-notes.md, "Benchmark references").
# `haze` keeps the cross-check's references (REFERENCE_SPP, independent).
BENCH_REFERENCE = {
    "conductor": ("multijitter", 256, 32),
    "roughconductor": ("multijitter", 1024, 16),
    "pplastic": ("multijitter", 1024, 16),
    "dielectric": ("multijitter", 1024, 16),
    "haze": ("independent", scenes.REFERENCE_SPP["haze"], 1),
}
METRICS = ("s0", "pol")
CLOCKS = ("wall", "cpu")
LEVEL_SPP = (64, 256, 1024)  # the comparison errors: Mitsuba's at these spp
SEED = 1_000_000  # Mitsuba's bench seeds start here, clear of the references' 0..2 * passes


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", type=Path, help="output dir: bench.json, bench.png, our renders")
    ap.add_argument("--refs", type=Path, default=None,
                    help="reference cache (default: OUT/refs); bench references go to REFS/bench")
    ap.add_argument("--threads", type=int, default=2, help="threads for both renderers (default 2)")
    ap.add_argument("--spp", type=lambda t: [int(v) for v in t.split(",")], default=[1, 4, 16, 64, 256, 1024],
                    help="comma-separated spp values for both renderers (include 64, 256, 1024: the comparison levels; low ones let a faster curve start above them)")
    ap.add_argument("--scenes", type=render_refs.parse_scene_list, default=scenes.SCENES)
    ap.add_argument("--mitsuba-samplers", type=parse_samplers, default=None,
                    help=f"Mitsuba samplers to time (default: independent,{MITSUBA_LD}; all: every one)")
    ap.add_argument("--mitsuba-only", action="store_true", help="do not run our renderer (sampler study)")
    ap.add_argument("--ours-exe", type=Path, default=None, help="our render_scene executable (default: cargo build)")
    ap.add_argument("--ours-only-if-available", action="store_true",
                    help="when our renderer is not there yet, bench Mitsuba alone, say so and exit 0")
    return ap.parse_args()


def parse_samplers(text):
    """Comma-separated Mitsuba sampler names, or `all`."""
    names = scenes.SAMPLERS if text == "all" else [n for n in text.split(",") if n]
    unknown = sorted(set(names) - set(scenes.SAMPLERS))
    if unknown:
        raise argparse.ArgumentTypeError(f"unknown samplers {unknown}; known: {scenes.SAMPLERS}")
    return names


class Reference:
    """The mean of two independent converged Mitsuba renders of one scene."""

    def __init__(self, mi, refs, name):
        sampler, spp, passes = BENCH_REFERENCE[name]
        shared = (sampler, spp, passes) == ("independent", scenes.REFERENCE_SPP[name], 1)
        root = refs if shared else refs / "bench"  # the cross-check's cache, or the bench's own
        r1, r2 = (scenes.read_stokes_exr(mi, render_refs.ensure_reference(
            mi, root / f"seed{s}", name, spp, s, sampler=sampler, passes=passes)).astype(np.float64) for s in (0, 1))
        self.spec = f"{sampler}, {passes} x {spp} spp, 2 seeds"
        self.mask = scenes.object_mask(name)
        self.pixels = self.mask.size
        self.stokes = 0.5 * (r1 + r2)[self.mask]
        self.scale = float(self.stokes[:, 0].mean())
        self.noise = {k: v / 4 for k, v in mean_squares((r1 - r2)[self.mask]).items()}

    def errors(self, renders):
        """{metric: relative RMSE against the truth} of the renders (their mean
        square averaged), reference noise removed (NaN if below it)."""
        ms = [mean_squares(r.astype(np.float64)[self.mask] - self.stokes) for r in renders]
        excess = {k: np.mean([m[k] for m in ms]) - self.noise[k] for k in METRICS}
        return {k: float(np.sqrt(v) / self.scale) if v > 0 else float("nan") for k, v in excess.items()}

    def floors(self):
        """The reference's own relative errors: errors near them are not measurable."""
        return {k: float(np.sqrt(v) / self.scale) for k, v in self.noise.items()}


def mean_squares(diff):
    """{"s0": mean dS0^2, "pol": mean (dS1^2 + dS2^2)} of (N, 4) Stokes differences."""
    return {"s0": float(np.mean(diff[:, 0] ** 2)), "pol": float(np.mean(diff[:, 1] ** 2 + diff[:, 2] ** 2))}


def row(spp, samples, seconds, cpu_seconds, errors):
    return {"spp": spp, "samples": samples, "seconds": seconds, "cpu_seconds": cpu_seconds, **errors}


def children_cpu():
    """CPU seconds (user + system) used so far by finished child processes."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def bench_mitsuba(mi, name, sampler, spp_list, ref):
    """Rows of Mitsuba with `sampler`, timed warm (see the module doc)."""
    scene = mi.load_dict(scenes.scene_dict(mi, name, 1, sampler), optimize=False)
    rows = []
    for i, spp in enumerate(spp_list):
        warm = scenes.render_stokes(mi, scene, spp, seed=SEED + 2 * i)
        t0, c0 = time.perf_counter(), time.process_time()
        timed = scenes.render_stokes(mi, scene, spp, seed=SEED + 2 * i + 1)
        seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
        samples = scene.sensors()[0].sampler().sample_count()
        rows.append(row(spp, samples, seconds, cpu, ref.errors([warm, timed])))
    return rows


def bench_ours(exe, name, sampler, spp_list, ref, out, threads):
    """Rows of our renderer with `sampler` (None: the scene file's), and the timing source."""
    rows, source = [], None
    for spp in spp_list:
        where = out / "ours" / f"{name}-{sampler or 'default'}-{spp}"
        c0 = children_cpu()
        stokes, seconds, source = ours.render(exe, name, where, spp, threads, sampler)
        rows.append(row(spp, spp, seconds, children_cpu() - c0, ref.errors([stokes])))
    return rows, source


def frontier(rows, metric):
    """(times, errors) of the points that improve on every faster point,
    so that error strictly falls with time (noise can break monotonicity)."""
    pts = sorted((r["seconds"], r[metric]) for r in rows if np.isfinite(r[metric]) and r["seconds"] > 0)
    t, e = [], []
    for ti, ei in pts:
        if not e or ei < e[-1]:
            t.append(ti)
            e.append(ei)
    return np.array(t), np.array(e)


def time_at(rows, metric, level):
    """Time the curve needs to reach error `level`: log(time) interpolated
    linearly in log(error) between measured points; NaN outside their range."""
    t, e = frontier(rows, metric)
    if len(e) == 0 or not e[-1] <= level <= e[0]:
        return float("nan")
    return float(np.exp(np.interp(np.log(level), np.log(e[::-1]), np.log(t[::-1]))))


def time_bound(rows, metric, level):
    """When the curve's fastest point is already below error `level`: that
    point's time, an upper bound on the time it needs; else NaN."""
    t, e = frontier(rows, metric)
    return float(t[0]) if len(e) and level > e[0] else float("nan")


def error_at(rows, metric, seconds):
    """The error the curve reaches in `seconds`, interpolated like time_at; NaN outside its range."""
    t, e = frontier(rows, metric)
    if len(t) == 0 or not t[0] <= seconds <= t[-1]:
        return float("nan")
    return float(np.exp(np.interp(np.log(seconds), np.log(t), np.log(e))))


def fit_c(rows, metric):
    """c of error = c / sqrt(t), least squares in log space over measurable points."""
    pts = [(r["seconds"], r[metric]) for r in rows if np.isfinite(r[metric]) and r["seconds"] > 0]
    return float(np.exp(np.mean([np.log(e) + 0.5 * np.log(t) for t, e in pts]))) if pts else float("nan")


def compare(curves, mitsuba, ours_key):
    """Time ratios Mitsuba / ours at Mitsuba's errors at LEVEL_SPP, per metric
    (NaN where the level is outside either measured range); for two
    independent samplers also the c / sqrt(t) fit ratio."""
    m_rows, o_rows = curves[mitsuba], curves[ours_key]
    out = {"mitsuba": mitsuba, "ours": ours_key}
    for metric in METRICS:
        levels = []
        for spp in LEVEL_SPP:
            level = next((r[metric] for r in m_rows if r["spp"] == spp), float("nan"))
            t_ours = time_at(o_rows, metric, level)
            # Our fastest point already below the level: its time bounds ours, the ratio from below.
            bound = bool(np.isfinite(level) and not np.isfinite(t_ours))
            if bound:
                t_ours = time_bound(o_rows, metric, level)
            ratio = time_at(m_rows, metric, level) / t_ours if np.isfinite(level) else np.nan
            levels.append({"spp": spp, "error": level, "ratio": float(ratio), "lower_bound": bool(bound and np.isfinite(ratio))})
        out[metric] = levels
        if mitsuba.endswith("/independent") and ours_key.endswith("/independent"):
            out[f"fit_{metric}"] = (fit_c(m_rows, metric) / fit_c(o_rows, metric)) ** 2
    return out


def pairs_of(curves):
    """The compared (Mitsuba, ours) curve pairs of a scene: independent with
    independent, Mitsuba's low-discrepancy sampler with our sobol (our
    default sampler stands in for both when render_scene has no --sampler)."""
    ours_ind = "ours/independent" if "ours/independent" in curves else "ours/default"
    ours_ld = "ours/sobol" if "ours/sobol" in curves else "ours/default"
    pairs = [("mitsuba/independent", ours_ind), (f"mitsuba/{MITSUBA_LD}", ours_ld)]
    return [(m, o) for m, o in pairs if m in curves and o in curves]


def sampler_study(curves):
    """Among Mitsuba's low-discrepancy curves: their errors (S0, pol) at 3
    render times spread over the upper two thirds (log scale) of the time
    range all of them measured, and the sampler with the lowest geometric
    mean of those errors (the one that converges furthest in equal time)."""
    ld = {k.split("/")[1]: v for k, v in curves.items() if k.startswith("mitsuba/") and k != "mitsuba/independent"}
    if len(ld) < 2:
        return None
    spans = [frontier(rows, m)[0] for rows in ld.values() for m in METRICS]
    lo, hi = max(t.min() for t in spans), min(t.max() for t in spans)
    if not lo < hi:
        return {"times": [], "note": "the time ranges do not overlap"}
    times = np.geomspace(lo, hi, 4)[1:]
    errors = {k: {m: [error_at(rows, m, t) for t in times] for m in METRICS} for k, rows in ld.items()}
    best = min(errors, key=lambda k: np.mean(np.log(errors[k]["s0"] + errors[k]["pol"])))
    return {"times": times.tolist(), "errors": errors, "best": best}


def fmt_ratio(cell):
    r, e = cell["ratio"], cell["error"]
    at_least = "≥" if cell.get("lower_bound") else ""
    return f"{at_least}{r:.2f}x @{100 * e:.3g}%" if np.isfinite(r) else (f"out of range @{100 * e:.3g}%" if np.isfinite(e) else "-")


def time_exponent(rows):
    """k of time ~ samples^k, least squares in log space (1: time linear in spp)."""
    x, y = np.log([r["samples"] for r in rows]), np.log([r["seconds"] for r in rows])
    return float(np.polyfit(x, y, 1)[0]) if len(rows) > 1 else float("nan")


def print_rows(results, pixels):
    print("\n| scene | renderer | sampler | spp | samples/px | wall s | CPU s | Msamples/s (wall) | S0 error | pol error |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, res in results.items():
        for key, rows in res["curves"].items():
            renderer, sampler = key.split("/")
            for r in rows:
                rate = r["samples"] * pixels[name] / r["seconds"] / 1e6
                print(f"| {name} | {renderer} | {sampler} | {r['spp']} | {r['samples']} | {r['seconds']:.3f} "
                      f"| {r['cpu_seconds']:.3f} "
                      f"| {rate:.2f} | {100 * r['s0']:.4f}% | {100 * r['pol']:.4f}% |")
    print("\nTime ~ samples^k over the spp values (1: linear, warm):")
    for name, res in results.items():
        print(f"  {name:<16}" + ", ".join(f"{key} {time_exponent(rows):.2f}" for key, rows in res["curves"].items()))


def print_comparisons(results, pixels, clock):
    hdr = [f"S0 at M's {s}-spp error" for s in LEVEL_SPP] + [f"pol at M's {s}-spp error" for s in LEVEL_SPP]
    print(f"\nTime-to-equal-error, Mitsuba {clock} time / our {clock} time (> 1: ours faster), at the error"
          " Mitsuba reaches at the given spp, interpolated on both curves; fit: error = c / sqrt(t) (S0, pol).\n")
    print("| scene | Mitsuba / ours | Msamples/s (wall) M / ours | " + " | ".join(hdr) + " | fit c/sqrt(t) |")
    print("|" + "---|" * (4 + len(hdr)))
    geo = {}
    for name, res in results.items():
        for cmp in res["comparisons"][clock]:
            m, o = cmp["mitsuba"], cmp["ours"]
            rates = [max(r["samples"] * pixels[name] / r["seconds"] for r in res["curves"][k]) / 1e6 for k in (m, o)]
            cells = [fmt_ratio(c) for metric in METRICS for c in cmp[metric]]
            fit = f"{cmp['fit_s0']:.2f}x, {cmp['fit_pol']:.2f}x" if "fit_s0" in cmp else "-"
            pair = f"{m.split('/')[1]} / {o.split('/')[1]}"
            print(f"| {name} | {pair} | {rates[0]:.1f} / {rates[1]:.1f} | " + " | ".join(cells) + f" | {fit} |")
            kind = pair
            for i, c in enumerate(c for metric in METRICS for c in cmp[metric]):
                if np.isfinite(c["ratio"]):
                    geo.setdefault(kind, {}).setdefault(i, []).append((c["ratio"], c.get("lower_bound", False)))
    for kind, cols in geo.items():
        cells = [f"{'≥' if any(b for _, b in cols[i]) else ''}{np.exp(np.mean(np.log([r for r, _ in cols[i]]))):.2f}x"
                 f" ({len(cols[i])})" if i in cols else "-" for i in range(len(hdr))]
        print(f"| geometric mean (scenes) | {kind} | | " + " | ".join(cells) + " | |")


def print_study(results):
    for name, res in results.items():
        st = res.get("sampler_study")
        if not st:
            continue
        if not st["times"]:
            print(f"\n{name}: Mitsuba samplers not compared: {st['note']}")
            continue
        times = " / ".join(f"{t:.3g} s" for t in st["times"])
        print(f"\n{name}: Mitsuba's S0 and pol errors after {times}; fastest to converge: {st['best']}")
        for sampler, errs in st["errors"].items():
            cells = [f"{100 * e:.3g}%" for m in METRICS for e in errs[m]]
            print(f"| {name} | {sampler} | " + " | ".join(cells) + " |")


def plot(path, results):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colors = {s: f"C{i}" for i, s in enumerate(scenes.SAMPLERS + ["sobol", "default"])}
    fig, axes = plt.subplots(len(results), 2, figsize=(9, 3.3 * len(results)), constrained_layout=True, squeeze=False)
    for ax_row, (name, res) in zip(axes, results.items()):
        for ax, metric in zip(ax_row, METRICS):
            for key, rows in res["curves"].items():
                renderer, sampler = key.split("/")
                pts = [(r["seconds"], r[metric]) for r in rows if np.isfinite(r[metric])]
                if pts:
                    ax.loglog(*zip(*pts), "o-" if renderer == "mitsuba" else "s--", color=colors[sampler],
                              label=f"{renderer} {sampler}", ms=4)
            ax.axhline(res["floors"][metric], color="gray", lw=0.8, label="reference noise")
            ax.set_title(f"{name}: {'S0' if metric == 's0' else 'polarization (S1, S2)'}", fontsize=9)
            ax.set_xlabel("render time (s, wall)")
            ax.set_ylabel("relative RMSE")
            ax.legend(fontsize=6)
    fig.savefig(path, dpi=80)
    plt.close(fig)


def our_renderer(args):
    """(executable or None, our sampler list, why not) for this run."""
    if args.mitsuba_only:
        return None, [], "--mitsuba-only"
    exe = args.ours_exe
    if exe is None:
        gaps = ours.missing(args.scenes)
        if gaps:
            return None, [], "missing " + ", ".join(gaps)
        exe = ours.build()
    if ours.supports_sampler(exe):
        return exe, OURS_SAMPLERS, None
    print("NOTE: render_scene has no --sampler flag yet: our renderer runs with its scene files' sampler only "
          "(curve ours/default, used in both pairs)")
    return exe, [None], None


def on_clock(curves, clock):
    """The curves with `seconds` = wall time, or CPU time for clock `cpu`."""
    if clock == "wall":
        return curves
    return {k: [dict(r, seconds=r["cpu_seconds"]) for r in rows] for k, rows in curves.items()}


def main():
    args = parse_args()
    mi, _ = scenes.setup_mitsuba(args.threads)
    args.out.mkdir(parents=True, exist_ok=True)
    refs = args.refs or args.out / "refs"
    exe, our_samplers, why = our_renderer(args)
    references = {n: Reference(mi, refs, n) for n in args.scenes}
    results = {}
    for name, ref in references.items():
        curves = {}
        for sampler in args.mitsuba_samplers or ["independent", MITSUBA_LD]:
            curves[f"mitsuba/{sampler}"] = bench_mitsuba(mi, name, sampler, args.spp, ref)
            print(f"{name}: mitsuba {sampler} done", flush=True)
        res = {"reference": ref.spec, "floors": ref.floors(), "curves": curves}
        for sampler in our_samplers:
            try:
                curves[f"ours/{sampler or 'default'}"], res["ours_timing"] = bench_ours(
                    exe, name, sampler, args.spp, ref, args.out, args.threads)
                print(f"{name}: ours {sampler or 'default'} done", flush=True)
            except ours.RenderFailed as err:
                print(f"{name}: OUR RENDERER FAILED ({sampler}), left out:\n{err}")
        res["comparisons"] = {clock: [compare(on_clock(curves, clock), m, o) for m, o in pairs_of(curves)]
                              for clock in CLOCKS}
        res["sampler_study"] = sampler_study(curves)
        results[name] = res
    pixels = {n: r.pixels for n, r in references.items()}
    print_rows(results, pixels)
    print("\n| scene | reference (Mitsuba) | its noise, S0 / pol |\n|---|---|---|")
    for n, r in results.items():
        print(f"| {n} | {r['reference']} | {100 * r['floors']['s0']:.4f}% / {100 * r['floors']['pol']:.4f}% |")
    print_study(results)
    if exe is not None:
        for clock in CLOCKS:
            print_comparisons(results, pixels, clock)
    meta = {"threads": args.threads, "spp": args.spp, "mitsuba": render_refs.scenes_version(),
            "pixels": pixels, "scenes": results}
    (args.out / "bench.json").write_text(json.dumps(meta, indent=2) + "\n")
    plot(args.out / "bench.png", results)
    print(f"\nwrote {args.out / 'bench.json'} and {args.out / 'bench.png'}")
    if exe is None and not args.mitsuba_only:
        print(f"\nOUR RENDERER IS NOT AVAILABLE YET: {why}. Only Mitsuba was benchmarked.")
        sys.exit(0 if args.ours_only_if_available else 2)


if __name__ == "__main__":
    main()
