//! The global method: height from polarization and shading in one sparse linear
//! least-squares problem, after Smith, Ramamoorthi & Tozza, "Height-from-polarisation
//! with unknown lighting or albedo" (TPAMI 2019).
//!
//! Unknown: the depth `Z` of every foreground pixel; slopes are forward differences
//! `P = Z(x+1) − Z(x)`, `Q = Z(y+1) − Z(y)`, and the normal is `∝ (P, −Q, 1)` (see
//! [`crate::integrate`]). Rows, each linear in `Z`:
//! - polarization azimuth (ambiguity-free): the normal's image-plane direction is
//!   collinear with the azimuth `v` of the pixel's reflection type, `P v_y + Q v_x = 0`,
//!   weight = polarization confidence. A π flip does not change the row, so this
//!   constraint holds for both ambiguous normals;
//! - shading (resolves the flip): Lambertian `s = b·n + a` with `n = (P, −Q, 1) cos θ`, θ
//!   the zenith, gives `b_x P − b_y Q = (s − a)/cos θ − b_z` on the pixels the local
//!   method calls diffuse (specular and mixed light is not Lambertian); the light `b`
//!   (times albedo) and ambient `a` are fitted to the normalised brightness by least squares over
//!   confidently lit, non-specular foreground pixels (two passes, the second without
//!   residual outliers: shadows, highlights); the zenith comes from the local method;
//! - a weak pull (weight 0.05) toward the local method's slopes, which keeps regions
//!   without light or polarization attached, and a `1e-6` screening term fixing offsets.
//!
//! Deviation from the paper: the light is fitted to the local method's disambiguated
//! normals, not by the paper's ambiguity-free quadratic form. The normal equations are
//! solved with faer's sparse Cholesky; the depth comes out directly and the normals are
//! the solved surface's slopes.

use faer::sparse::Triplet;
use nalgebra::{Matrix4, Vector3, Vector4};
use polar_image::Gray;

use crate::cues::{Cues, HIGHLIGHT};
use crate::integrate::{MAX_SLOPE, finish, slopes, solve_spd};
use crate::{Estimate, ReflectionType, ShapeError};

/// Weight of the pull toward the local method's slopes.
const LOCAL_WEIGHT: f64 = 0.05;
/// Weight of a shading row relative to an azimuth row.
const SHADING_WEIGHT: f64 = 2.0;

