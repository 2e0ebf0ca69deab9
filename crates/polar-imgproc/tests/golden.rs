//! Replays the golden cases written by `tools/imgproc_goldens.py` (OpenCV 5.0.0 /
//! opencv-contrib, scikit-image 0.26.0, numpy 2.4.6) and compares.
//!
//! Tolerances: label maps, counts, thresholds and structuring-element results are exact.
//! Float images are compared by the largest absolute difference relative to the largest
//! reference magnitude, `max|got - want| <= tol * max|want|`:
//! - linear filters `1e-6`: the same kernel taps in `f32`, summed in another order (a few
//!   ulp); box filters are exact to one `f32` ulp like OpenCV's `f64` running sums;
//! - morphology and median: exact (they only select input values);
//! - guided filter against `cv2.ximgproc.guidedFilter`: `5e-4`, because OpenCV computes
//!   `1 / (var + eps)` with the approximate `_mm_rcp_ps` (relative error <= 1.5 * 2^-12);
//!   against the same formula with an exact reciprocal (numpy, float32): `1e-6`;
//! - SSIM map `1e-4` and mean SSIM `1e-6` relative: scipy filters in `f64` and rounds
//!   between the two passes, we accumulate in `f32`; `var = E[x^2] - E[x]^2` cancels,
//!   which amplifies that rounding in flat regions.
//! - distance transform `1e-5` pixels (OpenCV's exact transform in `f32`);
//! - PSNR `1e-9` relative (`f64` sums in another order); angular error statistics
//!   `1e-6` degrees (we use `atan2`, numpy `arccos`).

use std::path::PathBuf;

use polar_image::{Gray, NormalImage};
use polar_imgproc::*;
use serde_json::Value;

struct Golden {
    dir: PathBuf,
    index: Value,
}

impl Golden {
    fn load() -> Self {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
        let text = std::fs::read_to_string(dir.join("index.json")).expect("golden index.json");
        Golden {
            dir,
            index: serde_json::from_str(&text).expect("valid index.json"),
        }
    }

    fn cases(&self, op: &str) -> Vec<&Value> {
        let all = self.index["cases"].as_array().expect("cases");
        let v: Vec<&Value> = all.iter().filter(|c| c["op"] == op).collect();
        assert!(!v.is_empty(), "no golden cases for {op}");
        v
    }

    /// Raw bytes and shape of an array by name.
    fn raw(&self, name: &str) -> (Vec<u8>, Vec<usize>) {
        let meta = &self.index["arrays"][name];
        let shape = meta["shape"]
            .as_array()
            .expect("shape")
            .iter()
            .map(|v| v.as_u64().unwrap() as usize)
            .collect();
        let bytes = std::fs::read(self.dir.join(meta["file"].as_str().expect("file")))
            .expect("golden file");
        (bytes, shape)
    }

    fn f32s(&self, name: &str) -> (Vec<f32>, Vec<usize>) {
        let (b, s) = self.raw(name);
        (
            b.chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                .collect(),
            s,
        )
    }

