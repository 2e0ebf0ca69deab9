//! The local method: the azimuth ambiguity resolved by propagation from the occluding
//! boundary with a convexity prior and smoothness (after Atkinson & Hancock 2006 and
//! Miyazaki et al. 2003).
//!
//! 1. Prior ([`boundary_prior`]): at the silhouette of a smooth object the normal lies in
//!    the image plane and points away from the object; for a convex object it turns
//!    smoothly toward the viewer inside. With `D` the distance to the nearest background
//!    pixel and `R` its maximum over the object's connected component, the prior normal
//!    has azimuth `−∇D` (smoothed) and zenith `asin(1 − D/R)` (exact for a sphere).
//!    It starts the iterations everywhere but weighs in them only where the nearest
//!    boundary shows the occluding-contour signature in its polarization
//!    (`verified_contour`), so a cast shadow or a missed part of an object does not
//!    pull the normals toward a boundary that is not a silhouette. A given object mask
//!    ([`Outline::Given`]) is the objects' outline: all of it weighs.
//! 2. Candidates per pixel, in the per-pixel Stokes frame: diffuse azimuths `AoLP`,
//!    `AoLP + π` and specular ones `AoLP ± π/2`. Observed light mixes diffuse, specular
//!    and unpolarized parts, so DoLP only bounds the zenith (`DoLP ≤ ρ(θ)` of the
//!    dominant part, [`crate::zenith`]); each candidate's zenith is the reference
//!    field's zenith projected onto that feasible set
//!    ([`ZenithModels::diffuse_mixed`](crate::zenith::ZenithModels::diffuse_mixed),
//!    [`ZenithModels::specular_mixed`](crate::zenith::ZenithModels::specular_mixed)),
//!    which is the pure model's zenith where the field lies outside it.
//! 3. Iterations: each pixel takes the candidate closest to a reference field; the
//!    field is the confidence-weighted Gaussian average of the chosen normals plus the
//!    prior. Pixels with DoLP beyond the diffuse model or highlights
//!    ([`Cues::surely_specular`]) only get specular candidates. Elsewhere a specular
//!    candidate costs [`MIXED_PENALTY`]; when one still wins, the pixel is
//!    [`ReflectionType::Mixed`] (specular azimuth in a DoLP the diffuse model also
//!    explains). On an object whose rim is polarized across its outward normal
//!    ([`Prior::specular_rim`]: specular reflection dominates its light, as on glossy
//!    plastic under a bright sky or on metal) the diffuse candidates pay the penalty
//!    instead.
//! 4. Output: a pixel's chosen candidate where it lies within [`AGREEMENT_DEG`] of the
//!    last field, else the field (the chosen candidates averaged with their confidences
//!    over the field's window). A lone candidate carries its pixel's noise and, where it
//!    won the choice by a small margin, possibly the wrong reflection type; the average
//!    keeps what the neighbours agree on, and pixels without measurable polarization
//!    take their neighbours' shape.
//! 5. Rim: near the silhouette the field's window sees only the object's inner, flatter
//!    side, so its zenith falls short of the 90° a smooth occluding contour reaches. In
//!    the outer part of an object ([`RIM_SINE`]) behind a curved outline
//!    ([`RIM_CURVATURE`]; a straight outline may be a flat face's edge, a concave one a
//!    hole's), the output's zenith cosine moves [`RIM_PULL`] of the way toward the
//!    prior's where that is steeper, its azimuth kept.
//!
//! Concave regions are recovered only where smoothness carries the DoLP/AoLP evidence
//! against the convex prior (the prior is weak away from the contour).

use nalgebra::Vector3;
use polar_image::Gray;
use polar_imgproc::{
    Border, Connectivity, Outside, distance_to_background, gaussian_blur, gaussian_kernel, label,
    sep_filter,
};
use rayon::prelude::*;

use crate::cues::{Cues, image_direction, image_direction_angle};
use crate::foreground::has_contour;
use crate::{Estimate, ReflectionType, ShapeError};

