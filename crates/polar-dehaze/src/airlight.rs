//! Automatic estimation of the airlight's polarization: its angle field `alpha(x, y)`, its
//! degree `p` and its brightness at infinity `A_inf`, from the observation alone.
//!
//! Estimator (all on block means of S0, S1, S2 over a grid of at most [`GRID`] blocks a
//! side, which averages noise and bounds the cost):
//!
//! 1. **Angle field.** The airlight's AoLP is not one angle over the frame (single
//!    scattering polarizes perpendicular to the sun-view plane, which turns across the
//!    field of view). We fit a polynomial of degree [`MAX_DEGREE`] in the normalised
//!    image coordinates to the unit vectors `(cos 2a, sin 2a)` of the blocks, weighted by
//!    their polarized intensity `sqrt(S1^2 + S2^2)` (so the airlight-dominated, distant
//!    blocks lead), by iteratively reweighted least squares with Tukey's biweight on the
//!    angular residual (blocks whose own polarization, e.g. specular reflection, points
//!    elsewhere drop out). `alpha` is the angle of the fitted vector.
//! 2. **Degree `p`.** With unpolarized direct light the projected polarization
//!    `P = S1 cos 2alpha + S2 sin 2alpha` equals `p A <= p S0`, with equality where no
//!    direct light arrives (sky, or a black object). So `p` is the upper envelope of
//!    `P / S0`: its [`ENVELOPE_QUANTILE`] quantile over blocks brighter than
//!    [`DARK_LEVEL`] (dark blocks are dominated by noise).
//! 3. **`A_inf`.** The airlight `A = P / p` grows with distance towards `A_inf`; we take
//!    its [`AIRLIGHT_QUANTILE`] quantile over the blocks: the most distant region's
//!    airlight, which is the sky's S0 where sky is visible (Schechner et al. measure
//!    `A_inf` and `p` on the sky).
//! 4. **`p` and `A_inf` over the frame** (`varying_airlight`, [`SkyField`]). Neither is
//!    one number: `p` follows the scattering angle, and the sky is brighter towards the
//!    sun. Blocks whose `P / S0` and `P` reach [`SKY_LEVEL`] of the levels under `p` and
//!    `p A_inf` (the quantiles of 2.-3. less the height at which the same quantiles of
//!    noise lie above its mean, `noise`) are sky candidates; an upper-envelope plane of
//!    their `P / S0`, fitted inside extended regions of them (a strongly polarized
//!    highlight is no sky) and lowered by the noise's height alike, picks those at
//!    infinity. Those inside extended regions of candidates and near the sky's brightness
//!    are the sky, where all the light is airlight: the upper-envelope plane of their S0
//!    gives `A_inf(x, y)` and a plane fitted to their `P / S0` gives `p(x, y)` (both
//!    clamped to the range seen). Needs [`MIN_SKY_BLOCKS`] at infinity; otherwise 1.-3.
//!    stand.
//!
//! Failure modes (reported as warnings where they can be detected):
//! - no sky and no black object in view: `P / S0 < p` everywhere, so `p` is underestimated
//!   and `A = P / p` overestimated: `t` comes out too low (over-dehazed, radiance too dark);
//! - no sky: the largest airlight is that of the most distant object, below `A_inf`, so
//!   `t` of that region tends to 0 (clamped at `t_min`);
//! - strongly polarized objects (specular reflections, glass, water) aligned with the
//!   airlight raise the envelope (`p` too high: under-dehazed) and look like airlight;
//! - haze thickening smoothly up to the horizon (a ground plane to infinity): hazy ground
//!   just below the horizon passes as sky and tilts the plane of `p` (`p` too low far
//!   from the horizon, so `t` too low there); `varying_airlight: false` avoids it;
//! - `A_inf` is a plane: a sky that varies more than a plane (a bright band around the
//!   sun) is dehazed as a bright object where it rises above the plane; the plane's
//!   extrapolation below the horizon is the sky's, not the airlight's towards the ground;
//! - sky whose `p` falls below [`SKY_LEVEL`] of the frame's envelope (towards the sun, where
//!   scattering polarizes least) is no candidate, and the plane of `p`, clamped to the
//!   range seen, stays too high there: `t` too high, the sky there left hazy;
//! - sensor or Monte Carlo noise comparable to `p` in a block's `P / S0` (weak airlight
//!   polarization on a small image) raises the envelope of `P / S0`. The sky field takes
//!   the noise's share off; 2.-3. (no sky field) do not: `p` too high, `A_inf = P / p` too
//!   low, `t` too high where the airlight is weak (on a haze-free frame a lower `p` would
//!   read more of the objects' own polarization as airlight);
//! - no sky region large enough for [`MIN_SKY_BLOCKS`] interior blocks: one `p` and
//!   `A_inf` (a sky much brighter on one side then leaves `t > 0` on the darker side);
//! - airlight polarization at the noise level: `p` is then noise; [`crate::polarization`]
//!   falls back when `p < min_airlight_dolp`.

