//! Order statistics of float samples without copying them.

/// The `q`-quantile (`q` clamped to `0..=1`) of the finite values: the value of rank
/// `round((n - 1) · q)` in ascending `f32::total_cmp` order, NaN and ±inf skipped;
/// `None` if no value is finite.
///
/// Exact, by radix selection over the bit patterns in two passes (a histogram of the
/// high 16 bits, then of the low 16 bits inside the bucket that holds the rank), so it
/// needs two 65536-entry histograms whatever the number of values, not a copy of them.
/// `values` is walked twice (hence `Clone`): pass `slice.iter().copied()`, or a filtered
/// iterator to take the quantile of a subset without collecting it.
pub fn quantile<I>(values: I, q: f64) -> Option<f32>
where
    I: IntoIterator<Item = f32>,
    I::IntoIter: Clone,
{
    let values = values.into_iter();
    let keys = || values.clone().filter(|v| v.is_finite()).map(order_key);
    let mut high = vec![0usize; 1 << 16];
    keys().for_each(|k| high[(k >> 16) as usize] += 1);
    let n: usize = high.iter().sum();
    if n == 0 {
        return None;
    }
    let rank = ((n - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize;
    let (bucket, rank) = select(&high, rank);
    let mut low = vec![0usize; 1 << 16];
    keys()
        .filter(|k| k >> 16 == bucket)
        .for_each(|k| low[(k & 0xffff) as usize] += 1);
    let (bits, _) = select(&low, rank);
    Some(from_order_key(bucket << 16 | bits))
}

/// The bin of a histogram holding the element of `rank`, and its rank inside that bin.
fn select(histogram: &[usize], mut rank: usize) -> (u32, usize) {
    for (bin, &count) in histogram.iter().enumerate() {
        if rank < count {
            return (bin as u32, rank);
        }
        rank -= count;
    }
    unreachable!("the rank is below the histogram's total")
}

/// A key whose unsigned order is `f32::total_cmp`'s: negative values have all bits
/// flipped, non-negative ones the sign bit set.
fn order_key(v: f32) -> u32 {
    let bits = v.to_bits();
    if bits >> 31 == 1 {
        !bits
    } else {
        bits | 1 << 31
    }
}

/// The inverse of [`order_key`].
fn from_order_key(key: u32) -> f32 {
    f32::from_bits(if key >> 31 == 1 {
        key & !(1 << 31)
    } else {
        !key
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The definition: sort the finite values and take the element of the rank.
    fn by_sorting(values: &[f32], q: f64) -> Option<f32> {
        let mut v: Vec<f32> = values.iter().copied().filter(|v| v.is_finite()).collect();
        v.sort_by(f32::total_cmp);
        let rank = ((v.len().checked_sub(1)?) as f64 * q.clamp(0.0, 1.0)).round() as usize;
        Some(v[rank])
    }

    fn special() -> impl Strategy<Value = f32> {
        prop_oneof![
            any::<f32>(),
            Just(0.0),
            Just(-0.0),
            Just(f32::NAN),
            Just(f32::INFINITY),
            Just(f32::MIN_POSITIVE / 8.0),
            -3.0f32..3.0,
        ]
    }

    proptest! {
        /// Bit-identical to sorting (signed zeros, subnormals, duplicates, NaN and inf mixed in).
        #[test]
        fn equals_the_sorted_definition(v in prop::collection::vec(special(), 0..300), q in -0.5f64..1.5) {
            let got = quantile(v.iter().copied(), q).map(f32::to_bits);
            prop_assert_eq!(got, by_sorting(&v, q).map(f32::to_bits));
        }
    }

    #[test]
    fn order_keys_sort_like_total_cmp_and_invert() {
        let v = [
            f32::MIN,
            -1.0,
            -f32::MIN_POSITIVE,
            -0.0,
            0.0,
            1e-45,
            1.0,
            f32::MAX,
        ];
        assert!(v.windows(2).all(|w| order_key(w[0]) < order_key(w[1])));
        assert!(
            v.iter()
                .all(|&x| from_order_key(order_key(x)).to_bits() == x.to_bits())
        );
    }

    #[test]
    fn no_finite_value_gives_none_and_ends_are_min_and_max() {
        assert_eq!(
            quantile([f32::NAN, f32::INFINITY, f32::NEG_INFINITY], 0.5),
            None
        );
        assert_eq!(quantile([], 0.5), None);
        let v = [5.0, -2.0, f32::NAN, 7.5, 1.0, 3.0];
        assert_eq!(
            (quantile(v, 0.0), quantile(v, 1.0)),
            (Some(-2.0), Some(7.5))
        );
        assert_eq!(quantile(v, 0.5), Some(3.0));
    }
}