/// Cost of explaining a pixel without specular evidence by the specular model.
pub const MIXED_PENALTY: f64 = 0.05;
/// Largest angle (degrees) between a pixel's chosen candidate and the field at which the
/// output keeps the candidate rather than the field.
pub const AGREEMENT_DEG: f64 = 5.0;
/// Gaussian sigma (pixels) of the smoothness field.
const FIELD_SIGMA: f64 = 2.0;
/// Weight of the boundary prior in the field.
const PRIOR_WEIGHT: f64 = 0.5;
/// Iterations of candidate choice and field update.
const ITERATIONS: usize = 6;
/// Depth (pixels from the background) of the boundary band whose polarization
/// [`verified_contour`] tests.
const CONTOUR_BAND: f64 = 2.0;
/// Gaussian sigma (pixels) along the boundary of that test.
const CONTOUR_SIGMA: f64 = 2.0;
/// How much farther (pixels) than the nearest boundary a verified contour may be for a
/// pixel to keep its prior.
const VERIFIED_SLACK: f64 = 1.0;
/// The rim of step 5: the prior's zenith sine (`1 − D/R`) at least this, the outer fifth
/// of the inscribed radius.
pub const RIM_SINE: f64 = 0.8;
/// Least curvature of the outline, times the object's inscribed radius `R`, for a rim of
/// step 5: the flattest point of a 2:1 ellipse's outline (a circle's is 1).
pub const RIM_CURVATURE: f64 = 0.25;
/// Share of the way from the output's zenith cosine to the prior's taken on a rim.
pub const RIM_PULL: f64 = 0.5;
/// Gaussian sigma (pixels) of the outline's curvature.
const CURVATURE_SIGMA: f64 = 1.5;

/// The prior of step 1: a unit normal and a weight per pixel.
pub struct Prior {
    /// Prior normals (camera frame).
    pub normal: Vec<Vector3<f64>>,
    /// Prior weight in `[0, 1]` (0 off the foreground or without any contour).
    pub weight: Vec<f64>,
    /// The pixel's object is specular-dominated at its rim (`specular_rims`).
    pub specular_rim: Vec<bool>,
    /// The pixel lies on a rim of step 5, where the output's zenith is raised.
    pub rim: Vec<bool>,
}

/// Where the objects' outline comes from, which decides how far the prior trusts it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outline<'a> {
    /// The foreground's, found in the image ([`crate::foreground::foreground`]): parts
    /// of it may be a cast shadow's edge or a cut through a missed part of an object, so
    /// the prior weighs only where the nearest boundary is a verified occluding contour.
    Found,
    /// The given object mask's (non-zero on objects, the image's size): all of it is the
    /// objects' occluding contour, unmeasured pixels at its edge (a saturated rim)
    /// included.
    Given(&'a [bool]),
}

/// Disambiguated normals of the foreground pixels.
pub fn disambiguate(cues: &Cues, fg: &[bool], outline: Outline) -> Result<Estimate, ShapeError> {
    disambiguate_with(cues, fg, &boundary_prior(cues, fg, outline)?)
}

/// [`disambiguate`] with a given prior.
pub fn disambiguate_with(cues: &Cues, fg: &[bool], prior: &Prior) -> Result<Estimate, ShapeError> {
    let n = cues.len();
    let bounds: Vec<Option<Bounds>> = (0..n)
        .into_par_iter()
        .map(|k| fg[k].then(|| Bounds::of(cues, k, prior.specular_rim[k])))
        .collect();
    let none = (Vector3::zeros(), ReflectionType::None, 0.0);
    let mut chosen: Vec<_> = (0..n).into_par_iter().map(|_| none).collect();
    let mut field = prior.normal.clone();
    let mut planes = FieldPlanes::new(cues.width, cues.height);
    for _ in 0..ITERATIONS {
        chosen.par_iter_mut().enumerate().for_each(|(k, c)| {
            *c = match &bounds[k] {
                Some(b) => choose_within(cues, k, b, &field[k]),
                None => none,
            };
        });
        smooth_field(cues, fg, &chosen, prior, &mut planes, &mut field)?;
    }
    let agreement = AGREEMENT_DEG.to_radians().cos();
    let normals = (0..n)
        .into_par_iter()
        .map(|k| match chosen[k] {
            (nc, kind, agree) if fg[k] && kind != ReflectionType::None && agree >= agreement => nc,
            // The field, zero off the foreground (smooth_field).
            _ => field[k],
        })
        .enumerate()
        .map(|(k, nv)| {
            if prior.rim[k] {
                toward_prior_zenith(&cues.frame(k).d, &nv, &prior.normal[k])
            } else {
                nv
            }
        })
        .collect();
    let confidence = (0..n)
        .into_par_iter()
        .map(|k| {
            let (_, kind, agree) = chosen[k];
            let penalty = if kind == ReflectionType::Mixed {
                0.5
            } else {
                1.0
            };
            let c = f64::from(cues.confidence[k]);
            if fg[k] {
                (c * agree.max(0.0) * penalty) as f32
            } else {
                0.0
            }
        })
        .collect();
    Ok(Estimate {
        normals,
        confidence,
        reflection: chosen.iter().map(|v| v.1).collect(),
        depth: None,
    })
}

