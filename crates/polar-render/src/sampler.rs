//! Counter-based random numbers: every sample is a pure function of
//! `(seed, pixel, sample index, dimension)`, so the image does not depend on
//! how pixels are scheduled over threads.

/// One stream of uniform numbers for one pixel sample.
#[derive(Clone, Debug)]
pub struct Sampler {
    key: u64,
    dimension: u64,
}

/// SplitMix64's increment (the golden ratio in 64 bits).
const GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// SplitMix64 finaliser (Steele et al. 2014): a bijective 64-bit mixer.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The streams of every sample of one pixel: hashes the seed and pixel once.
#[derive(Clone, Copy, Debug)]
pub struct PixelStreams(u64);

impl PixelStreams {
    /// The streams of pixel `pixel` under `seed`.
    pub fn new(seed: u64, pixel: u64) -> Self {
        Self(mix(mix(seed) ^ pixel))
    }

    /// The stream of sample `sample` (the same as [`Sampler::new`]).
    pub fn sample(&self, sample: u64) -> Sampler {
        let key = mix(self.0 ^ sample.wrapping_mul(GAMMA));
        Sampler { key, dimension: 0 }
    }
}

impl Sampler {
    /// The stream of sample `sample` of pixel `pixel` under `seed`.
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        PixelStreams::new(seed, pixel).sample(sample)
    }

    /// The next uniform number in `[0, 1)` (53 random bits): SplitMix64's output
    /// for state `key + dimension · γ` (one mix per number).
    pub fn next_1d(&mut self) -> f64 {
        self.dimension += 1;
        let bits = mix(self.key.wrapping_add(self.dimension.wrapping_mul(GAMMA)));
        (bits >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Two numbers in `[0, 1)`.
    pub fn next_2d(&mut self) -> [f64; 2] {
        [self.next_1d(), self.next_1d()]
    }

    /// Three numbers in `[0, 1)`.
    pub fn next_3d(&mut self) -> [f64; 3] {
        [self.next_1d(), self.next_1d(), self.next_1d()]
    }

    /// Skips `n` numbers without computing them: the later numbers are the same
    /// as if they had been drawn.
    pub fn skip(&mut self, n: u64) {
        self.dimension += n;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<f64> = (0..4)
            .map(|_| 0.0)
            .scan(Sampler::new(1, 2, 3), |s, _| Some(s.next_1d()))
            .collect();
        let b: Vec<f64> = (0..4)
            .map(|_| 0.0)
            .scan(Sampler::new(1, 2, 3), |s, _| Some(s.next_1d()))
            .collect();
        let c: Vec<f64> = (0..4)
            .map(|_| 0.0)
            .scan(Sampler::new(1, 2, 4), |s, _| Some(s.next_1d()))
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn skip_is_drawing_and_discarding() {
        let (mut a, mut b) = (Sampler::new(1, 2, 3), Sampler::new(1, 2, 3));
        a.next_3d();
        b.skip(3);
        assert_eq!(a.next_1d(), b.next_1d());
    }

    #[test]
    fn mean_of_uniforms_is_one_half() {
        // 10^5 samples: the standard error of the mean is 0.289/sqrt(1e5) ~ 9e-4; allow 5 sigma.
        let mut s = Sampler::new(7, 0, 0);
        let n = 100_000;
        let mean = (0..n).map(|_| s.next_1d()).sum::<f64>() / n as f64;
        assert!((mean - 0.5).abs() < 4.5e-3, "mean {mean}");
    }
}
