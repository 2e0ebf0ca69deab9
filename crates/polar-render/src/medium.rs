//! A participating medium (haze, fog) filling an axis-aligned box: scattering
//! and absorption coefficients, a polarized phase function
//! (`polar_optics::scatter`) and an optional density grid that scales both
//! coefficients. The medium fills the whole box, including the inside of the
//! shapes in it (a limit: a glass object in fog holds fog too).

use crate::math::Vec3;
use polar_optics::OpticsError;
use polar_optics::Polarization;
use polar_optics::scatter::PhaseFunction;

/// A homogeneous or grid-modulated medium in the box `[bounds_min, bounds_max]`;
/// vacuum outside. Coefficients are per scene length unit.
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    /// Lower corner of the box.
    pub bounds_min: Vec3,
    /// Upper corner of the box (each component greater than `bounds_min`'s).
    pub bounds_max: Vec3,
    /// Scattering coefficient `σ_s ≥ 0` (at density 1).
    pub sigma_s: f64,
    /// Absorption coefficient `σ_a ≥ 0` (at density 1).
    pub sigma_a: f64,
    /// The phase function (normalised: `∫ M00 dΩ = 1`).
    pub phase: PhaseFunction,
    /// Density multiplying `σ_s` and `σ_a`; `None` is density 1 everywhere.
    pub density: Option<DensityGrid>,
}

/// Density values at the centres of a regular grid of cells over the medium's
/// box, `x` fastest; trilinear between centres, constant beyond the outer
/// centres (clamped, as a cell-centred texture).
#[derive(Clone, Debug, PartialEq)]
pub struct DensityGrid {
    /// Cells along x, y, z (each at least 1).
    pub resolution: [usize; 3],
    /// `nx · ny · nz` finite, non-negative values, index `x + nx (y + ny z)`.
    pub values: Vec<f64>,
}

/// Cells along an axis that the height of a height fog varies on.
const FOG_CELLS: usize = 64;

impl DensityGrid {
    /// Height fog `exp(−h / falloff)` with `h = up · (p − p_low)` the height above the
    /// lowest corner of the box (density 1 there), sampled at cell centres. `resolution`
    /// defaults to 64 cells along every axis `up` has a component on and 1 on the others
    /// (trilinear error about `(Δh / falloff)² / 8` relative).
    pub fn height_fog(
        bounds_min: &Vec3,
        bounds_max: &Vec3,
        up: &Vec3,
        falloff: f64,
        resolution: Option<[usize; 3]>,
    ) -> Self {
        let up = up.normalize();
        let resolution = resolution
            .unwrap_or_else(|| [0, 1, 2].map(|a| if up[a] == 0.0 { 1 } else { FOG_CELLS }));
        let size = bounds_max - bounds_min;
        let low = (0..3).map(|a| {
            if up[a] > 0.0 {
                bounds_min[a]
            } else {
                bounds_max[a]
            }
        });
        let low = Vec3::from_iterator(low);
        let [nx, ny, nz] = resolution;
        let values = (0..nx * ny * nz)
            .map(|i| {
                let cell = [i % nx, (i / nx) % ny, i / (nx * ny)];
                let p = Vec3::from_fn(|a, _| {
                    bounds_min[a] + (cell[a] as f64 + 0.5) / resolution[a] as f64 * size[a]
                });
                (-up.dot(&(p - low)) / falloff).exp()
            })
            .collect();
        Self { resolution, values }
    }

    /// Largest value (the majorant of delta and ratio tracking).
    pub fn max(&self) -> f64 {
        self.values.iter().copied().fold(0.0, f64::max)
    }

    /// Trilinear density at `u` in box coordinates (`[0, 1]³` spans the box).
    pub fn at(&self, u: &Vec3) -> f64 {
        let [nx, ny, _] = self.resolution;
        // Per axis: the two neighbouring centres and the weight of the upper one.
        let axis = |a: usize| {
            let n = self.resolution[a];
            let x = (u[a] * n as f64 - 0.5).clamp(0.0, (n - 1) as f64);
            let i = (x as usize).min(n.saturating_sub(2));
            (i, (i + 1).min(n - 1), x - i as f64)
        };
        let (x, y, z) = (axis(0), axis(1), axis(2));
        let v = |i, j, k| self.values[i + nx * (j + ny * k)];
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let plane = |k| {
            lerp(
                lerp(v(x.0, y.0, k), v(x.1, y.0, k), x.2),
                lerp(v(x.0, y.1, k), v(x.1, y.1, k), x.2),
                y.2,
            )
        };
        lerp(plane(z.0), plane(z.1), z.2)
    }

