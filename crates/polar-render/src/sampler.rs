//! Per-sample random numbers: every number is a pure function of
//! `(seed, pixel, sample index, dimension)`, so the image does not depend on how
//! pixels are scheduled over threads.
//!
//! Two kinds of numbers. *Aligned draws* ([`Sampler::next_1d`], `next_2d`,
//! `next_3d`) are made in the same order by every sample of a pixel (camera jitter,
//! then per bounce the light, the BSDF and Russian roulette), so draw `j` of every
//! sample integrates the same dimension: with [`SamplerKind::Sobol`] they are
//! low-discrepancy. *Free* numbers ([`Sampler::next_free`]) are drawn in
//! data-dependent counts (delta and ratio tracking) and always come from an
//! independent hash stream, so they never shift the aligned draws.
//!
//! With [`SamplerKind::Sobol`], the *path point* ([`Sampler::next_scatter`]) draws
//! the first bounce, the first flight step in a medium and the choices of delta
//! vertices jointly with the camera jitter; other draws are padded (each its own
//! Owen-scrambled point). A Sobol draw costs more than hash numbers; its error
//! against independent numbers at equal samples per pixel, scene by scene, is in
//! docs/performance-notes.md.

use serde::Deserialize;

/// Where the aligned draws come from (`[render] sampler` in a scene file).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SamplerKind {
    /// Owen-scrambled Sobol points (Burley 2020, "Practical Hash-based Owen
    /// Scrambling", crate `sobol_burley`), padded: draw `j` takes Sobol dimensions
    /// 0–3 under its own per-pixel scramble seed, so every 2-D pair is a (0,2)-sequence
    /// and there is no dimension limit; except the first bounce and the lobe choices
    /// of delta vertices, which continue the camera draw's point
    /// ([`Sampler::next_scatter`]).
    #[default]
    Sobol,
    /// Independent uniform numbers (SplitMix64 of the sample key and a counter).
    Independent,
}

/// SplitMix64's increment (the golden ratio in 64 bits).
const GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// Domain separators, so Sobol seeds and low bits never reuse a hash stream input.
const SEED_DOMAIN: u64 = 0x5b0b_5eed_0000_0000;
const LOW_BITS_DOMAIN: u64 = 0x10e5_b175_0000_0000;
const PATH_LOW_BITS_DOMAIN: u64 = 0x9a7b_b175_0000_0000;
const BRANCH_DOMAIN: u64 = 0xb2a4_c400_0000_0000;

/// Spacing of the aligned draws of the paths split off one sample's path: split
/// `n` draws from `(n + 1) · BRANCH_DRAWS` on. A path makes at most 3 draws per
/// vertex, so only a path past vertex 349,525 (Russian roulette ends paths long
/// before) would reach the next split's scramble seeds: correlated numbers, still
/// unbiased.
const BRANCH_DRAWS: u64 = 1 << 20;

/// `sobol_burley` supports sample indices below 2^16; each further block of 2^16
/// samples gets its own scramble seed (an independent Owen-scrambled net).
const SOBOL_INDEX_BITS: u32 = 16;

/// `2^-53`, the spacing of the f64 grid on `[0, 1)` we sample.
const ULP_53: f64 = 1.0 / (1u64 << 53) as f64;

/// SplitMix64 finaliser (Steele et al. 2014): a bijective 64-bit mixer.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The streams of every sample of one pixel: hashes the seed and pixel once.
#[derive(Clone, Copy, Debug)]
pub struct PixelStreams {
    key: u64,
    kind: SamplerKind,
}

impl PixelStreams {
    /// The streams of pixel `pixel` under `seed`, aligned draws of kind `kind`.
    pub fn new(seed: u64, pixel: u64, kind: SamplerKind) -> Self {
        Self {
            key: mix(mix(seed) ^ pixel),
            kind,
        }
    }

    /// The stream of sample `sample` (the same as [`Sampler::new`]).
    pub fn sample(&self, sample: u64) -> Sampler {
        Sampler {
            key: mix(self.key ^ sample.wrapping_mul(GAMMA)),
            pixel: self.key,
            sample,
            kind: self.kind,
            dimension: 0,
            draw: 0,
            path_set: None,
            path_next: 0,
        }
    }
}

