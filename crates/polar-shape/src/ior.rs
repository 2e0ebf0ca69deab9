//! The refractive index from the image: the diffuse DoLP profile at occluding contours.
//!
//! Diffuse DoLP `ρ_d(θ, n)` rises with the zenith to `(n² − 1)/(n² + 1)` at grazing
//! (Atkinson & Hancock 2006), where the surface turns away at an occluding contour, so
//! the DoLP just inside a silhouette tells `n`. No pixel centre sits exactly at grazing:
//! near a smooth occluding contour the surface is locally parabolic across it, so at a
//! distance `d` inside the silhouette `cos θ ≈ √(2d/R)` with `R` the (unknown) radius of
//! curvature of the normal section. The DoLP profile over the first [`BAND`] pixels is
//! fitted with `ρ_d(acos √(2d/R), n)` over a grid of `(n, R)`; `n` comes out whatever `R`.
//!
//! Pixels used: valid foreground pixels within [`BAND`] pixels of the background, no
//! highlight, whose AoLP is within [`ALIGNMENT_DEG`] of the contour's outward normal
//! (the diffuse signature; the specular one is perpendicular). Their DoLP is corrected
//! for the upward noise bias, `√max(ρ² − σ², 0)` with `σ` the cues' DoLP noise
//! ([`crate::cues`]); per distance the upper quartile is kept, since specular and
//! unpolarized light only dilute the diffuse polarization. The estimated foreground can
//! reach up to [`MAX_OVERSHOOT`] pixels past the silhouette (dilated edges, demosaicing
//! blur), so the profile starts at its peak among the first distances, and the
//! silhouette is taken half a pixel outside that distance. Every object in the frame
//! joins one profile: one index per frame.
//!
//! Too little evidence (fewer than [`MIN_BINS`] distances with [`MIN_BIN_PIXELS`] pixels
//! each, or a DoLP that does not fall inward from the contour) gives no estimate; the
//! result is clamped to [`IOR_RANGE`], the indices of common dielectrics.

use polar_image::quantile;

use crate::ShapeError;
use crate::cues::{Cues, DOLP_NOISE_AT_SCALE, HIGHLIGHT};
use crate::local::outward_directions;
use polar_imgproc::{Outside, distance_to_background};
use polar_optics::reflection_dolp::diffuse_dolp;

/// Width (pixels) of the band inside the silhouette whose DoLP profile is fitted.
pub const BAND: usize = 6;
/// Whole pixels by which the foreground may extend past the silhouette.
pub const MAX_OVERSHOOT: usize = 2;
/// Largest angle (degrees) between AoLP and the contour normal of a diffuse-like pixel.
pub const ALIGNMENT_DEG: f64 = 20.0;
/// Distances (whole pixels) that must hold evidence.
pub const MIN_BINS: usize = 3;
/// Pixels a distance needs to count.
pub const MIN_BIN_PIXELS: usize = 10;
/// Plausible indices of dielectrics (water 1.33 to dense glass 1.8); estimates are clamped.
pub const IOR_RANGE: (f64, f64) = (1.3, 1.8);
/// Quantile of the corrected DoLP kept per distance.
const UPPER: f64 = 0.5;

/// An index estimated from the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IorEstimate {
    /// The index, clamped to [`IOR_RANGE`].
    pub ior: f64,
    /// The fitted index before clamping.
    pub unclamped: f64,
    /// Contour pixels used.
    pub pixels: usize,
}