use std::collections::{HashMap, HashSet};

use nalgebra::{DMatrix, DVector};
use polar_image::{Gray, quantile};
use rayon::prelude::*;

use crate::prep::Normalized;

/// Largest number of blocks along the longer image side.
pub const GRID: usize = 32;
/// Degree of the polynomial angle field (6 coefficients per component).
pub const MAX_DEGREE: usize = 2;
/// Blocks darker than this fraction of `s0_scale` are left out of the `p` envelope.
pub const DARK_LEVEL: f32 = 0.02;
/// Quantile of `P / S0` taken as the airlight's degree of polarization `p`.
pub const ENVELOPE_QUANTILE: f64 = 0.99;
/// Quantile of `P / p` taken as `A_inf`.
pub const AIRLIGHT_QUANTILE: f64 = 0.995;
/// Tukey biweight cut-off of the angle field's residual, in doubled-angle radians (45 deg
/// in 2a, i.e. 22.5 deg of AoLP).
const TUKEY_C: f64 = std::f64::consts::FRAC_PI_4;
/// Reweighting passes of the angle-field fit.
const IRLS_PASSES: usize = 5;

/// The airlight's polarization and brightness, in the units of the normalised S0.
#[derive(Clone, Debug, PartialEq)]
pub struct AirlightEstimate {
    /// Airlight at infinity `A_inf` (normalised by `s0_scale`).
    pub a_inf: f32,
    /// Degree of polarization `p` of the airlight (at the image centre when it varies).
    pub p: f32,
    /// The angle field (`cos 2alpha`, `sin 2alpha` polynomials).
    pub field: AngleField,
    /// `p` varying over the frame, where enough sky is seen.
    pub sky: Option<SkyField>,
    /// Fraction of the blocks that look like sky (the sky field's candidates, module doc).
    pub sky_fraction: f32,
    /// Number of blocks used.
    pub blocks: usize,
}

/// A smooth field of polarization directions: `(c, s)(x, y) = sum_k coef_k x^i y^j` over
/// the monomials of degree `<= degree` in normalised coordinates `x, y in [-1, 1]`;
/// the direction is `(c, s) / |(c, s)|`.
#[derive(Clone, Debug, PartialEq)]
pub struct AngleField {
    /// Polynomial degree.
    pub degree: usize,
    /// Coefficients of `cos 2alpha`.
    pub cos: Vec<f64>,
    /// Coefficients of `sin 2alpha`.
    pub sin: Vec<f64>,
}

impl AngleField {
    /// A constant direction `alpha`.
    pub fn constant(alpha: f64) -> Self {
        Self {
            degree: 0,
            cos: vec![(2.0 * alpha).cos()],
            sin: vec![(2.0 * alpha).sin()],
        }
    }

    /// Unit `(cos 2alpha, sin 2alpha)` at normalised `(x, y)`; `(1, 0)` where the field
    /// vanishes.
    pub fn direction(&self, x: f64, y: f64) -> (f64, f64) {
        let (phi, n) = monomials_array(self.degree, x, y);
        let c: f64 = phi[..n].iter().zip(&self.cos).map(|(p, a)| p * a).sum();
        let s: f64 = phi[..n].iter().zip(&self.sin).map(|(p, a)| p * a).sum();
        let n = c.hypot(s);
        if n > 0.0 && n.is_finite() {
            (c / n, s / n)
        } else {
            (1.0, 0.0)
        }
    }

