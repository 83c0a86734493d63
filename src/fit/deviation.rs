//! The distribution of a fit's signed deviations (data point → surface, model units), as an
//! engineer judging a fit reads it: mean, σ, percentiles of |d|, the share within the E_max
//! tolerance, and a histogram with the tolerance band marked. One computation for the page
//! (`Fitter.deviations()`) and the CLI report (`FitReport::deviation`).

use super::within_tolerance_pct;
use serde::Serialize;

/// Summary figures of signed deviations `d` (model units).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DeviationStats {
    /// Number of deviations.
    pub points: usize,
    /// Mean of `d` (signed: a bias of the surface to one side).
    pub mean: f64,
    /// Standard deviation of `d` (population, about the mean).
    pub sigma: f64,
    /// Median of `|d|` (percentiles by nearest rank).
    pub p50: f64,
    /// 90th percentile of `|d|`.
    pub p90: f64,
    /// 95th percentile of `|d|`.
    pub p95: f64,
    /// 99th percentile of `|d|`.
    pub p99: f64,
    /// Largest `|d|`.
    pub max: f64,
    /// The E_max tolerance in model units (`None` without one).
    pub tolerance: Option<f64>,
    /// Share of the points with `|d| <= tolerance`, % (`None` without a tolerance).
    pub within_tolerance_pct: Option<f64>,
}

impl DeviationStats {
    /// The figures of `errors`, with the E_max tolerance `tol_max_pct` % of `diagonal`. Empty
    /// input gives zeros (and 100 % within tolerance); the fitters never produce non-finite
    /// deviations.
    pub fn of(errors: &[f64], diagonal: f64, tol_max_pct: Option<f64>) -> DeviationStats {
        let n = errors.len();
        let mean = if n == 0 {
            0.0
        } else {
            errors.iter().sum::<f64>() / n as f64
        };
        let sigma = if n == 0 {
            0.0
        } else {
            (errors.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / n as f64).sqrt()
        };
        let mut abs: Vec<f64> = errors.iter().map(|d| d.abs()).collect();
        let max = abs.iter().copied().fold(0.0, f64::max);
        // Nearest rank: the k-th smallest |d| with k = ceil(p % of n). Selected from the top
        // percentile down, each in the part below the last: O(n) per frame, not a sort.
        let mut ranks = [0.0; 4];
        let mut upto = n;
        for (slot, p) in [(3, 99.0), (2, 95.0), (1, 90.0), (0, 50.0)] {
            if n == 0 {
                break;
            }
            let k = (((p / 100.0) * n as f64).ceil() as usize).clamp(1, n) - 1;
            let (_, v, _) = abs[..upto].select_nth_unstable_by(k, f64::total_cmp);
            ranks[slot] = *v;
            upto = k + 1;
        }
        let [p50, p90, p95, p99] = ranks;
        DeviationStats {
            points: n,
            mean,
            sigma,
            p50,
            p90,
            p95,
            p99,
            max,
            tolerance: tol_max_pct.map(|t| t / 100.0 * diagonal),
            within_tolerance_pct: tol_max_pct.map(|t| within_tolerance_pct(errors, diagonal, t)),
        }
    }
}

/// A histogram of signed deviations over `[-half_width, half_width]` in equal bins.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DeviationHistogram {
    /// The range is `-half_width..=half_width` (model units), symmetric around 0.
    pub half_width: f64,
    /// Points per bin, lowest deviations first; the end bins also hold the points beyond the
    /// range, so the counts add up to the number of points.
    pub counts: Vec<u32>,
    /// Of those, the points below `-half_width`.
    pub below: u32,
    /// Of those, the points above `half_width`.
    pub above: u32,
}

