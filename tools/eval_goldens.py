#!/usr/bin/env python3
"""Golden cases for crates/polar-eval: each metric computed independently with numpy 2.4.6
(and scikit-image 0.26.0 for PSNR/SSIM) on small seeded inputs, written as one JSON file
that crates/polar-eval/tests/golden.rs replays.

    tools/.venv/bin/python tools/eval_goldens.py           # (re)write the goldens
    tools/.venv/bin/python tools/eval_goldens.py --check   # regenerate and compare with the
                                                           # committed file (values to 1e-12)
"""

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from skimage.metrics import peak_signal_noise_ratio, structural_similarity

GOLDEN = Path(__file__).resolve().parent.parent / "crates/polar-eval/tests/golden/eval.json"
W, H = 24, 16
SEED = 20261202
REACHABLE_T = np.float32(0.1)  # polar_eval::REACHABLE_TRANSMISSION


def depth_fit(est, gt, mask):
    """Least squares a*est + b = gt over mask & finite, RMSE over the truth's range."""
    ok = (mask != 0) & np.isfinite(est) & np.isfinite(gt)
    e, g = est[ok].astype(np.float64), gt[ok].astype(np.float64)
    a, b = np.polyfit(e, g, 1)
    rmse = np.sqrt(np.mean((a * e + b - g) ** 2))
    return {"count": int(ok.sum()), "scale": a, "offset": b,
            "relative_rmse": rmse / (g.max() - g.min())}


def mask_case(pred, truth, distractors):
    p, t, d = pred != 0, truth != 0, distractors != 0
    inter = np.sum(p & t)
    return {"iou": inter / np.sum(p | t), "precision": inter / p.sum(), "recall": inter / t.sum(),
            "false_positive_on_distractors": np.sum(p & d) / d.sum()}


def material_case(pred, truth):
    fg = np.isin(truth, [1, 2]) & np.isin(pred, [1, 2])
    cm = np.zeros((4, 4), np.int64)
    np.add.at(cm, (truth.ravel(), pred.ravel()), 1)
    iou = [cm[c, c] / (cm[c].sum() + cm[:, c].sum() - cm[c, c]) for c in range(4)]
    return {"metal_vs_dielectric_accuracy": np.mean(pred[fg] == truth[fg]),
            "opaque_coverage": fg.sum() / np.isin(truth, [1, 2]).sum(),
            "pixel_accuracy": np.mean(pred == truth), "class_iou": iou,
            "confusion": cm.tolist()}


def dehaze_case(hazy, dehazed, ref, t_est, t_gt, labels):
    r = float(ref.max())
    ssim = lambda x: structural_similarity(ref, x, data_range=r, gaussian_weights=True, sigma=1.5,
                                           use_sample_covariance=False, full=True)
    score = lambda x: {"psnr_db": peak_signal_noise_ratio(ref, x, data_range=r), "ssim": ssim(x)[0]}
    psnr_over = lambda x, m: 10 * np.log10(r * r / np.mean((x[m] - ref[m]).astype(np.float64) ** 2))
    mae = lambda m: float(np.mean(np.abs(t_est[m].astype(np.float64) - t_gt[m])))
    corr = lambda m: float(np.corrcoef(t_est[m], t_gt[m])[0, 1])
    reach, obj = t_gt >= REACHABLE_T, labels != 0
    object_score = lambda x: {"psnr_db": psnr_over(x, obj), "ssim": float(np.mean(ssim(x)[1][obj]))}
    everywhere = np.ones_like(reach)
    return {"hazy": score(hazy), "dehazed": score(dehazed),
            "transmission_mae": mae(everywhere), "transmission_correlation": corr(everywhere),
            "reachable": {"fraction": reach.mean(), "hazy_psnr_db": psnr_over(hazy, reach),
                          "dehazed_psnr_db": psnr_over(dehazed, reach)},
            "objects": {"fraction": obj.mean(), "hazy": object_score(hazy),
                        "dehazed": object_score(dehazed), "transmission_mae": mae(obj),
                        "transmission_correlation": corr(obj)}}


