//! Order statistics of f64 samples (medians, quantiles by rank), in one place for every module
//! that summarises spacings, supports or parameters. NaN sorts last (`total_cmp`).

/// The median of `values`: the value of rank n / 2 (the upper one of an even count); 0 for
/// none.
pub(crate) fn median(values: &[f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mut v = values.to_vec();
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// The value of rank `share × (n − 1)` (rounded down) of `values` (non-empty).
pub(crate) fn quantile(values: &[f64], share: f64) -> f64 {
    let mut v = values.to_vec();
    let rank = ((v.len() - 1) as f64 * share) as usize;
    *v.select_nth_unstable_by(rank, f64::total_cmp).1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranks_are_the_sorted_positions() {
        let v = [5.0, 1.0, 4.0, 2.0, 3.0, 6.0];
        assert_eq!(median(&v), 4.0);
        assert_eq!(median(&v[..5]), 3.0);
        assert_eq!(median(&[]), 0.0);
        assert_eq!(quantile(&v, 0.5), 3.0);
        assert_eq!(quantile(&v, 0.0), 1.0);
        assert_eq!(quantile(&v, 1.0), 6.0);
    }
}
