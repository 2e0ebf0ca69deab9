"""Runs our renderer (the `render_scene` example of polar-render) on a
cross-check scene, for crosscheck.py and bench.py.

    cargo run --release -p polar-render --example render_scene -- SCENE OUT_DIR [--spp N] [--sampler S]

writes OUT_DIR/stokes.exr (channels S0..S3) and, when it does, meta.json with
the render time in "seconds". The example is built once with cargo, then its
executable is run directly so that timings exclude cargo.
"""

import json
import os
import subprocess
import time
from pathlib import Path

import scenes

EXAMPLE_SOURCE = scenes.REPO / "crates" / "polar-render" / "examples" / "render_scene.rs"


class RenderFailed(RuntimeError):
    """Our renderer exited with an error on a scene (e.g. a scene key it does not know)."""


def scene_file(name):
    """Our scene file for cross-check scene `name`."""
    return scenes.SCENE_DIR / f"{name}.toml"


def missing(names):
    """What is missing to run our renderer on `names`, or [] when it can run."""
    gaps = [] if EXAMPLE_SOURCE.is_file() else [f"{EXAMPLE_SOURCE.relative_to(scenes.REPO)} (the example binary)"]
    gaps += [str(scene_file(n).relative_to(scenes.REPO)) for n in names if not scene_file(n).is_file()]
    return gaps


def build():
    """Builds the example in release mode and returns its executable path."""
    cmd = ["cargo", "build", "--release", "-p", "polar-render", "--example", "render_scene",
           "--message-format=json-render-diagnostics"]
    proc = subprocess.run(cmd, cwd=scenes.REPO, stdout=subprocess.PIPE, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"`{' '.join(cmd)}` failed (exit {proc.returncode})")
    for line in proc.stdout.splitlines():
        msg = json.loads(line)
        if msg.get("reason") == "compiler-artifact" and msg.get("executable") and msg["target"]["name"] == "render_scene":
            return Path(msg["executable"])
    raise RuntimeError("cargo built render_scene but reported no executable")


def supports_sampler(exe):
    """True when the executable takes `--sampler` (its usage line, printed
    when run without arguments, names it)."""
    proc = subprocess.run([str(exe)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return "--sampler" in proc.stdout + proc.stderr


def render(exe, name, out_dir, spp=None, threads=None, sampler=None):
    """Renders scene `name` into out_dir (with `--sampler` when given); returns
    (stokes (H, W, 4), seconds, timing source).

    seconds is the renderer's own "seconds" from meta.json when it writes one
    (render time without start-up), else the wall time of the whole process.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    cmd = [str(exe), str(scene_file(name)), str(out_dir)] + (["--spp", str(spp)] if spp else [])
    cmd += ["--sampler", sampler] if sampler else []
    env = dict(os.environ, **({"RAYON_NUM_THREADS": str(threads)} if threads else {}))
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RenderFailed(f"`{' '.join(cmd)}` failed (exit {proc.returncode}):\n{proc.stderr[-2000:]}")
    meta = out_dir / "meta.json"
    seconds, source = wall, "wall"
    if meta.is_file():
        m = json.loads(meta.read_text())
        if isinstance(m.get("seconds"), (int, float)):
            seconds, source = float(m["seconds"]), "meta.json"
    mi, _ = scenes.setup_mitsuba()
    return scenes.read_stokes_exr(mi, out_dir / "stokes.exr"), seconds, source
