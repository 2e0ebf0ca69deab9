//! Transparent-object detection from polarization.
//!
//! Glass polarizes every ray it returns: light reflected off its surfaces is polarized
//! across the plane of incidence (strongly near Brewster's angle), light transmitted
//! through two interfaces is polarized along it (Fresnel transmission, `T_p > T_s`),
//! whereas floors, walls and textured backdrops are diffuse and send depolarized light.
//! A transparent object is therefore a region of *coherent* polarization over a
//! background of none. [`detect`] scores each pixel by cue maps ([`cues`]): the DoLP of
//! the locally averaged Stokes vector, its coherence (that DoLP over the mean per-pixel
//! DoLP: sensor noise and demosaicing artefacts at texture edges have random AoLP and
//! average out); it then thresholds the score ([`cue_threshold`]: Otsu's, bounded by the
//! background's level and by the noise's; or a given threshold), lets the seeds along the
//! frame's edge follow their neighbours inside ([`BORDER`]), closes and opens the mask,
//! fills holes (background components not touching the border), drops specks, replaces
//! each blob (components cut at narrow necks) by its convex hull (arcs of one rim by one
//! hull) and trims
//! the depolarized rim that the window added around it, all with polar-imgproc. The hull is
//! there because glass is polarized mostly along its rims and edges (reflection and
//! transmission both grow toward grazing) and little where it faces the camera, so the
//! seeds are open arcs around the object; glass objects (balls, slabs, cups, bottles) are
//! mostly convex.
//!
//! Opaque shiny objects polarize too: a dark glossy dielectric as strongly as glass. A
//! region much darker than its surroundings is dropped ([`SEE_THROUGH`]: glass lets the
//! background through); brighter ones neither segmenter tells apart reliably
//! (docs/benchmarks.md measures the false positives on them; the kNN adds the
//! polarization-difference contrast, the AoLP spread and intensity edges to the cues,
//! [`knn::FEATURES`]).
//!
//! [`detect`] runs one of two segmenters ([`Segmenter`]): the cue score above, which needs
//! no training, or a k-nearest-neighbour classifier over per-pixel features built on the
//! same cues ([`knn`], trained by `polar-vision train transparent`), whose vote counts only
//! where the cue score passes its own threshold: glass polarizes the light it returns, so
//! the vote decides which coherently polarized regions are glass, not whether there is
//! polarization (left to itself, a model trained on rendered scenes strays on frames
//! unlike them). Both end in the same mask clean-up.

pub mod cues;
pub mod knn;

use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

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
    /// An input does not have the observation's size.
    #[error("{what} is {got:?}, the observation {expected:?}")]
    SizeMismatch {
        /// Which input.
        what: &'static str,
        /// The observation's `(width, height)`.
        expected: (usize, usize),
        /// The input's `(width, height)`.
        got: (usize, usize),
    },
    /// A segmenter name is not known.
    #[error("unknown transparent method {0:?} (known: cues, learned)")]
    UnknownMethod(String),
    /// An image-processing primitive failed.
    #[error(transparent)]
    Imgproc(#[from] polar_imgproc::Error),
}

/// The segmenters by name, as the command line selects them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Method {
    /// The cue score with Otsu's threshold ([`cues`]); needs no training.
    #[default]
    Cues,
    /// The kNN classifier of [`knn`] (needs a model).
    Learned,
}

impl FromStr for Method {
    type Err = TransparencyError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "cues" => Ok(Method::Cues),
            "learned" => Ok(Method::Learned),
            _ => Err(TransparencyError::UnknownMethod(s.into())),
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Method::Cues => "cues",
            Method::Learned => "learned",
        })
    }
}

/// Which segmenter scores the pixels.
#[derive(Clone, Debug)]
pub enum Segmenter {
    /// The training-free cue score of [`cues::score`].
    Cues,
    /// The probability of transparent from a trained kNN model ([`knn::probability`]).
    Knn(Arc<knn::KnnClassifier>),
}

/// Options of [`detect`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TransparencyOptions {
    /// Score threshold in `[0, 1]`; `None` = for the cues, [`cue_threshold`] of the score
    /// map; for the kNN, [`KNN_THRESHOLD`].
    pub threshold: Option<f32>,
}

