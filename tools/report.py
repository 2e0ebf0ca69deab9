#!/usr/bin/env python3
"""Speed against error of every vision task, over its options, on a polar-datagen dataset.

For each task it runs `polar-vision eval` on the task's families once per option set and
reads the evaluation's metrics.json (the mean of the task's headline error over the
family's samples, and the task's mean seconds per megapixel, as the CLI measures them).
Beside each mean it gives the standard error of the mean over the samples (sample
standard deviation / sqrt(n)): how far a family's mean would move with other samples of the
same kind. Samples that share a scene (task_scenes.py's noise draws) are not independent,
so on such families it understates how far the mean would move with other scenes.
It writes one PNG plot per task (error against time) under docs/img/ and the tables into
docs/benchmarks.md between the markers `<!-- report:begin -->` and `<!-- report:end -->`.
Run on demand, not in CI:

    cargo build --release -p polar-vision
    tools/.venv/bin/python tools/report.py DATASET [--extra NAME=DATASET ...]

DATASET is a polar-datagen output (e.g. of /work/data/dev.toml or the standard suite);
each --extra dataset (e.g. scenes rendered by Mitsuba 3, tools/mitsuba/task_scenes.py) is
evaluated with the same options and reported beside it: the generalization gap.
"""

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
BIN = ROOT / "target/release/polar-vision"
DOC = ROOT / "docs/benchmarks.md"
IMG = ROOT / "docs/img"

MARKERS = ["o", "s", "^", "v", "D", "P", "X", "*", "<", ">", "h", "p", "d", "8"]
DEHAZE_OPTIONS = {
    "polarization": ["--dehaze-method", "polarization"],
    "dark channel": ["--dehaze-method", "dark-channel"],
}
# (picture name, task) -> (families by prefix, headline metric key, label, lower is better,
# option sets)
TASKS = {
    ("sfp", "sfp"): (["sfp", "mts-shape"], "normal.mean_deg", "mean angular error (deg)", True, {
        "local + poisson": ["--sfp-method", "local", "--integrator", "poisson"],
        "local + fc": ["--sfp-method", "local", "--integrator", "fc"],
        "global": ["--sfp-method", "global"],
        "local, bilinear demosaic": ["--sfp-method", "local", "--demosaic", "bilinear"],
        "local, known object mask": ["--sfp-method", "local", "--objects", "gt"],
    }),
    ("material", "material"): (["materials", "mts-material"], "metal_vs_dielectric_accuracy",
                               "metal vs dielectric accuracy", False, {
        "physics rule, with sfp normals": ["--tasks", "sfp,material"],
        "kNN, builtin model, with sfp normals": ["--tasks", "sfp,material", "--material-model", "builtin"],
        "physics rule, known object mask": ["--tasks", "sfp,material", "--objects", "gt"],
    }),
    ("transparent", "transparent"): (["glass"], "iou", "mask IoU", False, {
        "training-free": [],
        "kNN, builtin model": ["--transparent-method", "learned"],
    }),
    ("dehaze", "dehaze"): (["haze"], "against_dehazed.dehazed.psnr_db", "PSNR vs gt/dehazed (dB)", False,
                           DEHAZE_OPTIONS),
    ("dehaze-reachable", "dehaze"): (["haze"], "against_dehazed.reachable.dehazed_psnr_db",
                                     "PSNR vs gt/dehazed, reachable pixels (dB)", False, DEHAZE_OPTIONS),
    ("dehaze-objects", "dehaze"): (["haze"], "against_dehazed.objects.dehazed.psnr_db",
                                   "PSNR vs gt/dehazed, object pixels (dB)", False, DEHAZE_OPTIONS),
}


def families_of(dataset: Path) -> list:
    names = {p.name.rsplit("-", 1)[0] for p in dataset.iterdir() if p.is_dir() and not p.name.startswith(".")}
    return sorted(names)


def sample_value(record: dict, task: str, key: str):
    """The metric `key` (dotted path) of `task` in one sample's record of metrics.json, or
    None where the sample failed or lacks it."""
    value = (((record.get("Ok") or {}).get("tasks") or {}).get(task) or {}).get("metrics")
    for part in key.split("."):
        value = value.get(part) if isinstance(value, dict) else None
    return value if isinstance(value, (int, float)) else None


def standard_error(values: list):
    """Standard error of the mean (sample standard deviation / sqrt(n)); None below 2."""
    return statistics.stdev(values) / len(values) ** 0.5 if len(values) >= 2 else None