def make():
    rng = np.random.default_rng(SEED)
    f32 = lambda a: a.astype(np.float32)
    gt_depth = f32(2.0 + rng.random((H, W)))
    est_depth = f32(-3.0 * gt_depth + 1.0 + 0.05 * rng.standard_normal((H, W)))
    est_depth[0, :3] = np.nan
    dmask = (rng.random((H, W)) > 0.3).astype(np.uint8)
    truth_m = (rng.random((H, W)) > 0.6).astype(np.uint8) * 255
    pred_m = np.where(rng.random((H, W)) > 0.2, truth_m, 255 - truth_m).astype(np.uint8)
    distr = ((rng.random((H, W)) > 0.7) & (truth_m == 0)).astype(np.uint8)
    truth_l = rng.integers(0, 4, (H, W)).astype(np.uint8)
    pred_l = np.where(rng.random((H, W)) > 0.3, truth_l, rng.integers(0, 4, (H, W))).astype(np.uint8)
    ref = f32(rng.random((H, W)))
    hazy = f32(0.5 * ref + 0.4)
    dehazed = f32(ref + 0.05 * rng.standard_normal((H, W)))
    t_gt = f32(rng.random((H, W)))
    t_est = f32(np.clip(t_gt + 0.1 * rng.standard_normal((H, W)), 0.05, 1.0))
    object_labels = (rng.random((H, W)) > 0.7).astype(np.uint8) * rng.integers(1, 4, (H, W)).astype(np.uint8)
    arr = lambda a: np.where(np.isfinite(a), a, None).ravel().tolist() if a.dtype.kind == "f" else a.ravel().tolist()
    return {
        "width": W, "height": H,
        "inputs": {"gt_depth": arr(gt_depth), "est_depth": arr(est_depth), "depth_mask": arr(dmask),
                   "truth_mask": arr(truth_m), "pred_mask": arr(pred_m), "distractors": arr(distr),
                   "truth_labels": arr(truth_l), "pred_labels": arr(pred_l), "reference": arr(ref),
                   "hazy": arr(hazy), "dehazed": arr(dehazed), "t_gt": arr(t_gt), "t_est": arr(t_est),
                   "object_labels": arr(object_labels)},
        "expected": {"depth": depth_fit(est_depth, gt_depth, dmask),
                     "mask": mask_case(pred_m, truth_m, distr),
                     "material": material_case(pred_l, truth_l),
                     "dehaze": dehaze_case(hazy, dehazed, ref, t_est, t_gt, object_labels)},
    }


def plain(x):
    """numpy scalars to Python numbers, for JSON."""
    if isinstance(x, dict):
        return {k: plain(v) for k, v in x.items()}
    if isinstance(x, list):
        return [plain(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    return x


def close(a, b, path="") -> list:
    if isinstance(a, dict):
        return [m for k in a for m in close(a[k], b.get(k), f"{path}.{k}")]
    if isinstance(a, list):
        return [m for i, (x, y) in enumerate(zip(a, b)) for m in close(x, y, f"{path}[{i}]")]
    if isinstance(a, float) and isinstance(b, float):
        return [] if abs(a - b) <= 1e-12 * max(1.0, abs(a)) else [f"{path}: {a} vs {b}"]
    return [] if a == b else [f"{path}: {a} vs {b}"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="compare with the committed goldens")
    args = ap.parse_args()
    data = plain(make())
    if args.check:
        diffs = close(data, json.loads(GOLDEN.read_text()))
        for d in diffs:
            print("eval golden differs:", d)
        print(f"eval goldens: {'DIFFER' if diffs else 'match'} ({GOLDEN})")
        sys.exit(1 if diffs else 0)
    GOLDEN.write_text(json.dumps(data, indent=1) + "\n")
    print(f"wrote {GOLDEN}")


if __name__ == "__main__":
    main()