    /// The airlight's AoLP `alpha` in `[0, pi)` at normalised `(x, y)`.
    pub fn aolp(&self, x: f64, y: f64) -> f64 {
        let (c, s) = self.direction(x, y);
        (0.5 * s.atan2(c)).rem_euclid(std::f64::consts::PI)
    }

    /// The linear polarization in the airlight's frame, per pixel: along its direction
    /// `P = S1 cos 2alpha + S2 sin 2alpha` and across it `Q = S2 cos 2alpha − S1 sin 2alpha`
    /// (zero for airlight and unpolarized light).
    pub fn project(&self, s1: &Gray<f32>, s2: &Gray<f32>) -> (Gray<f32>, Gray<f32>) {
        let (w, h) = s1.size();
        let (mut along, mut across) = (Gray::new(w, h), Gray::new(w, h));
        along
            .as_mut_slice()
            .par_chunks_mut(w.max(1))
            .zip(across.as_mut_slice().par_chunks_mut(w.max(1)))
            .enumerate()
            .for_each(|(y, (p_row, q_row))| {
                let yn = norm_coord(y, h);
                for (x, (p, q)) in p_row.iter_mut().zip(q_row.iter_mut()).enumerate() {
                    let (c, s) = self.direction(norm_coord(x, w), yn);
                    let k = y * w + x;
                    let (a, b) = (f64::from(s1.as_slice()[k]), f64::from(s2.as_slice()[k]));
                    (*p, *q) = ((a * c + b * s) as f32, (b * c - a * s) as f32);
                }
            });
        (along, across)
    }
}

/// Pixel centre `i` of `n` mapped to `[-1, 1]`.
pub fn norm_coord(i: usize, n: usize) -> f64 {
    (2.0 * i as f64 + 1.0) / n as f64 - 1.0
}

/// The monomials `x^i y^j`, `i + j <= degree` (at most [`MAX_DEGREE`]), in a fixed order.
fn monomials(degree: usize, x: f64, y: f64) -> Vec<f64> {
    let (m, n) = monomials_array(degree, x, y);
    m[..n].to_vec()
}

/// [`monomials`] without allocation: the values and how many there are.
fn monomials_array(degree: usize, x: f64, y: f64) -> ([f64; 6], usize) {
    let all = [1.0, x, y, x * x, x * y, y * y];
    let n = match degree {
        0 => 1,
        1 => 3,
        _ => 6,
    };
    (all, n)
}

/// Block means of the valid pixels.
#[derive(Clone, Debug)]
pub struct Blocks {
    /// Mean normalised S0 per usable block.
    pub s0: Vec<f32>,
    /// Mean normalised S1.
    pub s1: Vec<f32>,
    /// Mean normalised S2.
    pub s2: Vec<f32>,
    /// Normalised x of the block's centre.
    pub x: Vec<f64>,
    /// Normalised y of the block's centre.
    pub y: Vec<f64>,
    /// Grid cell `(column, row)` of each block.
    pub cell: Vec<(usize, usize)>,
}

impl Blocks {
    /// Means over `b x b` blocks, `b = ceil(max(w, h) / GRID)`, keeping the blocks whose
    /// pixels are at least half valid and whose mean S0 is positive.
    pub fn new(input: &Normalized) -> Self {
        let (w, h) = input.s0.size();
        let b = w.max(h).div_ceil(GRID).max(1);
        let (gw, gh) = (w.div_ceil(b), h.div_ceil(b));
        let mut acc = vec![[0.0f64; 4]; gw * gh];
        let (s0, s1, s2) = (
            input.s0.as_slice(),
            input.s1.as_slice(),
            input.s2.as_slice(),
        );
        // One block row per task; within a block the sums run in row-major order.
        acc.par_chunks_mut(gw).enumerate().for_each(|(by, accs)| {
            for y in by * b..((by + 1) * b).min(h) {
                for x in 0..w {
                    let k = y * w + x;
                    if input.valid[k] {
                        let a = &mut accs[x / b];
                        a[0] += f64::from(s0[k]);
                        a[1] += f64::from(s1[k]);
                        a[2] += f64::from(s2[k]);
                        a[3] += 1.0;
                    }
                }
            }
        });
        let mut out = Self {
            s0: vec![],
            s1: vec![],
            s2: vec![],
            x: vec![],
            y: vec![],
            cell: vec![],
        };
        for (g, a) in acc.iter().enumerate() {
            let (bx, by) = (g % gw, g / gw);
            let (x0, y0) = (bx * b, by * b);
            let (bw, bh) = ((x0 + b).min(w) - x0, (y0 + b).min(h) - y0);
            if a[3] < 0.5 * (bw * bh) as f64 || a[0] <= 0.0 {
                continue;
            }
            out.s0.push((a[0] / a[3]) as f32);
            out.s1.push((a[1] / a[3]) as f32);
            out.s2.push((a[2] / a[3]) as f32);
            out.x.push((2.0 * x0 as f64 + bw as f64) / w as f64 - 1.0);
            out.y.push((2.0 * y0 as f64 + bh as f64) / h as f64 - 1.0);
            out.cell.push((bx, by));
        }
        out
    }

