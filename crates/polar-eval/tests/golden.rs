//! Replays `tests/golden/eval.json`, written by `tools/eval_goldens.py` with numpy and
//! scikit-image: every composed metric of this crate against an independent computation.
//! Tolerances (relative): counts and ratios of counts 1e-12; fits, MAE and correlation 1e-9
//! (both in f64 on the same f32 inputs, only the summation order differs); PSNR 1e-6 and
//! SSIM 1e-5 (polar-imgproc filters in f32 where scikit-image uses f64).

use polar_eval::{dehaze_metrics, depth_fit, mask_metrics, material_metrics};
use polar_image::Gray;
use serde_json::Value;

struct Golden {
    data: Value,
    w: usize,
    h: usize,
}

impl Golden {
    fn load() -> Self {
        let text = include_str!("golden/eval.json");
        let data: Value = serde_json::from_str(text).expect("golden JSON");
        let w = data["width"].as_u64().unwrap() as usize;
        let h = data["height"].as_u64().unwrap() as usize;
        Self { data, w, h }
    }

    fn f32(&self, name: &str) -> Gray<f32> {
        let v = self.data["inputs"][name].as_array().unwrap();
        let v = v
            .iter()
            .map(|x| x.as_f64().map_or(f32::NAN, |x| x as f32))
            .collect();
        Gray::from_vec(self.w, self.h, v).unwrap()
    }

    fn u8(&self, name: &str) -> Gray<u8> {
        let v = self.data["inputs"][name].as_array().unwrap();
        let v = v.iter().map(|x| x.as_u64().unwrap() as u8).collect();
        Gray::from_vec(self.w, self.h, v).unwrap()
    }

    fn expected(&self, path: &str) -> f64 {
        path.split('.')
            .fold(&self.data["expected"], |v, k| &v[k])
            .as_f64()
            .unwrap_or_else(|| panic!("no number at {path}"))
    }
}

fn assert_rel(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        (got - want).abs() <= tol * want.abs().max(1.0),
        "{what}: {got} vs numpy {want}"
    );
}

#[test]
fn depth_fit_matches_numpy_polyfit() {
    let g = Golden::load();
    let fit = depth_fit(&g.f32("est_depth"), &g.f32("gt_depth"), &g.u8("depth_mask"))
        .unwrap()
        .unwrap();
    assert_eq!(fit.count as f64, g.expected("depth.count"));
    assert_rel(fit.scale, g.expected("depth.scale"), 1e-9, "scale");
    assert_rel(fit.offset, g.expected("depth.offset"), 1e-9, "offset");
    assert_rel(
        fit.relative_rmse,
        g.expected("depth.relative_rmse"),
        1e-9,
        "rmse",
    );
}

#[test]
fn mask_metrics_match_numpy() {
    let g = Golden::load();
    let m = mask_metrics(
        &g.u8("pred_mask"),
        &g.u8("truth_mask"),
        Some(&g.u8("distractors")),
    )
    .unwrap();
    assert_rel(m.iou.unwrap(), g.expected("mask.iou"), 1e-12, "iou");
    assert_rel(
        m.precision.unwrap(),
        g.expected("mask.precision"),
        1e-12,
        "precision",
    );
    assert_rel(
        m.recall.unwrap(),
        g.expected("mask.recall"),
        1e-12,
        "recall",
    );
    let fp = m.false_positive_on_distractors.unwrap();
    assert_rel(
        fp,
        g.expected("mask.false_positive_on_distractors"),
        1e-12,
        "fp",
    );
}

#[test]
fn material_metrics_match_numpy() {
    let g = Golden::load();
    let m = material_metrics(&g.u8("pred_labels"), &g.u8("truth_labels")).unwrap();
    let acc = m.metal_vs_dielectric_accuracy.unwrap();
    assert_rel(
        acc,
        g.expected("material.metal_vs_dielectric_accuracy"),
        1e-12,
        "fg accuracy",
    );
    assert_rel(
        m.opaque_coverage.unwrap(),
        g.expected("material.opaque_coverage"),
        1e-12,
        "opaque coverage",
    );
    assert_rel(
        m.pixel_accuracy.unwrap(),
        g.expected("material.pixel_accuracy"),
        1e-12,
        "accuracy",
    );
    for c in 0..4 {
        let want = g.data["expected"]["material"]["class_iou"][c]
            .as_f64()
            .unwrap();
        assert_rel(m.class_iou[c].unwrap(), want, 1e-12, "class iou");
        for p in 0..4 {
            let want = g.data["expected"]["material"]["confusion"][c][p]
                .as_u64()
                .unwrap();
            assert_eq!(m.confusion[c][p], want, "confusion[{c}][{p}]");
        }
    }
}

#[test]
fn dehaze_metrics_match_scikit_image_and_numpy() {
    let g = Golden::load();
    let (t_est, t_gt) = (g.f32("t_est"), g.f32("t_gt"));
    let m = dehaze_metrics(
        &g.f32("hazy"),
        &g.f32("dehazed"),
        &g.f32("reference"),
        Some((&t_est, &t_gt)),
        Some(&g.u8("object_labels")),
    )
    .unwrap();
    assert_rel(
        m.hazy.psnr_db,
        g.expected("dehaze.hazy.psnr_db"),
        1e-6,
        "hazy psnr",
    );
    assert_rel(
        m.dehazed.psnr_db,
        g.expected("dehaze.dehazed.psnr_db"),
        1e-6,
        "psnr",
    );
    assert_rel(
        m.hazy.ssim,
        g.expected("dehaze.hazy.ssim"),
        1e-5,
        "hazy ssim",
    );
    assert_rel(
        m.dehazed.ssim,
        g.expected("dehaze.dehazed.ssim"),
        1e-5,
        "ssim",
    );
    assert_rel(
        m.transmission_mae.unwrap(),
        g.expected("dehaze.transmission_mae"),
        1e-9,
        "mae",
    );
    let corr = m.transmission_correlation.unwrap();
    assert_rel(
        corr,
        g.expected("dehaze.transmission_correlation"),
        1e-9,
        "correlation",
    );
    // Squared differences summed in f64 on both sides: only the order of the sum differs.
    let r = m.reachable.expect("some true transmission >= 0.1");
    assert_rel(
        r.fraction,
        g.expected("dehaze.reachable.fraction"),
        1e-12,
        "fraction",
    );
    for (got, key) in [
        (r.hazy_psnr_db, "hazy_psnr_db"),
        (r.dehazed_psnr_db, "dehazed_psnr_db"),
    ] {
        let want = g.expected(&format!("dehaze.reachable.{key}"));
        assert_rel(got, want, 1e-9, key);
    }
    // Over the object pixels: the mean of the SSIM map there (scikit-image's `full=True`).
    let o = m.objects.expect("some object labels");
    let objects = [
        (o.fraction, "fraction", 1e-12),
        (o.hazy.psnr_db, "hazy.psnr_db", 1e-9),
        (o.dehazed.psnr_db, "dehazed.psnr_db", 1e-9),
        (o.hazy.ssim, "hazy.ssim", 1e-5),
        (o.dehazed.ssim, "dehazed.ssim", 1e-5),
        (o.transmission_mae.unwrap(), "transmission_mae", 1e-9),
        (
            o.transmission_correlation.unwrap(),
            "transmission_correlation",
            1e-9,
        ),
    ];
    for (got, key, tol) in objects {
        assert_rel(got, g.expected(&format!("dehaze.objects.{key}")), tol, key);
    }
}