/// What a pixel's candidates take from its polarization, fixed over the iterations: the
/// AoLP's direction and the cosines of the zenith bounds its DoLP sets for each
/// reflection type (cosines, so that choosing needs no trigonometry).
#[derive(Clone, Copy, Debug)]
struct Bounds {
    /// `cos α`, `sin α` of the AoLP `α`.
    aolp: [f32; 2],
    /// Cosine of the smallest diffuse zenith ([`crate::zenith::ZenithModels::diffuse_mixed`]).
    diffuse: f32,
    /// Cosines of the specular interval's ends `[θ₋, max(θ₊, θ₋)]`
    /// ([`crate::zenith::ZenithModels::specular_mixed`]).
    specular: [f32; 2],
    /// Only specular candidates ([`Cues::surely_specular`]).
    specular_only: bool,
    /// The diffuse candidates, not the specular ones, pay [`MIXED_PENALTY`]
    /// ([`Prior::specular_rim`]).
    specular_rim: bool,
}

impl Bounds {
    fn of(cues: &Cues, k: usize, specular_rim: bool) -> Self {
        let dolp = f64::from(cues.dolp[k]).max(0.0);
        let (lo, hi) = cues.models.specular(dolp);
        let (sin, cos) = f64::from(cues.aolp[k]).sin_cos();
        Self {
            aolp: [cos as f32, sin as f32],
            diffuse: cues.models.diffuse(dolp).cos() as f32,
            specular: [lo.cos() as f32, hi.max(lo).cos() as f32],
            specular_only: cues.surely_specular(k),
            specular_rim,
        }
    }
}

/// The candidate of pixel `k` closest to `reference` (largest `n · reference` minus the
/// type's cost): `(normal, type, n · reference)`. Each candidate's zenith is the
/// reference's zenith projected onto the zeniths its reflection type allows for the
/// pixel's DoLP (module doc).
pub fn choose(
    cues: &Cues,
    k: usize,
    reference: &Vector3<f64>,
) -> (Vector3<f64>, ReflectionType, f64) {
    choose_within(cues, k, &Bounds::of(cues, k, false), reference)
}