/// Normals and depth by the global method from the local method's estimate `local` and
/// the light fitted to it ([`fit_light`]).
pub fn solve(
    cues: &Cues,
    fg: &[bool],
    local: Estimate,
    light: Option<&Light>,
) -> Result<Estimate, ShapeError> {
    let (w, h) = (cues.width, cues.height);
    let light = light.map(|l| (l.scaled_direction, l.ambient));
    let (p_loc, q_loc) = slopes(&local.normals, fg);
    let mut index = vec![usize::MAX; w * h];
    let mut count = 0;
    for (k, &f) in fg.iter().enumerate() {
        if f {
            index[k] = count;
            count += 1;
        }
    }
    if count == 0 {
        return Ok(Estimate {
            depth: Some(Gray::from_vec(w, h, vec![f32::NAN; w * h]).expect("sized")),
            ..local
        });
    }
    let mut sys = Normal::new(count);
    for k in 0..w * h {
        if !fg[k] {
            continue;
        }
        let (x, y) = (k % w, k / w);
        let right = (x + 1 < w && fg[k + 1]).then(|| index[k + 1]);
        let down = (y + 1 < h && fg[k + w]).then(|| index[k + w]);
        let i = index[k];
        // Rows on P and Q need both neighbours.
        if let (Some(r), Some(d)) = (right, down) {
            // Row c_p P + c_q Q = rhs with P = z_r − z_i, Q = z_d − z_i.
            let mut row = |cp: f64, cq: f64, rhs: f64, wt: f64| {
                sys.add(&[(r, cp), (d, cq), (i, -cp - cq)], rhs, wt);
            };
            let n = local.normals[k];
            let conf = f64::from(cues.confidence[k]);
            if cues.valid[k] && n.norm_squared() > 0.0 {
                let v = azimuth_direction(cues, k, local.reflection[k]);
                row(v.y, v.x, 0.0, conf);
                if let Some((b, a)) = light {
                    let s = f64::from(cues.s0n[k]);
                    let lit = b.dot(&n) + a;
                    let ok = local.reflection[k] == ReflectionType::Diffuse
                        && s < HIGHLIGHT
                        && lit > 0.05
                        && n.z > 0.1;
                    if ok {
                        row(b.x, -b.y, (s - a) / n.z - b.z, SHADING_WEIGHT);
                    }
                }
            }
        }
        if let Some(r) = right {
            sys.add(
                &[(r, 1.0), (i, -1.0)],
                0.5 * (p_loc[k] + p_loc[k + 1]),
                LOCAL_WEIGHT,
            );
        }
        if let Some(d) = down {
            sys.add(
                &[(d, 1.0), (i, -1.0)],
                0.5 * (q_loc[k] + q_loc[k + w]),
                LOCAL_WEIGHT,
            );
        }
    }
    let sol = sys.solve()?;
    let mut z = vec![0.0; w * h];
    for (k, &i) in index.iter().enumerate() {
        if i != usize::MAX {
            z[k] = sol[i];
        }
    }
    let normals = normals_from_depth(&z, fg, &local.normals, w, h);
    let depth = finish(&z, fg, w, h);
    Ok(Estimate {
        normals,
        confidence: local.confidence,
        reflection: local.reflection,
        depth: Some(depth),
    })
}

/// The image-plane direction `(v_x, v_y)` (camera x right, y up) of the azimuth that the
/// pixel's reflection type gives its normal (either sign).
fn azimuth_direction(cues: &Cues, k: usize, kind: ReflectionType) -> Vector3<f64> {
    let f = cues.frame(k);
    let alpha = f64::from(cues.aolp[k]);
    let az = match kind {
        ReflectionType::Specular | ReflectionType::Mixed => alpha + std::f64::consts::FRAC_PI_2,
        _ => alpha,
    };
    let v = f.in_plane(az);
    Vector3::new(v.x, v.y, 0.0)
        .try_normalize(1e-12)
        .unwrap_or_else(Vector3::x)
}

/// A distant light and ambient term fitted to the image: `s ≈ b·n + a` (Lambert), with `s`
/// the S0 normalised by the observation's robust scale ([`Cues::s0n`]) and `n` the normal.
/// Albedo and irradiance enter only as their product, so `|b|` is albedo × irradiance in
/// that unit, and `a` the albedo-weighted ambient light in the same unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// `b`: the unit direction toward the light (camera frame) times the strength.
    pub scaled_direction: Vector3<f64>,
    /// `a`: the light reaching every pixel whatever its normal.
    pub ambient: f64,
}

impl Light {
    /// Unit direction toward the light in the camera frame (x right, y up, z toward the
    /// camera); `None` for a zero fit.
    pub fn direction(&self) -> Option<Vector3<f64>> {
        self.scaled_direction.try_normalize(1e-12)
    }

    /// `|b|`: albedo × irradiance in units of the observation's robust S0 scale.
    pub fn strength(&self) -> f64 {
        self.scaled_direction.norm()
    }
}

