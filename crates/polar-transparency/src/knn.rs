//! The learned segmenter: k nearest neighbours (polar-learn) over per-pixel feature vectors
//! that training and inference both compute one way ([`pixel_features`]).
//!
//! Every feature is a ratio of Stokes components or of S0 to the frame's robust scale
//! ([`Observation::s0_scale`]), so a global change of exposure leaves it unchanged, and
//! none depends on how the scene was rendered: only on glass polarizing what it returns
//! coherently over its extent, with an AoLP that follows its silhouette, where diffuse
//! backgrounds return depolarized light ([`crate::cues`]).

use polar_image::{Gray, par_map};
use polar_imgproc::{Border, box_filter, sobel};
use polar_learn::{Expect, Knn};
use polar_sensor::Observation;
use rayon::prelude::*;

use crate::cues::{CueMaps, cue_maps};
use crate::{TransparencyError, norm};

/// The task name in model files.
pub const TASK: &str = "transparent";
/// Number of features.
pub const DIMS: usize = 10;
/// The ordered feature list, written into every model file (windows: the cue window
/// [`crate::cues::WINDOW`]², the context [`CONTEXT`]², the wide context [`WIDE`]²):
/// - `dolp`, `coherence`: the cue maps ([`crate::cues`]);
/// - `dolp_context`, `coherence_context`: their means over the context;
/// - `dolp_context_sd`: the standard deviation of the DoLP over the context (the DoLP
///   discontinuity at a glass silhouette);
/// - `aolp_spread`: `1 − |mean (q, u)| / mean DoLP` over the context, with `(q, u)` the
///   windowed normalised Stokes vector: 0 where the AoLP is the same over the context,
///   1 where it points anywhere (local AoLP inconsistency);
/// - `pd_contrast`: polarization-difference contrast `(I∥ − I⊥)/(I∥ + I⊥)` of the window
///   with the analyser parallel and perpendicular to the context's mean AoLP;
/// - `dolp_wide`: the mean DoLP over the wide context;
/// - `s0_relative`: windowed S0 over the frame's robust scale;
/// - `s0_edge`: Sobel gradient magnitude of that S0 over `S0 + EDGE_FLOOR` (intensity edges,
///   relative).
pub const FEATURES: [&str; DIMS] = [
    "dolp",
    "coherence",
    "dolp_context",
    "coherence_context",
    "dolp_context_sd",
    "aolp_spread",
    "pd_contrast",
    "dolp_wide",
    "s0_relative",
    "s0_edge",
];
/// Class names; class index 1 is transparent.
pub const CLASSES: [&str; 2] = ["other", "transparent"];
/// Class index of transparent pixels.
pub const TRANSPARENT: u8 = 1;
/// Side of the context window (pixels, odd).
pub const CONTEXT: usize = 15;
/// Side of the wide context window (pixels, odd).
pub const WIDE: usize = 31;
/// Relative S0 added to the denominator of `s0_edge`, so that dark pixels' noise does not
/// read as edges.
pub const EDGE_FLOOR: f32 = 0.05;
/// What a transparent model file must declare.
pub const EXPECT: Expect<'static> = Expect {
    task: TASK,
    features: &FEATURES,
    classes: &CLASSES,
};

/// The default model file shipped with the project, trained on
/// `datasets-synth/suites/transparent-train.toml` by `tools/train-default-models.sh`.
pub const BUILTIN_MODEL: &[u8] = include_bytes!("../models/transparent-knn.bin");

/// A loaded transparent kNN classifier (load it with [`EXPECT`]).
pub type KnnClassifier = Knn<DIMS>;

/// Most kNN queries per frame: beyond it the classifier is queried on a grid of stride `s`
/// and the probability interpolated bilinearly between grid nodes (the features are window
/// means already, so neighbouring pixels differ little).
pub const MAX_QUERIES: usize = 1 << 12;

/// The feature planes of one frame, one vector per pixel on demand.
struct FrameFeatures {
    planes: [Vec<f32>; DIMS],
    valid: Vec<bool>,
}

