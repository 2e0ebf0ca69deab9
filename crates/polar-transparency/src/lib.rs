//! Transparent-object detection from polarization, without training.
//!
//! Glass polarizes every ray it returns: light reflected off its surfaces is polarized
//! across the plane of incidence (strongly near Brewster's angle), light transmitted
//! through two interfaces is polarized along it (Fresnel transmission, `T_p > T_s`),
//! whereas floors, walls and textured backdrops are diffuse and send depolarized light.
//! A transparent object is therefore a region of *coherent* polarization over a
//! background of none. [`detect`] scores each pixel by cue maps ([`cues`]): the DoLP of
//! the locally averaged Stokes vector, its coherence (that DoLP over the mean per-pixel
//! DoLP: sensor noise and demosaicing artefacts at texture edges have random AoLP and
//! average out) and the polarization-difference contrast; it then thresholds the score
//! (Otsu, or a given threshold), closes and opens the mask, fills holes (background
//! components not touching the border) and drops specks, all with polar-imgproc.
//!
//! Opaque shiny objects polarize too: a dark glossy dielectric as strongly as glass.
//! The cue that separates them is transmission: see [`cues`] for what is measured.

pub mod cues;

use polar_image::Gray;
use polar_imgproc::threshold_otsu;
use polar_sensor::Observation;
use thiserror::Error;

/// Mask value on transparent pixels, as in `gt/transparent.png`.
pub const ON: u8 = 255;

/// Errors of transparency detection.
#[derive(Debug, Error)]
pub enum TransparencyError {
    /// The observation has no pixels.
    #[error("empty observation ({0}x{1})")]
    Empty(usize, usize),
    /// The threshold is not a finite number in `[0, 1]`.
    #[error("threshold {0} is not in [0, 1]")]
    Threshold(f32),
    /// An image-processing primitive failed.
    #[error(transparent)]
    Imgproc(#[from] polar_imgproc::Error),
}

/// Options of [`detect`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TransparencyOptions {
    /// Score threshold in `[0, 1]`; `None` = Otsu's threshold of the score map, floored at
    /// [`MIN_THRESHOLD`] so that a scene without glass is not split in two anyway.
    pub threshold: Option<f32>,
}

/// The Otsu threshold never goes below this score: a DoLP of a few percent coherent
/// over a window is what depolarizing surfaces reach at most (see [`cues::score`]).
pub const MIN_THRESHOLD: f32 = 0.3;

/// The result of [`detect`].
#[derive(Clone, Debug, PartialEq)]
pub struct TransparencyMap {
    /// [`ON`] on transparent pixels, 0 elsewhere.
    pub mask: Gray<u8>,
    /// Per-pixel score in `[0, 1]` (higher = more likely transparent).
    pub score: Gray<f32>,
}

/// Detects transparent objects in `obs`.
pub fn detect(
    obs: &Observation,
    opts: &TransparencyOptions,
) -> Result<TransparencyMap, TransparencyError> {
    let (w, h) = obs.size();
    if w == 0 || h == 0 {
        return Err(TransparencyError::Empty(w, h));
    }
    if let Some(t) = opts.threshold
        && !(0.0..=1.0).contains(&t)
    {
        return Err(TransparencyError::Threshold(t));
    }
    let score = cues::score(obs)?;
    let t = match opts.threshold {
        Some(t) => t,
        None => threshold_otsu(&score)?.max(MIN_THRESHOLD),
    };
    let seed: Vec<bool> = score.as_slice().iter().map(|&s| s > t).collect();
    let m = polar_imgproc::mask::clean(&seed, w, h)?;
    let mask = Gray::from_vec(w, h, m.iter().map(|&b| if b { ON } else { 0 }).collect())
        .expect("size of the observation");
    Ok(TransparencyMap { mask, score })
}