/// One pixel sample's numbers.
#[derive(Clone, Debug)]
pub struct Sampler {
    /// Key of this sample's hash stream.
    key: u64,
    /// Key of the pixel (the Sobol scramble seeds depend on it and the draw only).
    pixel: u64,
    sample: u64,
    kind: SamplerKind,
    /// Counter of the hash stream.
    dimension: u64,
    /// Index of the next aligned draw.
    draw: u64,
    /// The last computed dimension set (4 dimensions) of the path point.
    path_set: Option<(u32, [f32; 4])>,
    /// The path point's next unused dimension.
    path_next: u32,
}

impl Sampler {
    /// The stream of sample `sample` of pixel `pixel` under `seed`.
    pub fn new(seed: u64, pixel: u64, sample: u64, kind: SamplerKind) -> Self {
        PixelStreams::new(seed, pixel, kind).sample(sample)
    }

    /// The next number of the hash stream, uniform in `[0, 1)` (53 random bits):
    /// SplitMix64's output for state `key + dimension · γ`. For numbers drawn in
    /// data-dependent counts.
    pub fn next_free(&mut self) -> f64 {
        self.dimension += 1;
        let bits = mix(self.key.wrapping_add(self.dimension.wrapping_mul(GAMMA)));
        (bits >> 11) as f64 * ULP_53
    }

    /// Aligned draw of one number in `[0, 1)`.
    pub fn next_1d(&mut self) -> f64 {
        match self.kind {
            SamplerKind::Sobol => self.sobol::<1>()[0],
            SamplerKind::Independent => self.next_free(),
        }
    }

    /// Aligned draw of a 2-D point in `[0, 1)²` (Sobol dimensions 0 and 1).
    #[inline(always)]
    pub fn next_2d(&mut self) -> [f64; 2] {
        match self.kind {
            SamplerKind::Sobol => self.sobol::<2>(),
            SamplerKind::Independent => [self.next_free(), self.next_free()],
        }
    }

    /// Aligned draw of three numbers for "choose, then sample a 2-D point":
    /// `u[0]` is Sobol dimension 2, `(u[1], u[2])` dimensions 0 and 1, a
    /// (0,2)-sequence, as the BSDFs and lights use them.
    #[inline(always)]
    pub fn next_3d(&mut self) -> [f64; 3] {
        match self.kind {
            SamplerKind::Sobol => {
                let [a, b, c] = self.sobol::<3>();
                [c, a, b]
            }
            SamplerKind::Independent => [self.next_free(), self.next_free(), self.next_free()],
        }
    }

    /// Skips one [`Self::next_3d`] draw without computing it: the later numbers
    /// are the same as if it had been drawn.
    pub fn skip_3d(&mut self) {
        match self.kind {
            SamplerKind::Sobol => self.draw += 1,
            SamplerKind::Independent => self.dimension += 3,
        }
    }

    /// Aligned draw for sampling the BSDF (or phase function) of the vertex at path
    /// depth `depth` (0: the camera ray's vertex), as [`Self::next_3d`] orders it:
    /// `u[0]` chooses a lobe (used if `choice`), `(u[1], u[2])` samples a direction
    /// (used if `point`; not by a vertex with only delta lobes).
    ///
    /// With Sobol, the numbers that matter most come from one point, the *path point*,
    /// in the order the path uses them: the camera jitter ([`Self::next_2d`]), each
    /// flight's first number in a medium ([`Self::next_flight`]), the first vertex's
    /// choice and direction, and the choices of the delta vertices after it (glass).
    /// Where the first bounce, the distance to the first scattering in a medium and
    /// the chain of reflect/refract choices depend on the position in the pixel, this
    /// stratifies them jointly; padded draws only stratify each draw by itself. Other
    /// vertices keep a padded 3-D draw, whose choice and 2-D point are stratified
    /// together. Numbers not used take the place of free ones but are not
    /// computed (NaN, see `path_or_free`); where the integrator traces both
    /// outcomes of a choice (the camera vertex of glass and plastic, smooth glass
    /// above `split_depth`), `u[0]` is drawn and not used, so with the default
    /// split depth the path point chooses only at glass vertices from depth 5 on.
    #[inline(always)]
    pub fn next_scatter(&mut self, depth: u32, choice: bool, point: bool) -> [f64; 3] {
        if self.kind == SamplerKind::Independent || (depth > 0 && point) {
            return self.next_3d();
        }
        self.draw += 1;
        let u0 = self.path_or_free(choice);
        let u1 = self.path_or_free(point);
        [u0, u1, self.path_or_free(point)]
    }