    /// Number of usable blocks.
    pub fn len(&self) -> usize {
        self.s0.len()
    }

    /// `true` without usable blocks.
    pub fn is_empty(&self) -> bool {
        self.s0.is_empty()
    }
}

/// Fits the airlight's angle field to the blocks (IRLS, see the module doc). The degree
/// drops to 1 or 0 when there are too few blocks for a stable fit (fewer than four per
/// coefficient). `None` when no block is polarized at all.
pub fn fit_angle_field(blocks: &Blocks) -> Option<AngleField> {
    let n = blocks.len();
    let degree = (0..=MAX_DEGREE)
        .rev()
        .find(|&d| n >= 4 * (d + 1) * (d + 2) / 2)
        .unwrap_or(0);
    let mag: Vec<f64> = (0..n)
        .map(|i| f64::from(blocks.s1[i]).hypot(f64::from(blocks.s2[i])))
        .collect();
    if !mag.iter().any(|&m| m > 0.0) {
        return None;
    }
    let unit: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            if mag[i] > 0.0 {
                (
                    f64::from(blocks.s1[i]) / mag[i],
                    f64::from(blocks.s2[i]) / mag[i],
                )
            } else {
                (0.0, 0.0)
            }
        })
        .collect();
    let phi: Vec<Vec<f64>> = (0..n)
        .map(|i| monomials(degree, blocks.x[i], blocks.y[i]))
        .collect();
    let mut weights = mag.clone();
    let mut field = weighted_fit(degree, &phi, &unit, &weights)?;
    for _ in 0..IRLS_PASSES {
        let mut any = false;
        for i in 0..n {
            let (c, s) = field.direction(blocks.x[i], blocks.y[i]);
            let cos_r = (unit[i].0 * c + unit[i].1 * s).clamp(-1.0, 1.0);
            let r = cos_r.acos() / TUKEY_C;
            weights[i] = if r < 1.0 {
                mag[i] * (1.0 - r * r).powi(2)
            } else {
                0.0
            };
            any |= weights[i] > 0.0;
        }
        if !any {
            break;
        }
        match weighted_fit(degree, &phi, &unit, &weights) {
            Some(f) => field = f,
            None => break,
        }
    }
    Some(field)
}

/// Weighted least squares of both components on the monomials, with a tiny ridge so
/// that a degenerate layout (one row of blocks) still solves (LU, `None` if singular).
fn weighted_fit(
    degree: usize,
    phi: &[Vec<f64>],
    unit: &[(f64, f64)],
    weights: &[f64],
) -> Option<AngleField> {
    let m = (degree + 1) * (degree + 2) / 2;
    let mut ata = DMatrix::<f64>::zeros(m, m);
    let mut atb = DMatrix::<f64>::zeros(m, 2);
    let mut wsum = 0.0;
    for ((p, u), &w) in phi.iter().zip(unit).zip(weights) {
        if w <= 0.0 {
            continue;
        }
        wsum += w;
        let row = DVector::from_column_slice(&p[..m]);
        ata.ger(w, &row, &row, 1.0);
        atb.column_mut(0).axpy(w * u.0, &row, 1.0);
        atb.column_mut(1).axpy(w * u.1, &row, 1.0);
    }
    if wsum <= 0.0 {
        return None;
    }
    let x = (ata + DMatrix::identity(m, m) * (1e-9 * wsum))
        .lu()
        .solve(&atb)?;
    x.iter().all(|v| v.is_finite()).then(|| AngleField {
        degree,
        cos: x.column(0).iter().copied().collect(),
        sin: x.column(1).iter().copied().collect(),
    })
}