impl FrameFeatures {
    /// The features of `obs` from its cue maps `c`.
    fn new(obs: &Observation, c: CueMaps) -> Result<Self, TransparencyError> {
        let (w, h) = obs.size();
        if w == 0 || h == 0 {
            return Err(TransparencyError::Empty(w, h));
        }
        let n = w * h;
        let CueMaps {
            pixel_dolp: _,
            dolp,
            coherence,
            q,
            u,
        } = c;
        let d2: Vec<f32> = par_map(n, |k| dolp[k] * dolp[k]);
        let ctx = |v: &[f32]| mean(v, w, h, CONTEXT);
        let (qc, uc, dc, d2c, cc) = (ctx(&q)?, ctx(&u)?, ctx(&dolp)?, ctx(&d2)?, ctx(&coherence)?);
        let wide = mean(&dolp, w, h, WIDE)?;
        let scale = obs.s0_scale();
        let s0 = obs.planes.s0.as_slice();
        let valid: Vec<bool> = par_map(n, |k| {
            let p = &obs.planes;
            obs.is_valid(k)
                && s0[k] > 0.0
                && [s0[k], p.s1.as_slice()[k], p.s2.as_slice()[k]]
                    .iter()
                    .all(|v| v.is_finite())
        });
        let s0n = par_map(n, |k| if valid[k] { s0[k] / scale } else { 0.0 });
        let s0w = mean(&s0n, w, h, crate::cues::WINDOW)?;
        let edge = gradient(&s0w, w, h)?;
        let sd = par_map(n, |k| (d2c[k] - dc[k] * dc[k]).max(0.0).sqrt());
        let spread = par_map(n, |k| {
            if dc[k] > 0.0 {
                (1.0 - norm(qc[k], uc[k]) / dc[k]).clamp(0.0, 1.0)
            } else {
                1.0
            }
        });
        let pd = par_map(n, |k| {
            let r = norm(qc[k], uc[k]);
            if r > 0.0 {
                (q[k] * qc[k] + u[k] * uc[k]) / r
            } else {
                0.0
            }
        });
        let s0_edge = par_map(n, |k| edge[k] / (s0w[k] + EDGE_FLOOR));
        Ok(Self {
            planes: [dolp, coherence, dc, cc, sd, spread, pd, wide, s0w, s0_edge],
            valid,
        })
    }

    /// The feature vector of pixel `k`.
    fn at(&self, k: usize) -> [f32; DIMS] {
        std::array::from_fn(|j| self.planes[j][k])
    }
}

/// Box mean of a plane over `side`² (reflected borders).
fn mean(v: &[f32], w: usize, h: usize, side: usize) -> Result<Vec<f32>, TransparencyError> {
    let src = Gray::from_vec(w, h, v.to_vec()).expect("size of the planes");
    let mut dst = Gray::new(w, h);
    box_filter(&src, &mut dst, side, side, Border::Reflect101)?;
    Ok(dst.into_vec())
}

/// Sobel (3x3) gradient magnitude of a plane.
fn gradient(v: &[f32], w: usize, h: usize) -> Result<Vec<f32>, TransparencyError> {
    let src = Gray::from_vec(w, h, v.to_vec()).expect("size of the planes");
    let (mut gx, mut gy) = (Gray::new(w, h), Gray::new(w, h));
    sobel(&src, &mut gx, 1, 0, 3)?;
    sobel(&src, &mut gy, 0, 1, 3)?;
    let (gx, gy) = (gx.as_slice(), gy.as_slice());
    Ok(par_map(w * h, |k| norm(gx[k], gy[k])))
}

/// Per-pixel feature vectors ([`FEATURES`]), row-major, one per pixel.
pub fn pixel_features(obs: &Observation) -> Result<Vec<[f32; DIMS]>, TransparencyError> {
    let x = FrameFeatures::new(obs, cue_maps(obs)?)?;
    Ok(par_map(x.valid.len(), |k| x.at(k)))
}

