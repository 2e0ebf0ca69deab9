//! 8-bit pictures of the task outputs, for people (written under `pictures/`).

use polar_image::{Gray, Image, NormalImage, quantile};
use polar_sensor::picture::colormap;

/// Normals as colours: `(n + 1) / 2` per axis (x red, y green, z blue); black where none.
pub fn normal_picture(normals: &NormalImage) -> Image<u8, 3> {
    map_rgb(normals.size(), normals.pixels(), |n| {
        if n.iter().all(|&v| v == 0.0) || n.iter().any(|v| !v.is_finite()) {
            [0, 0, 0]
        } else {
            n.map(|v| ((v.clamp(-1.0, 1.0) * 0.5 + 0.5) * 255.0).round() as u8)
        }
    })
}

/// A label image through a palette (labels past its end are white).
pub fn label_picture(labels: &Gray<u8>, palette: &[[u8; 3]]) -> Image<u8, 3> {
    map_rgb(labels.size(), labels.pixels(), |[l]| {
        palette.get(usize::from(*l)).copied().unwrap_or([255; 3])
    })
}

/// Reflection types: none black, diffuse blue, specular red, mixed yellow.
pub const REFLECTION_PALETTE: [[u8; 3]; 4] =
    [[0, 0, 0], [40, 90, 230], [230, 40, 40], [230, 200, 40]];

/// Material labels: background dark grey, dielectric orange, metal steel blue, transparent cyan.
pub const MATERIAL_PALETTE: [[u8; 3]; 4] = [
    [40, 40, 40],
    [230, 140, 40],
    [110, 140, 190],
    [60, 220, 230],
];

/// S0 as grey levels in `[0, 255]`, from 0 to its 99.5th percentile (non-finite: 0).
fn grey_levels(s0: &Gray<f32>) -> impl Iterator<Item = f32> + '_ {
    let top = quantile(s0.as_slice().iter().copied(), 0.995)
        .filter(|&q| q > 0.0)
        .unwrap_or(1.0);
    s0.as_slice().iter().map(move |&v| {
        if v.is_finite() {
            (v / top).clamp(0.0, 1.0) * 255.0
        } else {
            0.0
        }
    })
}

/// S0 as a grey picture ([`grey_levels`]).
fn grey_picture(s0: &Gray<f32>) -> Image<u8, 3> {
    grey_from(s0.size(), grey_levels(s0))
}

/// A grey picture of grey levels in `[0, 255]`.
fn grey_from(size: (usize, usize), levels: impl Iterator<Item = f32>) -> Image<u8, 3> {
    from_pixels(size, levels.map(|g| [g as u8; 3]).collect())
}

/// Largest angular error (degrees) on the error scale of [`normal_error_picture`].
pub const ERROR_SCALE_DEG: f32 = 90.0;

/// S0 (grey), estimated normals, true normals ([`normal_picture`]) and the angular error
/// `error` (degrees, viridis from 0 to [`ERROR_SCALE_DEG`], black where NaN), side by side.
pub fn normal_error_picture(
    s0: &Gray<f32>,
    est: &NormalImage,
    truth: &NormalImage,
    error: &Gray<f32>,
) -> Image<u8, 3> {
    let grey = grey_picture(s0);
    hstack(&[
        grey,
        normal_picture(est),
        normal_picture(truth),
        colormap(error, 0.0, ERROR_SCALE_DEG),
    ])
}

/// S0 as grey (0 to its 99.5th percentile) with `mask` (non-zero) tinted red.
pub fn overlay_picture(s0: &Gray<f32>, mask: &Gray<u8>) -> Image<u8, 3> {
    let data: Vec<[u8; 3]> = grey_levels(s0)
        .zip(mask.as_slice())
        .map(|(g, &m)| {
            if m != 0 {
                [(0.5 * g + 127.0) as u8, (0.5 * g) as u8, (0.5 * g) as u8]
            } else {
                [g as u8; 3]
            }
        })
        .collect();
    from_pixels(s0.size(), data)
}

/// S0 as grey, the estimated labels and the true labels through `palette`, side by side.
pub fn label_error_picture(
    s0: &Gray<f32>,
    est: &Gray<u8>,
    truth: &Gray<u8>,
    palette: &[[u8; 3]],
) -> Image<u8, 3> {
    let grey = grey_picture(s0);
    hstack(&[
        grey,
        label_picture(est, palette),
        label_picture(truth, palette),
    ])
}

/// Found (green), falsely marked (red) and missed (blue) pixels of a mask against the truth.
pub const MASK_ERROR_COLOURS: [[u8; 3]; 3] = [[40, 200, 60], [230, 40, 40], [40, 90, 230]];

/// S0 as grey beside S0 with the mask `est` compared with `truth` (non-zero = on): found
/// pixels green, false ones red, missed ones blue ([`MASK_ERROR_COLOURS`]), each half
/// blended with the grey.
pub fn mask_error_picture(s0: &Gray<f32>, est: &Gray<u8>, truth: &Gray<u8>) -> Image<u8, 3> {
    let grey: Vec<f32> = grey_levels(s0).collect();
    let tinted = grey
        .iter()
        .zip(est.as_slice().iter().zip(truth.as_slice()))
        .map(|(&g, (&e, &t))| {
            let colour = match (e != 0, t != 0) {
                (true, true) => MASK_ERROR_COLOURS[0],
                (true, false) => MASK_ERROR_COLOURS[1],
                (false, true) => MASK_ERROR_COLOURS[2],
                (false, false) => return [g as u8; 3],
            };
            colour.map(|c| (0.5 * g + 0.5 * f32::from(c)) as u8)
        })
        .collect();
    hstack(&[
        grey_from(s0.size(), grey.into_iter()),
        from_pixels(s0.size(), tinted),
    ])
}