/// Estimates `alpha(x, y)`, `p` and `A_inf` (see the module doc). `None` when no usable
/// block is polarized.
pub fn estimate(input: &Normalized, varying: bool) -> Option<AirlightEstimate> {
    let blocks = Blocks::new(input);
    let field = fit_angle_field(&blocks)?;
    let n = blocks.len();
    let (proj, across): (Vec<f32>, Vec<f32>) = (0..n)
        .map(|i| {
            let (c, s) = field.direction(blocks.x[i], blocks.y[i]);
            let (s1, s2) = (f64::from(blocks.s1[i]), f64::from(blocks.s2[i]));
            ((s1 * c + s2 * s) as f32, (s2 * c - s1 * s) as f32)
        })
        .unzip();
    let bright: Vec<usize> = (0..n).filter(|&i| blocks.s0[i] >= DARK_LEVEL).collect();
    let ratio = |i: usize| f64::from(proj[i]) / f64::from(blocks.s0[i]);
    let p = quantile(bright.iter().map(|&i| ratio(i) as f32), ENVELOPE_QUANTILE)?.clamp(0.0, 1.0);
    let a_inf = if p > 0.0 {
        quantile(proj.iter().map(|&v| v / p), AIRLIGHT_QUANTILE)?
    } else {
        0.0
    };
    // Noise raises both quantiles above the sky's level: the candidates are judged against
    // the levels (without a sky field the quantiles stand, module doc).
    let all: Vec<usize> = (0..n).collect();
    let ratio_level = f64::from(p)
        - Z_QUANTILE
            * noise(&blocks, &across, &bright, &|i| {
                1.0 / f64::from(blocks.s0[i])
            });
    let polarized_level =
        f64::from(p * a_inf) - Z_QUANTILE_HIGH * noise(&blocks, &across, &all, &|_| 1.0);
    let sky: Vec<usize> = bright
        .iter()
        .copied()
        .filter(|&i| {
            p > 0.0
                && ratio(i) >= f64::from(SKY_LEVEL) * ratio_level
                && f64::from(proj[i]) >= f64::from(SKY_LEVEL) * polarized_level
        })
        .collect();
    let sky_field = (varying && sky.len() >= MIN_SKY_BLOCKS)
        .then(|| SkyField::fit(&blocks, &proj, &across, &sky))
        .flatten()
        .filter(|f| f.dolp_range.0 > 0.0);
    let (p, a_inf) = match &sky_field {
        Some(f) => (f.at(0.0, 0.0) as f32, f.airlight_at(0.0, 0.0) as f32),
        None => (p, a_inf),
    };
    Some(AirlightEstimate {
        a_inf,
        p,
        field,
        sky: sky_field,
        sky_fraction: sky.len() as f32 / n.max(1) as f32,
        blocks: n,
    })
}

/// How far an upper quantile or envelope of Gaussian noise lies above its level, in
/// standard deviations: the [`ENVELOPE_QUANTILE`] and [`AIRLIGHT_QUANTILE`] quantiles and
/// the [`ENVELOPE_EXPECTILE`] expectile of the standard normal.
const Z_QUANTILE: f64 = 2.326;
const Z_QUANTILE_HIGH: f64 = 2.576;
const Z_EXPECTILE: f64 = 1.717;
/// Half-width, in noise deviations, of the band around the envelope of `P / S0` whose
/// blocks count as at infinity (where wider than [`INFINITY_TOLERANCE`]).
const NOISE_BAND: f64 = 2.0;

