//! Validity mask: which output pixels cannot be trusted.
//!
//! A pixel is flagged [`SATURATED`] when any raw sample its demosaicing method
//! reads (see [`DemosaicMethod::support_radius`]) is at the saturation level:
//! the true intensity is unknown there, so Stokes, DoLP and AoLP are biased.
//! It is flagged [`ZERO`] where `S0 <= 0` (or not finite): DoLP and AoLP are
//! undefined there and are NaN in the float outputs.

use polar_image::Gray;
use rayon::prelude::*;

use crate::SensorError;
use crate::demosaic::DemosaicMethod;
use crate::demosaic::color::split_colors;
use crate::layout::{Mosaic, MosaicSample};

/// Flag bit: a raw sample used by this pixel is saturated.
pub const SATURATED: u8 = 1;
/// Flag bit: `S0` is zero (or negative / not finite), so DoLP and AoLP are undefined.
pub const ZERO: u8 = 2;

/// Flags per output pixel (`0` = valid) for `raw` demosaiced with `method` into planes
/// whose `S0` is `s0`. `saturation` is the saturation level in DN (e.g. `2^bits − 1`).
pub fn validity_mask<T: MosaicSample>(
    raw: &Mosaic<T>,
    saturation: u32,
    method: DemosaicMethod,
    s0: &Gray<f32>,
) -> Gray<u8> {
    let sat = saturated_support(raw, saturation, method);
    let mut mask = Gray::<u8>::new(s0.width(), s0.height());
    mask.as_mut_slice()
        .par_iter_mut()
        .zip(sat.as_slice())
        .zip(s0.as_slice())
        .for_each(|((m, &s), &v)| {
            *m = if s { SATURATED } else { 0 } | if v > 0.0 && v.is_finite() { 0 } else { ZERO };
        });
    mask
}

/// [`validity_mask`] of a colour mosaic ([`crate::MosaicPattern::Rgb`]) whose Stokes planes
/// (e.g. the luminance of [`crate::ColorStokesPlanes`]) have `S0` `s0`: [`SATURATED`] where
/// a raw sample behind any colour of the pixel is. Found by sending an indicator (4 at
/// saturated samples, else 0) through the same colour split: a rounded mean of up to four
/// samples with a 4 among them is at least 1, so the indicator marks exactly the split
/// samples that read a saturated one, and [`validity_mask`] of the largest over the
/// colours spreads that over the demosaicing support.
pub fn validity_mask_rgb<T: MosaicSample>(
    raw: &Mosaic<T>,
    saturation: u32,
    method: DemosaicMethod,
    s0: &Gray<f32>,
) -> Result<Gray<u8>, SensorError> {
    let (w, h) = raw.size();
    let hit: Vec<u8> = raw
        .as_slice()
        .par_iter()
        .map(|&v| if v.into() >= saturation { 4 } else { 0 })
        .collect();
    let [r, g, b] = split_colors(&Mosaic::from_vec(w, h, hit).expect("size of raw"))?;
    // Flagged in any colour: the spread of the colours' largest indicator (a dilation of
    // the union is the union of the dilations).
    let any = (r.as_slice().par_iter().zip(g.as_slice()).zip(b.as_slice()))
        .map(|((&r, &g), &b)| r.max(g).max(b))
        .collect();
    let any = Mosaic::from_vec(w, h, any).expect("size of raw");
    Ok(validity_mask(&any, 1, method, s0))
}

/// `true` at output pixels whose demosaicing support holds a sample `>= saturation`.
fn saturated_support<T: MosaicSample>(
    raw: &Mosaic<T>,
    saturation: u32,
    method: DemosaicMethod,
) -> Gray<bool> {
    let (w, h) = raw.size();
    let src = raw.as_slice();
    if method == DemosaicMethod::Superpixel {
        let data = (0..(w / 2) * (h / 2))
            .map(|k| {
                let (x, y) = (2 * (k % (w / 2)), 2 * (k / (w / 2)));
                [0, 1, w, w + 1]
                    .iter()
                    .any(|&d| src[y * w + x + d].into() >= saturation)
            })
            .collect();
        return Gray::from_vec(w / 2, h / 2, data).expect("size matches");
    }
    // Separable dilation of the saturated samples by a (2r+1) square, centred on
    // the clamped pixel because border pixels copy their inner neighbour (bilinear).
    let r = method.support_radius();
    let mut rows = vec![false; w * h];
    rows.par_chunks_mut(w.max(1))
        .zip(src.par_chunks(w.max(1)))
        .for_each(|(out, row)| dilate_row(row, saturation, r, out));
    let mut data = vec![false; w * h];
    data.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, out)| {
            let cy = centre(y, h);
            for yy in cy.saturating_sub(r)..(cy + r + 1).min(h) {
                out.iter_mut()
                    .zip(&rows[yy * w..][..w])
                    .for_each(|(o, &s)| *o |= s);
            }
        });
    Gray::from_vec(w, h, data).expect("size matches")
}

/// The output pixel whose support is centred on `v` of `0..n`: border pixels copy their
/// inner neighbour (bilinear), so their support is the neighbour's.
fn centre(v: usize, n: usize) -> usize {
    if n >= 4 { v.clamp(1, n - 2) } else { v }
}

