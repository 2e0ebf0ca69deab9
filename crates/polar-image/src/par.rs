//! Element-wise maps over whole planes, in parallel blocks of plain loops.
//!
//! A per-element parallel iterator calls the element function through a reference, one
//! call per pixel; a loop per block lets the compiler inline (and often vectorise) it.

use rayon::prelude::*;

/// Elements per parallel block: enough work to amortise a task, small beside a frame.
pub const PAR_BLOCK: usize = 1 << 14;

/// Sets `dst[k] = f(k)` for every index, in parallel (the same values whatever the
/// thread count).
pub fn par_fill<T: Send>(dst: &mut [T], f: impl Fn(usize) -> T + Sync) {
    dst.par_chunks_mut(PAR_BLOCK)
        .enumerate()
        .for_each(|(b, block)| {
            for (j, d) in block.iter_mut().enumerate() {
                *d = f(b * PAR_BLOCK + j);
            }
        });
}

/// `f(k)` for every index `k < n`, computed in parallel, in index order.
pub fn par_map<T: Send + Clone + Default>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let mut out = vec![T::default(); n];
    par_fill(&mut out, f);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every index is visited once, in order, across block boundaries and for the empty
    /// and one-element cases.
    #[test]
    fn maps_every_index_in_order() {
        for n in [0, 1, PAR_BLOCK - 1, PAR_BLOCK, 3 * PAR_BLOCK + 7] {
            let v = par_map(n, |k| k as u64 * 3);
            assert_eq!(v, (0..n as u64).map(|k| k * 3).collect::<Vec<_>>(), "n {n}");
        }
    }
}
