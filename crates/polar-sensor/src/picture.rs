//! 8-bit RGB pictures of polarization images.
//!
//! - [`aolp_hsv`]: hue = AoLP, saturation = 1, value = DoLP, exactly as
//!   polanalyser's `applyColorToAoLP(aolp, value=dolp)` (OpenCV hue `0..179`,
//!   `COLOR_HSV2BGR`), but returned as RGB.
//! - [`colormap`]: a scalar image through a viridis-like colour map of [`VIRIDIS_LEVELS`]
//!   colours; [`colormap_index_into`] gives the same picture as indices into
//!   [`viridis_palette`], for a palette PNG a third the size of its RGB.
//! - [`srgb_into`]: linear colour values (a colour sensor's S0) as sRGB.
//!
//! Undefined pixels (NaN) are black.

use polar_image::{Gray, Image, par_fill};

/// An 8-bit RGB picture.
pub type Rgb8 = Image<u8, 3>;

/// AoLP (radians) as hue and DoLP as value; NaN in either gives black.
///
/// Quantisation follows polanalyser: `hue = trunc(mod(aolp, π) / π · 179)`,
/// `value = trunc(clip(dolp, 0, 1) · 255)`, then OpenCV's 8-bit HSV -> RGB.
pub fn aolp_hsv(aolp: &Gray<f32>, dolp: &Gray<f32>) -> Rgb8 {
    let mut out = Rgb8::new(aolp.width(), aolp.height());
    aolp_hsv_into(aolp.as_slice(), dolp.as_slice(), out.pixels_mut());
    out
}

/// [`aolp_hsv`] of a run of pixels (e.g. a block of rows streamed to a PNG encoder); the
/// three slices have one length (else a panic: a caller's bug).
pub fn aolp_hsv_into(aolp: &[f32], dolp: &[f32], out: &mut [[u8; 3]]) {
    assert!(aolp.len() == out.len() && dolp.len() == out.len());
    let table = full_saturation_table();
    par_fill(out, |k| {
        let (a, d) = (aolp[k], dolp[k]);
        if a.is_finite() && d.is_finite() {
            let hue = (angle_mod_pi(a) / std::f32::consts::PI * 179.0) as u8;
            let value = (d.clamp(0.0, 1.0) * 255.0) as u8;
            table[usize::from(hue) * 256 + usize::from(value)]
        } else {
            [0; 3]
        }
    });
}

/// `a.rem_euclid(π)`, without the division inside the AoLP range `(-π, π)` (where it is
/// exactly `a` or `a + π`).
fn angle_mod_pi(a: f32) -> f32 {
    use std::f32::consts::PI;
    match a {
        a if (0.0..PI).contains(&a) => a,
        a if a > -PI && a < 0.0 => a + PI,
        a => a.rem_euclid(PI),
    }
}

/// [`hsv_to_rgb`] at saturation 255 for every hue `0..180` and value `0..=255`, indexed
/// `hue * 256 + value`: one look-up per pixel instead of the float sector arithmetic.
fn full_saturation_table() -> &'static [[u8; 3]] {
    static TABLE: std::sync::OnceLock<Vec<[u8; 3]>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        (0..180u8)
            .flat_map(|h| (0..=255u8).map(move |v| hsv_to_rgb(h, 255, v)))
            .collect()
    })
}