/// The Otsu threshold never goes below this score: a DoLP of a few percent coherent
/// over a window is what depolarizing surfaces reach at most (see [`cues::score`]).
pub const MIN_THRESHOLD: f32 = 0.3;

/// Nor above this multiple of the frame's median score, the depolarizing background's
/// level (most of a frame is background): where one object polarizes far more than
/// another, Otsu splits the strong one from the rest and loses the weaker glass.
pub const BACKGROUND_MULTIPLE: f32 = 5.0;

/// Sensor noise alone gives a window of unpolarized pixels a chance coherence (see
/// [`cues::score`]), so a noisy frame's background scores above [`MIN_THRESHOLD`] in
/// places. The threshold's coherent DoLP (`e` of [`cues::score`]) is therefore at least
/// this multiple of the background's, read at the frame's median score: the top of a
/// frame of pure noise, not its middle.
pub const NOISE_MULTIPLE: f32 = 2.0;

/// The noise floor is capped at this coherent DoLP: a frame polarized coherently nearly
/// everywhere (a water surface or a pane filling the view) is one transparent surface,
/// not noise.
pub const NOISE_FLOOR_CAP: f32 = 0.075;

/// The cue segmenter's default threshold: Otsu's threshold of the score map, at most
/// [`BACKGROUND_MULTIPLE`] times its median, at least [`MIN_THRESHOLD`] (so that a scene
/// without glass is not split in two anyway) and at least the noise floor
/// ([`NOISE_MULTIPLE`], [`NOISE_FLOOR_CAP`]). On a clean frame the background's level is
/// far below the floors and [`MIN_THRESHOLD`] decides; sensor noise raises that level,
/// Otsu with it, and on very noisy frames the noise floor.
pub fn cue_threshold(score: &Gray<f32>) -> Result<Threshold, TransparencyError> {
    let otsu = threshold_otsu(score)?;
    let background = polar_image::quantile(score.as_slice().iter().copied(), 0.5).unwrap_or(0.0);
    let bounded = otsu
        .min(BACKGROUND_MULTIPLE * background)
        .max(MIN_THRESHOLD);
    let noise =
        cues::score_of((NOISE_MULTIPLE * cues::coherent_dolp(background)).min(NOISE_FLOOR_CAP));
    Ok(Threshold {
        value: bounded.max(noise),
        noise_floor: noise > bounded,
    })
}

/// A cue-score threshold ([`cue_threshold`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Threshold {
    /// Pixels scoring above it pass.
    pub value: f32,
    /// The noise floor set it: the frame's background scores high (a dim or noisy frame),
    /// so weak glass may be lost with the noise.
    pub noise_floor: bool,
}

/// The kNN's default threshold on its vote for transparent. Above the majority vote: the
/// training points are balanced per class, so the vote over-weights transparent pixels
/// against their share of real frames (about one in eight in the training suite).
pub const KNN_THRESHOLD: f32 = 0.7;

/// A component of the cleaned mask must cover this many averaging windows
/// ([`cues::WINDOW`]²): fewer hold too few independent polarization samples to be told
/// from a noise speck, and the convex hull would spread the speck.
pub const MIN_WINDOWS: usize = 4;

/// The result of [`detect`].
#[derive(Clone, Debug, PartialEq)]
pub struct TransparencyMap {
    /// [`ON`] on transparent pixels, 0 elsewhere.
    pub mask: Gray<u8>,
    /// Per-pixel score in `[0, 1]` (higher = more likely transparent).
    pub score: Gray<f32>,
    /// The threshold applied to [`Self::score`].
    pub threshold: f32,
    /// The cue-score threshold every seed passed, where the noise floor of
    /// [`cue_threshold`] set it (for either segmenter).
    pub noise_floor: Option<f32>,
}

