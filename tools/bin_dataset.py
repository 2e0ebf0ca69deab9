#!/usr/bin/env python3
"""Bins every sample of a polar-datagen dataset by F x F: a camera with F times larger pixels.

The raw mosaic keeps its 2x2 polarizer pattern (each big pixel averages its own polarizer's
samples inside its F x F area, rounded to DN; F even), float planes are block means, normals the renormalised
mean of the block's surface normals (none where most of the block is background), label
images the block's most frequent label. Used to measure how the vision tasks depend on the
image resolution with the scenes held fixed (docs/benchmarks.md, "full size"):

    tools/.venv/bin/python tools/bin_dataset.py DATASET OUT [--factor 4]
"""

import argparse
import json
import shutil
from pathlib import Path

import numpy as np
from PIL import Image

from polanalyser_goldens import read_exr


def write_exr(path, planes):
    import mitsuba as mi

    names = list(planes)
    data = np.stack([planes[n] for n in names], axis=-1).astype(np.float32)
    mi.Bitmap(data, pixel_format=mi.Bitmap.PixelFormat.MultiChannel, channel_names=names).write(str(path))


def block(a, f):
    h, w = a.shape[:2]
    return a[: h - h % f, : w - w % f].reshape(h // f, f, w // f, f, *a.shape[2:])


def bin_mosaic(raw, f):
    """A mosaic of pixels f times larger: each big pixel keeps its own polarizer (the same
    2x2 pattern) and averages that polarizer's samples inside its own f x f area."""
    h, w = raw.shape
    out = np.zeros((h // f, w // f))
    for oy in range(2):
        for ox in range(2):
            # Big pixels (Y, X) with Y = oy, X = ox mod 2; their area starts at (f Y, f X),
            # even for even f, so its samples of that polarizer sit at offsets (oy, ox) + 2k.
            chan = raw[oy::2, ox::2].astype(np.float64)
            means = block(chan, f // 2).mean(axis=(1, 3))
            out[oy::2, ox::2] = means[oy::2, ox::2]
    return np.rint(out)


def bin_normals(n, f):
    b = block(n, f)
    surface = np.linalg.norm(b, axis=-1) > 0
    mean = b.sum(axis=(1, 3))
    norm = np.linalg.norm(mean, axis=-1, keepdims=True)
    keep = (surface.mean(axis=(1, 3)) > 0.5)[..., None] & (norm > 0)
    return np.where(keep, mean / np.where(norm > 0, norm, 1), 0)


def bin_labels(lab, f):
    b = block(lab, f).transpose(0, 2, 1, 3).reshape(lab.shape[0] // f, lab.shape[1] // f, f * f)
    values = np.unique(b)
    counts = np.stack([(b == v).sum(axis=-1) for v in values], axis=-1)
    return values[np.argmax(counts, axis=-1)].astype(lab.dtype)


def bin_sample(src, dst, f):
    dst.mkdir(parents=True)
    (dst / "gt").mkdir()
    shutil.copy(src / "meta.json", dst / "meta.json")
    raw = np.array(Image.open(src / "raw.png"))
    binned = bin_mosaic(raw, f).astype(raw.dtype)
    Image.fromarray(binned).save(dst / "raw.png")
    for rel in ["stokes.exr", "gt/depth.exr", "gt/clear.exr", "gt/dehazed.exr", "gt/transmission.exr"]:
        if (src / rel).exists():
            planes = read_exr(src / rel)
            write_exr(dst / rel, {k: block(v, f).mean(axis=(1, 3)) for k, v in planes.items()})
    if (src / "gt/normal.exr").exists():
        planes = read_exr(src / "gt/normal.exr")
        names = list(planes)
        n = bin_normals(np.stack([planes[k] for k in names], axis=-1), f)
        write_exr(dst / "gt/normal.exr", {k: n[..., i] for i, k in enumerate(names)})
    for rel in ["gt/material.png", "gt/transparent.png"]:
        if (src / rel).exists():
            Image.fromarray(bin_labels(np.array(Image.open(src / rel)), f)).save(dst / rel)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--factor", type=int, default=4)
    args = ap.parse_args()
    samples = sorted(p for p in args.dataset.iterdir() if (p / "raw.png").exists())
    for s in samples:
        bin_sample(s, args.out / s.name, args.factor)
    print(json.dumps({"samples": len(samples), "factor": args.factor, "out": str(args.out)}))


if __name__ == "__main__":
    main()
