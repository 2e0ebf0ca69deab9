//! polar-sensor against polanalyser 3.0.0 / OpenCV 5.0 golden data
//! (made by `tools/polanalyser_goldens.py`; fixtures in `tests/data/`).

use polar_image::PolarizerStack;
use polar_sensor::layout::COLOR_NAMES;
use polar_sensor::picture::aolp_hsv;
use polar_sensor::{
    DemosaicMethod, Mosaic, MosaicSample, StokesPlanes, demosaic, demosaic_rgb, stokes_planes,
    stokes_planes_rgb,
};
use serde_json::Value;

/// Tolerances, and why:
/// - demosaiced images: 0 DN, we reproduce OpenCV's integer rounding and border rule bit for bit;
/// - S0..S2: 1e-6 relative to the largest |value|; ours are f32 sums of exact integers
///   (exact), polanalyser's come from a float64 pseudo-inverse (rounding ~1e-15);
/// - DoLP: 1e-6 absolute, f32 rounding of sqrt and division;
/// - AoLP: 1e-5 rad, f32 atan2 (absolute error about 1 ulp of pi);
/// - AoLP picture: 1 DN per channel (hue/value truncation can flip on f32 vs f64 rounding).
const STOKES_REL: f32 = 1e-6;
const DOLP_ABS: f32 = 1e-6;
const AOLP_ABS: f32 = 1e-5;

fn load(name: &str) -> Value {
    let path = format!("{}/tests/data/{name}.json", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(&path).expect("fixture exists"))
        .expect("fixture is JSON")
}

fn floats(v: &Value, key: &str) -> Vec<f32> {
    v[key]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().map_or(f32::NAN, |f| f as f32))
        .collect()
}

fn mosaic<T: TryFrom<u64>>(v: &Value) -> Mosaic<T> {
    let data = v["raw"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| T::try_from(x.as_u64().unwrap()).ok().unwrap())
        .collect();
    Mosaic::from_vec(
        v["width"].as_u64().unwrap() as usize,
        v["height"].as_u64().unwrap() as usize,
        data,
    )
    .unwrap()
}

fn check_fixture<T: MosaicSample + TryFrom<u64>>(name: &str) {
    let v = load(name);
    let raw = mosaic::<T>(&v);
    let stack = demosaic(&raw, DemosaicMethod::Bilinear).unwrap();
    check_stack(name, &v, "", &stack);
    let planes = stokes_planes(&raw, DemosaicMethod::Bilinear).unwrap();
    check_planes(name, &v, "", &planes);

    let picture = aolp_hsv(&planes.aolp, &planes.dolp);
    let want = v["aolp_rgb"].as_array().unwrap();
    for (k, (&got, want)) in picture.as_slice().iter().zip(want).enumerate() {
        let want = want.as_i64().unwrap();
        assert!(
            (i64::from(got) - want).abs() <= 1,
            "{name} aolp picture[{k}]: {got} vs {want}"
        );
    }
}

/// A colour fixture: per colour (keys prefixed `R.`, `G.`, `B.`) the same checks and
/// tolerances as a monochrome one, against polanalyser's `COLOR_PolarRGB` chain.
fn check_colour_fixture<T: MosaicSample + TryFrom<u64>>(name: &str) {
    let v = load(name);
    let raw = mosaic::<T>(&v);
    let stacks = demosaic_rgb(&raw, DemosaicMethod::Bilinear).unwrap();
    let planes = stokes_planes_rgb(&raw, DemosaicMethod::Bilinear).unwrap();
    for (c, colour) in COLOR_NAMES.into_iter().enumerate() {
        let prefix = format!("{colour}.");
        check_stack(name, &v, &prefix, &stacks[c]);
        check_planes(name, &v, &prefix, &planes.colors[c]);
    }
}