impl DeviationHistogram {
    /// `bins` bins (at least 1) of `errors`. The range covers the 99th percentile of `|d|` and
    /// 1.5 times the tolerance band (`stats.tolerance`), so that the band and the bulk of the
    /// points show however large a few outliers are; outliers go to the end bins.
    pub fn of(errors: &[f64], stats: &DeviationStats, bins: usize) -> DeviationHistogram {
        let bins = bins.max(1);
        let band = stats.tolerance.unwrap_or(0.0) * 1.5;
        let mut half_width = stats.p99.max(band);
        if !(half_width > 0.0 && half_width.is_finite()) {
            half_width = if stats.max > 0.0 && stats.max.is_finite() {
                stats.max
            } else {
                1.0
            };
        }
        let mut counts = vec![0u32; bins];
        let (mut below, mut above) = (0, 0);
        let width = 2.0 * half_width / bins as f64;
        for &d in errors {
            if d < -half_width {
                below += 1;
            } else if d > half_width {
                above += 1;
            }
            // NaN maps to bin 0 through the saturating cast; the fitters never give one.
            let k = ((d + half_width) / width).floor().max(0.0) as usize;
            counts[k.min(bins - 1)] += 1;
        }
        DeviationHistogram {
            half_width,
            counts,
            below,
            above,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_of_known_values() {
        // 1..=100 and their negatives: mean 0, |d| percentiles by nearest rank.
        let errors: Vec<f64> = (1..=100).flat_map(|i| [i as f64, -(i as f64)]).collect();
        let s = DeviationStats::of(&errors, 1000.0, Some(5.0));
        assert_eq!(s.points, 200);
        assert_eq!(s.mean, 0.0);
        let var = (1..=100).map(|i| (i * i) as f64).sum::<f64>() / 100.0;
        assert!((s.sigma - var.sqrt()).abs() < 1e-12);
        assert_eq!(
            (s.p50, s.p90, s.p95, s.p99, s.max),
            (50.0, 90.0, 95.0, 99.0, 100.0)
        );
        // Tolerance 5 % of 1000 = 50: |d| <= 50 for 100 of 200.
        assert_eq!(s.tolerance, Some(50.0));
        assert_eq!(s.within_tolerance_pct, Some(50.0));
    }

    #[test]
    fn percentiles_are_the_nearest_ranks_of_the_sorted_values() {
        // 1013 values in a scrambled order (a multiplicative permutation), both signs.
        let n = 1013;
        let errors: Vec<f64> = (0..n)
            .map(|i| ((i * 389) % n) as f64 * if i % 3 == 0 { -0.01 } else { 0.01 })
            .collect();
        let mut sorted: Vec<f64> = errors.iter().map(|d| d.abs()).collect();
        sorted.sort_by(f64::total_cmp);
        let rank = |p: f64| sorted[((p / 100.0) * n as f64).ceil() as usize - 1];
        let s = DeviationStats::of(&errors, 1.0, None);
        assert_eq!(
            [s.p50, s.p90, s.p95, s.p99, s.max],
            [
                rank(50.0),
                rank(90.0),
                rank(95.0),
                rank(99.0),
                sorted[n - 1]
            ]
        );
    }

    #[test]
    fn stats_of_nothing_are_zero() {
        let s = DeviationStats::of(&[], 1.0, None);
        assert_eq!(
            (s.points, s.mean, s.sigma, s.p99, s.max),
            (0, 0.0, 0.0, 0.0, 0.0)
        );
        assert_eq!(s.within_tolerance_pct, None);
        let h = DeviationHistogram::of(&[], &s, 4);
        assert_eq!(h.counts, vec![0; 4]);
        assert_eq!(h.half_width, 1.0);
    }

    #[test]
    fn histogram_counts_are_exact_and_symmetric() {
        // Tolerance 1 (1 % of 100): range ±1.5 over 6 bins of 0.5.
        let errors = [-1.4, -0.9, -0.1, 0.0, 0.2, 0.6, 1.2, 1.49, 7.0, -9.0];
        let mut s = DeviationStats::of(&errors, 100.0, Some(1.0));
        s.p99 = 0.0; // let the band alone set the range
        let h = DeviationHistogram::of(&errors, &s, 6);
        assert_eq!(h.half_width, 1.5);
        // Bins: [-1.5,-1) [-1,-0.5) [-0.5,0) [0,0.5) [0.5,1) [1,1.5]; -9 and 7 in the end bins.
        assert_eq!(h.counts, vec![2, 1, 1, 2, 1, 3]);
        assert_eq!((h.below, h.above), (1, 1));
        assert_eq!(h.counts.iter().sum::<u32>() as usize, errors.len());
    }

    #[test]
    fn histogram_range_covers_p99_of_the_data() {
        let errors: Vec<f64> = (0..1000).map(|i| (i as f64 - 500.0) / 100.0).collect();
        let s = DeviationStats::of(&errors, 1.0, None);
        let h = DeviationHistogram::of(&errors, &s, 10);
        assert_eq!(h.half_width, s.p99);
        assert_eq!(h.counts.iter().sum::<u32>(), 1000);
        // -5.00..=-4.96 below the range, 4.96..=4.99 above it.
        assert_eq!((h.below, h.above), (5, 4));
    }
}