/// OpenCV's 8-bit `HSV2RGB`: hue in `0..180` (2° steps), saturation and value in `0..=255`.
///
/// Reproduces OpenCV 5.0 exactly (checked over every hue and value at full
/// saturation): f32 arithmetic with `x · (1/255)` scaling, `h · (6/180)` sectors and
/// truncation (not rounding) of the final `· 255`.
pub fn hsv_to_rgb(h: u8, s: u8, v: u8) -> [u8; 3] {
    let (s, v) = (f32::from(s) * (1.0 / 255.0), f32::from(v) * (1.0 / 255.0));
    let h = (f32::from(h) * (6.0 / 180.0)).rem_euclid(6.0);
    let sector = h.floor();
    let f = h - sector;
    let tab = [
        v,
        v * (1.0 - s),
        v * (1.0 - s * f),
        v * (1.0 - s * (1.0 - f)),
    ];
    // (r, g, b) indices into `tab` per 60° sector.
    const SECTORS: [[usize; 3]; 6] = [
        [0, 3, 1],
        [2, 0, 1],
        [1, 0, 3],
        [1, 2, 0],
        [3, 1, 0],
        [0, 1, 2],
    ];
    SECTORS[sector as usize % 6].map(|i| (tab[i] * 255.0) as u8)
}

/// Anchor colours of the map at `t = 0, 1/8, …, 1` (sampled from matplotlib's viridis), linearly interpolated.
const VIRIDIS: [[f32; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];

/// Colour of `t` in `[0, 1]` (clamped) on the viridis-like map.
///
/// Rounded as `trunc(x + 0.5)`: equal to `round(x)` for `0.5 <= x < 2^22` (the addition is
/// exact there) and every channel is at least 1, but without a libm call per channel.
pub fn viridis(t: f32) -> [u8; 3] {
    let u = t.clamp(0.0, 1.0) * (VIRIDIS.len() - 1) as f32;
    let i = (u as usize).min(VIRIDIS.len() - 2);
    let f = u - i as f32;
    let [lo, hi] = [VIRIDIS[i], VIRIDIS[i + 1]];
    let channel = |c: usize| (lo[c] + f * (hi[c] - lo[c]) + 0.5) as u8;
    [channel(0), channel(1), channel(2)]
}

/// Colours of the map in pictures: `[vmin, vmax]` is cut into this many levels (matplotlib's
/// viridis is likewise a table, of 256), so that a picture fits an 8-bit palette with black
/// for undefined pixels ([`viridis_palette`]).
pub const VIRIDIS_LEVELS: usize = 255;

/// The palette of viridis pictures: index 0 black (undefined pixels), index `1 + j` the colour
/// [`viridis`]`(j / (VIRIDIS_LEVELS - 1))`.
pub fn viridis_palette() -> &'static [[u8; 3]; VIRIDIS_LEVELS + 1] {
    static PALETTE: std::sync::OnceLock<[[u8; 3]; VIRIDIS_LEVELS + 1]> = std::sync::OnceLock::new();
    PALETTE.get_or_init(|| {
        let top = (VIRIDIS_LEVELS - 1) as f32;
        std::array::from_fn(|i| match i {
            0 => [0; 3],
            i => viridis((i - 1) as f32 / top),
        })
    })
}

/// `values` mapped linearly from `[vmin, vmax]` onto the colour map; NaN gives black.
pub fn colormap(values: &Gray<f32>, vmin: f32, vmax: f32) -> Rgb8 {
    let mut out = Rgb8::new(values.width(), values.height());
    colormap_into(values.as_slice(), vmin, vmax, out.pixels_mut());
    out
}

/// [`colormap`] of a run of pixels (e.g. a block of rows streamed to a PNG encoder); `values`
/// and `out` have one length (else a panic: a caller's bug).
pub fn colormap_into(values: &[f32], vmin: f32, vmax: f32, out: &mut [[u8; 3]]) {
    assert_eq!(values.len(), out.len());
    let (palette, level) = (viridis_palette(), Levels::new(vmin, vmax));
    par_fill(out, |k| palette[usize::from(level.index(values[k]))]);
}

/// [`colormap`] as indices into [`viridis_palette`].
pub fn colormap_indices(values: &Gray<f32>, vmin: f32, vmax: f32) -> Gray<u8> {
    let mut out = Gray::new(values.width(), values.height());
    colormap_index_into(values.as_slice(), vmin, vmax, out.as_mut_slice());
    out
}