/// [`choose`] with the pixel's [`Bounds`]. In the pixel frame `(x_ref, y_ref, −d)` with
/// `u` the AoLP's direction and `v` the direction across it, the candidates are
/// `−d cos θ ± u sin θ` (diffuse) and `−d cos θ ± v sin θ` (specular), `θ` the
/// reference's zenith clamped to the type's bounds.
fn choose_within(
    cues: &Cues,
    k: usize,
    b: &Bounds,
    reference: &Vector3<f64>,
) -> (Vector3<f64>, ReflectionType, f64) {
    if !cues.valid[k] {
        return (*reference, ReflectionType::None, 1.0);
    }
    let f = cues.frame(k);
    let [ca, sa] = b.aolp.map(f64::from);
    let u = f.x_ref * ca + f.y_ref * sa;
    let v = f.y_ref * ca - f.x_ref * sa;
    // The reference's zenith cosine and its projections on u and v.
    let (c, pu, pv) = (-f.d.dot(reference), u.dot(reference), v.dot(reference));
    let sine = |cz: f64| (1.0 - cz * cz).max(0.0).sqrt();
    let [s_lo, s_hi] = b.specular.map(f64::from);
    let cs = c.clamp(s_lo.min(s_hi), s_lo);
    let ss = sine(cs);
    // (cos θ, sin θ, in-plane direction, score, type); `p` is `direction · reference`.
    let mut best = (1.0, 0.0, v, f64::NEG_INFINITY, ReflectionType::None);
    let mut consider = |cz: f64, sz: f64, dir: Vector3<f64>, p: f64, kind, cost: f64| {
        let score = c * cz + p * sz - cost;
        if score > best.3 {
            best = (cz, sz, dir, score, kind);
        }
    };
    if b.specular_only {
        consider(cs, ss, v, pv, ReflectionType::Specular, 0.0);
        consider(cs, ss, -v, -pv, ReflectionType::Specular, 0.0);
    } else {
        let cd = c.min(f64::from(b.diffuse));
        let sd = sine(cd);
        let (diffuse_cost, specular_cost) = if b.specular_rim {
            (MIXED_PENALTY, 0.0)
        } else {
            (0.0, MIXED_PENALTY)
        };
        consider(cd, sd, u, pu, ReflectionType::Diffuse, diffuse_cost);
        consider(cd, sd, -u, -pu, ReflectionType::Diffuse, diffuse_cost);
        consider(cs, ss, v, pv, ReflectionType::Mixed, specular_cost);
        consider(cs, ss, -v, -pv, ReflectionType::Mixed, specular_cost);
    }
    let (cz, sz, dir, _, kind) = best;
    let n = -f.d * cz + dir * sz;
    (n, kind, n.dot(reference))
}

/// `n` with its zenith cosine moved [`RIM_PULL`] of the way toward `prior`'s where that
/// is steeper, its azimuth about the ray `d` kept (step 5).
fn toward_prior_zenith(d: &Vector3<f64>, n: &Vector3<f64>, prior: &Vector3<f64>) -> Vector3<f64> {
    let c = -d.dot(n);
    let target = c.min(c + RIM_PULL * (-d.dot(prior) - c));
    match (n + d * c).try_normalize(1e-9) {
        Some(u) => -d * target + u * (1.0 - target * target).max(0.0).sqrt(),
        None => *n,
    }
}

/// The planes [`smooth_field`] blurs, allocated once for all iterations.
struct FieldPlanes {
    weighted: [Gray<f32>; 3],
    blurred: [Gray<f32>; 3],
}

impl FieldPlanes {
    fn new(w: usize, h: usize) -> Self {
        Self {
            weighted: std::array::from_fn(|_| Gray::new(w, h)),
            blurred: std::array::from_fn(|_| Gray::new(w, h)),
        }
    }
}

/// Confidence-weighted Gaussian average of the chosen normals plus the prior, normalised,
/// into `field`.
fn smooth_field(
    cues: &Cues,
    fg: &[bool],
    chosen: &[(Vector3<f64>, ReflectionType, f64)],
    prior: &Prior,
    planes: &mut FieldPlanes,
    field: &mut [Vector3<f64>],
) -> Result<(), ShapeError> {
    let [x, y, z] = &mut planes.weighted;
    (x.as_mut_slice(), y.as_mut_slice(), z.as_mut_slice())
        .into_par_iter()
        .enumerate()
        .for_each(|(k, (x, y, z))| {
            let wt = if fg[k] {
                0.05 + f64::from(cues.confidence[k])
            } else {
                0.0
            };
            let n = chosen[k].0 * wt;
            (*x, *y, *z) = (n.x as f32, n.y as f32, n.z as f32);
        });
    for (src, dst) in planes.weighted.iter().zip(&mut planes.blurred) {
        gaussian_blur(src, dst, 0, FIELD_SIGMA)?;
    }
    let [x, y, z] = planes.blurred.each_ref().map(|p| p.as_slice());
    field.par_iter_mut().enumerate().for_each(|(k, out)| {
        *out = if fg[k] {
            let avg = Vector3::new(f64::from(x[k]), f64::from(y[k]), f64::from(z[k]));
            let v = avg + prior.normal[k] * (PRIOR_WEIGHT * prior.weight[k]);
            v.try_normalize(1e-12).unwrap_or(prior.normal[k])
        } else {
            Vector3::zeros()
        };
    });
    Ok(())
}