/// Images side by side on one viridis scale from 0 to the first image's 99.5th percentile
/// (so a dehazed image is seen against its hazy input), then `extra` on its own 0..1 scale.
pub fn side_by_side(same_scale: &[&Gray<f32>], extra: Option<&Gray<f32>>) -> Image<u8, 3> {
    let top = same_scale
        .first()
        .and_then(|g| quantile(g.as_slice().iter().copied(), 0.995))
        .filter(|&q| q > 0.0)
        .unwrap_or(1.0);
    let mut parts: Vec<Image<u8, 3>> = same_scale.iter().map(|g| colormap(g, 0.0, top)).collect();
    parts.extend(extra.map(|g| colormap(g, 0.0, 1.0)));
    hstack(&parts)
}

/// Pictures of one size side by side, left to right.
fn hstack(parts: &[Image<u8, 3>]) -> Image<u8, 3> {
    let (w, h) = parts.first().map_or((0, 0), |p| p.size());
    let mut data = Vec::with_capacity(w * h * parts.len());
    for y in 0..h {
        for p in parts {
            data.extend_from_slice(&p.pixels()[y * w..(y + 1) * w]);
        }
    }
    from_pixels((w * parts.len(), h), data)
}

fn map_rgb<T, const C: usize>(
    size: (usize, usize),
    px: &[[T; C]],
    f: impl Fn(&[T; C]) -> [u8; 3],
) -> Image<u8, 3> {
    from_pixels(size, px.iter().map(f).collect())
}

fn from_pixels((w, h): (usize, usize), px: Vec<[u8; 3]>) -> Image<u8, 3> {
    Image::from_vec(w, h, px.into_flattened()).expect("one RGB triple per pixel")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three panels: grey S0, then the estimate and the truth through the palette.
    #[test]
    fn label_error_picture_shows_estimate_beside_truth() {
        let s0 = Gray::from_vec(2, 1, vec![0.0f32, 0.0]).unwrap();
        let est = Gray::from_vec(2, 1, vec![1u8, 2]).unwrap();
        let truth = Gray::from_vec(2, 1, vec![2u8, 2]).unwrap();
        let p = label_error_picture(&s0, &est, &truth, &MATERIAL_PALETTE);
        let [_, d, m, _] = MATERIAL_PALETTE;
        assert_eq!(p.pixels(), &[[0, 0, 0], [0, 0, 0], d, m, m, m]);
    }

    /// Two panels; the second tints found, false and missed pixels and leaves the rest grey.
    #[test]
    fn mask_error_picture_colours_found_false_and_missed_pixels() {
        let s0 = Gray::from_vec(4, 1, vec![0.0f32, 0.0, 0.0, 0.0]).unwrap();
        let est = Gray::from_vec(4, 1, vec![1u8, 1, 0, 0]).unwrap();
        let truth = Gray::from_vec(4, 1, vec![255u8, 0, 255, 0]).unwrap();
        let p = mask_error_picture(&s0, &est, &truth);
        assert_eq!(p.size(), (8, 1));
        let half = |c: [u8; 3]| c.map(|v| (0.5 * f32::from(v)) as u8);
        let [found, false_on, missed] = MASK_ERROR_COLOURS.map(half);
        assert_eq!(&p.pixels()[4..], &[found, false_on, missed, [0, 0, 0]]);
        assert_eq!(&p.pixels()[..4], &[[0, 0, 0]; 4]);
    }

    #[test]
    fn normals_map_to_colours_and_missing_ones_to_black() {
        let n = NormalImage::from_vec(2, 1, vec![0.0, 0.0, 1.0, 0.0, 0.0, 0.0]).unwrap();
        let p = normal_picture(&n);
        assert_eq!(p.pixels(), &[[128, 128, 255], [0, 0, 0]]);
    }

    /// Four panels; the error panel is black where there is no error and the top of the
    /// scale where the error reaches it.
    #[test]
    fn normal_error_picture_has_four_panels() {
        let n = NormalImage::from_vec(2, 1, vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0]).unwrap();
        let s0 = Gray::from_vec(2, 1, vec![1.0f32, 0.0]).unwrap();
        let err = Gray::from_vec(2, 1, vec![f32::NAN, ERROR_SCALE_DEG]).unwrap();
        let p = normal_error_picture(&s0, &n, &n, &err);
        assert_eq!(p.size(), (8, 1));
        assert_eq!(p.pixels()[0], [255; 3]);
        assert_eq!(p.pixels()[2], [128, 128, 255]);
        assert_eq!(p.pixels()[6], [0; 3]);
        assert_eq!(p.pixels()[7], polar_sensor::picture::viridis(1.0));
    }

    #[test]
    fn side_by_side_is_as_wide_as_its_parts() {
        let a = Gray::from_vec(3, 2, vec![0.0f32, 1.0, 2.0, 3.0, 4.0, 5.0]).unwrap();
        let p = side_by_side(&[&a, &a], Some(&a));
        assert_eq!(p.size(), (9, 2));
        assert_eq!(p.pixel(1, 1), p.pixel(4, 1));
    }
}
