#!/usr/bin/env python3
"""Golden inputs/outputs for crates/polar-imgproc, from the pinned references.

Runs OpenCV (opencv-contrib-python-headless 5.0.0.93) and scikit-image 0.26.0 (numpy 2.4.6)
from tools/.venv on small deterministic (seeded) images and writes them to
crates/polar-imgproc/tests/golden/: one raw little-endian file per array plus index.json
(per case: op, parameters, array files with dtype and shape, scalar results). The Rust test
tests/golden.rs replays every case.

    tools/.venv/bin/python tools/imgproc_goldens.py           # (re)write the goldens
    tools/.venv/bin/python tools/imgproc_goldens.py --check   # regenerate into a temp dir
                                                              # and compare with the committed ones
"""

import argparse
import json
import shutil
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
import skimage
from skimage.filters import threshold_otsu
from skimage.measure import label as sk_label
from skimage.morphology import convex_hull_object
from skimage.metrics import peak_signal_noise_ratio, structural_similarity

GOLDEN = Path(__file__).resolve().parent.parent / "crates/polar-imgproc/tests/golden"
W, H = 64, 48
SEED = 20261123
PINNED = {"cv2": "5.0.0", "skimage": "0.26.0", "numpy": "2.4.6"}
DTYPES = {"float32": "f32", "float64": "f64", "uint8": "u8", "int32": "i32"}


class Writer:
    """Collects arrays (written as raw little-endian files) and cases for index.json."""

    def __init__(self, out: Path):
        self.out = out
        self.cases = []
        self.arrays = {}

    def array(self, name: str, a: np.ndarray) -> str:
        a = np.ascontiguousarray(a)
        dtype = DTYPES[a.dtype.name]
        if name not in self.arrays:
            (self.out / f"{name}.bin").write_bytes(a.astype(a.dtype.newbyteorder("<")).tobytes())
            self.arrays[name] = {"file": f"{name}.bin", "dtype": dtype, "shape": list(a.shape)}
        return name

    def case(self, name, op, params, inputs, outputs=None, scalars=None):
        self.cases.append({
            "name": name,
            "op": op,
            "params": params,
            "inputs": {k: self.array(v[0], v[1]) for k, v in inputs.items()},
            "outputs": {k: self.array(f"{name}.{k}", v) for k, v in (outputs or {}).items()},
            "scalars": scalars or {},
        })

    def finish(self):
        index = {"generator": "tools/imgproc_goldens.py", "versions": PINNED, "seed": SEED,
                 "arrays": self.arrays, "cases": self.cases}
        (self.out / "index.json").write_text(json.dumps(index, indent=1) + "\n")


def test_images(rng):
    """A smooth scene with edges, blobs and noise in [0, 1], and a degraded copy."""
    y, x = np.mgrid[0:H, 0:W].astype(np.float64)
    img = 0.3 + 0.2 * np.sin(x / 7.0) * np.cos(y / 5.0)
    img += 0.3 * ((x - 20) ** 2 + (y - 18) ** 2 < 120)      # disc
    img -= 0.2 * ((x > 40) & (y > 28))                       # step corner
    img += 0.05 * rng.standard_normal((H, W))
    img = np.clip(img, 0, 1).astype(np.float32)
    degraded = cv2.GaussianBlur(img, (5, 5), 1.0) + 0.03 * rng.standard_normal((H, W))
    return img, degraded.astype(np.float32)


def filters(wr, img):
    src = ("img", img)
    for k, s in [(3, 0.0), (5, 0.0), (7, 1.2), (9, 0.0), (11, 0.0), (0, 2.0), (5, 0.6)]:
        out = cv2.GaussianBlur(img, (k, k), s)
        wr.case(f"gaussian_k{k}_s{s}", "gaussian_blur", {"ksize": k, "sigma": s}, {"src": src}, {"dst": out})
    borders = {"reflect101": cv2.BORDER_REFLECT_101, "reflect": cv2.BORDER_REFLECT,
               "replicate": cv2.BORDER_REPLICATE}
    for kw, kh, b in [(3, 3, "reflect101"), (5, 3, "reflect101"), (7, 7, "reflect"), (9, 9, "replicate"),
                      (21, 15, "reflect")]:
        out = cv2.boxFilter(img, -1, (kw, kh), normalize=True, borderType=borders[b])
        wr.case(f"box_{kw}x{kh}_{b}", "box_filter", {"kw": kw, "kh": kh, "border": b}, {"src": src}, {"dst": out})
    for dx, dy, k in [(1, 0, 3), (0, 1, 3), (1, 1, 3), (1, 0, 5), (0, 2, 5), (0, 1, 1), (2, 0, 7)]:
        out = cv2.Sobel(img, cv2.CV_32F, dx, dy, ksize=k)
        wr.case(f"sobel_{dx}{dy}_k{k}", "sobel", {"dx": dx, "dy": dy, "ksize": k}, {"src": src}, {"dst": out})
    for dx, dy in [(1, 0), (0, 1)]:
        out = cv2.Scharr(img, cv2.CV_32F, dx, dy)
        wr.case(f"scharr_{dx}{dy}", "scharr", {"dx": dx, "dy": dy}, {"src": src}, {"dst": out})


