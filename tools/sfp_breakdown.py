#!/usr/bin/env python3
"""Shape from polarization broken down by what the scene holds.

Joins a `polar-vision eval --tasks sfp` run with the parameters polar-datagen recorded in
the dataset's manifest.jsonl, sample by sample, and prints markdown tables of the angular
error by shape kind, albedo band, roughness band, refractive-index band and sensor noise.
Samples must hold one object each (datasets-synth/suites/sfp-breakdown.toml), so that a
sample's error belongs to one kind of surface. The methods never see these parameters;
only this evaluation does.

    polar-datagen suite datasets-synth/suites/sfp-breakdown.toml --out data/sfpb --size full
    polar-vision eval data/sfpb --tasks sfp --out data/sfpb-eval
    tools/.venv/bin/python tools/sfp_breakdown.py data/sfpb data/sfpb-eval
"""

import argparse
import json
import statistics
import sys
from pathlib import Path

# Band edges (lower bounds) of the continuous parameters, spanning the shape family's ranges.
BANDS = {
    "albedo": [0.05, 0.3, 0.6],
    "roughness": [0.0, 0.1, 0.2],
    "ior": [1.3, 1.45, 1.6],
}


def band(value, edges):
    """The label `lo-hi` of the band of `value` (the last band is open above)."""
    i = max(j for j, lo in enumerate(edges) if value >= lo or j == 0)
    hi = f"{edges[i + 1]:g}" if i + 1 < len(edges) else "max"
    return f"{edges[i]:g}-{hi}"


def rows(dataset, evaluation):
    """(attributes, normal metrics) of every sample that has both."""
    samples = json.loads((evaluation / "metrics.json").read_text())["samples"]
    for line in (dataset / "manifest.jsonl").read_text().splitlines():
        entry = json.loads(line)
        p = entry["params"]
        objects = p.get("objects", [])
        result = samples.get(entry["id"], {}).get("Ok", {}).get("tasks", {}).get("sfp")
        if len(objects) != 1 or not result or "metrics" not in result:
            continue
        o = objects[0]
        m = o["material"]
        attributes = {
            "shape kind": o["shape"]["type"],
            "albedo": band(m["albedo"], BANDS["albedo"]),
            "roughness": band(m["roughness"], BANDS["roughness"]),
            "ior": band(m["ior"], BANDS["ior"]),
            "noise": p["noise"]["name"],
        }
        yield attributes, result["metrics"]["normal"]


def table(data, key):
    """Markdown table of the error grouped by `key`; a sample without a single estimated
    normal on its object (`normal` null: the foreground missed it) counts as missed."""
    groups = {}
    for attributes, normal in data:
        groups.setdefault(attributes[key], []).append(normal)
    out = [
        f"| {key} | samples | missed | mean error (deg) | median of medians (deg) "
        "| within 22.5° (%) | object pixels with a normal |",
        "|---|---|---|---|---|---|---|",
    ]
    for name in sorted(groups):
        g = [n for n in groups[name] if n]
        missed = len(groups[name]) - len(g)
        if not g:
            out.append(f"| {name} | {missed} | {missed} | - | - | - | 0 |")
            continue
        mean = statistics.fmean(n["mean_deg"] for n in g)
        median = statistics.median(n["median_deg"] for n in g)
        within = statistics.fmean(n["pct_below_22_5"] for n in g)
        coverage = statistics.fmean(n["coverage"] for n in g) * len(g) / len(groups[name])
        out.append(
            f"| {name} | {len(groups[name])} | {missed} | {mean:.1f} | {median:.1f} "
            f"| {within:.0f} | {coverage:.2f} |"
        )
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset", type=Path, help="polar-datagen output with manifest.jsonl")
    ap.add_argument("evaluation", type=Path, help="polar-vision eval output with metrics.json")
    args = ap.parse_args()
    for path in [args.dataset / "manifest.jsonl", args.evaluation / "metrics.json"]:
        if not path.is_file():
            sys.exit(f"sfp_breakdown: {path} not found")
    data = list(rows(args.dataset, args.evaluation))
    if not data:
        sys.exit("sfp_breakdown: no one-object sample with sfp metrics in both inputs")
    print(f"{len(data)} samples\n")
    for key in ["shape kind", "albedo", "roughness", "ior", "noise"]:
        print(table(data, key) + "\n")


if __name__ == "__main__":
    main()