    /// The stream of the `n`-th path split off this sample's path (both outcomes
    /// of a lobe choice, see the integrator; `n` counts the sample's splits): its
    /// aligned draws continue this stream's under other scramble seeds (each still
    /// stratified over the pixel's samples, and apart from every other split's), its
    /// free numbers come from another hash key, and it has no path point (its delta
    /// vertices choose with free numbers), so that its numbers are independent of
    /// the other paths'.
    pub fn branch(&self, n: u64) -> Sampler {
        Sampler {
            key: mix(self.key ^ BRANCH_DOMAIN.wrapping_add(n.wrapping_mul(GAMMA))),
            draw: (n + 1) * BRANCH_DRAWS + self.draw % BRANCH_DRAWS,
            path_set: None,
            path_next: sobol_burley::NUM_DIMENSIONS,
            ..self.clone()
        }
    }

    /// The number for the first free-flight step of a ray in a medium: the path
    /// point's next dimension with Sobol (see [`Self::next_scatter`]), else a free
    /// number. Further steps, in data-dependent counts, take free numbers.
    #[inline(always)]
    pub fn next_flight(&mut self) -> f64 {
        match self.kind {
            SamplerKind::Sobol => self.path_or_free(true),
            SamplerKind::Independent => self.next_free(),
        }
    }

    /// The path point's next dimension if `used` (past its last, a free number).
    /// A number not used is a free one that is skipped, not computed (NaN: a BSDF
    /// reading it would show; polar-bsdf's tests/sample_reads.rs checks that none does).
    #[inline(always)]
    fn path_or_free(&mut self, used: bool) -> f64 {
        if !used {
            self.dimension += 1;
            f64::NAN
        } else if self.path_next < sobol_burley::NUM_DIMENSIONS {
            self.path_next += 1;
            self.path_dim(self.path_next - 1)
        } else {
            self.next_free()
        }
    }

    /// Dimension `dim` of this sample's path point: the Sobol point of the camera
    /// draw (draw 0, whose scramble seed it shares), continued to higher dimensions.
    #[inline(always)]
    fn path_dim(&mut self, dim: u32) -> f64 {
        let set = dim / 4;
        let x = match self.path_set {
            Some((s, x)) if s == set => x,
            _ => {
                let x = sobol_burley::sample_4d(self.index(), set, self.seed(0));
                self.path_set = Some((set, x));
                x
            }
        };
        fill_low_bits(
            x[(dim % 4) as usize],
            self.key ^ PATH_LOW_BITS_DOMAIN,
            u64::from(dim),
        )
    }

    /// The sample's index within its block of 2^16 samples.
    fn index(&self) -> u32 {
        (self.sample & ((1 << SOBOL_INDEX_BITS) - 1)) as u32
    }

    /// The Owen scramble seed of aligned draw `draw` (per pixel, draw and block of 2^16 samples).
    fn seed(&self, draw: u64) -> u32 {
        let block = self.sample >> SOBOL_INDEX_BITS;
        let seed_input = SEED_DOMAIN ^ (draw | block << 32).wrapping_mul(GAMMA);
        (mix(self.pixel ^ seed_input) >> 32) as u32
    }

    /// The first `N` dimensions of this sample's point in the padded Sobol set of
    /// the next draw, as f64.
    ///
    /// `sobol_burley` returns f32 multiples of `2^-23` (23 bits; checked by a test).
    /// Below the net's resolution an Owen scramble makes every further digit an
    /// independent fair bit, so we continue the scramble with 30 hash bits:
    /// `x + r · 2^-53`, `r < 2^30`, which is exact in f64, uniform on the `2^-53`
    /// grid of `[0, 1)` and at most `1 − 2^-53` (never 1).
    #[inline(always)]
    fn sobol<const N: usize>(&mut self) -> [f64; N] {
        let x = sobol_burley::sample_4d(self.index(), 0, self.seed(self.draw));
        if self.draw == 0 {
            // The camera draw is the path point's first set and dimensions (see `path_dim`).
            self.path_set = Some((0, x));
            self.path_next = N as u32;
        }
        let low_key = self.key ^ LOW_BITS_DOMAIN ^ (4 * self.draw).wrapping_mul(GAMMA);
        self.draw += 1;
        std::array::from_fn(|lane| fill_low_bits(x[lane], low_key, lane as u64))
    }
}

