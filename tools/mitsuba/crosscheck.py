#!/usr/bin/env python3
"""Cross-checks our renderer against Mitsuba 3 on the scenes of scenes.md
(four surface scenes and `haze`, a participating medium).

For each scene: the Mitsuba reference (rendered, or reused from --refs), our
render (the polar-render `render_scene` example, or OURS/<scene>/stokes.exr
with --ours), the figures of scenes.md over the object pixels (the sphere's;
for `haze` the medium box's)

    mean |dDoLP| <= 0.01, mean |dAoLP| <= 2 deg where DoLP > 0.05, S0 rel. RMSE <= 2%

a table, and OUT/<scene>.png (ours | Mitsuba | difference for S0, DoLP, AoLP).
Exit status: 0 all pass, 1 a figure fails or our renderer refuses a scene
file (its error is printed), 2 our renderer is not available (0 instead with
--ours-only-if-available, which then only renders the references and says so).

    tools/.venv/bin/python tools/mitsuba/crosscheck.py OUT [--refs DIR] [--ours DIR]
        [--spp-ours N] [--threads 2] [--ours-only-if-available]
"""

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import ours  # noqa: E402
import render_refs  # noqa: E402
import scenes  # noqa: E402


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", type=Path, help="output dir: comparison PNGs and our renders")
    ap.add_argument("--refs", type=Path, default=None, help="Mitsuba reference cache (default: a temporary dir)")
    ap.add_argument("--ours", type=Path, default=None, help="use OURS/<scene>/stokes.exr instead of running our renderer")
    ap.add_argument("--spp-ours", type=int, default=None, help=f"--spp for our renderer, all scenes (default per scene: {scenes.OURS_SPP})")
    ap.add_argument("--scenes", type=render_refs.parse_scene_list, default=scenes.SCENES)
    ap.add_argument("--threads", type=int, default=None, help="threads for both renderers (default: all cores)")
    ap.add_argument("--ours-only-if-available", action="store_true",
                    help="when our renderer is not there yet, render the references, say so and exit 0")
    return ap.parse_args()


def our_stokes_source(args):
    """A function name -> our Stokes image, or None (with a message) if unavailable."""
    if args.ours is not None:
        absent = [n for n in args.scenes if not (args.ours / n / "stokes.exr").is_file()]
        if absent:
            return None, f"no {args.ours}/<scene>/stokes.exr for {absent}"
        mi, _ = scenes.setup_mitsuba()
        return (lambda n: scenes.read_stokes_exr(mi, args.ours / n / "stokes.exr")), None
    gaps = ours.missing(args.scenes)
    if gaps:
        return None, "missing " + ", ".join(gaps)
    exe = ours.build()
    print(f"our renderer: {exe}")

    def run(name):
        stokes, seconds, source = ours.render(exe, name, args.out / "ours" / name, args.spp_ours or scenes.OURS_SPP[name], args.threads)
        print(f"{name}: our render took {seconds:.2f} s ({source})")
        return stokes

    return run, None