/// The block means' noise, read from the polarization across the airlight's angle `Q`
/// (`across`): airlight has none, so on the blocks an envelope rests on (sky) `Q` is noise
/// with the deviation of the projection `P` along it, plus the angle field's misfit, which
/// is smooth and drops out of the differences between grid neighbours. Returns the robust
/// deviation `MAD_TO_SIGMA · median |d| / √2` of `d = Q_i scale(i) − Q_j scale(j)` over the
/// neighbouring blocks `i`, `j` of `idx`: the noise of the value `P_i scale(i)`; 0 without
/// such pairs.
fn noise(blocks: &Blocks, across: &[f32], idx: &[usize], scale: &dyn Fn(usize) -> f64) -> f64 {
    let at: HashMap<(usize, usize), usize> = idx.iter().map(|&i| (blocks.cell[i], i)).collect();
    let q = |i: usize| f64::from(across[i]) * scale(i);
    let diffs: Vec<f32> = idx
        .iter()
        .flat_map(|&i| {
            let (x, y) = blocks.cell[i];
            [(x + 1, y), (x, y + 1)]
                .into_iter()
                .filter_map(|c| at.get(&c).map(|&j| (q(i) - q(j)).abs() as f32))
                .collect::<Vec<_>>()
        })
        .collect();
    f64::from(crate::refine::MAD_TO_SIGMA) * f64::from(quantile(diffs, 0.5).unwrap_or(0.0))
        / std::f64::consts::SQRT_2
}

/// Blocks whose airlight fraction `P / (p S0)` and airlight `P / p` both reach this
/// fraction of their maxima count as sky (or as distant enough to stand for it).
pub const SKY_LEVEL: f32 = 0.5;
/// Fewest sky blocks for the [`SkyField`] planes (three coefficients each).
pub const MIN_SKY_BLOCKS: usize = 12;
/// Expectile of the upper-envelope plane of `P` over the sky candidates.
pub const ENVELOPE_EXPECTILE: f64 = 0.99;
/// Reweighting passes of the expectile fit.
const EXPECTILE_PASSES: usize = 10;
/// Candidates whose `P / S0` is within this fraction of the envelope, either side, are at
/// infinity.
pub const INFINITY_TOLERANCE: f64 = 0.1;
/// Blocks at infinity whose airlight is below this share of the brightest sky's are not
/// sky (`bright_inner`); a sky brighter towards the sun keeps its dimmer side down to
/// this share.
pub const SKY_AIRLIGHT_SHARE: f64 = 0.7;

/// The airlight's degree of polarization as it varies over the frame: a plane
/// `p(x, y) = a + b x + c y` in normalised image coordinates fitted to the blocks at
/// infinity (sky), where `P / S0 = p` exactly, evaluated clamped to the range of their
/// values so that the extrapolation stays within what was seen. Single scattering makes
/// `p` depend on the angle to the sun, which turns across a wide field of view.
#[derive(Clone, Debug, PartialEq)]
pub struct SkyField {
    /// Plane coefficients `[a, b, c]` of `p` over the sky blocks.
    pub dolp: [f64; 3],
    /// Range of the sky blocks' `P / S0`.
    pub dolp_range: (f64, f64),
    /// Plane coefficients `[a, b, c]` of `A_inf`: the upper envelope of the sky blocks' S0
    /// (at infinity all the light is airlight).
    pub airlight: [f64; 3],
    /// Range of the sky blocks' S0.
    pub airlight_range: (f64, f64),
    /// Number of blocks taken as infinity.
    pub blocks: usize,
}