/// `x + r · 2^-53` with `r < 2^30` hash bits of `(key, lane)`: see `Sampler::sobol`.
fn fill_low_bits(x: f32, key: u64, lane: u64) -> f64 {
    let r = mix(key.wrapping_add(lane.wrapping_mul(GAMMA))) >> 34;
    f64::from(x) + r as f64 * ULP_53
}

#[cfg(test)]
mod tests {
    use super::*;

    const KINDS: [SamplerKind; 2] = [SamplerKind::Sobol, SamplerKind::Independent];

    fn draws(kind: SamplerKind, sample: u64) -> Vec<f64> {
        let mut s = Sampler::new(1, 2, sample, kind);
        (0..4).flat_map(|_| s.next_3d()).collect()
    }

    #[test]
    fn streams_are_reproducible_and_distinct() {
        for kind in KINDS {
            assert_eq!(draws(kind, 3), draws(kind, 3));
            assert_ne!(draws(kind, 3), draws(kind, 4));
        }
    }

    #[test]
    fn skip_is_drawing_and_discarding() {
        for kind in KINDS {
            let (mut a, mut b) = (Sampler::new(1, 2, 3, kind), Sampler::new(1, 2, 3, kind));
            a.next_3d();
            b.skip_3d();
            assert_eq!(a.next_1d(), b.next_1d());
        }
    }

    #[test]
    fn free_numbers_leave_sobol_draws_aligned() {
        let (mut a, mut b) = (
            Sampler::new(1, 2, 3, SamplerKind::Sobol),
            Sampler::new(1, 2, 3, SamplerKind::Sobol),
        );
        a.next_free();
        assert_eq!(a.next_3d(), b.next_3d());
    }

    #[test]
    fn mean_of_uniforms_is_one_half() {
        // 10^5 numbers (aligned draws over samples, free numbers of one sample): the
        // standard error of the mean is 0.289/sqrt(1e5) ~ 9e-4; allow 5 sigma.
        let n = 100_000;
        for kind in KINDS {
            let streams = PixelStreams::new(7, 0, kind);
            let aligned = (0..n).map(|i| streams.sample(i).next_1d()).sum::<f64>();
            let mut s = streams.sample(0);
            let free = (0..n).map(|_| s.next_free()).sum::<f64>();
            for sum in [aligned, free] {
                let mean = sum / n as f64;
                assert!((mean - 0.5).abs() < 4.5e-3, "{kind:?}: mean {mean}");
            }
        }
    }

    #[test]
    fn sobol_crate_returns_multiples_of_2_pow_minus_23() {
        // The low-bit filling in `Sampler::sobol` is exact only for such values.
        for i in 0..4096 {
            for x in sobol_burley::sample_4d(i, 0, i.wrapping_mul(0x9e37_79b9)) {
                let scaled = f64::from(x) * (1u64 << 23) as f64;
                assert!((0.0..1.0).contains(&x) && scaled.fract() == 0.0, "{x}");
            }
        }
    }

    #[test]
    fn sobol_numbers_have_53_bits_and_stay_below_one() {
        // Every number lies in [0, 1); the bits below 2^-23 are filled: their mean over
        // 2^14 numbers is 0.5 within 5 sigma (sigma = 0.289 / 128).
        let streams = PixelStreams::new(3, 5, SamplerKind::Sobol);
        let n = 1 << 14;
        let mut low_sum = 0.0;
        for i in 0..n {
            for x in streams.sample(i).next_3d() {
                assert!((0.0..1.0).contains(&x), "{x}");
                low_sum += (x * (1u64 << 23) as f64).fract();
            }
        }
        let low_mean = low_sum / (3 * n) as f64;
        assert!((low_mean - 0.5).abs() < 5.0 * 0.289 / 128.0, "{low_mean}");
    }

