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

use polar_image::{Gray, NormalImage, par_map};
use polar_imgproc::{Outside, gaussian_blur};
use polar_sensor::Observation;

use crate::features::Features;
use crate::{CHUNK, MaterialError, Regions};
use nalgebra::Vector3;
use rayon::prelude::*;

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
    /// `true` when `zenith` is the silhouette's sphere prior alone rather than measured.
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
    let unknown = (f32::NAN, (f32::NAN, f32::NAN));
    let (zenith, (phase_sin, phase)) = (0..w * h)
        .into_par_iter()
        .with_min_len(CHUNK)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            let [a, b, c] = *normals.pixel(x, y);
            let v = Vector3::new(f64::from(a), f64::from(b), f64::from(c));
            let len = v.norm();
            if !len.is_finite() || len <= 0.5 {
                return unknown;
            }
            let (az, ze) = obs.pixel_frame(x, y).angles(&(v / len));
            (ze as f32, (2.0 * (f.aolp(k) - az as f32)).sin_cos())
        })
        .collect();
    Ok(Cues {
        phase,
        phase_sin,
        zenith,
        prior: false,
    })
}

impl Cues {
    /// Raises each measured zenith to the silhouette's sphere prior where that is larger
    /// (and takes the prior where no normal is known). The shape task inverts a
    /// dielectric's polarization model, so on a metal its zeniths come out far too small
    /// (a metal's weak polarization reads as near-normal incidence), and a zenith too
    /// small lowers the metal envelope under the metal's own DoLP. The prior errs the
    /// other way (a face turned to the camera is read as turned away), which only makes
    /// the Fresnel cue more cautious; it also lets the phase cue count the pixels it
    /// puts near the occluding contour.
    /// `distance`: [`silhouette_distance`] of the object mask the `regions` label.
    pub fn with_prior_floor(mut self, regions: &Regions, distance: &[f32]) -> Self {
        let prior = sphere_prior_zenith(regions, distance);
        for (z, &p) in self.zenith.iter_mut().zip(&prior) {
            if p.is_finite() && (z.is_nan() || *z < p) {
                *z = p;
            }
        }
        self
    }
}

/// Half-width of the silhouette band, pixels.
pub const BAND: usize = 3;

/// Cues from the silhouette of the object mask `fg`: phase in a band of [`BAND`] pixels
/// inside the boundary; zenith from a sphere prior: a pixel at distance `d` from the
/// silhouette of a region whose largest such distance is `R` sees `sin θ = 1 − d/R`
/// (exact for a sphere, a rough guess for other convex shapes). `distance`:
/// [`silhouette_distance`] of `fg`.
pub fn from_silhouette(
    f: &Features,
    fg: &[bool],
    regions: &Regions,
    distance: &[f32],
) -> Result<Cues, MaterialError> {
    let (w, h) = (f.width, f.height);
    let m =
        Gray::from_vec(w, h, par_map(w * h, |k| f32::from(u8::from(fg[k])))).expect("mask size");
    let mut blur = Gray::new(w, h);
    let ks = 2 * BAND + 1;
    gaussian_blur(&m, &mut blur, ks, BAND as f64 * 0.6)?;
    let b = blur.as_slice();
    let unknown = (f32::NAN, f32::NAN);
    let (phase_sin, phase) = (0..w * h)
        .into_par_iter()
        .with_min_len(CHUNK)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            // Inside the object, off the image border and within the blur's reach of its edge.
            if x == 0 || y == 0 || x + 1 >= w || y + 1 >= h || !fg[k] || b[k] > 0.98 {
                return unknown;
            }
            let gx = b[k + 1] - b[k - 1];
            let gy = b[k + w] - b[k - w];
            if gx.hypot(gy) < 1e-3 {
                return unknown;
            }
            // Outward = −∇; image y runs down, the Stokes frame's y_ref up.
            let beta = gy.atan2(-gx);
            (2.0 * (f.aolp(k) - beta)).sin_cos()
        })
        .unzip();
    let zenith = sphere_prior_zenith(regions, distance);
    Ok(Cues {
        phase,
        phase_sin,
        zenith,
        prior: true,
    })
}

/// Zenith of the sphere prior (NaN outside the mask), from each pixel's distance
/// to the nearest pixel outside the mask (or the image) and its maximum per region.
fn sphere_prior_zenith(regions: &Regions, d: &[f32]) -> Vec<f32> {
    let lab = &regions.labels;
    let mut rmax = vec![0.0f32; regions.count + 1];
    for (k, &l) in lab.iter().enumerate() {
        rmax[l as usize] = rmax[l as usize].max(d[k]);
    }
    par_map(d.len(), |k| {
        let r = rmax[lab[k] as usize];
        if d[k] <= 0.0 || r <= 0.0 {
            return f32::NAN;
        }
        // The outermost pixel centre lies half a pixel inside the silhouette.
        let s = (1.0 - (d[k] - 0.5).max(0.0) / r).clamp(0.0, 1.0);
        s.asin()
    })
}

/// Euclidean distance in pixels from each `fg` pixel to the nearest non-`fg` pixel, the
/// image outside counting as non-`fg` ([`polar_imgproc::distance_to_background`]).
pub fn silhouette_distance(fg: &[bool], w: usize, h: usize) -> Vec<f32> {
    polar_imgproc::distance_to_background(fg, w, h, Outside::Background)
        .iter()
        .map(|&d| d as f32)
        .collect()
}