impl SkyField {
    /// Fits the planes. `P / S0 <= p` everywhere, with equality only where no direct light
    /// arrives, so the candidates (which include hazy but finite distances) get an
    /// upper-envelope plane of `P / S0` ([`envelope_plane`]), fitted to those inside
    /// extended regions of them ([`interior`]): a polarized highlight on a glossy object,
    /// aligned with the airlight and stronger than it, is too small to hold a block there
    /// and would pull the envelope up. With noise the envelope lies [`Z_EXPECTILE`] noise
    /// deviations ([`noise`]) above the level of `P / S0` at infinity, and is lowered by
    /// that much; the candidates within [`INFINITY_TOLERANCE`] of it, either side (or
    /// within [`NOISE_BAND`] deviations, where wider), are taken as infinity. At infinity S0
    /// is all airlight, `A_inf`, measured there on S0 rather than on `P / p`, whose noise is
    /// `1 / p` times larger and would raise its upper envelope. So the sky is the blocks at
    /// infinity inside extended regions of candidates and bright enough ([`bright_inner`]),
    /// in the top cluster of S0 ([`upper_blocks`]): a black object also has `P / S0 = p`, at
    /// any distance, and a ramp of them down a hazy slope would tilt the planes. `A_inf` is
    /// the upper-envelope plane of their S0, `p` the least-squares plane of their `P / S0`
    /// (unbiased by noise). `None` with fewer than 3 such blocks (then one `p` and `A_inf`
    /// over the frame).
    fn fit(blocks: &Blocks, proj: &[f32], across: &[f32], candidates: &[usize]) -> Option<Self> {
        let eval = |c: &[f64; 3], i: usize| c[0] + c[1] * blocks.x[i] + c[2] * blocks.y[i];
        let dolp = |i: usize| f64::from(proj[i]) / f64::from(blocks.s0[i]);
        let inner = interior(blocks, candidates);
        let dolp_noise = noise(blocks, across, &inner, &|i| 1.0 / f64::from(blocks.s0[i]));
        let mut env = envelope_plane(blocks, &inner, &dolp)?;
        env[0] -= Z_EXPECTILE * dolp_noise;
        let inf: Vec<usize> = candidates
            .iter()
            .copied()
            .filter(|&i| {
                let e = eval(&env, i);
                (dolp(i) - e).abs() <= (INFINITY_TOLERANCE * e).max(NOISE_BAND * dolp_noise)
            })
            .collect();
        if inf.len() < MIN_SKY_BLOCKS {
            return None;
        }
        let range = |idx: &[usize], v: &dyn Fn(usize) -> f64| {
            idx.iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &i| {
                    (lo.min(v(i)), hi.max(v(i)))
                })
        };
        // Black objects pass the `p` test at any distance, but their S0, all airlight, is
        // below A_inf.
        let s0 = |i: usize| f64::from(blocks.s0[i]);
        let top = upper_blocks(blocks, &bright_inner(&inner, &inf, &s0)?, &s0)?;
        let dolp_plane = plane_fit(blocks, &top, &dolp, &vec![1.0; top.len()])?;
        let dolp_range = range(&top, &dolp);
        Some(Self {
            dolp: dolp_plane,
            dolp_range,
            airlight: envelope_plane(blocks, &top, &s0)?,
            airlight_range: range(&top, &s0),
            blocks: inf.len(),
        })
    }

    /// `p` at normalised `(x, y)`.
    pub fn at(&self, x: f64, y: f64) -> f64 {
        plane(&self.dolp, self.dolp_range, x, y)
    }

    /// `A_inf` at normalised `(x, y)`.
    pub fn airlight_at(&self, x: f64, y: f64) -> f64 {
        plane(&self.airlight, self.airlight_range, x, y)
    }
}

/// Least-squares plane `c0 + c1 x + c2 y` of `v` over the blocks `idx` with weights `wts`.
fn plane_fit(
    blocks: &Blocks,
    idx: &[usize],
    v: &dyn Fn(usize) -> f64,
    wts: &[f64],
) -> Option<[f64; 3]> {
    let phi: Vec<Vec<f64>> = idx
        .iter()
        .map(|&i| monomials(1, blocks.x[i], blocks.y[i]))
        .collect();
    let vals: Vec<(f64, f64)> = idx.iter().map(|&i| (v(i), 0.0)).collect();
    weighted_fit(1, &phi, &vals, wts).map(|f| [f.cos[0], f.cos[1], f.cos[2]])
}

/// Upper-envelope plane of `v` over the blocks `idx`: expectile regression
/// ([`ENVELOPE_EXPECTILE`], Newey and Powell 1987) by [`EXPECTILE_PASSES`] reweighted
/// least-squares passes.
fn envelope_plane(blocks: &Blocks, idx: &[usize], v: &dyn Fn(usize) -> f64) -> Option<[f64; 3]> {
    let mut wts = vec![1.0; idx.len()];
    let mut env = plane_fit(blocks, idx, v, &wts)?;
    for _ in 0..EXPECTILE_PASSES {
        for (w, &i) in wts.iter_mut().zip(idx) {
            *w = if v(i) >= env[0] + env[1] * blocks.x[i] + env[2] * blocks.y[i] {
                ENVELOPE_EXPECTILE
            } else {
                1.0 - ENVELOPE_EXPECTILE
            };
        }
        env = plane_fit(blocks, idx, v, &wts)?;
    }
    Some(env)
}