    /// Whether `points` (2^m of them) form a (0,m,2)-net in base 2: exactly one point
    /// in each elementary interval `[a/2^k, (a+1)/2^k) × [b/2^(m−k), (b+1)/2^(m−k))`.
    fn is_net(points: &[[f64; 2]]) -> bool {
        let m = points.len().trailing_zeros();
        assert_eq!(points.len(), 1 << m);
        (0..=m).all(|k| {
            let mut seen = vec![false; points.len()];
            points.iter().all(|p| {
                let a = (p[0] * (1u64 << k) as f64) as usize;
                let b = (p[1] * (1u64 << (m - k)) as f64) as usize;
                !std::mem::replace(&mut seen[(a << (m - k)) | b], true)
            })
        })
    }

    /// The first `2^m` samples (from `first`) of the 2-D part of aligned draw `draw`.
    fn draw_points(
        kind: SamplerKind,
        pixel: u64,
        draw: usize,
        first: u64,
        m: u32,
    ) -> Vec<[f64; 2]> {
        let streams = PixelStreams::new(11, pixel, kind);
        (first..first + (1 << m))
            .map(|i| {
                let mut s = streams.sample(i);
                (0..draw).for_each(|_| s.skip_3d());
                let u = s.next_3d();
                [u[1], u[2]]
            })
            .collect()
    }

    #[test]
    fn sobol_draws_are_0_m_2_nets_and_independent_ones_are_not() {
        for pixel in [0, 1, 1000] {
            for draw in [0, 1, 7] {
                for m in 0..=10 {
                    assert!(
                        is_net(&draw_points(SamplerKind::Sobol, pixel, draw, 0, m)),
                        "pixel {pixel}, draw {draw}, 2^{m} samples"
                    );
                }
                // Samples past 2^16 start a new net.
                let far = draw_points(SamplerKind::Sobol, pixel, draw, 1 << 16, 8);
                assert!(is_net(&far));
                // The test can fail: 256 independent points are (almost surely) not a net.
                assert!(!is_net(&draw_points(
                    SamplerKind::Independent,
                    pixel,
                    draw,
                    0,
                    8
                )));
            }
        }
        // The camera draw (the first one) is a net as well.
        let streams = PixelStreams::new(0, 42, SamplerKind::Sobol);
        let camera: Vec<[f64; 2]> = (0..1024).map(|i| streams.sample(i).next_2d()).collect();
        assert!(is_net(&camera));
    }

    /// The smallest `t` for which `points` (2^m of them) form a (t,m,2)-net in base 2:
    /// every elementary interval of area `2^(t−m)` holds exactly `2^t` points.
    fn t_value(points: &[[f64; 2]]) -> u32 {
        let m = points.len().trailing_zeros();
        (0..=m)
            .find(|&t| {
                (0..=m - t).all(|k| {
                    let mut count = vec![0; 1 << (m - t)];
                    for p in points {
                        let a = (p[0] * (1u64 << k) as f64) as usize;
                        let b = (p[1] * (1u64 << (m - t - k)) as f64) as usize;
                        count[(a << (m - t - k)) | b] += 1;
                    }
                    count.iter().all(|&c| c == 1 << t)
                })
            })
            .unwrap_or(m)
    }

    /// Camera jitter and one number of each of 2^m samples of one pixel, drawn by
    /// `draw` after the camera draw.
    fn jitter_and(m: u32, draw: impl Fn(&mut Sampler) -> f64) -> Vec<[f64; 2]> {
        let streams = PixelStreams::new(5, 77, SamplerKind::Sobol);
        (0..1u64 << m)
            .map(|i| {
                let mut s = streams.sample(i);
                [s.next_2d()[0], draw(&mut s)]
            })
            .collect()
    }

    /// Coordinate `coord` of the scatter draw at `depth` after light draws and delta
    /// vertices (a choice each) at the depths before, as the integrator draws them.
    fn scatter_at(s: &mut Sampler, depth: u32, choice: bool, point: bool, coord: usize) -> f64 {
        for d in 0..depth {
            s.next_3d();
            s.next_scatter(d, true, false);
        }
        s.next_3d();
        s.next_scatter(depth, choice, point)[coord]
    }