/// Least-squares Lambertian [`Light`] over confidently lit diffuse pixels of the local
/// estimate, a second pass without residuals beyond 2.5 median absolute residuals
/// (shadows, highlights); `None` without enough pixels.
pub fn fit_light(cues: &Cues, fg: &[bool], local: &Estimate) -> Option<Light> {
    let usable: Vec<usize> = (0..cues.len())
        .filter(|&k| {
            fg[k]
                && cues.valid[k]
                && local.reflection[k] == ReflectionType::Diffuse
                && f64::from(cues.s0n[k]) < HIGHLIGHT
                && local.confidence[k] > 0.1
        })
        .collect();
    let mut keep = usable.clone();
    let mut fit = None;
    for _ in 0..2 {
        if keep.len() < 8 {
            return fit;
        }
        let mut ata = Matrix4::<f64>::zeros();
        let mut atb = Vector4::<f64>::zeros();
        for &k in &keep {
            let n = local.normals[k];
            let row = Vector4::new(n.x, n.y, n.z, 1.0);
            ata += row * row.transpose();
            atb += row * f64::from(cues.s0n[k]);
        }
        let x = ata.try_inverse()? * atb;
        let (b, a) = (Vector3::new(x[0], x[1], x[2]), x[3]);
        fit = Some(Light {
            scaled_direction: b,
            ambient: a,
        });
        let res: Vec<f64> = usable
            .iter()
            .map(|&k| (f64::from(cues.s0n[k]) - b.dot(&local.normals[k]) - a).abs())
            .collect();
        let mut sorted = res.clone();
        sorted.sort_by(f64::total_cmp);
        let mad = sorted[sorted.len() / 2].max(1e-9);
        keep = usable
            .iter()
            .zip(&res)
            .filter(|(_, r)| **r < 2.5 * mad)
            .map(|(&k, _)| k)
            .collect();
    }
    fit
}

/// Normals of the solved surface (forward differences, backward at the foreground's
/// edge); the local normal where a pixel has no foreground neighbour.
fn normals_from_depth(
    z: &[f64],
    fg: &[bool],
    fallback: &[Vector3<f64>],
    w: usize,
    h: usize,
) -> Vec<Vector3<f64>> {
    (0..w * h)
        .map(|k| {
            if !fg[k] {
                return Vector3::zeros();
            }
            let (x, y) = (k % w, k / w);
            let p = if x + 1 < w && fg[k + 1] {
                Some(z[k + 1] - z[k])
            } else if x > 0 && fg[k - 1] {
                Some(z[k] - z[k - 1])
            } else {
                None
            };
            let q = if y + 1 < h && fg[k + w] {
                Some(z[k + w] - z[k])
            } else if y > 0 && fg[k - w] {
                Some(z[k] - z[k - w])
            } else {
                None
            };
            match (p, q) {
                (Some(p), Some(q)) => {
                    let (p, q) = (
                        p.clamp(-MAX_SLOPE, MAX_SLOPE),
                        q.clamp(-MAX_SLOPE, MAX_SLOPE),
                    );
                    Vector3::new(p, -q, 1.0).normalize()
                }
                _ => fallback[k],
            }
        })
        .collect()
}

/// Normal equations `AᵀW A z = AᵀW b` of a sparse least-squares problem, accumulated row
/// by row (the lower triangle of `AᵀW A`: [`solve_spd`] reads no more).
struct Normal {
    trips: Vec<Triplet<usize, usize, f64>>,
    rhs: Vec<f64>,
}

impl Normal {
    fn new(n: usize) -> Self {
        Self {
            trips: (0..n).map(|i| Triplet::new(i, i, 1e-6)).collect(),
            rhs: vec![0.0; n],
        }
    }

    /// Adds the row `Σ c_j z_j = b` with weight `wt`.
    fn add(&mut self, row: &[(usize, f64)], b: f64, wt: f64) {
        if wt <= 0.0 || !b.is_finite() {
            return;
        }
        for &(i, ci) in row {
            self.rhs[i] += wt * ci * b;
            for &(j, cj) in row.iter().filter(|&&(j, _)| j <= i) {
                self.trips.push(Triplet::new(i, j, wt * ci * cj));
            }
        }
    }

    fn solve(&self) -> Result<Vec<f64>, ShapeError> {
        solve_spd(self.rhs.len(), &self.trips, &self.rhs)
    }
}