def comparison_png(path, name, mine, ref, mask, figures):
    """Writes a 3 x 3 picture: rows S0, DoLP, AoLP; columns ours, Mitsuba, difference."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 3, figsize=(10.5, 10), constrained_layout=True)
    s0_max = float(np.percentile(ref[..., 0], 99.5))
    d_ours, d_ref = scenes.dolp(mine), scenes.dolp(ref)
    d_max = float(max(np.nanpercentile(d_ref, 99.5), 0.05))
    a_ours = np.where(d_ours > 0.01, np.degrees(scenes.aolp(mine)), np.nan)
    a_ref = np.where(d_ref > 0.01, np.degrees(scenes.aolp(ref)), np.nan)
    a_diff = np.where(mask & (d_ref > 0.05), np.degrees(scenes.angle_diff(scenes.aolp(mine), scenes.aolp(ref))), np.nan)
    rows = [
        ("S0", mine[..., 0], ref[..., 0], dict(cmap="gray", vmin=0, vmax=s0_max), mine[..., 0] - ref[..., 0], 0.1 * s0_max),
        ("DoLP", d_ours, d_ref, dict(cmap="viridis", vmin=0, vmax=d_max), d_ours - d_ref, 0.02),
        ("AoLP (deg)", a_ours, a_ref, dict(cmap="hsv", vmin=0, vmax=180), a_diff, 5.0),
    ]
    for r, (label, a, b, style, diff, lim) in enumerate(rows):
        for c, img in enumerate((a, b)):
            im = ax[r, c].imshow(img, **style)
        fig.colorbar(im, ax=ax[r, :2], shrink=0.8)
        imd = ax[r, 2].imshow(diff, cmap="RdBu_r", vmin=-lim, vmax=lim)
        fig.colorbar(imd, ax=ax[r, 2], shrink=0.8)
        ax[r, 0].set_ylabel(label)
    for c, title in enumerate(("ours", "Mitsuba 3", "ours - Mitsuba")):
        ax[0, c].set_title(title)
    for a in ax.ravel():
        a.set_xticks([])
        a.set_yticks([])
    fig.suptitle(
        f"{name}: mean|dDoLP| {figures['dolp_mae']:.4f}, mean|dAoLP| {figures['aolp_mae_deg']:.2f} deg, "
        f"S0 rel. RMSE {100 * figures['s0_rel_rmse']:.2f}%"
    )
    fig.savefig(path, dpi=80)
    plt.close(fig)


def print_table(rows):
    """The cross-check table, one line per scene."""
    lim = scenes.LIMITS
    print(f"\n{'scene':<16}{'mean|dDoLP|':>12}{'mean|dAoLP| deg':>17}{'(pixels)':>10}{'S0 rel RMSE':>13}  result")
    print(f"{'limit':<16}{lim['dolp_mae']:>12.4f}{lim['aolp_mae_deg']:>17.2f}{'':>10}{100 * lim['s0_rel_rmse']:>12.2f}%")
    for name, f in rows:
        if f is None:
            print(f"{name:<16}{'our renderer failed (see above)':>52}  FAIL")
            continue
        verdict = "pass" if scenes.passes(f) else "FAIL"
        print(f"{name:<16}{f['dolp_mae']:>12.4f}{f['aolp_mae_deg']:>17.2f}{f['aolp_pixels']:>10}"
              f"{100 * f['s0_rel_rmse']:>12.2f}%  {verdict}")


def main():
    args = parse_args()
    mi, _ = scenes.setup_mitsuba(args.threads)
    refs = args.refs or Path(tempfile.mkdtemp(prefix="mitsuba-refs-"))
    reference = {n: scenes.read_stokes_exr(mi, render_refs.ensure_reference(mi, refs, n, scenes.REFERENCE_SPP[n]))
                 for n in args.scenes}
    get_ours, why = our_stokes_source(args)
    if get_ours is None:
        print(f"\nOUR RENDERER IS NOT AVAILABLE YET: {why}.\nOnly the Mitsuba references were rendered (in {refs}); "
              "nothing was compared.")
        sys.exit(0 if args.ours_only_if_available else 2)
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name in args.scenes:
        try:
            mine = get_ours(name)
        except ours.RenderFailed as err:
            print(f"\n{name}: OUR RENDERER FAILED on {ours.scene_file(name).relative_to(scenes.REPO)}:\n{err}")
            rows.append((name, None))
            continue
        if mine.shape != reference[name].shape:
            raise SystemExit(f"{name}: our image is {mine.shape[:2]}, Mitsuba's {reference[name].shape[:2]}")
        mask = scenes.object_mask(name)
        figures = scenes.compare(mine, reference[name], mask)
        comparison_png(args.out / f"{name}.png", name, mine, reference[name], mask, figures)
        rows.append((name, figures))
    print_table(rows)
    print(f"\npictures: {args.out}/<scene>.png")
    sys.exit(0 if all(f is not None and scenes.passes(f) for _, f in rows) else 1)


if __name__ == "__main__":
    main()