/// The index from the contour DoLP profile of the foreground `fg` (module doc); `Err`
/// with the reason where the image gives too little evidence.
pub fn estimate_ior(cues: &Cues, fg: &[bool]) -> Result<Result<IorEstimate, String>, ShapeError> {
    let profile = contour_profile(cues, fg)?;
    let bins: Vec<&Bin> = profile
        .iter()
        .filter(|b| b.dolp.len() >= MIN_BIN_PIXELS)
        .collect();
    let pixels: usize = bins.iter().map(|b| b.dolp.len()).sum();
    if bins.len() < MIN_BINS {
        return Ok(Err(format!(
            "{} distances from a contour with {MIN_BIN_PIXELS}+ diffuse-like pixels, {MIN_BINS} needed",
            bins.len()
        )));
    }
    let points: Vec<(f64, f64, f64)> = bins
        .iter()
        .map(|b| {
            let y = quantile(b.dolp.iter().copied(), UPPER).map_or(0.0, f64::from);
            (b.distance / b.dolp.len() as f64, y, b.dolp.len() as f64)
        })
        .collect();
    // The foreground may overshoot the silhouette (dilated edges, demosaicing blur): the
    // profile starts at its peak among the first distances.
    let peak = (0..points.len().min(MAX_OVERSHOOT + 1))
        .max_by(|&a, &b| points[a].1.total_cmp(&points[b].1))
        .unwrap_or(0);
    let offset = points[peak].0;
    let points: Vec<(f64, f64, f64)> = points[peak..]
        .iter()
        .map(|&(d, y, wt)| (d - offset + 0.5, y, wt))
        .collect();
    let (first, last) = (points[0].1, points[points.len() - 1].1);
    if points.len() < MIN_BINS || first <= last {
        return Ok(Err(format!(
            "no DoLP falling inward from the contours ({first:.3} at the edge, {last:.3} inside)"
        )));
    }
    let unclamped = fit(&points);
    Ok(Ok(IorEstimate {
        ior: unclamped.clamp(IOR_RANGE.0, IOR_RANGE.1),
        unclamped,
        pixels,
    }))
}

/// The corrected DoLPs of the diffuse-like pixels at one whole-pixel distance.
#[derive(Default)]
struct Bin {
    /// Sum of the pixels' distances to the silhouette.
    distance: f64,
    dolp: Vec<f32>,
}

/// Diffuse-like contour pixels binned by distance `1..=BAND` (module doc).
fn contour_profile(cues: &Cues, fg: &[bool]) -> Result<Vec<Bin>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let dist = distance_to_background(fg, w, h, Outside::NotBackground);
    let mut bins: Vec<Bin> = (0..BAND).map(|_| Bin::default()).collect();
    if dist.iter().all(|d| !d.is_finite()) {
        return Ok(bins);
    }
    let outward = outward_directions(&dist, w, h)?;
    let cos_tol = (2.0 * ALIGNMENT_DEG.to_radians()).cos();
    for k in 0..w * h {
        let slot = dist[k].round() as usize;
        if !fg[k] || !cues.valid[k] || slot == 0 || slot > BAND {
            continue;
        }
        let s = f64::from(cues.s0n[k]);
        let (dx, dy) = outward[k];
        if s >= HIGHLIGHT || dx.hypot(dy) < 1e-6 {
            continue;
        }
        let normal = crate::cues::image_direction_angle(&cues.frame(k), dx, dy);
        if (2.0 * (f64::from(cues.aolp[k]) - normal)).cos() < cos_tol {
            continue;
        }
        let rho = f64::from(cues.dolp[k]);
        let sigma2 = DOLP_NOISE_AT_SCALE * DOLP_NOISE_AT_SCALE / s.max(1e-6);
        let b = &mut bins[slot - 1];
        b.distance += dist[k] - 0.5;
        b.dolp.push((rho * rho - sigma2).max(0.0).sqrt() as f32);
    }
    Ok(bins)
}

/// Indices searched, and curvature radii (pixels, log-spaced) of the contour model.
const N_GRID: (f64, f64, usize) = (1.05, 2.5, 291);
const R_GRID: (f64, f64, usize) = (1.0, 2000.0, 120);

/// The `n` of the least-squares fit of `ρ_d(acos √(2d/R), n)` to the points
/// `(distance, DoLP, weight)` over the `(n, R)` grid.
fn fit(points: &[(f64, f64, f64)]) -> f64 {
    let mut best = (f64::INFINITY, N_GRID.0);
    for i in 0..N_GRID.2 {
        let n = N_GRID.0 + (N_GRID.1 - N_GRID.0) * i as f64 / (N_GRID.2 - 1) as f64;
        for j in 0..R_GRID.2 {
            let r = R_GRID.0 * (R_GRID.1 / R_GRID.0).powf(j as f64 / (R_GRID.2 - 1) as f64);
            let sse: f64 = points
                .iter()
                .map(|&(d, y, wt)| {
                    let zenith = (2.0 * d / r).sqrt().min(1.0).acos();
                    wt * (diffuse_dolp(zenith, n) - y).powi(2)
                })
                .sum();
            if sse < best.0 {
                best = (sse, n);
            }
        }
    }
    best.1
}
