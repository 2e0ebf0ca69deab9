//! Splitting a dataset over independent jobs (Slurm array tasks, Kubernetes indexed jobs):
//! one rule for making a dataset (`polar-datagen`) and for evaluating it (`polar-vision`).

use std::fmt;
use std::str::FromStr;

/// Shard `k` of `n` (1-based): it owns the items whose global index i has i mod n = k - 1,
/// so costly and cheap families spread evenly over the shards.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// This shard, 1..=n.
    pub k: u32,
    /// Number of shards.
    pub n: u32,
}

impl Shard {
    /// The whole dataset as one shard.
    pub const ALL: Shard = Shard { k: 1, n: 1 };

    /// Whether this shard owns the item with global index `i`.
    pub fn owns(self, i: usize) -> bool {
        i % self.n as usize == (self.k - 1) as usize
    }
}

/// A shard given as other than `K/N` with `1 <= K <= N`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("bad shard '{0}': expected K/N with 1 <= K <= N, e.g. --shard 2/8")]
pub struct ShardError(pub String);

impl FromStr for Shard {
    type Err = ShardError;

    fn from_str(s: &str) -> Result<Shard, ShardError> {
        let bad = || ShardError(s.to_owned());
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let k: u32 = k.trim().parse().map_err(|_| bad())?;
        let n: u32 = n.trim().parse().map_err(|_| bad())?;
        if k == 0 || n == 0 || k > n {
            return Err(bad());
        }
        Ok(Shard { k, n })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_k_of_n_and_rejects_the_rest() {
        assert_eq!("2/5".parse::<Shard>(), Ok(Shard { k: 2, n: 5 }));
        for bad in ["0/3", "4/3", "1/0", "1", "a/b", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        let s = Shard { k: 2, n: 3 };
        assert_eq!((0..7).filter(|&i| s.owns(i)).collect::<Vec<_>>(), [1, 4]);
        assert_eq!(s.to_string(), "2/3");
    }
}