/// The four demosaiced images equal the fixture's `{prefix}i0` ... `{prefix}i135` exactly.
fn check_stack(name: &str, v: &Value, prefix: &str, stack: &PolarizerStack) {
    let w = stack.width();
    for (c, key) in ["i0", "i45", "i90", "i135"].into_iter().enumerate() {
        let want = floats(v, &format!("{prefix}{key}"));
        assert_eq!(want.len(), stack.pixels().len(), "{name} {prefix}{key}");
        for (k, px) in stack.pixels().iter().enumerate() {
            assert_eq!(
                px[c],
                want[k],
                "{name} {prefix}{key} at ({}, {})",
                k % w,
                k / w
            );
        }
    }
}

/// S0..S2, DoLP and AoLP against the fixture's `{prefix}s0` ... `{prefix}aolp`.
fn check_planes(name: &str, v: &Value, prefix: &str, planes: &StokesPlanes) {
    let key = |k: &str| format!("{prefix}{k}");
    for (plane, k) in [(&planes.s0, "s0"), (&planes.s1, "s1"), (&planes.s2, "s2")] {
        let want = floats(v, &key(k));
        assert_eq!(want.len(), plane.as_slice().len(), "{name} {}", key(k));
        let scale = want.iter().fold(0.0f32, |m, x| m.max(x.abs()));
        for (i, (&got, &w_)) in plane.as_slice().iter().zip(&want).enumerate() {
            assert!(
                (got - w_).abs() <= STOKES_REL * scale,
                "{name} {}[{i}]: {got} vs {w_}",
                key(k)
            );
        }
    }
    let (dolp, aolp) = (floats(v, &key("dolp")), floats(v, &key("aolp")));
    for k in 0..dolp.len() {
        let (gd, ga) = (planes.dolp.as_slice()[k], planes.aolp.as_slice()[k]);
        assert_eq!(
            gd.is_nan(),
            dolp[k].is_nan(),
            "{name} {prefix}DoLP NaN pattern at {k}"
        );
        if dolp[k].is_nan() {
            assert!(ga.is_nan(), "{name}: AoLP must be NaN where DoLP is");
            continue;
        }
        assert!(
            (gd - dolp[k]).abs() <= DOLP_ABS,
            "{name} {prefix}DoLP[{k}]: {gd} vs {}",
            dolp[k]
        );
        let d = (ga - aolp[k]).abs().rem_euclid(std::f32::consts::PI);
        assert!(
            d.min(std::f32::consts::PI - d) <= AOLP_ABS,
            "{name} {prefix}AoLP[{k}]: {ga} vs {}",
            aolp[k]
        );
    }
}

#[test]
fn bilinear_matches_polanalyser_on_random_8bit_mosaic() {
    check_fixture::<u8>("bilinear_u8");
}

#[test]
fn bilinear_matches_polanalyser_on_random_16bit_mosaic() {
    check_fixture::<u16>("bilinear_u16");
}

#[test]
fn bilinear_matches_polanalyser_on_real_crop() {
    check_fixture::<u8>("real_crop_u8");
}

#[test]
fn colour_bilinear_matches_polanalyser_on_random_8bit_mosaic() {
    check_colour_fixture::<u8>("rgb_u8");
}

#[test]
fn colour_bilinear_matches_polanalyser_on_random_16bit_mosaic() {
    check_colour_fixture::<u16>("rgb_u16");
}

#[test]
fn colour_bilinear_matches_polanalyser_on_real_crop() {
    check_colour_fixture::<u8>("rgb_real_crop_u8");
}

/// The 8-bit frame read as 16-bit values must give the same Stokes images.
#[test]
fn sample_type_does_not_change_results() {
    let v = load("real_crop_u8");
    let (a, b) = (mosaic::<u8>(&v), mosaic::<u16>(&v));
    for m in DemosaicMethod::ALL {
        let (pa, pb) = (stokes_planes(&a, m).unwrap(), stokes_planes(&b, m).unwrap());
        assert_eq!(pa.s0, pb.s0, "{m}");
        assert_eq!(pa.s1, pb.s1, "{m}");
    }
}