/// The occluding-boundary prior of step 1 (module doc) over the foreground `fg`. It starts
/// the iterations everywhere, but on a found outline weighs in them only where the
/// nearest boundary is a verified occluding contour (`verified_contour`), or everywhere
/// when no part of the boundary is.
pub fn boundary_prior(cues: &Cues, fg: &[bool], outline: Outline) -> Result<Prior, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let n = w * h;
    let objects = match outline {
        Outline::Found => fg,
        Outline::Given(objects) => objects,
    };
    let dist = distance_to_background(objects, w, h, Outside::NotBackground);
    if dist.iter().all(|d| !d.is_finite()) {
        // No contour: the prior faces the camera and carries no weight.
        let normal = (0..n).map(|k| -cues.frame(k).d).collect();
        return Ok(Prior {
            normal,
            weight: vec![0.0; n],
            specular_rim: vec![false; n],
            rim: vec![false; n],
        });
    }
    let radius = component_max(objects, &dist, w, h)?;
    let outward = outward_directions(&dist, w, h)?;
    // Distance to the nearest verified contour: on a given outline, the outline itself.
    let to_verified = match outline {
        Outline::Found => {
            let seeds = verified_contour(cues, fg, &dist, &outward)?;
            if seeds.iter().any(|&s| s) {
                let not_seed: Vec<bool> = seeds.iter().map(|&s| !s).collect();
                distance_to_background(&not_seed, w, h, Outside::NotBackground)
            } else {
                dist.clone()
            }
        }
        Outline::Given(_) => dist.clone(),
    };
    let out: Vec<(Vector3<f64>, f64)> = (0..n)
        .into_par_iter()
        .map(|k| {
            let f = cues.frame(k);
            if !fg[k] {
                return (-f.d, 0.0);
            }
            let (dx, dy) = outward[k];
            let sin_z = prior_sine(dist[k], radius[k]);
            let Some(out) = image_direction(&f, dx, dy).filter(|_| dx.hypot(dy) >= 1e-6) else {
                return (-f.d, 0.0);
            };
            // Unverified: the prior still starts the iterations, without weight in them.
            let verified = to_verified[k] <= dist[k] + VERIFIED_SLACK;
            let cos_z = (1.0 - sin_z * sin_z).sqrt();
            (
                -f.d * cos_z + out * sin_z,
                f64::from(u8::from(verified)) * sin_z * sin_z,
            )
        })
        .collect();
    let curvature = outline_curvature(objects, &outward, w, h)?;
    let rim = (0..n)
        .map(|k| {
            fg[k]
                && prior_sine(dist[k], radius[k]) >= RIM_SINE
                && curvature[k] * radius[k] >= RIM_CURVATURE
        })
        .collect();
    Ok(Prior {
        normal: out.iter().map(|v| v.0).collect(),
        weight: out.iter().map(|v| v.1).collect(),
        specular_rim: specular_rims(cues, objects, &dist, &outward)?,
        rim,
    })
}

/// The prior's zenith sine `1 − D/R` at distance `dist` (pixels, from the pixel centre
/// half a pixel inside the outline) in an object of inscribed radius `radius`.
fn prior_sine(dist: f64, radius: f64) -> f64 {
    (1.0 - (dist - 0.5).max(0.0) / radius.max(1.0)).clamp(0.0, 1.0)
}