def morphology(wr, img):
    shapes = {"rect": cv2.MORPH_RECT, "cross": cv2.MORPH_CROSS, "ellipse": cv2.MORPH_ELLIPSE}
    ops = {"erode": cv2.MORPH_ERODE, "dilate": cv2.MORPH_DILATE, "open": cv2.MORPH_OPEN,
           "close": cv2.MORPH_CLOSE}
    for op, shape, kw, kh in [("erode", "rect", 3, 3), ("dilate", "rect", 5, 3), ("erode", "ellipse", 5, 5),
                              ("dilate", "cross", 3, 3), ("open", "rect", 5, 5), ("close", "ellipse", 7, 7),
                              ("erode", "ellipse", 9, 7), ("dilate", "cross", 5, 7), ("dilate", "rect", 4, 6),
                              ("dilate", "rect", 15, 11), ("erode", "rect", 3, 12)]:
        kernel = cv2.getStructuringElement(shapes[shape], (kw, kh))
        out = cv2.morphologyEx(img, ops[op], kernel)
        wr.case(f"{op}_{shape}_{kw}x{kh}", op, {"shape": shape, "kw": kw, "kh": kh}, {"src": ("img", img)},
                {"dst": out})


def medians(wr, img):
    for k in (3, 5):
        wr.case(f"median_f32_k{k}", "median_blur", {"ksize": k}, {"src": ("img", img)},
                {"dst": cv2.medianBlur(img, k)})
    img8 = (img * 255).round().astype(np.uint8)
    for k in (3, 5, 7, 11):
        wr.case(f"median_u8_k{k}", "median_blur_u8", {"ksize": k}, {"src": ("img_u8", img8)},
                {"dst": cv2.medianBlur(img8, k)})


def guided_exact(guide, src, r, eps):
    """opencv-contrib's guided filter step for step in float32, with an exact reciprocal
    where OpenCV uses the approximate _mm_rcp_ps."""
    f = np.float32
    box = lambda a: cv2.boxFilter(a, cv2.CV_32F, (2 * r + 1, 2 * r + 1), normalize=True,
                                  borderType=cv2.BORDER_REFLECT)
    mi, mp = box(guide), box(src)
    var = (box(guide * guide) + f(eps)) - mi * mi
    a = (f(1) / var) * (box(src * guide) - mp * mi)
    b = mp - a * mi
    return box(b) + box(a) * guide


def guided(wr, img, degraded):
    for r, eps in [(2, 1e-3), (4, 1e-2), (8, 1e-4)]:
        out = cv2.ximgproc.guidedFilter(img, degraded, r, eps)
        wr.case(f"guided_r{r}_eps{eps}", "guided_filter", {"radius": r, "eps": eps},
                {"guide": ("img", img), "src": ("degraded", degraded)},
                {"dst": out, "dst_exact": guided_exact(img, degraded, r, eps)})


def otsu(wr, rng, img):
    skewed = (rng.gamma(2.0, 0.1, (H, W)) + 0.5 * (rng.random((H, W)) > 0.8)).astype(np.float32)
    quantized = (np.floor(img * 64) / 64).astype(np.float32)  # many values exactly on bin edges
    for name, a in [("img", img), ("skewed", skewed), ("quantized", quantized)]:
        wr.case(f"otsu_{name}", "threshold_otsu", {}, {"src": (name, a)},
                scalars={"threshold": float(threshold_otsu(a))})
    img8 = (img * 255).round().astype(np.uint8)
    wr.case("otsu_u8", "threshold_otsu_u8", {}, {"src": ("img_u8", img8)},
            scalars={"threshold": int(threshold_otsu(img8))})


