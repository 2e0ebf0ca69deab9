//! The objects' pixels, found without ground truth or scene knowledge.
//!
//! Objects are regions enclosed by strong edges of brightness or polarization that do
//! not reach the image border, where the background (floor, walls, sky) does:
//! 1. edge strength `g = √(|∇ ln s|² + k² (|∇ s₁/s₀|² + |∇ s₂/s₀|²))` (Sobel, on the
//!    normalised brightness `s` and the normalised Stokes vector; `k = 4` weighs a DoLP
//!    step of 0.25 like a brightness ratio of e), invariant to the global scale;
//! 2. edges are `g` above half of Otsu's threshold of `g` (Otsu alone follows the
//!    strongest edges, e.g. cast shadows, and leaves gaps in a silhouette against a floor
//!    of similar brightness), and above a floor so a flat frame has none; the edge map is
//!    dilated by a 3×3 square to close one-pixel gaps;
//! 3. the edge-free 4-connected regions touching the border are background; the rest
//!    (enclosed regions, the edges around them, invalid pixels such as saturated
//!    highlights inside an object) is the foreground, eroded by 3×3 (undoing the
//!    dilation) and opened by 3×3 to drop thin edge lines. Invalid pixels are never
//!    foreground themselves.
//!
//! If nothing is enclosed (a surface filling the view, a tiny image), every valid pixel
//! is foreground: the frame shows one surface and no occluding contour. This holds on
//! real frames of objects in front of a background that reaches the border; it fails
//! for an object cut by the border on all sides or a background split off by shadows.

use polar_image::Gray;
use polar_imgproc::mask::fill_holes;
use polar_imgproc::{MorphShape, dilate, erode, gaussian_blur, open, sobel, threshold_otsu};

use crate::ShapeError;
use crate::cues::Cues;

/// Weight of a polarization step against a log-brightness step.
const POLARIZATION_WEIGHT: f32 = 4.0;
/// Gaussian pre-smoothing (pixels) of the edge features, against sensor noise.
const EDGE_SIGMA: f64 = 1.0;
/// Lowest edge strength counted as an edge (a log-brightness change of 0.1 per pixel).
const MIN_EDGE: f32 = 0.1;
/// Fraction of Otsu's threshold used.
const OTSU_FRACTION: f32 = 0.3;
/// Brightness floor (normalised) inside the logarithm, so dark noise is not an edge.
const DARK_FLOOR: f32 = 0.02;

/// Foreground mask (`true` on objects) of the cues.
pub fn foreground(cues: &Cues) -> Result<Vec<bool>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let any_valid = cues.valid.iter().any(|&v| v);
    if !any_valid {
        return Ok(vec![false; w * h]);
    }
    if w < 3 || h < 3 {
        return Ok(cues.valid.clone());
    }
    let g = edge_strength(cues)?;
    let t = (OTSU_FRACTION * threshold_otsu(&g)?).max(MIN_EDGE);
    let edges: Vec<bool> = g
        .as_slice()
        .iter()
        .zip(&cues.valid)
        .map(|(&v, &ok)| !ok || v > t)
        .collect();
    let edges = morph_mask(&edges, w, h, Morph::Dilate)?;
    let background = border_regions(&edges, w, h)?;
    let raw: Vec<bool> = background.iter().map(|&b| !b).collect();
    let raw = morph_mask(&raw, w, h, Morph::Erode)?;
    let cleaned: Vec<bool> = morph_mask(&raw, w, h, Morph::Open)?
        .into_iter()
        .zip(&cues.valid)
        .map(|(f, &ok)| f && ok)
        .collect();
    if cleaned.iter().any(|&v| v) {
        Ok(cleaned)
    } else {
        Ok(cues.valid.clone())
    }
}

/// The edge strength `g` of the module doc.
pub fn edge_strength(cues: &Cues) -> Result<Gray<f32>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let plane = |f: &dyn Fn(usize) -> f32| -> Gray<f32> {
        Gray::from_vec(w, h, (0..w * h).map(f).collect()).expect("sized")
    };
    let log_s = plane(&|k| (cues.s0n[k].max(0.0) + DARK_FLOOR).ln());
    let (c, s) = (
        plane(&|k| cues.dolp[k] * (2.0 * cues.aolp[k]).cos()),
        plane(&|k| cues.dolp[k] * (2.0 * cues.aolp[k]).sin()),
    );
    let mut g = vec![0.0f32; w * h];
    for (src, weight) in [
        (&log_s, 1.0f32),
        (&c, POLARIZATION_WEIGHT),
        (&s, POLARIZATION_WEIGHT),
    ] {
        let mut smooth = Gray::new(w, h);
        gaussian_blur(src, &mut smooth, 0, EDGE_SIGMA)?;
        for (dx, dy) in [(1, 0), (0, 1)] {
            let mut d = Gray::new(w, h);
            sobel(&smooth, &mut d, dx, dy, 3)?;
            // A unit ramp gives a 3x3 Sobel response of 8.
            for (acc, v) in g.iter_mut().zip(d.as_slice()) {
                let v = v / 8.0 * weight;
                *acc += v * v;
            }
        }
    }
    Ok(Gray::from_vec(w, h, g.into_iter().map(f32::sqrt).collect()).expect("sized"))
}

/// Pixels of the edge-free 4-connected regions that touch the image border: the
/// complement of the edge mask with its holes filled.
fn border_regions(edges: &[bool], w: usize, h: usize) -> Result<Vec<bool>, ShapeError> {
    Ok(fill_holes(edges, w, h)?.into_iter().map(|v| !v).collect())
}

/// A 3x3 square morphological operation on a mask.
#[derive(Clone, Copy)]
enum Morph {
    Dilate,
    Erode,
    Open,
}

/// Applies `op` with a 3x3 square to a mask.
fn morph_mask(mask: &[bool], w: usize, h: usize, op: Morph) -> Result<Vec<bool>, ShapeError> {
    let src = Gray::from_vec(w, h, mask.iter().map(|&m| f32::from(u8::from(m))).collect())
        .expect("sized");
    let mut dst = Gray::new(w, h);
    match op {
        Morph::Dilate => dilate(&src, &mut dst, MorphShape::Rect, 3, 3)?,
        Morph::Erode => erode(&src, &mut dst, MorphShape::Rect, 3, 3)?,
        Morph::Open => open(&src, &mut dst, MorphShape::Rect, 3, 3)?,
    }
    Ok(dst.as_slice().iter().map(|&v| v > 0.5).collect())
}