/// Curvature of the outline nearest each foreground pixel (1/pixels, positive where it
/// is convex): the divergence of the unit outward directions (a circle's level sets at
/// radius `r` give `1/r`), averaged over the foreground by a Gaussian of
/// [`CURVATURE_SIGMA`].
fn outline_curvature(
    fg: &[bool],
    outward: &[(f64, f64)],
    w: usize,
    h: usize,
) -> Result<Vec<f64>, ShapeError> {
    let unit = |k: usize| {
        let (x, y) = outward[k];
        let m = x.hypot(y);
        if m > 1e-9 { (x / m, y / m) } else { (0.0, 0.0) }
    };
    let div: Vec<f32> = (0..w * h)
        .into_par_iter()
        .map(|k| {
            if !fg[k] {
                return 0.0;
            }
            let (x, y) = (k % w, k / w);
            let dx = unit(y * w + (x + 1).min(w - 1)).0 - unit(y * w + x.saturating_sub(1)).0;
            let dy = unit((y + 1).min(h - 1) * w + x).1 - unit(y.saturating_sub(1) * w + x).1;
            (0.5 * (dx + dy)) as f32
        })
        .collect();
    let weights: Vec<f32> = fg.iter().map(|&f| f32::from(u8::from(f))).collect();
    let blur = |v: Vec<f32>| -> Result<Vec<f32>, ShapeError> {
        let mut dst = Gray::new(w, h);
        gaussian_blur(
            &Gray::from_vec(w, h, v).expect("sized"),
            &mut dst,
            0,
            CURVATURE_SIGMA,
        )?;
        Ok(dst.into_vec())
    };
    let (num, den) = (blur(div)?, blur(weights)?);
    Ok(num
        .iter()
        .zip(&den)
        .map(|(&a, &b)| if b > 0.0 { f64::from(a / b) } else { 0.0 })
        .collect())
}

/// `true` on the pixels of each 8-connected object whose polarization lies across its
/// outward normal along its rim: the DoLP-weighted mean of `cos 2Δ` (Δ = AoLP − outward
/// direction) over the band within [`CONTOUR_BAND`] pixels of the background is
/// negative. At an occluding contour diffuse light leaves polarized along the normal
/// (`cos 2Δ = +1`) and specular reflection across it (`−1`), so the sign says which of
/// the two dominates the object's light (a glossy plastic under a bright sky, a metal).
fn specular_rims(
    cues: &Cues,
    fg: &[bool],
    dist: &[f64],
    outward: &[(f64, f64)],
) -> Result<Vec<bool>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let (id, n) = polar_imgproc::mask::components(fg, w, h)?;
    let mut sums = vec![0.0f64; n + 1];
    for k in (0..w * h).filter(|&k| fg[k] && cues.valid[k] && dist[k] <= CONTOUR_BAND) {
        let (dx, dy) = outward[k];
        if dx.hypot(dy) < 1e-6 {
            continue;
        }
        let normal = image_direction_angle(&cues.frame(k), dx, dy);
        let delta = f64::from(cues.aolp[k]) - normal;
        sums[id[k] as usize] += f64::from(cues.dolp[k]) * (2.0 * delta).cos();
    }
    Ok(id
        .iter()
        .map(|&c| c != 0 && sums[c as usize] < 0.0)
        .collect())
}