/// The blocks at infinity (`inf`) inside extended regions of the sky candidates (`inner`,
/// their [`interior`]) whose airlight `v` (S0) is at least [`SKY_AIRLIGHT_SHARE`] of the
/// [`AIRLIGHT_QUANTILE`] of theirs. The regions are the candidates', not those of `inf`:
/// where noise is comparable to the spread of `P / S0` over the sky, it picks which sky
/// blocks reach the envelope, scattered, and few of them have all four neighbours among
/// them. Black objects and hazy ground inside the candidates' regions also reach it, at
/// any distance; their airlight `A_inf (1 - t)` falls short of the sky's.
fn bright_inner(inner: &[usize], inf: &[usize], v: &dyn Fn(usize) -> f64) -> Option<Vec<usize>> {
    let extended: HashSet<usize> = inner.iter().copied().collect();
    let inside: Vec<usize> = inf
        .iter()
        .copied()
        .filter(|i| extended.contains(i))
        .collect();
    let top = f64::from(quantile(
        inside.iter().map(|&i| v(i) as f32),
        AIRLIGHT_QUANTILE,
    )?);
    Some(
        inside
            .into_iter()
            .filter(|&i| v(i) >= SKY_AIRLIGHT_SHARE * top)
            .collect(),
    )
}

/// The blocks of `idx` whose four grid neighbours are in `idx` too (or outside the frame):
/// the inside of extended regions. A sky is one; a black object, whose `P / S0` is `p` at
/// any distance, is usually too small to keep a block.
fn interior(blocks: &Blocks, idx: &[usize]) -> Vec<usize> {
    let set: HashSet<(usize, usize)> = idx.iter().map(|&i| blocks.cell[i]).collect();
    let (gw, gh) = blocks
        .cell
        .iter()
        .fold((0, 0), |(w, h), &(x, y)| (w.max(x + 1), h.max(y + 1)));
    let inside = |(x, y): (usize, usize), dx: isize, dy: isize| match (
        x.checked_add_signed(dx),
        y.checked_add_signed(dy),
    ) {
        (Some(nx), Some(ny)) if nx < gw && ny < gh => set.contains(&(nx, ny)),
        _ => true,
    };
    idx.iter()
        .copied()
        .filter(|&i| {
            let c = blocks.cell[i];
            [(-1, 0), (1, 0), (0, -1), (0, 1)]
                .iter()
                .all(|&(dx, dy)| inside(c, dx, dy))
        })
        .collect()
}

/// The blocks of `idx` not more than [`INFINITY_TOLERANCE`] below the least-squares plane
/// of `v` over the blocks kept, iterated from all of `idx` to a fixed point (at most
/// [`EXPECTILE_PASSES`] times): the top cluster of `v`, without the values well below it
/// that would tilt an envelope plane. `None` with fewer than 3 blocks.
fn upper_blocks(blocks: &Blocks, idx: &[usize], v: &dyn Fn(usize) -> f64) -> Option<Vec<usize>> {
    let mut kept = idx.to_vec();
    for _ in 0..EXPECTILE_PASSES {
        let c = plane_fit(blocks, &kept, v, &vec![1.0; kept.len()])?;
        let next: Vec<usize> = idx
            .iter()
            .copied()
            .filter(|&i| {
                v(i) >= (1.0 - INFINITY_TOLERANCE)
                    * (c[0] + c[1] * blocks.x[i] + c[2] * blocks.y[i])
            })
            .collect();
        if next == kept || next.len() < 3 {
            break;
        }
        kept = next;
    }
    (kept.len() >= 3).then_some(kept)
}

/// `c0 + c1 x + c2 y` clamped to `range`.
fn plane(c: &[f64; 3], range: (f64, f64), x: f64, y: f64) -> f64 {
    (c[0] + c[1] * x + c[2] * y).clamp(range.0, range.1)
}
