//! When to give up: a fit whose control budget is spent and whose errors have stopped falling
//! says so (status `stalled`, SPEC §6) instead of running to the iteration cap.

use super::{IterationRecord, Tolerances, BACK_TOLERANCE_FACTOR};

/// Iterations over which progress is judged.
pub(crate) const STALL_WINDOW: usize = 10;

/// The least relative fall of an unmet statistic's best value over [`STALL_WINDOW`] iterations
/// that counts as progress.
const MIN_GAIN: f64 = 0.01;

/// One figure of an iteration record, where it has it.
type Statistic = fn(&IterationRecord) -> Option<f64>;

/// Whether the fit recorded in `history` is stalled: some statistic whose best value over the
/// last [`STALL_WINDOW`] iterations misses its tolerance has not improved on the window before
/// by [`MIN_GAIN`],
/// or improves so slowly that, at that rate, it would not meet its tolerance within
/// `remaining` more iterations. A fit is only stalled when nothing else can change its course,
/// so the caller asks only when no refinement is left and the last one is a window back.
pub(crate) fn stalled(
    history: &[IterationRecord],
    tolerances: &Tolerances,
    remaining: usize,
) -> bool {
    if history.len() <= STALL_WINDOW {
        return false;
    }
    // The last window against the one before it: a best value from before a refinement (when
    // the surface was coarser) says nothing about whether this surface still improves.
    let (before, last) = history.split_at(history.len() - STALL_WINDOW);
    let before = &before[before.len().saturating_sub(STALL_WINDOW)..];
    let statistics: [(Option<f64>, Statistic); 4] = [
        (tolerances.avg_pct, |r| Some(r.e_avg_pct)),
        (tolerances.max_pct, |r| Some(r.e_max_pct)),
        (tolerances.rms_pct, |r| Some(r.e_rms_pct)),
        (tolerances.max_pct.map(|t| t * BACK_TOLERANCE_FACTOR), |r| {
            r.e_back_max_pct
        }),
    ];
    statistics.into_iter().any(|(tol, value)| {
        let Some(tol) = tol else { return false };
        let best = |records: &[IterationRecord]| {
            records
                .iter()
                .filter_map(value)
                .filter(|v| v.is_finite())
                .fold(f64::INFINITY, f64::min)
        };
        let (old, now) = (best(before), best(last));
        if !(now > tol && old.is_finite()) {
            return false;
        }
        // A statistic whose latest value is the best of a window it has been falling through
        // is progressing, whatever an earlier window held: its rate is that fall.
        let values: Vec<f64> = last.iter().filter_map(value).collect();
        let falling = match (values.first(), values.last()) {
            (Some(&first), Some(&latest)) if latest <= now && first > 0.0 => latest / first,
            _ => 1.0,
        };
        let ratio = (now / old).min(falling);
        if ratio > 1.0 - MIN_GAIN {
            return true;
        }
        // Windows needed at this rate: ratio^k · now = tol.
        let windows = libm::log(tol / now) / libm::log(ratio);
        windows * STALL_WINDOW as f64 > remaining as f64
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(iter: usize, e_max_pct: f64) -> IterationRecord {
        IterationRecord {
            iter,
            control_points: 10,
            e_avg_pct: 0.0,
            e_max_pct,
            e_rms_pct: 0.0,
            ms: 1.0,
            refined: false,
            e_back_max_pct: None,
            e_back_p99_pct: None,
            phases: None,
        }
    }

    fn tol(max: f64) -> Tolerances {
        Tolerances {
            avg_pct: None,
            max_pct: Some(max),
            rms_pct: None,
        }
    }

    #[test]
    fn a_flat_error_is_stalled_a_falling_one_is_not() {
        let flat: Vec<_> = (1..=20).map(|i| record(i, 0.5)).collect();
        assert!(stalled(&flat, &tol(0.1), 100));
        assert!(!stalled(&flat[..STALL_WINDOW], &tol(0.1), 100), "too early");
        assert!(!stalled(&flat, &tol(0.6), 100), "met");
        // Halving every 10 iterations, at 0.125 after 20: 0.01 takes ~36 more iterations.
        let falling: Vec<_> = (1..=20)
            .map(|i| record(i, 0.5 * 0.5f64.powf(i as f64 / 10.0)))
            .collect();
        assert!(!stalled(&falling, &tol(0.01), 100));
        assert!(stalled(&falling, &tol(0.01), 30), "too slow for the cap");
    }

    #[test]
    fn an_early_best_does_not_hide_a_stall() {
        // E_back was low on the coarse start, then stays high after a refinement.
        let mut h: Vec<_> = (1..=30).map(|i| record(i, 0.01)).collect();
        for r in &mut h {
            r.e_back_max_pct = Some(if r.iter == 1 { 0.6 } else { 1.17 });
        }
        assert!(stalled(&h, &tol(0.5), 100));
    }

    #[test]
    fn a_statistic_falling_through_the_window_is_not_stalled() {
        // E_back rose after a refinement (0.79 before it), then falls from 1.41 to 1.0016
        // (teapot at 0.1 / 0.5): one more iteration meets the bound of 1.0.
        let mut h: Vec<_> = (1..=21).map(|i| record(i, 0.01)).collect();
        for r in &mut h {
            r.e_back_max_pct = Some(if r.iter <= 11 {
                0.79
            } else {
                1.41 - 0.0409 * (r.iter - 11) as f64
            });
        }
        assert!(!stalled(&h, &tol(0.5), 100));
    }

    #[test]
    fn the_surface_to_data_error_counts_at_its_own_bound() {
        let mut h: Vec<_> = (1..=20).map(|i| record(i, 0.01)).collect();
        for r in &mut h {
            r.e_back_max_pct = Some(0.5);
        }
        assert!(stalled(&h, &tol(0.1), 100));
        assert!(!stalled(&h, &tol(0.3), 100), "0.5 is within 2 × 0.3");
    }
}