    #[test]
    fn the_path_point_is_stratified_with_the_pixel_and_padded_draws_are_not() {
        // 1024 samples. From the path point, jointly with the jitter: a flight, the
        // first vertex's choice and direction, the choices of delta vertices deeper
        // down: (t,10,2)-nets with small t (measured 0-2). Padded draws (vertices
        // after the first that sample a direction): only as random pairs are,
        // t = 6 or more (measured 9).
        let m = 10;
        let t = t_value(&jitter_and(m, |s| s.next_flight()));
        assert!(t <= 2, "flight: t = {t}");
        for (choice, coords) in [(true, 0..3), (false, 1..3)] {
            for coord in coords {
                let t = t_value(&jitter_and(m, |s| scatter_at(s, 0, choice, true, coord)));
                assert!(
                    t <= 3,
                    "first vertex (choice {choice}), u[{coord}]: t = {t}"
                );
            }
        }
        for depth in 1..4 {
            let t = t_value(&jitter_and(m, |s| scatter_at(s, depth, true, false, 0)));
            assert!(t <= 3, "delta vertex at depth {depth}: t = {t}");
            let t = t_value(&jitter_and(m, |s| scatter_at(s, depth, true, true, 1)));
            assert!(
                t >= 6,
                "vertex sampling a direction at depth {depth}: t = {t}"
            );
        }
    }

    #[test]
    fn the_independent_sampler_has_no_path_point() {
        for (depth, choice, point) in [(0, true, true), (1, true, false), (2, false, true)] {
            let (mut a, mut b) = (
                Sampler::new(1, 2, 3, SamplerKind::Independent),
                Sampler::new(1, 2, 3, SamplerKind::Independent),
            );
            assert_eq!(a.next_scatter(depth, choice, point), b.next_3d());
            assert_eq!(a.next_flight(), b.next_free());
        }
    }

    #[test]
    fn a_branch_is_reproducible_stratified_and_independent_of_its_parent() {
        let streams = PixelStreams::new(5, 77, SamplerKind::Sobol);
        let after_camera = |i| {
            let mut s = streams.sample(i);
            s.next_2d();
            s
        };
        // Its padded draws are (0,10,2)-nets over the pixel's 1024 samples.
        let points: Vec<[f64; 2]> = (0..1 << 10)
            .map(|i| after_camera(i).branch(0).next_2d())
            .collect();
        assert!(is_net(&points));
        let (mut parent, mut branch) = (after_camera(3), after_camera(3).branch(0));
        assert_eq!(
            after_camera(3).branch(0).next_3d(),
            branch.clone().next_3d()
        );
        assert_ne!(branch.next_3d(), parent.next_3d());
        assert_ne!(branch.next_free(), parent.next_free());
        // No path point: a delta vertex's choice is a free number.
        let mut free = after_camera(3).branch(0);
        assert_eq!(
            after_camera(3).branch(0).next_scatter(1, true, false)[0],
            free.next_free()
        );
        // Later splits, of the parent one vertex on or of the branch itself, get
        // other numbers than the first split and than each other.
        let mut later = after_camera(3);
        later.next_3d();
        let splits = [
            later.branch(1),
            after_camera(3).branch(0).branch(1),
            after_camera(3).branch(2),
        ];
        let first = (
            after_camera(3).branch(0).next_3d(),
            after_camera(3).branch(0).next_free(),
        );
        for (i, s) in splits.iter().enumerate() {
            let numbers = (s.clone().next_3d(), s.clone().next_free());
            assert_ne!(numbers, first, "split {i}");
            for t in &splits[i + 1..] {
                assert_ne!(
                    numbers,
                    (t.clone().next_3d(), t.clone().next_free()),
                    "split {i}"
                );
            }
        }
    }

    #[test]
    fn neighbouring_pixels_and_draws_get_other_points() {
        let first = |pixel, draw| draw_points(SamplerKind::Sobol, pixel, draw, 0, 4);
        assert_ne!(first(0, 0), first(1, 0));
        assert_ne!(first(0, 0), first(0, 1));
    }
}
