#!/usr/bin/env python3
"""Renders the Mitsuba 3 references of the cross-check scenes (scenes.md).

Writes OUT/<scene>/stokes.exr (float32 channels S0, S1, S2, S3 in the
per-pixel frame of the conventions, which is the frame Mitsuba's `stokes`
integrator outputs: see README.md) and OUT/<scene>/meta.json.

    tools/.venv/bin/python tools/mitsuba/render_refs.py OUT [--spp N] [--scenes a,b] [--threads 2]

An existing reference with the same spp and seed is reused unless --force.

bench.py also renders references with a low-discrepancy sampler as the mean
of several passes (ensure_reference's `sampler` and `passes`): the mean is
taken in float64, because Mitsuba accumulates a pixel's samples in float32
and a single pass of many samples drifts (docs/performance-notes.md, "Benchmark references").
"""

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import scenes  # noqa: E402


def parse_scene_list(text):
    """Comma-separated scene names, checked against scenes.SCENES."""
    names = [n for n in text.split(",") if n]
    unknown = sorted(set(names) - set(scenes.SCENES))
    if unknown:
        raise argparse.ArgumentTypeError(f"unknown scenes {unknown}; known: {scenes.SCENES}")
    return names


def cached(out_dir, spp, seed, sampler="independent", passes=1):
    """True when out_dir holds a reference rendered with these settings
    (a meta.json without sampler / passes is an independent single pass)."""
    meta = out_dir / "meta.json"
    if not (meta.is_file() and (out_dir / "stokes.exr").is_file()):
        return False
    m = json.loads(meta.read_text())
    return (m.get("spp") == spp and m.get("seed") == seed and m.get("mitsuba") == scenes_version()
            and m.get("sampler", "independent") == sampler and m.get("passes", 1) == passes)


def scenes_version():
    import mitsuba

    return f"{mitsuba.__version__} {scenes.VARIANT}"


def render_reference(mi, name, spp, seed, sampler="independent", passes=1):
    """Renders scene `name` as the float64 mean of `passes` renders of `spp`
    samples each (seeds seed * passes + i: references with different seeds
    are independent); returns (stokes (H, W, 4), seconds)."""
    scene = mi.load_dict(scenes.scene_dict(mi, name, spp, sampler), optimize=False)
    t0 = time.perf_counter()
    total = sum(scenes.render_stokes(mi, scene, spp, seed * passes + i).astype(np.float64) for i in range(passes))
    return total / passes, time.perf_counter() - t0


def ensure_reference(mi, root, name, spp, seed=0, force=False, log=print, sampler="independent", passes=1):
    """Path of the reference stokes.exr of `name`, rendering it if needed
    (`passes` renders of `spp` each with `sampler`, averaged)."""
    out_dir = Path(root) / name
    what = f"{spp} spp" + (f" x {passes} passes, {sampler}" if (sampler, passes) != ("independent", 1) else "")
    if not force and cached(out_dir, spp, seed, sampler, passes):
        log(f"{name}: cached reference {out_dir / 'stokes.exr'} ({what})")
        return out_dir / "stokes.exr"
    stokes, seconds = render_reference(mi, name, spp, seed, sampler, passes)
    scenes.write_stokes_exr(mi, out_dir / "stokes.exr", stokes)
    meta = {
        "scene": name,
        "renderer": "mitsuba",
        "mitsuba": scenes_version(),
        "size": list(scenes.image_size(name)),
        "spp": spp,
        "seed": seed,
        "sampler": sampler,
        "passes": passes,
        "seconds": round(seconds, 3),
    }
    (out_dir / "meta.json").write_text(json.dumps(meta, indent=2) + "\n")
    log(f"{name}: rendered {what} in {seconds:.1f} s -> {out_dir / 'stokes.exr'}")
    return out_dir / "stokes.exr"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", type=Path, help="reference directory (cache)")
    ap.add_argument("--spp", type=int, default=None, help=f"samples per pixel (default per scene: {scenes.REFERENCE_SPP})")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--scenes", type=parse_scene_list, default=scenes.SCENES, help="comma-separated subset")
    ap.add_argument("--threads", type=int, default=None, help="Dr.Jit threads (default: all cores)")
    ap.add_argument("--force", action="store_true", help="re-render even when cached")
    args = ap.parse_args()
    if args.spp is not None and args.spp < 1:
        ap.error("--spp must be >= 1")
    mi, _ = scenes.setup_mitsuba(args.threads)
    for name in args.scenes:
        spp = args.spp or scenes.REFERENCE_SPP[name]
        ensure_reference(mi, args.out, name, spp, args.seed, args.force)


if __name__ == "__main__":
    main()
