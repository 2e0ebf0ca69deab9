//! The sampling settings of a render and the depth limits they are checked against.

use crate::sampler::SamplerKind;

/// Russian roulette starts at this bounce (Mitsuba's default `rr_depth`): earlier,
/// it mostly kills glass paths whose throughput is still near 1, adding variance.
pub const RR_DEPTH: u32 = 5;

/// The deepest [`RenderSettings::split_depth`]: split paths stay above Russian
/// roulette, which divides their share out.
pub const MAX_SPLIT_DEPTH: u32 = RR_DEPTH;

/// Sampling settings.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Samples per pixel.
    pub spp: u32,
    /// Seed of the per-pixel sample streams.
    pub seed: u64,
    /// Maximum number of scattering events on a path (1 = direct lighting only).
    pub max_depth: u32,
    /// Vertices before this depth trace both outcomes of a lobe choice instead of
    /// drawing one: the camera vertex of glass and plastic, and every smooth-glass
    /// vertex (0 = never; at most [`MAX_SPLIT_DEPTH`], where Russian roulette starts).
    pub split_depth: u32,
    /// Where the sample points come from (Owen-scrambled Sobol by default).
    pub sampler: SamplerKind,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            spp: 64,
            seed: 0,
            max_depth: 8,
            split_depth: MAX_SPLIT_DEPTH,
            sampler: SamplerKind::Sobol,
        }
    }
}
