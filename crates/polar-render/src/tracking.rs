//! Distance sampling and transmittance in the medium: analytic for a
//! homogeneous medium, delta tracking (free flights) and ratio tracking
//! (transmittance) against the grid's majorant for a heterogeneous one
//! (Novák et al. 2014, "Residual ratio tracking for estimating attenuation in
//! participating media"), and the exact optical depth for the ground truth.

use crate::math::Vec3;
use crate::medium::Medium;
use crate::sampler::Sampler;

/// What happens to a ray segment in the medium.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Flight<'a> {
    /// A real scattering event at distance `t` in `medium`; the throughput is
    /// multiplied by `weight`.
    Scatter {
        t: f64,
        weight: f64,
        medium: &'a Medium,
    },
    /// The ray reaches the end of its segment; the throughput is multiplied by `weight`.
    Pass { weight: f64 },
}

/// The parameter interval where the ray `o + t d` (`t ≥ 0`) lies inside the box,
/// clipped to `t < t_max` (slab test; `None` when empty).
pub(crate) fn clip(m: &Medium, o: &Vec3, d: &Vec3, t_max: f64) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0_f64, t_max);
    for a in 0..3 {
        let inv = 1.0 / d[a];
        let (lo, hi) = (
            (m.bounds_min[a] - o[a]) * inv,
            (m.bounds_max[a] - o[a]) * inv,
        );
        // NaN (ray in a slab plane, parallel to it) leaves the bounds unchanged.
        t0 = t0.max(lo.min(hi));
        t1 = t1.min(lo.max(hi));
    }
    (t0 < t1).then_some((t0, t1))
}

/// An exponential step of rate `rate` (`rate > 0`) for the uniform number `u`.
/// Tracking draws its numbers in data-dependent counts, so from the sampler's free
/// stream, except a flight's first step (see [`Sampler::next_flight`]).
fn step(rate: f64, u: f64) -> f64 {
    -(1.0 - u).ln() / rate
}

/// Samples the first scattering event along `o + t d`, `t < t_max`. Homogeneous:
/// `t ∝ σ_t e^{−σ_t t}`, weight `σ_s / σ_t` at an event and 1 past the end. Grid:
/// delta tracking with majorant `σ_t · max density`, the same weights. Without
/// scattering (`σ_s = 0`) no event is sampled and the weight is the transmittance.
#[inline(always)]
pub(crate) fn flight<'a>(
    m: &'a Medium,
    o: &Vec3,
    d: &Vec3,
    t_max: f64,
    sampler: &mut Sampler,
) -> Flight<'a> {
    let Some((t0, t1)) = clip(m, o, d, t_max) else {
        return Flight::Pass { weight: 1.0 };
    };
    if m.sigma_s == 0.0 {
        return Flight::Pass {
            weight: transmittance(m, o, d, t_max, sampler),
        };
    }
    let albedo = m.sigma_s / m.sigma_t();
    let majorant = m.sigma_t() * m.density.as_ref().map_or(1.0, |g| g.max());
    if majorant == 0.0 {
        return Flight::Pass { weight: 1.0 };
    }
    let mut t = t0 + step(majorant, sampler.next_flight());
    loop {
        if t >= t1 {
            return Flight::Pass { weight: 1.0 };
        }
        // Homogeneous: every tentative collision is real (no random number spent).
        let real = match &m.density {
            None => true,
            Some(_) => sampler.next_free() * majorant < m.sigma_t() * m.density_at(&(o + t * d)),
        };
        if real {
            return Flight::Scatter {
                t,
                weight: albedo,
                medium: m,
            };
        }
        t += step(majorant, sampler.next_free());
    }
}

/// Transmittance `exp(−∫ σ_t ds)` of the segment `o + t d`, `t < t_max`: analytic for a
/// homogeneous medium, an unbiased ratio-tracking estimate `∏ (1 − σ_t(x_i) / σ̄)` for a grid.
pub(crate) fn transmittance(
    m: &Medium,
    o: &Vec3,
    d: &Vec3,
    t_max: f64,
    sampler: &mut Sampler,
) -> f64 {
    let Some((t0, t1)) = clip(m, o, d, t_max) else {
        return 1.0;
    };
    let Some(grid) = &m.density else {
        return (-m.sigma_t() * (t1 - t0)).exp();
    };
    let majorant = m.sigma_t() * grid.max();
    if majorant == 0.0 {
        return 1.0;
    }
    let (mut t, mut tr) = (t0, 1.0);
    loop {
        t += step(majorant, sampler.next_free());
        if t >= t1 {
            return tr;
        }
        tr *= 1.0 - m.sigma_t() * m.density_at(&(o + t * d)) / majorant;
    }
}

/// Optical depth `∫ σ_t ds` along `o + t d`, `t < t_max`, exactly (up to rounding):
/// on a grid the segment is split where it crosses a plane of cell centres, inside
/// which the trilinear density is a cubic in `t`, integrated exactly by Simpson's rule.
pub(crate) fn optical_depth(m: &Medium, o: &Vec3, d: &Vec3, t_max: f64) -> f64 {
    let Some((t0, t1)) = clip(m, o, d, t_max) else {
        return 0.0;
    };
    let Some(grid) = &m.density else {
        return m.sigma_t() * (t1 - t0);
    };
    let mut cuts = vec![t0, t1];
    for a in 0..3 {
        let n = grid.resolution[a];
        let size = m.bounds_max[a] - m.bounds_min[a];
        cuts.extend((0..n).map(|i| {
            let plane = m.bounds_min[a] + (i as f64 + 0.5) / n as f64 * size;
            (plane - o[a]) / d[a]
        }));
    }
    cuts.retain(|t| *t >= t0 && *t <= t1);
    cuts.sort_by(f64::total_cmp);
    let density = |t: f64| m.density_at(&(o + t * d));
    let integral: f64 = cuts
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            (b - a) / 6.0 * (density(a) + 4.0 * density(0.5 * (a + b)) + density(b))
        })
        .sum();
    m.sigma_t() * integral
}