/// Grid nodes along an axis of `n` pixels at `stride`: `0, s, 2s, ...` and the last pixel.
fn nodes(n: usize, stride: usize) -> Vec<usize> {
    let mut v: Vec<usize> = (0..n).step_by(stride).collect();
    if v.last() != Some(&(n - 1)) {
        v.push(n - 1);
    }
    v
}

/// For pixel coordinate `x`, the grid nodes around it (indices into `nodes`) and the
/// weight of the second.
fn bracket(x: usize, nodes: &[usize], stride: usize) -> (usize, usize, f32) {
    let i = (x / stride).min(nodes.len() - 1);
    if nodes[i] == x || i + 1 == nodes.len() {
        return (i, i, 0.0);
    }
    let (a, b) = (nodes[i], nodes[i + 1]);
    (i, i + 1, (x - a) as f32 / (b - a) as f32)
}

/// Probability of transparent per pixel: the fraction of transparent points among the `k`
/// nearest training points, on a grid of at most about [`MAX_QUERIES`] nodes, interpolated
/// bilinearly in between (every pixel is a node on frames up to that size). `cues` are
/// the cue maps of `obs` (their `pixel_dolp` is not a feature and may be taken out).
pub fn probability(
    clf: &KnnClassifier,
    obs: &Observation,
    cues: CueMaps,
) -> Result<Gray<f32>, TransparencyError> {
    let (w, h) = obs.size();
    let x = FrameFeatures::new(obs, cues)?;
    let stride = (((w * h) as f64 / MAX_QUERIES as f64).sqrt().ceil() as usize).max(1);
    let (nx, ny) = (nodes(w, stride), nodes(h, stride));
    let grid: Vec<f32> = (0..nx.len() * ny.len())
        .into_par_iter()
        .map(|i| {
            let k = ny[i / nx.len()] * w + nx[i % nx.len()];
            clf.fraction(&x.at(k), TRANSPARENT)
        })
        .collect();
    let cols: Vec<(usize, usize, f32)> = (0..w).map(|c| bracket(c, &nx, stride)).collect();
    let at = |r: usize, c: usize| grid[r * nx.len() + c];
    let p = par_map(w * h, |k| {
        let (r0, r1, ty) = bracket(k / w, &ny, stride);
        let (c0, c1, tx) = cols[k % w];
        let top = at(r0, c0) + tx * (at(r0, c1) - at(r0, c0));
        let bottom = at(r1, c0) + tx * (at(r1, c1) - at(r1, c0));
        top + ty * (bottom - top)
    });
    Ok(Gray::from_vec(w, h, p).expect("size of the observation"))
}

/// Training points of one labelled frame: the feature vectors of its valid pixels with
/// their class (transparent where `labels`, as `gt/transparent.png`, is non-zero).
/// Appends to `points` (row-major) and `classes`.
pub fn add_training_pixels(
    obs: &Observation,
    labels: &Gray<u8>,
    points: &mut Vec<f32>,
    classes: &mut Vec<u8>,
) -> Result<(), TransparencyError> {
    if labels.size() != obs.size() {
        return Err(TransparencyError::SizeMismatch {
            what: "labels",
            expected: obs.size(),
            got: labels.size(),
        });
    }
    let x = FrameFeatures::new(obs, cue_maps(obs)?)?;
    for (k, &l) in labels.as_slice().iter().enumerate() {
        if x.valid[k] {
            points.extend_from_slice(&x.at(k));
            classes.push(u8::from(l != 0));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Grid nodes cover both ends and interpolation weights run from 0 at a node to 1
    /// at the next (checked against the definition on a stride that does not divide n).
    #[test]
    fn grid_brackets_every_pixel() {
        let (n, s) = (23, 5);
        let v = nodes(n, s);
        assert_eq!(v, [0, 5, 10, 15, 20, 22]);
        for x in 0..n {
            let (a, b, t) = bracket(x, &v, s);
            let (xa, xb) = (v[a] as f32, v[b] as f32);
            let back = xa + t * (xb - xa);
            assert!((back - x as f32).abs() < 1e-5, "{x}: {a} {b} {t}");
            assert!((0.0..=1.0).contains(&t) && b <= a + 1);
        }
    }
}