/// Background pixels next to the part of the foreground's boundary that shows the
/// occluding-contour signature: within [`CONTOUR_BAND`] pixels of the background, the
/// AoLP parallel (diffuse) or perpendicular (specular) to the boundary's normal, i.e.
/// the local DoLP-weighted sum of `cos 4Δ` significant against random angles
/// ([`has_contour`] over a Gaussian window of [`CONTOUR_SIGMA`] along the boundary).
/// A cast shadow taken into the foreground, or a cut through an object whose rest it
/// missed, has no such signature and so does not steer the prior.
fn verified_contour(
    cues: &Cues,
    fg: &[bool],
    dist: &[f64],
    outward: &[(f64, f64)],
) -> Result<Vec<bool>, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let in_band = |k: usize| fg[k] && cues.valid[k] && dist[k] <= CONTOUR_BAND;
    let mut sums = [
        vec![0.0f32; w * h],
        vec![0.0f32; w * h],
        vec![0.0f32; w * h],
    ];
    for k in (0..w * h).filter(|&k| in_band(k)) {
        let (dx, dy) = outward[k];
        if dx.hypot(dy) < 1e-6 {
            continue;
        }
        let normal = image_direction_angle(&cues.frame(k), dx, dy);
        let rho = f64::from(cues.dolp[k]);
        sums[0][k] = (rho * (4.0 * (f64::from(cues.aolp[k]) - normal)).cos()) as f32;
        sums[1][k] = rho as f32;
        sums[2][k] = (rho * rho) as f32;
    }
    let g = gaussian_kernel((CONTOUR_SIGMA * 6.0).round() as usize | 1, CONTOUR_SIGMA)?;
    let g2: Vec<f32> = g.iter().map(|v| v * v).collect();
    let filter = |src: Vec<f32>, kernel: &[f32]| -> Result<Vec<f32>, ShapeError> {
        let src = Gray::from_vec(w, h, src).expect("sized");
        let mut dst = Gray::new(w, h);
        sep_filter(&src, &mut dst, kernel, kernel, Border::Reflect101)?;
        Ok(dst.into_vec())
    };
    let [c, r, r2] = sums;
    let (c, r, r2) = (filter(c, &g)?, filter(r, &g)?, filter(r2, &g2)?);
    let verified: Vec<bool> = (0..w * h)
        .map(|k| in_band(k) && has_contour(f64::from(c[k]), f64::from(r[k]), f64::from(r2[k])))
        .collect();
    Ok((0..w * h)
        .map(|k| !fg[k] && neighbours8(k, w, h).any(|j| verified[j]))
        .collect())
}

/// The 8-neighbours of pixel `k` inside a `w × h` image.
fn neighbours8(k: usize, w: usize, h: usize) -> impl Iterator<Item = usize> {
    let (x, y) = ((k % w) as isize, (k / w) as isize);
    let (w, h) = (w as isize, h as isize);
    (-1isize..=1)
        .flat_map(move |dy| (-1isize..=1).map(move |dx| (x + dx, y + dy)))
        .filter(move |&(a, b)| (a, b) != (x, y) && (0..w).contains(&a) && (0..h).contains(&b))
        .map(move |(a, b)| (b * w + a) as usize)
}

/// Outward directions `(−∂D/∂x, −∂D/∂y)` (image axes, y down, not normalised) of the
/// distance map `D` ([`distance_to_background`]) smoothed by a Gaussian of 1 pixel,
/// by central differences: away from the object, across its nearest contour.
pub fn outward_directions(dist: &[f64], w: usize, h: usize) -> Result<Vec<(f64, f64)>, ShapeError> {
    let src =
        Gray::from_vec(w, h, dist.iter().map(|&d| d.min(1e6) as f32).collect()).expect("sized");
    let mut smooth = Gray::new(w, h);
    gaussian_blur(&src, &mut smooth, 0, 1.0)?;
    let s = smooth.as_slice();
    let at = |x: usize, y: usize| f64::from(s[y * w + x]);
    Ok((0..w * h)
        .into_par_iter()
        .map(|k| {
            let (x, y) = (k % w, k / w);
            let gx = at((x + 1).min(w - 1), y) - at(x.saturating_sub(1), y);
            let gy = at(x, (y + 1).min(h - 1)) - at(x, y.saturating_sub(1));
            (-gx, -gy)
        })
        .collect())
}

/// Per foreground pixel, the largest distance in its 8-connected component.
fn component_max(fg: &[bool], dist: &[f64], w: usize, h: usize) -> Result<Vec<f64>, ShapeError> {
    let mask = Gray::from_vec(w, h, fg.iter().map(|&f| u8::from(f)).collect()).expect("sized");
    let mut labels = Gray::new(w, h);
    let count = label(&mask, &mut labels, Connectivity::Eight)?;
    let mut max = vec![0.0f64; count + 1];
    let l = labels.as_slice();
    for k in 0..w * h {
        if fg[k] && dist[k].is_finite() {
            let m = &mut max[l[k] as usize];
            *m = m.max(dist[k]);
        }
    }
    Ok(l.iter().map(|&c| max[c as usize]).collect())
}
