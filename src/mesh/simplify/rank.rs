//! The cost of the n-th cheapest candidate collapse, from a histogram of the costs: what a
//! pass needs to set its cost goal, without sorting the candidates.
//!
//! The bin of a cost is the top 16 bits of its `f64` pattern — the sign (always 0: costs are
//! never negative), the 11 exponent bits and 4 mantissa bits — so a bin spans about 6 %, and
//! one linear pass over the costs with a 128 KiB histogram gives the answer to within that.

/// Bits of the `f64` pattern below the bin.
const SHIFT: u32 = 48;
/// Number of bins: non-negative costs have the top bit clear.
const BINS: usize = 1 << (64 - SHIFT - 1);

/// The bin of a cost; NaN and negative costs (never those of a candidate) are left out.
fn bin(cost: f64) -> Option<usize> {
    (cost >= 0.0).then(|| (cost.to_bits() >> SHIFT) as usize)
}

/// An upper bound, within 6.25 %, of the `n`-th smallest (from 0) of `costs`; infinite when
/// there are not more than `n` costs. `count` is scratch space for the histogram.
pub(super) fn cost_at_rank(
    costs: impl Iterator<Item = f64>,
    n: usize,
    count: &mut Vec<u32>,
) -> f64 {
    count.clear();
    count.resize(BINS, 0);
    for c in costs.filter_map(bin) {
        count[c] += 1;
    }
    let mut seen = 0usize;
    for (b, &k) in count.iter().enumerate() {
        seen += k as usize;
        if seen > n {
            // The bin of infinity (and of the largest finite costs) has no finite bound.
            let bound = f64::from_bits(((b as u64) + 1) << SHIFT);
            return if bound.is_finite() {
                bound
            } else {
                f64::INFINITY
            };
        }
    }
    f64::INFINITY
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rank_bounds_the_cost_from_above_within_a_bin() {
        let costs = [
            3.0,
            0.0,
            1e-30,
            2.0,
            3.0,
            1e300,
            2.0,
            f64::NAN,
            f64::INFINITY,
        ];
        let at = |n| cost_at_rank(costs.iter().copied(), n, &mut Vec::new());
        assert!(at(0) > 0.0 && at(0) < 1e-300);
        assert!(at(1) >= 1e-30 && at(1) < 1.07e-30);
        assert!(at(2) >= 2.0 && at(2) < 2.13);
        assert_eq!(at(3), at(2));
        assert!(at(6) >= 1e300);
        assert_eq!(at(7), f64::INFINITY);
        assert_eq!(at(8), f64::INFINITY);
    }

    #[test]
    fn costs_in_one_bin_are_close() {
        // 1.0 and 1.06 share a bin; 1.07 does not.
        assert_eq!(bin(1.0), bin(1.06));
        assert_ne!(bin(1.0), bin(1.07));
        assert_eq!(bin(f64::NAN), None);
    }
}