    fn f64s(&self, name: &str) -> Vec<f64> {
        self.raw(name)
            .0
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    fn i32s(&self, name: &str) -> Vec<i32> {
        self.raw(name)
            .0
            .chunks_exact(4)
            .map(|c| i32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    fn gray(&self, name: &str) -> Gray<f32> {
        let (v, s) = self.f32s(name);
        Gray::from_vec(s[1], s[0], v).unwrap()
    }

    fn gray_u8(&self, name: &str) -> Gray<u8> {
        let (v, s) = self.raw(name);
        Gray::from_vec(s[1], s[0], v).unwrap()
    }

    fn input(&self, case: &Value, key: &str) -> String {
        case["inputs"][key].as_str().expect("input").to_string()
    }

    fn output(&self, case: &Value, key: &str) -> String {
        case["outputs"][key].as_str().expect("output").to_string()
    }
}

fn param(case: &Value, key: &str) -> usize {
    case["params"][key]
        .as_u64()
        .unwrap_or_else(|| panic!("param {key}")) as usize
}

fn scalar(case: &Value, key: &str) -> f64 {
    case["scalars"][key]
        .as_f64()
        .unwrap_or_else(|| panic!("scalar {key}"))
}

/// `max|got - want| / max|want|`, asserting it is within `tol`.
fn assert_close(name: &str, got: &[f32], want: &[f32], tol: f64) -> f64 {
    assert_eq!(got.len(), want.len(), "{name}: length");
    let scale = want
        .iter()
        .fold(0.0f64, |m, v| m.max(f64::from(v.abs())))
        .max(f64::MIN_POSITIVE);
    let err = got
        .iter()
        .zip(want)
        .fold(0.0f64, |m, (a, b)| m.max(f64::from(a - b).abs()));
    let rel = err / scale;
    eprintln!("{name}: max rel diff {rel:.2e}");
    assert!(
        rel <= tol,
        "{name}: max |diff| {err:.3e} = {rel:.3e} of max |ref| > {tol:e}"
    );
    rel
}

/// Runs a float-image operation on every case of `op` and compares with its `dst`.
fn check_filter(
    op: &str,
    tol: f64,
    f: impl Fn(&Value, &Gray<f32>, &mut Gray<f32>) -> Result<(), Error>,
) {
    let g = Golden::load();
    for case in g.cases(op) {
        let src = g.gray(&g.input(case, "src"));
        let mut dst = Gray::new(src.width(), src.height());
        f(case, &src, &mut dst).unwrap();
        let want = g.f32s(&g.output(case, "dst")).0;
        assert_close(case["name"].as_str().unwrap(), dst.as_slice(), &want, tol);
    }
}

#[test]
fn gaussian_blur_matches_cv2() {
    check_filter("gaussian_blur", 1e-6, |c, s, d| {
        gaussian_blur(
            s,
            d,
            param(c, "ksize"),
            c["params"]["sigma"].as_f64().unwrap(),
        )
    });
}

fn border(c: &Value) -> Border {
    match c["params"]["border"].as_str().unwrap() {
        "reflect101" => Border::Reflect101,
        "reflect" => Border::Reflect,
        _ => Border::Replicate,
    }
}

#[test]
fn box_filter_matches_cv2() {
    check_filter("box_filter", 1e-6, |c, s, d| {
        box_filter(s, d, param(c, "kw"), param(c, "kh"), border(c))
    });
}

#[test]
fn sobel_and_scharr_match_cv2() {
    check_filter("sobel", 1e-6, |c, s, d| {
        sobel(s, d, param(c, "dx"), param(c, "dy"), param(c, "ksize"))
    });
    check_filter("scharr", 1e-6, |c, s, d| {
        scharr(s, d, param(c, "dx"), param(c, "dy"))
    });
}

fn shape(c: &Value) -> MorphShape {
    match c["params"]["shape"].as_str().unwrap() {
        "rect" => MorphShape::Rect,
        "cross" => MorphShape::Cross,
        _ => MorphShape::Ellipse,
    }
}

#[test]
fn morphology_matches_cv2_exactly() {
    type Op = fn(&Gray<f32>, &mut Gray<f32>, MorphShape, usize, usize) -> Result<(), Error>;
    let ops: [(&str, Op); 4] = [
        ("erode", erode),
        ("dilate", dilate),
        ("open", open),
        ("close", close),
    ];
    for (name, op) in ops {
        check_filter(name, 0.0, |c, s, d| {
            op(s, d, shape(c), param(c, "kw"), param(c, "kh"))
        });
    }
}

#[test]
fn median_matches_cv2_exactly() {
    check_filter("median_blur", 0.0, |c, s, d| {
        median_blur(s, d, param(c, "ksize"))
    });
    let g = Golden::load();
    for case in g.cases("median_blur_u8") {
        let src = g.gray_u8(&g.input(case, "src"));
        let mut dst = Gray::new(src.width(), src.height());
        median_blur_u8(&src, &mut dst, param(case, "ksize")).unwrap();
        assert_eq!(
            dst.as_slice(),
            g.raw(&g.output(case, "dst")).0,
            "{}",
            case["name"]
        );
    }
}

#[test]
fn guided_filter_matches_cv2_ximgproc() {
    let g = Golden::load();
    for case in g.cases("guided_filter") {
        let (guide, src) = (
            g.gray(&g.input(case, "guide")),
            g.gray(&g.input(case, "src")),
        );
        let mut dst = Gray::new(src.width(), src.height());
        guided_filter(
            &guide,
            &src,
            &mut dst,
            param(case, "radius"),
            case["params"]["eps"].as_f64().unwrap(),
        )
        .unwrap();
        let name = case["name"].as_str().unwrap();
        assert_close(
            &format!("{name} vs cv2"),
            dst.as_slice(),
            &g.f32s(&g.output(case, "dst")).0,
            5e-4,
        );
        let exact = g.f32s(&g.output(case, "dst_exact")).0;
        assert_close(
            &format!("{name} vs exact-reciprocal emulation"),
            dst.as_slice(),
            &exact,
            1e-6,
        );
    }
}

#[test]
fn otsu_threshold_equals_skimage() {
    let g = Golden::load();
    for case in g.cases("threshold_otsu") {
        let t = threshold_otsu(&g.gray(&g.input(case, "src"))).unwrap();
        assert_eq!(f64::from(t), scalar(case, "threshold"), "{}", case["name"]);
    }
    for case in g.cases("threshold_otsu_u8") {
        let t = threshold_otsu_u8(&g.gray_u8(&g.input(case, "src"))).unwrap();
        assert_eq!(f64::from(t), scalar(case, "threshold"));
    }
}

fn connectivity(c: &Value) -> Connectivity {
    if param(c, "connectivity") == 4 {
        Connectivity::Four
    } else {
        Connectivity::Eight
    }
}

fn run_label(g: &Golden, case: &Value) -> (Gray<u32>, usize) {
    let src = g.gray_u8(&g.input(case, "src"));
    let mut lab = Gray::new(src.width(), src.height());
    let n = label(&src, &mut lab, connectivity(case)).unwrap();
    (lab, n)
}

#[test]
fn labels_equal_skimage_label() {
    let g = Golden::load();
    for case in g.cases("label") {
        let (lab, n) = run_label(&g, case);
        assert_eq!(n as f64, scalar(case, "n"), "{}", case["name"]);
        let want: Vec<u32> = g
            .i32s(&g.output(case, "labels"))
            .iter()
            .map(|&v| v as u32)
            .collect();
        assert_eq!(lab.as_slice(), want, "{}", case["name"]);
    }
}

/// Exact: both take the hull of the pixels' edge midpoints and keep the pixel centres
/// inside or on it, and every coordinate is a half-integer.
#[test]
fn convex_hulls_equal_skimage_convex_hull_object() {
    let g = Golden::load();
    let cases = g.cases("convex_hull_objects");
    assert_eq!(cases.len(), 2);
    for case in cases {
        let src = g.gray_u8(&g.input(case, "src"));
        let (w, h) = (src.width(), src.height());
        let m: Vec<bool> = src.as_slice().iter().map(|&v| v != 0).collect();
        let got = polar_imgproc::mask::convex_hull_objects(&m, w, h).unwrap();
        let want = g.gray_u8(&g.output(case, "hull"));
        let differ = got
            .iter()
            .zip(want.as_slice())
            .filter(|(a, b)| **a != (**b != 0))
            .count();
        assert_eq!(differ, 0, "{}: {differ} pixels differ", case["name"]);
        assert!(got.iter().filter(|&&b| b).count() > m.iter().filter(|&&b| b).count());
    }
}

/// `cv2.distanceTransform(DIST_L2, DIST_MASK_PRECISE)` is the same exact transform in
/// `f32`: `1e-5` pixels.
#[test]
fn distances_equal_cv2_distance_transform() {
    let g = Golden::load();
    let cases = g.cases("distance_to_background");
    assert_eq!(cases.len(), 2);
    for case in cases {
        let src = g.gray_u8(&g.input(case, "src"));
        let (w, h) = (src.width(), src.height());
        let m: Vec<bool> = src.as_slice().iter().map(|&v| v != 0).collect();
        let outside = match case["params"]["outside"].as_str() {
            Some("background") => Outside::Background,
            Some("not_background") => Outside::NotBackground,
            other => panic!("outside {other:?}"),
        };
        let got = distance_to_background(&m, w, h, outside);
        let (want, _) = g.f32s(&g.output(case, "dist"));
        let err = got
            .iter()
            .zip(&want)
            .map(|(a, b)| (a - f64::from(*b)).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-5, "{}: max |diff| {err}", case["name"]);
        assert!(want.iter().any(|&d| d > 3.0), "a mask with an inside");
    }
}

#[test]
fn stats_equal_cv2_connected_components_with_stats() {
    let g = Golden::load();
    for case in g.cases("component_stats") {
        let name = case["name"].as_str().unwrap();
        let (lab, n) = run_label(&g, case);
        assert_eq!(n as f64, scalar(case, "n"), "{name}");
        let sauf: Vec<u32> = g
            .i32s(&g.output(case, "labels"))
            .iter()
            .map(|&v| v as u32)
            .collect();
        assert_eq!(lab.as_slice(), sauf, "{name}: numbering equals CCL_SAUF");
        // OpenCV's default algorithm: same partition, numbering possibly permuted.
        let default = g.i32s(&g.output(case, "labels_default"));
        let mut map = vec![None; n + 1];
        for (&ours, &cv) in lab.as_slice().iter().zip(&default) {
            let m = map[ours as usize].get_or_insert(cv);
            assert_eq!(*m, cv, "{name}: default labelling splits a component");
        }
        let stats = component_stats(&lab, n).unwrap();
        let (want, cent) = (
            g.i32s(&g.output(case, "stats")),
            g.f64s(&g.output(case, "centroids")),
        );
        for (l, s) in stats.iter().enumerate() {
            let row = [s.left, s.top, s.width, s.height, s.area].map(|v| v as i32);
            assert_eq!(row, want[l * 5..l * 5 + 5], "{name}: stats of label {l}");
            let (cx, cy) = s.centroid;
            assert!(
                (cx - cent[2 * l]).abs() < 1e-12 && (cy - cent[2 * l + 1]).abs() < 1e-12,
                "{name}: centroid {l}"
            );
        }
    }
}

fn rel_eq(name: &str, got: f64, want: f64, tol: f64) {
    eprintln!(
        "{name}: got {got}, want {want}, rel diff {:.2e}",
        ((got - want) / want).abs()
    );
    assert!(
        (got - want).abs() <= tol * want.abs(),
        "{name}: {got} vs {want}"
    );
}

#[test]
fn psnr_and_ssim_match_skimage() {
    let g = Golden::load();
    for case in g.cases("psnr") {
        let (a, b) = (g.gray(&g.input(case, "a")), g.gray(&g.input(case, "b")));
        let r = case["params"]["data_range"].as_f64().unwrap();
        rel_eq(
            case["name"].as_str().unwrap(),
            psnr(&a, &b, r).unwrap(),
            scalar(case, "psnr"),
            1e-9,
        );
    }
    for case in g.cases("ssim") {
        let name = case["name"].as_str().unwrap();
        let (a, b) = (g.gray(&g.input(case, "a")), g.gray(&g.input(case, "b")));
        let r = case["params"]["data_range"].as_f64().unwrap();
        let mut map = Gray::new(a.width(), a.height());
        let m = ssim_map(&a, &b, r, &mut map).unwrap();
        assert_eq!(m, ssim(&a, &b, r).unwrap(), "{name}: mean-only path");
        rel_eq(name, m, scalar(case, "ssim"), 1e-6);
        assert_close(
            &format!("{name} map"),
            map.as_slice(),
            &g.f32s(&g.output(case, "map")).0,
            1e-4,
        );
    }
}

#[test]
fn angular_error_iou_and_confusion_match_numpy() {
    let g = Golden::load();
    let case = g.cases("angular_error")[0];
    let normals = |k: &str| {
        let (v, s) = g.f32s(&g.input(case, k));
        NormalImage::from_vec(s[1], s[0], v).unwrap()
    };
    let mask = g.gray_u8(&g.input(case, "mask"));
    let s = angular_error(&normals("est"), &normals("truth"), Some(&mask))
        .unwrap()
        .unwrap();
    assert_eq!(s.count as f64, scalar(case, "count"));
    for (name, got) in [("mean", s.mean), ("median", s.median), ("rmse", s.rmse)] {
        assert!(
            (got - scalar(case, name)).abs() < 1e-6,
            "{name}: {got} vs {}",
            scalar(case, name)
        );
    }
    for (name, got) in [
        ("pct_below_11.25", s.pct_below_11_25),
        ("pct_below_22.5", s.pct_below_22_5),
        ("pct_below_30", s.pct_below_30),
    ] {
        assert!((got - scalar(case, name)).abs() < 1e-9, "{name}");
    }

    let case = g.cases("confusion_matrix")[0];
    let (t, p) = (
        g.gray_u8(&g.input(case, "truth")),
        g.gray_u8(&g.input(case, "pred")),
    );
    let cm = ConfusionMatrix::from_labels(&t, &p, param(case, "n_classes")).unwrap();
    let want = g.i32s(&g.output(case, "counts"));
    for (i, &w) in want.iter().enumerate() {
        assert_eq!(cm.count(i / 4, i % 4), w as u64);
    }
    assert!((cm.mean_iou().unwrap() - scalar(case, "mean_iou")).abs() < 1e-12);
    assert!((cm.accuracy().unwrap() - scalar(case, "accuracy")).abs() < 1e-12);
    let ones = |img: &Gray<u8>| {
        Gray::from_vec(
            img.width(),
            img.height(),
            img.as_slice().iter().map(|&v| u8::from(v == 1)).collect(),
        )
        .unwrap()
    };
    let m = iou(&ones(&p), &ones(&t)).unwrap().unwrap();
    assert!((m - scalar(case, "iou_mask_1")).abs() < 1e-12);
}