/// `out[x]`: whether `row` holds a sample `>= saturation` within `r` of `centre(x)`,
/// from a running count of the hits (one pass, no per-pixel window scan).
fn dilate_row<T: MosaicSample>(row: &[T], saturation: u32, r: usize, out: &mut [bool]) {
    let w = row.len();
    let mut count = Vec::with_capacity(w + 1);
    count.push(0u32);
    for &v in row {
        let hits = count[count.len() - 1] + u32::from(v.into() >= saturation);
        count.push(hits);
    }
    if count[w] == 0 {
        return;
    }
    for (x, o) in out.iter_mut().enumerate() {
        let c = centre(x, w);
        *o = count[(c + r + 1).min(w)] > count[c.saturating_sub(r)];
    }
}

/// Number of raw samples at or above `saturation`.
pub fn count_saturated<T: MosaicSample>(raw: &Mosaic<T>, saturation: u32) -> usize {
    raw.as_slice()
        .par_iter()
        .filter(|&&v| v.into() >= saturation)
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::products::stokes_planes;

    #[test]
    fn saturated_sample_flags_its_bilinear_neighbourhood_only() {
        let mut raw = Mosaic::<u8>::from_vec(8, 8, vec![100; 64]).unwrap();
        raw.as_mut_slice()[4 * 8 + 4] = 255;
        let planes = stokes_planes(&raw, DemosaicMethod::Bilinear).unwrap();
        let mask = validity_mask(&raw, 255, DemosaicMethod::Bilinear, &planes.s0);
        for y in 0..8usize {
            for x in 0..8usize {
                let near = x.abs_diff(4) <= 1 && y.abs_diff(4) <= 1;
                assert_eq!(
                    mask.pixel(x, y)[0],
                    if near { SATURATED } else { 0 },
                    "({x},{y})"
                );
            }
        }
    }

    /// The definition, pixel by pixel: a raw sample `>= saturation` in the (2r+1) square
    /// around the clamped centre.
    fn brute_force(raw: &Mosaic<u16>, saturation: u32, r: usize) -> Vec<bool> {
        let (w, h) = raw.size();
        let mut out = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let (cx, cy) = (centre(x, w), centre(y, h));
                let xs = cx.saturating_sub(r)..(cx + r + 1).min(w);
                let ys = cy.saturating_sub(r)..(cy + r + 1).min(h);
                out.push(ys.into_iter().any(|yy| {
                    xs.clone()
                        .any(|xx| u32::from(raw.pixel(xx, yy)[0]) >= saturation)
                }));
            }
        }
        out
    }

    #[test]
    fn saturated_support_matches_its_definition_on_random_frames() {
        let mut state = 0x9e37_79b9_u32;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state
        };
        for (w, h) in [(2, 2), (4, 2), (2, 6), (6, 4), (10, 8), (34, 12)] {
            for density in [1, 8, 64] {
                let data = (0..w * h)
                    .map(|_| if next() % 256 < density { 4095 } else { 7 })
                    .collect();
                let raw = Mosaic::<u16>::from_vec(w, h, data).unwrap();
                for method in [DemosaicMethod::Bilinear, DemosaicMethod::Residual] {
                    let fast = saturated_support(&raw, 4095, method);
                    let r = method.support_radius();
                    assert_eq!(
                        fast.as_slice(),
                        brute_force(&raw, 4095, r),
                        "{w}x{h}, density {density}/256, {method:?}"
                    );
                }
            }
        }
    }

    /// One saturated sample of a colour mosaic flags exactly the pixels whose value reads
    /// it: those whose luminance S0 changes when the sample changes (bilinear), and none else.
    #[test]
    fn saturated_colour_sample_flags_the_pixels_it_reaches() {
        let (w, h) = (16, 16);
        let base: Vec<u16> = (0..w * h).map(|k| 1000 + (k * 7 % 50) as u16).collect();
        let lum = |data: Vec<u16>| {
            let raw = Mosaic::from_vec(w, h, data).unwrap();
            crate::stokes_planes_rgb(&raw, DemosaicMethod::Bilinear)
                .unwrap()
                .luminance()
        };
        let mut sat = base.clone();
        sat[6 * w + 9] = 4095;
        let raw = Mosaic::from_vec(w, h, sat.clone()).unwrap();
        let (a, b) = (lum(base), lum(sat));
        let mask = validity_mask_rgb(&raw, 4095, DemosaicMethod::Bilinear, &b.s0).unwrap();
        for k in 0..w * h {
            let changed = a.s0.as_slice()[k] != b.s0.as_slice()[k];
            assert_eq!(mask.as_slice()[k] == SATURATED, changed, "pixel {k}");
        }
        assert!(mask.as_slice().contains(&SATURATED));
    }

    #[test]
    fn zero_intensity_is_flagged() {
        let raw = Mosaic::<u16>::new(4, 4);
        let planes = stokes_planes(&raw, DemosaicMethod::Superpixel).unwrap();
        let mask = validity_mask(&raw, 4095, DemosaicMethod::Superpixel, &planes.s0);
        assert!(mask.as_slice().iter().all(|&m| m == ZERO));
    }
}
