//! Statistical checks shared by the workspace's tests: the chi-square goodness-of-fit
//! test that every sampling routine (BSDFs, phase functions) is held to.

/// Standard normal quantile at `1 − 1e-3`: a correct sampler fails a chi-square test at
/// this level with probability 1e-3 (the tests' seeds are fixed, so they never flake).
pub const Z_ALPHA: f64 = 3.090_232;

/// Pearson statistic over bins pooled so that every cell expects at least 5 samples
/// (cells expecting less are merged into one), and its degrees of freedom.
pub fn pearson(observed: &[f64], expected: &[f64]) -> (f64, f64) {
    let (mut stat, mut cells) = (0.0, 0usize);
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    for (o, e) in observed.iter().zip(expected) {
        if *e < 5.0 {
            pool_o += o;
            pool_e += e;
        } else {
            stat += (o - e).powi(2) / e;
            cells += 1;
        }
    }
    if pool_e > 0.0 {
        stat += (pool_o - pool_e).powi(2) / pool_e.max(1.0);
        cells += 1;
    }
    (stat, cells.saturating_sub(1) as f64)
}

/// Wilson–Hilferty approximation of the chi-square quantile at `1 − 1e-3` for `dof`
/// degrees of freedom (relative error well below 1 % for dof > 10).
pub fn chi2_critical(dof: f64) -> f64 {
    let a = 2.0 / (9.0 * dof);
    dof * (1.0 - a + Z_ALPHA * a.sqrt()).powi(3)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_counts_give_zero_and_skewed_counts_fail() {
        let expected = vec![100.0; 50];
        assert_eq!(pearson(&expected, &expected), (0.0, 49.0));
        // Moving 60 samples between two cells: (60² + 60²) / 100 = 72, within the 1e-3 level.
        let mut skewed = expected.clone();
        skewed[0] += 60.0;
        skewed[1] -= 60.0;
        let (stat, dof) = pearson(&skewed, &expected);
        assert!((stat - 72.0).abs() < 1e-12 && stat < chi2_critical(dof));
        // Emptying a cell into another: 200, far beyond it.
        skewed[0] += 40.0;
        skewed[1] -= 40.0;
        let (stat, dof) = pearson(&skewed, &expected);
        assert!((stat - 200.0).abs() < 1e-12 && stat > chi2_critical(dof));
    }

    #[test]
    fn wilson_hilferty_matches_tabulated_quantiles() {
        // chi-square 0.999 quantiles: dof 10 -> 29.588, dof 100 -> 149.449 (standard tables).
        assert!((chi2_critical(10.0) - 29.588).abs() / 29.588 < 0.01);
        assert!((chi2_critical(100.0) - 149.449).abs() / 149.449 < 0.002);
    }

    #[test]
    fn small_expectations_are_pooled() {
        let (_, dof) = pearson(&[1.0, 2.0, 50.0], &[1.0, 2.0, 50.0]);
        assert_eq!(dof, 1.0, "two cells: the pool and the one >= 5");
    }
}
