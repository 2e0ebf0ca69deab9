//! Per-pixel physical cues: the windowed DoLP, the zenith angle where normals are given,
//! and the AoLP phase against the surface azimuth.
//!
//! The phase is `cos 2(AoLP − azimuth)`: `+1` where light is polarized along the
//! projected normal (diffuse light refracted out of a dielectric), `−1` where it is
//! polarized across it (specular reflection, the only kind a metal gives). Without
//! normals the azimuth is known at the occluding contour of each object: there the
//! normal is perpendicular to the line of sight and points out of the silhouette, so the
//! phase is measured in a band along the mask boundary, against the outward direction
//! of the blurred mask's gradient.

use polar_image::{Gray, NormalImage};
use polar_imgproc::gaussian_blur;
use polar_sensor::Observation;

use crate::MaterialError;
use crate::features::Features;
use nalgebra::Vector3;

/// Per-pixel cues (NaN where unknown).
#[derive(Clone, Debug)]
pub struct Cues {
    /// `cos 2(AoLP − azimuth)` in `[-1, 1]`; NaN where the azimuth is unknown.
    pub phase: Vec<f32>,
    /// `sin 2(AoLP − azimuth)`, NaN where the azimuth is unknown: with `phase`, the full
    /// angle (its sign tells a rotation of the AoLP away from the azimuth's axes).
    pub phase_sin: Vec<f32>,
    /// Zenith angle of the normal from the view direction (radians); NaN where unknown.
    pub zenith: Vec<f32>,
    /// `true` when `zenith` is the silhouette's sphere prior rather than measured.
    pub prior: bool,
}

/// Cues from a camera-frame normal map (`(0, 0, 0)` or non-finite = no surface).
pub fn from_normals(
    obs: &Observation,
    f: &Features,
    normals: &NormalImage,
) -> Result<Cues, MaterialError> {
    let (w, h) = (f.width, f.height);
    if normals.size() != (w, h) {
        return Err(MaterialError::SizeMismatch {
            what: "normals",
            expected: (w, h),
            got: normals.size(),
        });
    }
    let n = w * h;
    let mut phase = vec![f32::NAN; n];
    let mut phase_sin = vec![f32::NAN; n];
    let mut zenith = vec![f32::NAN; n];
    for y in 0..h {
        for x in 0..w {
            let k = y * w + x;
            let [a, b, c] = *normals.pixel(x, y);
            let v = Vector3::new(f64::from(a), f64::from(b), f64::from(c));
            let len = v.norm();
            if !len.is_finite() || len <= 0.5 {
                continue;
            }
            let (az, ze) = obs.pixel_frame(x, y).angles(&(v / len));
            zenith[k] = ze as f32;
            (phase_sin[k], phase[k]) = (2.0 * (f.aolp[k] - az as f32)).sin_cos();
        }
    }
    Ok(Cues {
        phase,
        phase_sin,
        zenith,
        prior: false,
    })
}

/// Half-width of the silhouette band, pixels.
pub const BAND: usize = 3;

/// Cues from the silhouette of the object mask `fg`: phase in a band of [`BAND`] pixels
/// inside the boundary; zenith from a sphere prior: a pixel at distance `d` from the
/// silhouette of a region whose largest such distance is `R` sees `sin θ = 1 − d/R`
/// (exact for a sphere, a rough guess for other convex shapes).
pub fn from_silhouette(f: &Features, fg: &[bool]) -> Result<Cues, MaterialError> {
    let (w, h) = (f.width, f.height);
    let n = w * h;
    let m = Gray::from_vec(w, h, fg.iter().map(|&b| f32::from(u8::from(b))).collect())
        .expect("mask size");
    let mut blur = Gray::new(w, h);
    let ks = 2 * BAND + 1;
    gaussian_blur(&m, &mut blur, ks, BAND as f64 * 0.6)?;
    let b = blur.as_slice();
    let mut phase = vec![f32::NAN; n];
    let mut phase_sin = vec![f32::NAN; n];
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let k = y * w + x;
            // Inside the object and within the blur's reach of its edge.
            if !fg[k] || b[k] > 0.98 {
                continue;
            }
            let gx = b[k + 1] - b[k - 1];
            let gy = b[k + w] - b[k - w];
            if gx.hypot(gy) < 1e-3 {
                continue;
            }
            // Outward = −∇; image y runs down, the Stokes frame's y_ref up.
            let beta = gy.atan2(-gx);
            (phase_sin[k], phase[k]) = (2.0 * (f.aolp[k] - beta)).sin_cos();
        }
    }
    let zenith = sphere_prior_zenith(fg, w, h)?;
    Ok(Cues {
        phase,
        phase_sin,
        zenith,
        prior: true,
    })
}

/// Zenith of the sphere prior (NaN outside `fg`), from the chamfer distance to the
/// nearest pixel outside `fg` (or outside the image) and its maximum per component.
fn sphere_prior_zenith(fg: &[bool], w: usize, h: usize) -> Result<Vec<f32>, MaterialError> {
    let d = chamfer_distance(fg, w, h);
    let (lab, n) = polar_imgproc::mask::components(fg, w, h)?;
    let mut rmax = vec![0.0f32; n + 1];
    for (k, &l) in lab.iter().enumerate() {
        rmax[l as usize] = rmax[l as usize].max(d[k]);
    }
    Ok((0..w * h)
        .map(|k| {
            let r = rmax[lab[k] as usize];
            if !fg[k] || r <= 0.0 {
                return f32::NAN;
            }
            // The outermost pixel centre lies half a pixel inside the silhouette.
            let s = (1.0 - (d[k] - 0.5).max(0.0) / r).clamp(0.0, 1.0);
            s.asin()
        })
        .collect())
}

/// Two-pass 3-4 chamfer distance (Borgefors 1986) in pixels from each `fg` pixel to the
/// nearest non-`fg` pixel, the image outside counting as non-`fg`.
pub fn chamfer_distance(fg: &[bool], w: usize, h: usize) -> Vec<f32> {
    let big = 1e9f32;
    let mut d: Vec<f32> = fg.iter().map(|&b| if b { big } else { 0.0 }).collect();
    let at = |d: &[f32], x: isize, y: isize| -> f32 {
        if x < 0 || y < 0 || x >= w as isize || y >= h as isize {
            0.0
        } else {
            d[y as usize * w + x as usize]
        }
    };
    for y in 0..h as isize {
        for x in 0..w as isize {
            let k = y as usize * w + x as usize;
            if d[k] == 0.0 {
                continue;
            }
            let v = (at(&d, x - 1, y) + 3.0)
                .min(at(&d, x, y - 1) + 3.0)
                .min(at(&d, x - 1, y - 1) + 4.0)
                .min(at(&d, x + 1, y - 1) + 4.0);
            d[k] = d[k].min(v);
        }
    }
    for y in (0..h as isize).rev() {
        for x in (0..w as isize).rev() {
            let k = y as usize * w + x as usize;
            if d[k] == 0.0 {
                continue;
            }
            let v = (at(&d, x + 1, y) + 3.0)
                .min(at(&d, x, y + 1) + 3.0)
                .min(at(&d, x + 1, y + 1) + 4.0)
                .min(at(&d, x - 1, y + 1) + 4.0);
            d[k] = d[k].min(v);
        }
    }
    d.iter().map(|v| v / 3.0).collect()
}