/// Detects transparent objects in `obs` with `segmenter`.
pub fn detect(
    obs: &Observation,
    segmenter: &Segmenter,
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
    let mut maps = cues::cue_maps(obs)?;
    let pixel_dolp = std::mem::take(&mut maps.pixel_dolp);
    let cue_score = cues::score(&maps, w, h);
    // Every seed passes the cue score's bar: a given threshold for the cues, else
    // `cue_threshold`; the kNN's vote picks among the coherently polarized pixels.
    let bar = match (segmenter, opts.threshold) {
        (Segmenter::Cues, Some(value)) => Threshold {
            value,
            noise_floor: false,
        },
        _ => cue_threshold(&cue_score)?,
    };
    let (score, threshold, seed) = match segmenter {
        Segmenter::Cues => {
            let seed: Vec<bool> = cue_score
                .as_slice()
                .iter()
                .map(|&s| s > bar.value)
                .collect();
            (cue_score, bar.value, seed)
        }
        Segmenter::Knn(clf) => {
            let t = opts.threshold.unwrap_or(KNN_THRESHOLD);
            let p = knn::probability(clf, obs, maps)?;
            let seed: Vec<bool> = (p.as_slice().iter().zip(cue_score.as_slice()))
                .map(|(&vote, &s)| vote > t && s > bar.value)
                .collect();
            (p, t, seed)
        }
    };
    let seed = border_from_inside(seed, w, h);
    let m = polar_imgproc::mask::clean_keeping_lines(&seed, w, h, LINE_DENSITY)?;
    let m = polar_imgproc::mask::remove_small(&m, w, h, MIN_WINDOWS * cues::WINDOW.pow(2))?;
    let m = lit_hulls(obs, m)?;
    let m = without_depolarized_rim(&m, &pixel_dolp, w, h)?;
    let mask = Gray::from_vec(w, h, m.iter().map(|&b| if b { ON } else { 0 }).collect())
        .expect("size of the observation");
    Ok(TransparencyMap {
        mask,
        score,
        threshold,
        noise_floor: bar.noise_floor.then_some(bar.value),
    })
}

/// The least share of a thin part of the closed seed (a line the cleaning's opening would
/// drop) that seed pixels must cover for it to stay with the region it leads from
/// ([`polar_imgproc::mask::close_open_keeping_lines`]): a glass edge seen at grazing
/// incidence is polarized along its length and its seed is a dashed line; a chain the
/// closing draws through a floor's noise specks is mostly gaps.
pub const LINE_DENSITY: f32 = 0.7;

/// Seeds this close to the frame's edge (pixels) are not judged by their own cues but
/// take the nearest judged pixel's verdict: there the median and the averaging window
/// ([`cues::MEDIAN`], [`cues::WINDOW`]), with the demosaicing's interpolation one pixel
/// further, reach past the edge and see its mirror image, so the demosaicing's false
/// polarization along an intensity edge near the border (the polarizers of a super-pixel
/// sample either side of it) is repeated instead of cancelled by the edge's other side,
/// and reads as coherent.
pub const BORDER: usize = cues::MEDIAN / 2 + cues::WINDOW / 2 + 1;

/// `seed` with each pixel within [`BORDER`] of the frame's edge set as the nearest pixel
/// beyond that band: an object (or a surface filling the view) reaching the band reaches
/// the edge, a border's false polarization is dropped.
fn border_from_inside(seed: Vec<bool>, w: usize, h: usize) -> Vec<bool> {
    if w <= 2 * BORDER || h <= 2 * BORDER {
        return seed;
    }
    let inner = |k: usize| {
        let (x, y) = (k % w, k / w);
        x.clamp(BORDER, w - 1 - BORDER) + y.clamp(BORDER, h - 1 - BORDER) * w
    };
    (0..w * h).map(|k| seed[inner(k)]).collect()
}

/// The convex hulls of the blobs ([`polar_imgproc::mask::blobs_apart`]: glass and an opaque
/// object side by side, their masks touching through a glint or a polarized strip of floor,
/// take one each) of `mask`'s components that are not darker than their surroundings
/// ([`without_dark_regions`], judged on each component's own hull: joined first, a dark
/// glossy object would share a hull with the lit specks around it), blobs close enough
/// sharing one ([`polar_imgproc::mask::ArcJoin::rim_arcs`]): a glass ball's or ring's rim
/// is polarized in arcs, cut where reflection (polarized across the plane of incidence) and
/// transmission (along it) cancel and where neither is strong.
fn lit_hulls(obs: &Observation, mask: Vec<bool>) -> Result<Vec<bool>, TransparencyError> {
    let (w, h) = obs.size();
    let lit = without_dark_regions(obs, polar_imgproc::mask::convex_hull_objects(&mask, w, h)?)?;
    let seeds: Vec<bool> = mask.iter().zip(&lit).map(|(&s, &l)| s && l).collect();
    let seeds = polar_imgproc::mask::blobs_apart(&seeds, w, h)?;
    let join = polar_imgproc::mask::ArcJoin::rim_arcs(w, h, cues::WINDOW / 2);
    Ok(polar_imgproc::mask::convex_hulls_joined(
        &seeds, w, h, &join,
    )?)
}

