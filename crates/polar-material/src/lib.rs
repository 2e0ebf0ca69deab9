//! Material classification from polarization: background, opaque dielectric, metal.
//!
//! [`classify`] labels every pixel `0` background, `1` opaque dielectric, `2` metal (`3`
//! transparent where a transparency mask is given). The physics rule needs no training:
//! a metal reflects unpolarized light only weakly polarized and always across the plane
//! of incidence (Wolff 1990), whereas a dielectric either polarizes specular reflection
//! strongly (above any metal's Fresnel curve) or sends diffuse light polarized along the
//! surface azimuth; see [`rule`]. Inputs are an [`Observation`] (scale-free: S0 is divided
//! by its `s0_scale`), optional camera-frame normals, an optional object mask (else
//! [`foreground::estimate`]) and an optional transparency mask.

pub mod cues;
pub mod features;
pub mod foreground;
pub mod fresnel_cues;
pub mod knn;
pub mod rule;

use std::sync::Arc;

use polar_image::{Gray, NormalImage};
use polar_io::MaterialLabel;
use polar_sensor::Observation;
use rayon::prelude::*;
use thiserror::Error;

/// Label of background pixels (floors, walls, sky), as in `gt/material.png`.
pub const BACKGROUND: u8 = MaterialLabel::Background.value();
/// Label of opaque dielectric pixels.
pub const DIELECTRIC: u8 = MaterialLabel::Dielectric.value();
/// Label of metal pixels.
pub const METAL: u8 = MaterialLabel::Metal.value();
/// Label of transparent pixels (only where a transparency mask is given).
pub const TRANSPARENT: u8 = MaterialLabel::Transparent.value();

/// Errors of material classification.
#[derive(Debug, Error)]
pub enum MaterialError {
    /// The observation has no pixels.
    #[error("empty observation ({0}x{1})")]
    Empty(usize, usize),
    /// An optional input does not have the observation's size.
    #[error("{what} is {got:?}, the observation {expected:?}")]
    SizeMismatch {
        /// Which input.
        what: &'static str,
        /// The observation's `(width, height)`.
        expected: (usize, usize),
        /// The input's `(width, height)`.
        got: (usize, usize),
    },
    /// An image-processing primitive failed.
    #[error(transparent)]
    Imgproc(#[from] polar_imgproc::Error),
}

/// What every classifier starts from: the features, the object pixels, their regions
/// and the cues.
#[derive(Clone, Debug)]
pub struct Prepared {
    /// Per-pixel polarization features.
    pub features: features::Features,
    /// `true` on object pixels.
    pub fg: Vec<bool>,
    /// The 8-connected regions of `fg`.
    pub regions: Regions,
    /// Euclidean distance of each pixel to the nearest pixel outside `fg` or the image (0
    /// outside `fg`, [`cues::silhouette_distance`]): the sphere prior's and the neck
    /// splitting's one distance map.
    pub distance: Vec<f32>,
    /// Phase and zenith cues, from the normals where given, else from the silhouettes.
    pub cues: cues::Cues,
}

/// The 8-connected regions of an object mask, labelled once and shared by the cues and
/// the classifiers' region votes.
#[derive(Clone, Debug, PartialEq)]
pub struct Regions {
    /// Per-pixel region id in `1..=count`, 0 outside the mask.
    pub labels: Vec<u32>,
    /// Number of regions.
    pub count: usize,
}

impl Regions {
    /// The regions of the `w x h` mask `fg`.
    pub fn new(fg: &[bool], w: usize, h: usize) -> Result<Self, MaterialError> {
        let (labels, count) = polar_imgproc::mask::components(fg, w, h)?;
        Ok(Self { labels, count })
    }
}

/// Which classifier decides dielectric versus metal.
#[derive(Clone, Debug)]
pub enum Classifier {
    /// The training-free Fresnel / AoLP-phase rule of [`rule`].
    Physics,
    /// k nearest neighbours over [`knn::FEATURES`] from a trained model file, computed
    /// from the same cues as the rule's.
    Knn(Arc<knn::KnnClassifier>),
}

/// Options of [`classify`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialOptions {
    /// Give every connected object region the label its pixels' evidence favours
    /// (a region is one material far more often than not); off = per-pixel labels.
    pub smooth_regions: bool,
}

impl Default for MaterialOptions {
    fn default() -> Self {
        Self {
            smooth_regions: true,
        }
    }
}