    /// Checks the size and the values: `Err((key under density, reason))`.
    fn validate(&self) -> Result<(), (&'static str, String)> {
        let cells = check_resolution(self.resolution).map_err(|r| ("resolution", r))?;
        if cells != self.values.len() {
            return Err((
                "values",
                format!(
                    "{} values for resolution {:?} ({cells} cells)",
                    self.values.len(),
                    self.resolution,
                ),
            ));
        }
        if let Some((i, v)) = self
            .values
            .iter()
            .enumerate()
            .find(|(_, v)| !(v.is_finite() && **v >= 0.0))
        {
            return Err((
                "values",
                format!("values[{i}] = {v}: densities must be finite and >= 0"),
            ));
        }
        Ok(())
    }
}

/// Largest density grid (cells) a scene may have: 128 MiB of values, far finer than the
/// smooth media it describes.
pub const MAX_DENSITY_CELLS: usize = 1 << 24;

/// The number of cells of a grid `resolution`: at least 1 per axis, at most
/// [`MAX_DENSITY_CELLS`] in all (checked without overflow).
pub(crate) fn check_resolution(resolution: [usize; 3]) -> Result<usize, String> {
    if resolution.contains(&0) {
        return Err(format!("{resolution:?}: every axis needs at least 1 cell"));
    }
    resolution
        .iter()
        .try_fold(1_usize, |a, &n| a.checked_mul(n))
        .filter(|&c| c <= MAX_DENSITY_CELLS)
        .ok_or_else(|| format!("{resolution:?}: more than {MAX_DENSITY_CELLS} cells"))
}

impl Medium {
    /// Extinction coefficient `σ_t = σ_s + σ_a` at density 1.
    pub fn sigma_t(&self) -> f64 {
        self.sigma_s + self.sigma_a
    }

    /// The cheapest exact transport model for this medium: none without scattering,
    /// else its phase function's ([`Polarization::of_phase`]).
    pub fn polarization(&self) -> Polarization {
        if self.sigma_s == 0.0 {
            Polarization::None
        } else {
            Polarization::of_phase(&self.phase)
        }
    }

    /// Checks every value: `Err((key under medium, reason))`.
    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        let (lo, hi) = (&self.bounds_min, &self.bounds_max);
        for (k, v) in [("bounds_min", lo), ("bounds_max", hi)] {
            if !v.iter().all(|c| c.is_finite()) {
                return Err((k.into(), format!("not finite: {:?}", v.as_slice())));
            }
        }
        if (0..3).any(|a| lo[a] >= hi[a]) {
            return Err((
                "bounds_max".into(),
                format!(
                    "must exceed bounds_min on every axis: min {:?}, max {:?}",
                    lo.as_slice(),
                    hi.as_slice()
                ),
            ));
        }
        for (k, v) in [("sigma_s", self.sigma_s), ("sigma_a", self.sigma_a)] {
            if !(v >= 0.0 && v.is_finite()) {
                return Err((k.into(), format!("must be finite and >= 0, got {v}")));
            }
        }
        self.phase
            .validate()
            .map_err(|e| (phase_key(&e), e.to_string()))?;
        if let Some(d) = &self.density {
            d.validate().map_err(|(k, r)| (format!("density.{k}"), r))?;
        }
        Ok(())
    }

    /// The point `p` in box coordinates (`[0, 1]³` spans the box).
    pub(crate) fn box_coordinates(&self, p: &Vec3) -> Vec3 {
        (p - self.bounds_min).component_div(&(self.bounds_max - self.bounds_min))
    }

    /// Density at world point `p` (1 without a grid).
    pub(crate) fn density_at(&self, p: &Vec3) -> f64 {
        self.density
            .as_ref()
            .map_or(1.0, |g| g.at(&self.box_coordinates(p)))
    }
}

/// The scene-file key under `medium` that a phase-function error is about.
pub(crate) fn phase_key(e: &OpticsError) -> String {
    match e {
        OpticsError::OutOfRange { name, .. } if name.starts_with("relative_index") => {
            "phase.ior".into()
        }
        OpticsError::OutOfRange { name, .. } => format!("phase.{name}"),
        _ => "phase".into(),
    }
}