/// [`colormap_into`] as indices into [`viridis_palette`].
pub fn colormap_index_into(values: &[f32], vmin: f32, vmax: f32, out: &mut [u8]) {
    assert_eq!(values.len(), out.len());
    let level = Levels::new(vmin, vmax);
    par_fill(out, |k| level.index(values[k]));
}

/// The linear map of `[vmin, vmax]` onto the palette's levels.
#[derive(Clone, Copy)]
struct Levels {
    vmin: f32,
    scale: f32,
}

impl Levels {
    fn new(vmin: f32, vmax: f32) -> Self {
        let scale = if vmax > vmin {
            (VIRIDIS_LEVELS - 1) as f32 / (vmax - vmin)
        } else {
            0.0
        };
        Levels { vmin, scale }
    }

    /// Palette index of `v`: the nearest level (clamped to the range) plus one; 0 where `v`
    /// is not finite. `trunc(x + 0.5)` rounds as [`viridis`] does.
    #[inline]
    fn index(self, v: f32) -> u8 {
        if v.is_finite() {
            let x = ((v - self.vmin) * self.scale).clamp(0.0, (VIRIDIS_LEVELS - 1) as f32);
            1 + (x + 0.5) as u8
        } else {
            0
        }
    }
}

/// Linear R, G, B values divided by `vmax`, clipped to `[0, 1]` and encoded with the sRGB
/// transfer function (IEC 61966-2-1) to 8 bits; a pixel with a NaN channel is black. The four
/// slices have one length (else a panic: a caller's bug).
pub fn srgb_into(rgb: [&[f32]; 3], vmax: f32, out: &mut [[u8; 3]]) {
    let scale = if vmax > 0.0 { 1.0 / vmax } else { 0.0 };
    let encode = |v: f32| {
        let v = (v * scale).clamp(0.0, 1.0);
        let e = if v <= 0.003_130_8 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        };
        (e * 255.0).round() as u8
    };
    assert!(rgb.iter().all(|c| c.len() == out.len()));
    par_fill(out, |k| {
        let v = [rgb[0][k], rgb[1][k], rgb[2][k]];
        if v.iter().all(|c| !c.is_nan()) {
            [encode(v[0]), encode(v[1]), encode(v[2])]
        } else {
            [0; 3]
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast AoLP path equals `rem_euclid` bit for bit on both sides of 0 and at ±π/2,
    /// and the look-up table equals the arithmetic at every hue and value.
    #[test]
    fn aolp_fast_paths_equal_the_definitions() {
        use std::f32::consts::{FRAC_PI_2, PI};
        let angles = (-2000..=2000).map(|k| k as f32 * 0.0016).chain([
            -FRAC_PI_2,
            FRAC_PI_2,
            -0.0,
            0.0,
            -PI,
            PI,
            7.5,
            -7.5,
            f32::MIN_POSITIVE,
        ]);
        for a in angles {
            assert_eq!(angle_mod_pi(a).to_bits(), a.rem_euclid(PI).to_bits(), "{a}");
        }
        for h in 0..180u8 {
            for v in 0..=255u8 {
                let got = full_saturation_table()[usize::from(h) * 256 + usize::from(v)];
                assert_eq!(got, hsv_to_rgb(h, 255, v), "hue {h} value {v}");
            }
        }
    }

    #[test]
    fn hsv_primaries() {
        assert_eq!(hsv_to_rgb(0, 255, 255), [255, 0, 0]);
        assert_eq!(hsv_to_rgb(60, 255, 255), [0, 255, 0]);
        assert_eq!(hsv_to_rgb(120, 255, 255), [0, 0, 255]);
        assert_eq!(hsv_to_rgb(30, 255, 255), [255, 255, 0]);
        assert_eq!(hsv_to_rgb(77, 0, 200), [200, 200, 200]);
    }

    #[test]
    fn undefined_pixels_are_black() {
        let a = Gray::from_vec(2, 1, vec![f32::NAN, 0.0]).unwrap();
        let d = Gray::from_vec(2, 1, vec![0.5, f32::NAN]).unwrap();
        assert_eq!(aolp_hsv(&a, &d).as_slice(), &[0; 6]);
        assert_eq!(colormap(&a, 0.0, 1.0).pixels()[0], [0, 0, 0]);
    }

    /// Known sRGB codes: 0 and 1 at the ends, linear 0.5 -> 188, 0.002 on the linear toe -> 7
    /// (12.92 · 0.002 · 255 = 6.6); the scale divides first; NaN is black.
    #[test]
    fn srgb_known_values() {
        let (r, g, b) = (
            [0.0, 2.0, 1.0, f32::NAN],
            [0.5, 4.0, 0.004, 1.0],
            [1.0, -1.0, 0.0, 1.0],
        );
        let mut out = [[9; 3]; 4];
        srgb_into([&r, &g, &b], 2.0, &mut out);
        assert_eq!(out, [[0, 137, 188], [255, 255, 0], [188, 7, 0], [0, 0, 0]]);
    }

    #[test]
    fn viridis_rounds_like_round_everywhere() {
        let reference = |t: f32| {
            let u = t.clamp(0.0, 1.0) * 8.0;
            let i = (u.floor() as usize).min(7);
            let f = u - i as f32;
            std::array::from_fn::<u8, 3, _>(|c| {
                (VIRIDIS[i][c] + f * (VIRIDIS[i + 1][c] - VIRIDIS[i][c])).round() as u8
            })
        };
        // Every f32 in [0, 1] would take minutes; every 64th bit pattern covers all
        // sub-intervals and rounding boundaries at this map's 8-bit resolution.
        for bits in (0..=1.0f32.to_bits()).step_by(64) {
            let t = f32::from_bits(bits);
            assert_eq!(viridis(t), reference(t), "t {t}");
        }
    }

    /// The palette's levels sit at `vmin + j (vmax - vmin) / 254`: each maps to its own
    /// index `1 + j`, a value within under half a step of it too; the range's ends clamp;
    /// the RGB map is the palette at the index; undefined pixels take index 0, black.
    #[test]
    fn colormap_indices_are_the_palette_levels() {
        let (vmin, vmax) = (-2.0f32, 3.0f32);
        let step = (vmax - vmin) / (VIRIDIS_LEVELS - 1) as f32;
        let mut values: Vec<f32> = (0..VIRIDIS_LEVELS)
            .flat_map(|j| [0.0, 0.45, -0.45].map(|d| vmin + (j as f32 + d) * step))
            .collect();
        values.extend([
            vmin - 1.0,
            vmax + 1.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ]);
        let mut index = vec![9u8; values.len()];
        let mut rgb = vec![[9u8; 3]; values.len()];
        colormap_index_into(&values, vmin, vmax, &mut index);
        colormap_into(&values, vmin, vmax, &mut rgb);
        for j in 0..VIRIDIS_LEVELS {
            let at = (3 * j..3 * j + 3)
                .filter(|&k| (0.0..=254.0).contains(&((values[k] - vmin) / step)));
            for k in at {
                assert_eq!(
                    usize::from(index[k]),
                    1 + j,
                    "level {j}, value {}",
                    values[k]
                );
            }
        }
        let n = values.len();
        assert_eq!(index[n - 5..], [1, 255, 0, 0, 0]);
        for (k, (&i, &c)) in index.iter().zip(&rgb).enumerate() {
            assert_eq!(c, viridis_palette()[usize::from(i)], "value {}", values[k]);
        }
        assert_eq!(viridis_palette()[0], [0; 3]);
        assert_eq!(viridis_palette()[1], viridis(0.0));
        assert_eq!(viridis_palette()[VIRIDIS_LEVELS], viridis(1.0));
    }

    #[test]
    fn viridis_ends() {
        assert_eq!(viridis(-1.0), [68, 1, 84]);
        assert_eq!(viridis(2.0), [253, 231, 37]);
    }
}