def components(wr, rng):
    noise = cv2.GaussianBlur(rng.random((H, W)).astype(np.float32), (0, 0), 2.0)
    mask = (noise > np.quantile(noise, 0.6)).astype(np.uint8) * 255
    mask[::7, ::5] = 255                                          # isolated pixels and diagonals
    multi = (np.digitize(noise, np.quantile(noise, [0.5, 0.7, 0.85])) * (noise > 0)).astype(np.uint8)
    for conn, sk_conn in [(4, 1), (8, 2)]:
        for name, src in [("mask", mask), ("multi", multi)]:
            lab = sk_label(src, background=0, connectivity=sk_conn).astype(np.int32)
            wr.case(f"label_{name}_c{conn}", "label", {"connectivity": conn}, {"src": (name, src)},
                    {"labels": lab}, {"n": int(lab.max())})
        n, lab_sauf, stats, cent = cv2.connectedComponentsWithStatsWithAlgorithm(
            mask, conn, cv2.CV_32S, cv2.CCL_SAUF)
        n_def, lab_def, _, _ = cv2.connectedComponentsWithStats(mask, connectivity=conn)
        wr.case(f"cc_stats_c{conn}", "component_stats", {"connectivity": conn}, {"src": ("mask", mask)},
                {"labels": lab_sauf.astype(np.int32), "stats": stats.astype(np.int32),
                 "centroids": cent.astype(np.float64), "labels_default": lab_def.astype(np.int32)},
                {"n": int(n) - 1})
    # Convex hulls: the blobs above, and open outlines (arcs, a diagonal line, single pixels)
    # whose hulls are large next to their pixels.
    outlines = np.zeros((H, W), np.uint8)
    cv2.ellipse(outlines, (16, 14), (11, 8), 20, 30, 300, 255, 1)
    cv2.ellipse(outlines, (45, 30), (9, 12), -35, 200, 470, 255, 1)
    cv2.line(outlines, (3, 44), (30, 33), 255, 1)
    outlines[2, 60] = outlines[46, 62] = outlines[40, 2] = 255
    for name, src in [("mask", mask), ("outlines", outlines)]:
        hull = convex_hull_object(src > 0, connectivity=2).astype(np.uint8)
        wr.case(f"convex_hull_{name}", "convex_hull_objects", {}, {"src": (name, src)}, {"hull": hull})
    # Euclidean distance to the nearest zero pixel, beyond the frame not background (as
    # OpenCV has it) or background (a zero frame added, then cropped).
    inside = cv2.distanceTransform(mask, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    framed = cv2.distanceTransform(np.pad(mask, 1), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)[1:-1, 1:-1]
    for outside, dist in [("not_background", inside), ("background", framed)]:
        wr.case(f"distance_{outside}", "distance_to_background", {"outside": outside},
                {"src": ("mask", mask)}, {"dist": dist.astype(np.float32)})


def metrics(wr, rng, img, degraded):
    for r in (1.0, 2.0):
        wr.case(f"psnr_r{r}", "psnr", {"data_range": r}, {"a": ("img", img), "b": ("degraded", degraded)},
                scalars={"psnr": float(peak_signal_noise_ratio(img, degraded, data_range=r))})
        m, smap = structural_similarity(img, degraded, data_range=r, gaussian_weights=True, sigma=1.5,
                                        use_sample_covariance=False, full=True)
        wr.case(f"ssim_r{r}", "ssim", {"data_range": r}, {"a": ("img", img), "b": ("degraded", degraded)},
                {"map": smap.astype(np.float32)}, {"ssim": float(m)})
    gt = rng.standard_normal((H, W, 3))
    gt /= np.linalg.norm(gt, axis=2, keepdims=True)
    est = gt + 0.4 * rng.standard_normal((H, W, 3))
    gt[:5] = 0.0                                                 # "no surface" rows
    mask = (rng.random((H, W)) > 0.2).astype(np.uint8)
    valid = (mask != 0) & (np.linalg.norm(gt, axis=2) > 0) & (np.linalg.norm(est, axis=2) > 0)
    cosang = np.sum(gt * est, axis=2) / (np.linalg.norm(gt, axis=2) * np.linalg.norm(est, axis=2) + 1e-300)
    ang = np.degrees(np.arccos(np.clip(cosang, -1, 1)))[valid]
    wr.case("angular_error", "angular_error", {},
            {"est": ("normals_est", est.astype(np.float32)), "truth": ("normals_gt", gt.astype(np.float32)),
             "mask": ("normals_mask", mask)},
            scalars={"count": int(ang.size), "mean": float(ang.mean()), "median": float(np.median(ang)),
                     "rmse": float(np.sqrt(np.mean(ang ** 2))),
                     **{f"pct_below_{t}": float(100 * np.mean(ang < t)) for t in (11.25, 22.5, 30)}})
    truth = rng.integers(0, 4, (H, W)).astype(np.uint8)
    pred = np.where(rng.random((H, W)) < 0.7, truth, rng.integers(0, 4, (H, W))).astype(np.uint8)
    cm = np.bincount(truth.ravel().astype(np.int64) * 4 + pred.ravel(), minlength=16).reshape(4, 4)
    inter = np.diag(cm)
    union = cm.sum(0) + cm.sum(1) - inter
    wr.case("confusion", "confusion_matrix", {"n_classes": 4},
            {"truth": ("classes_truth", truth), "pred": ("classes_pred", pred)},
            {"counts": cm.astype(np.int32)},
            {"mean_iou": float(np.mean(inter / union)), "accuracy": float(inter.sum() / cm.sum()),
             "iou_mask_1": float(np.sum((truth == 1) & (pred == 1)) / np.sum((truth == 1) | (pred == 1)))})


def generate(out: Path):
    versions = {"cv2": cv2.__version__, "skimage": skimage.__version__, "numpy": np.__version__}
    if versions != PINNED:
        sys.exit(f"reference versions {versions} differ from the pinned {PINNED}; use tools/.venv")
    cv2.setNumThreads(1)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(SEED)
    img, degraded = test_images(rng)
    wr = Writer(out)
    filters(wr, img)
    morphology(wr, img)
    medians(wr, img)
    guided(wr, img, degraded)
    otsu(wr, rng, img)
    components(wr, rng)
    metrics(wr, rng, img, degraded)
    wr.finish()


def load(d: Path, meta):
    dt = {"f32": "<f4", "f64": "<f8", "u8": "u1", "i32": "<i4"}[meta["dtype"]]
    return np.fromfile(d / meta["file"], dtype=dt).reshape(meta["shape"])


def check() -> int:
    """Regenerates into a temp dir; integer arrays and scalars must match exactly, float
    arrays to 1e-6 of their largest magnitude (SIMD paths differ between CPUs by a few ulp),
    except OpenCV's own guided filter output (`guided_*.dst`), held to 1e-4: its float32
    division takes an approximate-reciprocal path whose width differs between CPUs (AVX2
    against AVX-512 machines differ by up to 1.2e-5); the exact-reciprocal replay
    (`dst_exact`), which the Rust tests compare against, keeps 1e-6."""
    with tempfile.TemporaryDirectory() as tmp:
        generate(Path(tmp))
        new = json.loads((Path(tmp) / "index.json").read_text())
        old = json.loads((GOLDEN / "index.json").read_text())
        problems = []
        if [c["name"] for c in new["cases"]] != [c["name"] for c in old["cases"]]:
            problems.append("case list differs")
        for name, meta in new["arrays"].items():
            if name not in old["arrays"]:
                problems.append(f"{name}: missing from committed goldens")
                continue
            a, b = load(Path(tmp), meta), load(GOLDEN, old["arrays"][name])
            if a.shape != b.shape:
                problems.append(f"{name}: shape {a.shape} vs {b.shape}")
            elif a.dtype.kind == "f":
                rel = 1e-4 if name.startswith("guided_") and name.endswith(".dst") else 1e-6
                tol = rel * max(1.0, float(np.nanmax(np.abs(b))))
                err = float(np.nanmax(np.abs(a.astype(np.float64) - b)))
                if err > tol:
                    problems.append(f"{name}: max abs diff {err:.3g} > {tol:.3g}")
            elif not np.array_equal(a, b):
                problems.append(f"{name}: {int(np.sum(a != b))} values differ")
        for cn, co in zip(new["cases"], old["cases"]):
            for k, v in cn["scalars"].items():
                if isinstance(v, int) and v != co["scalars"].get(k):
                    problems.append(f"{cn['name']}.{k}: {v} vs {co['scalars'].get(k)}")
                elif abs(v - co["scalars"].get(k, float("nan"))) > 1e-9 * max(1.0, abs(v)):
                    problems.append(f"{cn['name']}.{k}: {v} vs {co['scalars'].get(k)}")
    for p in problems:
        print("DRIFT", p)
    print(f"imgproc goldens: {len(new['cases'])} cases, {len(problems)} drifted")
    return 1 if problems else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="compare a fresh regeneration with the committed files")
    args = ap.parse_args()
    if args.check:
        sys.exit(check())
    if GOLDEN.exists():
        shutil.rmtree(GOLDEN)
    generate(GOLDEN)
    size = sum(p.stat().st_size for p in GOLDEN.iterdir())
    print(f"wrote {len(list(GOLDEN.iterdir()))} files, {size / 1024:.0f} KiB to {GOLDEN}")


if __name__ == "__main__":
    main()