def evaluate(dataset: Path, task: str, key: str, families: list, options: list) -> dict:
    """Runs eval; returns {family: (mean of the metric `key`, its standard error over the
    samples, seconds per MP, samples)}."""
    tasks = options[options.index("--tasks") + 1] if "--tasks" in options else task
    rest = [o for i, o in enumerate(options) if o != "--tasks" and (i == 0 or options[i - 1] != "--tasks")]
    with tempfile.TemporaryDirectory() as out:
        cmd = [str(BIN), "eval", str(dataset), "--out", out, "--tasks", tasks,
               "--family", ",".join(families), *rest]
        subprocess.run(cmd, check=False, capture_output=True)
        metrics = json.loads((Path(out) / "metrics.json").read_text())
    per_family = {}
    for sample, record in metrics["samples"].items():
        value = sample_value(record, task, key)
        if value is not None:
            per_family.setdefault(sample.rsplit("-", 1)[0], []).append(value)
    result = {}
    for fam, per_task in metrics["families"].items():
        agg = per_task.get(task)
        if agg:
            values, mean = per_family.get(fam, []), agg["means"].get(key)
            if mean is not None and values and abs(sum(values) / len(values) - mean) > 1e-6 * max(1.0, abs(mean)):
                sys.exit(f"{fam}: the samples' {key} do not average to the family's mean {mean}")
            result[fam] = (mean, standard_error(values), agg["seconds_per_mp"], agg["samples"])
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset", type=Path)
    ap.add_argument("--extra", action="append", default=[], help="NAME=DATASET evaluated beside it")
    args = ap.parse_args()
    if not BIN.exists():
        sys.exit(f"{BIN} missing: cargo build --release -p polar-vision")
    sets = [("ours", args.dataset)] + [tuple(e.split("=", 1)) for e in args.extra]
    IMG.mkdir(parents=True, exist_ok=True)
    lines = []
    for (picture, task), (prefixes, key, label, lower, options) in TASKS.items():
        lines += [f"### {task}: {label} against time", "",
                  "| data | family | option | " + label + " | standard error | s / MP | samples |",
                  "|---|---|---|---|---|---|---|"]
        fig, ax = plt.subplots(figsize=(8, 4.5))
        # Colour = option, marker = data set and family, so the legend lists each once.
        colours = {opt: f"C{i}" for i, opt in enumerate(options)}
        markers = {}
        for name, path in sets:
            path = Path(path)
            fams = [f for f in families_of(path) if any(f.startswith(p) or f"-{p}" in f for p in prefixes)]
            if not fams:
                continue
            for opt_name, opts in options.items():
                res = evaluate(path, task, key, fams, opts)
                for fam, (value, se, spm, n) in sorted(res.items()):
                    v = "-" if value is None else f"{value:.3f}"
                    e = "-" if se is None else f"{se:.3f}"
                    s = "-" if spm is None else f"{spm:.3f}"
                    lines.append(f"| {name} | {fam} | {opt_name} | {v} | {e} | {s} | {n} |")
                    if value is not None and spm is not None:
                        marker = markers.setdefault(f"{name} {fam}", MARKERS[len(markers) % len(MARKERS)])
                        ax.scatter(spm, value, color=colours[opt_name], marker=marker)
        ax.set_xscale("log")
        ax.set_xlabel("seconds per megapixel (2 cores)")
        ax.set_ylabel(label + (" (lower is better)" if lower else " (higher is better)"))
        handles = [Line2D([], [], color=c, marker="o", linestyle="", label=o) for o, c in colours.items()]
        handles += [Line2D([], [], color="0.4", marker=m, linestyle="", label=d) for d, m in markers.items()]
        ax.legend(handles=handles, fontsize=6, loc="center left", bbox_to_anchor=(1.01, 0.5))
        fig.tight_layout()
        fig.savefig(IMG / f"report-{picture}.png", dpi=110)
        plt.close(fig)
        lines += ["", f"![{picture}](img/report-{picture}.png)", ""]
        print(f"{picture}: done", file=sys.stderr)
    text = DOC.read_text() if DOC.exists() else "# Benchmarks\n\n<!-- report:begin -->\n<!-- report:end -->\n"
    head, _, rest = text.partition("<!-- report:begin -->")
    _, _, tail = rest.partition("<!-- report:end -->")
    DOC.write_text(head + "<!-- report:begin -->\n" + "\n".join(lines) + "\n<!-- report:end -->" + tail)
    print(f"wrote {DOC}")


if __name__ == "__main__":
    main()