/// `mask` without the components whose median S0 is below [`SEE_THROUGH`] times the
/// median S0 of the ring around them ([`RING`] pixels wide; a ring pixel near two
/// components counts for the one with the larger label).
fn without_dark_regions(
    obs: &Observation,
    mask: Vec<bool>,
) -> Result<Vec<bool>, TransparencyError> {
    let (w, h) = obs.size();
    let (id, n) = polar_imgproc::mask::components(&mask, w, h)?;
    if n == 0 {
        return Ok(mask);
    }
    let ids = Gray::from_vec(w, h, id.iter().map(|&i| i as f32).collect()).expect("size");
    let mut ring = Gray::new(w, h);
    polar_imgproc::max_filter(&ids, &mut ring, 2 * RING + 1, 2 * RING + 1)?;
    let mut inside = vec![Vec::new(); n + 1];
    let mut around = vec![Vec::new(); n + 1];
    let s0 = obs.planes.s0.as_slice();
    for k in (0..w * h).filter(|&k| obs.is_valid(k)) {
        match id[k] {
            0 => around[ring.as_slice()[k] as usize].push(s0[k]),
            c => inside[c as usize].push(s0[k]),
        }
    }
    let median = |v: &[f32]| polar_image::quantile(v.iter().copied(), 0.5);
    let keep: Vec<bool> = (0..=n)
        .map(|c| match (median(&inside[c]), median(&around[c])) {
            (Some(i), Some(a)) => i >= SEE_THROUGH * a,
            _ => true,
        })
        .collect();
    Ok((0..w * h)
        .map(|k| mask[k] && keep[id[k] as usize])
        .collect())
}

/// `mask` without the pixels within [`cues::WINDOW`]` / 2` of its outline whose own
/// (median-filtered) DoLP is below [`cues::HALF_DOLP`]: the window carries a rim's strong
/// polarization that far onto the depolarizing background around it, and the hull
/// encloses it. Glass keeps its rims: reflection and transmission polarize most toward
/// grazing.
fn without_depolarized_rim(
    mask: &[bool],
    pixel_dolp: &[f32],
    w: usize,
    h: usize,
) -> Result<Vec<bool>, TransparencyError> {
    let src = Gray::from_vec(w, h, mask.iter().map(|&b| f32::from(u8::from(b))).collect())
        .expect("size of the observation");
    let mut inner = Gray::new(w, h);
    polar_imgproc::min_filter(&src, &mut inner, cues::WINDOW, cues::WINDOW)?;
    let inner = inner.as_slice();
    Ok((0..w * h)
        .map(|k| mask[k] && (inner[k] > 0.5 || pixel_dolp[k] >= cues::HALF_DOLP))
        .collect())
}

/// Glass passes about 90 % of the light behind it (two interfaces, little absorption), so
/// a glass region is about as bright as what surrounds it, whereas a dark glossy opaque
/// object, polarized as strongly, returns only its surface reflection: regions darker
/// than this share of their surroundings' median S0 are dropped. Below a half, to leave
/// room for glass over the darker parts of a backdrop and for its refracted view.
pub const SEE_THROUGH: f32 = 0.45;
/// Width (pixels) of the ring whose brightness [`without_dark_regions`] compares.
const RING: usize = 10;

/// `√(a² + b²)` without `hypot`'s overflow guard (a libm call per pixel): the inputs are
/// normalised Stokes components and image gradients, far from `f32`'s range.
#[inline]
pub(crate) fn norm(a: f32, b: f32) -> f32 {
    (a * a + b * b).sqrt()
}
