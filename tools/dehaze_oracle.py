#!/usr/bin/env python3
"""How much of the whole-frame dehazing score any method can earn from what the image shows.

For every sample of a haze dataset (sample folders with stokes.exr, gt/dehazed.exr and
gt/transmission.exr: our haze family or tools/mitsuba/task_scenes.py's mts-haze scenes),
two oracles are scored with the PSNR `polar-vision eval` uses over the whole frame
(against gt/dehazed.exr, data range its maximum; polar_eval::dehaze_metrics):

  seen    the true haze-free S0 on every pixel the haze leaves reachable (true t >= 0.1,
          polar_eval's REACHABLE_TRANSMISSION) and the hazy S0 where it hides the scene
          (t < 0.1): a perfect dehazer that does not guess what it cannot see;
  guessed the same, with the hidden pixels given the mean of their true values (one
          number per frame, which no method can read from the image).

Both are reported as the gain over the hazy input, the figure the +4 dB target is set on.
Where the `seen` oracle gains little, the whole-frame score is decided by what a method
outputs where nothing is seen.

Usage: tools/.venv/bin/python tools/dehaze_oracle.py DATASET [DATASET ...]
  (DRJIT_LIBLLVM_PATH as in tools/setup-venv.sh: the EXR files are read by Mitsuba's Bitmap)
"""

import argparse
import math
from pathlib import Path

import numpy as np
from polanalyser_goldens import read_exr

REACHABLE_TRANSMISSION = 0.1


def psnr(reference, image, data_range):
    mse = float(np.mean((image.astype(np.float64) - reference) ** 2))
    return math.inf if mse == 0.0 else 10.0 * math.log10(data_range**2 / mse)


def oracles(sample):
    """(hidden share, hazy PSNR, gain of `seen`, gain of `guessed`) of one sample folder."""
    needed = [sample / "gt" / "transmission.exr", sample / "stokes.exr"]
    missing = [str(p) for p in needed if not p.is_file()]
    if missing:
        raise SystemExit(f"{sample}: no {', '.join(missing)} (a haze sample needs both beside gt/dehazed.exr)")
    t = read_exr(sample / "gt" / "transmission.exr")["Y"]
    truth = read_exr(sample / "gt" / "dehazed.exr")["Y"].astype(np.float64)
    hazy = read_exr(sample / "stokes.exr")["S0"].astype(np.float64)
    data_range = float(truth[np.isfinite(truth)].max())
    hidden = t < REACHABLE_TRANSMISSION
    seen = np.where(hidden, hazy, truth)
    guessed = np.where(hidden, truth[hidden].mean() if hidden.any() else 0.0, truth)
    base = psnr(truth, hazy, data_range)
    return hidden.mean(), base, psnr(truth, seen, data_range) - base, psnr(truth, guessed, data_range) - base


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("datasets", nargs="+", type=Path)
    args = parser.parse_args()
    samples = sorted(
        p.parent.parent for d in args.datasets for p in d.glob("*/gt/dehazed.exr")
    )
    if not samples:
        raise SystemExit("no sample folder with gt/dehazed.exr under " + ", ".join(map(str, args.datasets)))
    print("| sample | hidden share | hazy PSNR dB | gain, seen oracle | gain, guessed oracle |")
    print("|---|---|---|---|---|")
    rows = []
    for s in samples:
        row = oracles(s)
        rows.append(row)
        print(f"| {s.name} | {row[0]:.2f} | {row[1]:.2f} | {row[2]:+.2f} | {row[3]:+.2f} |")
    # Frames without hidden pixels score +inf for both oracles (exact everywhere): left out
    # of the means, counted.
    finite = np.array([r for r in rows if math.isfinite(r[2]) and math.isfinite(r[3])])
    print(
        f"\n{len(samples)} samples ({len(samples) - len(finite)} without hidden pixels left out of the means): "
        f"hidden share {finite[:, 0].mean():.2f}, hazy {finite[:, 1].mean():.2f} dB, "
        f"gain of the seen oracle {finite[:, 2].mean():+.2f} dB (median {np.median(finite[:, 2]):+.2f}), "
        f"of the guessed oracle {finite[:, 3].mean():+.2f} dB"
    )


if __name__ == "__main__":
    main()