/// The result of [`classify`].
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialMap {
    /// Per-pixel label: [`BACKGROUND`], [`DIELECTRIC`], [`METAL`] or [`TRANSPARENT`].
    pub labels: Gray<u8>,
    /// Confidence of the label in `[0, 1]` (0.5 = a coin toss between dielectric and metal).
    pub confidence: Gray<f32>,
}

/// Labels the pixels of `obs`.
///
/// `normals`: camera-frame unit normals (e.g. from shape from polarization; `(0,0,0)` =
/// unknown) give the zenith and azimuth at every pixel; without them the azimuth is taken
/// from the object silhouettes (a kNN model's features differ with the cues, so it holds
/// only for the kind it is trained with; `polar-vision train` uses shape from
/// polarization's). `foreground`: non-zero on object
/// pixels; without it [`foreground::estimate`] decides. `transparent`: non-zero on
/// transparent pixels, which are labelled [`TRANSPARENT`] over the opaque classification
/// except on objects it calls metal: glass is a dielectric, and the transparency cues also
/// mark mirror-like metals, whose reflections polarize coherently. Transparent pixels stay
/// in the object regions it classifies: the edge of a transparency mask is no
/// occluding contour, and cutting an opaque object along a mistaken one would give its
/// remaining pixels a false silhouette and a smaller region vote.
pub fn classify(
    obs: &Observation,
    normals: Option<&NormalImage>,
    foreground: Option<&Gray<u8>>,
    transparent: Option<&Gray<u8>>,
    clf: &Classifier,
    opts: &MaterialOptions,
) -> Result<MaterialMap, MaterialError> {
    check_size("transparent", obs.size(), transparent.map(|m| m.size()))?;
    let p = prepare(obs, normals, foreground)?;
    let smooth = opts.smooth_regions;
    let metal = match clf {
        Classifier::Physics => rule::metal_probability(&p, smooth)?,
        Classifier::Knn(m) => knn::metal_probability(m, &p, smooth)?,
    };
    let (w, h) = obs.size();
    let clear = |m: Option<&Gray<u8>>, k: usize| m.is_some_and(|m| m.as_slice()[k] != 0);
    let label = |k: usize| {
        let metal_object = p.fg[k] && metal[k] > 0.5;
        if clear(transparent, k) && !metal_object {
            (TRANSPARENT, 1.0)
        } else if !p.fg[k] {
            (BACKGROUND, 1.0)
        } else if metal[k] > 0.5 {
            (METAL, metal[k])
        } else {
            (DIELECTRIC, 1.0 - metal[k])
        }
    };
    let (labels, conf) = (0..w * h)
        .into_par_iter()
        .with_min_len(CHUNK)
        .map(label)
        .unzip();
    Ok(MaterialMap {
        labels: Gray::from_vec(w, h, labels).expect("size of the observation"),
        confidence: Gray::from_vec(w, h, conf).expect("size of the observation"),
    })
}

/// Features, object pixels (`foreground`, else [`foreground::estimate`]), their regions
/// and cues (from `normals`, with zeniths no smaller than the silhouettes' sphere prior,
/// else from the silhouettes alone) of `obs`.
pub fn prepare(
    obs: &Observation,
    normals: Option<&NormalImage>,
    foreground: Option<&Gray<u8>>,
) -> Result<Prepared, MaterialError> {
    let size = obs.size();
    check_size("foreground", size, foreground.map(|m| m.size()))?;
    let features = features::Features::new(obs)?;
    let fg = match foreground {
        Some(m) => m.as_slice().iter().map(|&v| v != 0).collect(),
        None => foreground::estimate(&features)?,
    };
    let regions = Regions::new(&fg, size.0, size.1)?;
    let distance = cues::silhouette_distance(&fg, size.0, size.1);
    let cues = match normals {
        Some(n) => cues::from_normals(obs, &features, n)?.with_prior_floor(&regions, &distance),
        None => cues::from_silhouette(&features, &fg, &regions, &distance)?,
    };
    Ok(Prepared {
        features,
        fg,
        regions,
        distance,
        cues,
    })
}

/// Pixels per rayon task in the element-wise passes (large enough to amortise a task).
pub(crate) const CHUNK: usize = polar_image::PAR_BLOCK;

fn check_size(
    what: &'static str,
    expected: (usize, usize),
    got: Option<(usize, usize)>,
) -> Result<(), MaterialError> {
    match got {
        Some(g) if g != expected => Err(MaterialError::SizeMismatch {
            what,
            expected,
            got: g,
        }),
        _ => Ok(()),
    }
}
