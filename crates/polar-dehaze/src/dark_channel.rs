//! Dark channel prior (He, Sun, Tang, "Single image haze removal using dark channel
//! prior", CVPR 2009 / TPAMI 2011) on one channel, S0.
//!
//! In haze-free outdoor images most patches hold some pixel that is nearly black
//! (shadow, dark object), so the patch minimum of `S0 / A_inf` measures the airlight
//! fraction `1 - t`: `t = 1 - omega min_patch(S0 / A_inf)`. With one channel the prior is
//! weaker than with colour (a bright grey surface looks like haze). `A_inf` is He et al.'s
//! choice: the brightest S0 among the 0.1 % pixels with the highest dark channel.
//!
//! The steps mirror `tools/dehaze_dcp_reference.py` (OpenCV) one for one: `dark0 =
//! erode(S0n, patch)`; `A` = max `S0n` over valid pixels with `dark0 >=` the k-th largest
//! valid `dark0`, `k = max(1, n / 1000)`; `t = 1 - omega erode(S0n / A)`.

use polar_image::Gray;
use polar_imgproc::min_filter;

use crate::prep::Normalized;
use crate::{DehazeError, DehazeOptions, Inversion, Method, RawEstimate};

/// Fraction of the pixels with the highest dark channel among which `A_inf` is the brightest.
pub const AIRLIGHT_FRACTION: f64 = 0.001;

/// Raw dark-channel transmission of the normalised observation.
pub fn transmission(input: &Normalized, opts: &DehazeOptions) -> Result<RawEstimate, DehazeError> {
    let (w, h) = input.s0.size();
    let patch = opts.dcp_patch;
    let mut dark0 = Gray::new(w, h);
    min_filter(&input.s0, &mut dark0, patch, patch)?;
    let mut warnings = Vec::new();
    let Some(a) = airlight(input, &dark0) else {
        warnings.push(
            "dark channel: no valid pixel with light; airlight unknown, transmission set to 1"
                .to_string(),
        );
        return Ok(RawEstimate {
            raw_t: Gray::from_vec(w, h, vec![1.0; w * h]).expect("size matches"),
            airlight_inf: 1.0,
            airlight_field: None,
            airlight_dolp: 0.0,
            inversion: Inversion::Clamped,
            method: Method::DarkChannel,
            guided_eps: opts.guided_eps,
            warnings,
        });
    };
    let ratio: Vec<f32> = input.s0.as_slice().iter().map(|&v| v / a).collect();
    let ratio = Gray::from_vec(w, h, ratio).expect("size matches");
    let mut dark = Gray::new(w, h);
    min_filter(&ratio, &mut dark, patch, patch)?;
    let omega = opts.dcp_omega;
    let t: Vec<f32> = dark.as_slice().iter().map(|&d| 1.0 - omega * d).collect();
    Ok(RawEstimate {
        raw_t: Gray::from_vec(w, h, t).expect("size matches"),
        airlight_inf: a,
        airlight_field: None,
        airlight_dolp: 0.0,
        inversion: Inversion::Clamped,
        method: Method::DarkChannel,
        guided_eps: opts.guided_eps,
        warnings,
    })
}

/// He et al.'s airlight: the largest S0 among the valid pixels whose dark channel is at
/// least the `k`-th largest valid dark channel value, `k = max(1, AIRLIGHT_FRACTION n)`
/// (ties all included, so the choice is deterministic). `None` without a positive one.
pub fn airlight(input: &Normalized, dark0: &Gray<f32>) -> Option<f32> {
    let d = dark0.as_slice();
    let mut vals: Vec<f32> = (0..d.len())
        .filter(|&k| input.valid[k])
        .map(|k| d[k])
        .collect();
    if vals.is_empty() {
        return None;
    }
    let n = d.len();
    let k = ((n as f64 * AIRLIGHT_FRACTION) as usize).clamp(1, vals.len());
    let idx = vals.len() - k;
    let thr = *vals.select_nth_unstable_by(idx, f32::total_cmp).1;
    let s0 = input.s0.as_slice();
    (0..n)
        .filter(|&k| input.valid[k] && d[k] >= thr)
        .map(|k| s0[k])
        .fold(None, |m: Option<f32>, v| Some(m.map_or(v, |m| m.max(v))))
        .filter(|&a| a > 0.0)
}
