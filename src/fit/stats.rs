use super::FitError;
use serde::{Deserialize, Serialize};

/// Stopping tolerances, each in % of the data's bounding-box diagonal. A fit stops when every
/// tolerance given is met. With none given, the defaults of the specification apply
/// (E_avg 0.01 %, E_max 0.05 %).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tolerances {
    /// Bound on E_avg (mean distance), %.
    pub avg_pct: Option<f64>,
    /// Bound on E_max (largest distance), %.
    pub max_pct: Option<f64>,
    /// Bound on E_rms (root-mean-square distance), %.
    pub rms_pct: Option<f64>,
}

default_is_const!(Tolerances);

impl Tolerances {
    /// The specification's tolerances (SPEC §1, the patent's Table 1): E_avg 0.01 %, E_max
    /// 0.05 %.
    pub const DEFAULT: Tolerances = Tolerances {
        avg_pct: Some(0.01),
        max_pct: Some(0.05),
        rms_pct: None,
    };

    /// Only an E_max tolerance of `pct` %.
    pub const fn max_only(pct: f64) -> Tolerances {
        Tolerances {
            avg_pct: None,
            max_pct: Some(pct),
            rms_pct: None,
        }
    }

    /// Rejects negative or non-finite tolerances, naming the option (`tolAvg`, `tolMax`,
    /// `tolRms`).
    pub fn validate(&self) -> Result<(), FitError> {
        for (name, v) in [
            ("tolAvg", self.avg_pct),
            ("tolMax", self.max_pct),
            ("tolRms", self.rms_pct),
        ] {
            if let Some(v) = v.filter(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(FitError::InvalidOption {
                    name,
                    reason: format!("{v} is not a finite percentage >= 0"),
                });
            }
        }
        Ok(())
    }

    /// The tolerances a user gave, or `default` when none is given: giving one tolerance
    /// means only that one counts, so the defaults must not mix in.
    pub fn given_or(
        avg_pct: Option<f64>,
        max_pct: Option<f64>,
        rms_pct: Option<f64>,
        default: Tolerances,
    ) -> Self {
        if avg_pct.is_some() || max_pct.is_some() || rms_pct.is_some() {
            Tolerances {
                avg_pct,
                max_pct,
                rms_pct,
            }
        } else {
            default
        }
    }

    /// Whether `stats` meets every tolerance given.
    pub fn met_by(&self, stats: &ErrorStats) -> bool {
        let ok = |tol: Option<f64>, value: f64| tol.is_none_or(|t| value <= t);
        ok(self.avg_pct, stats.e_avg_pct)
            && ok(self.max_pct, stats.e_max_pct)
            && ok(self.rms_pct, stats.e_rms_pct)
    }
}

/// Point-to-surface distance statistics. The `_pct` figures are % of the data's bounding-box
/// diagonal, the others are in model units.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ErrorStats {
    /// Mean distance, model units.
    pub e_avg: f64,
    /// Largest distance, model units.
    pub e_max: f64,
    /// Root-mean-square distance, model units.
    pub e_rms: f64,
    /// E_avg in % of the bounding-box diagonal.
    pub e_avg_pct: f64,
    /// E_max in % of the bounding-box diagonal.
    pub e_max_pct: f64,
    /// E_rms in % of the bounding-box diagonal.
    pub e_rms_pct: f64,
}

impl ErrorStats {
    /// Statistics of unsigned or signed `distances` (absolute values are used), relative to a
    /// bounding-box `diagonal`. Empty input gives zeros.
    pub fn from_distances(distances: &[f64], diagonal: f64) -> ErrorStats {
        if distances.is_empty() {
            return ErrorStats::default();
        }
        let n = distances.len() as f64;
        let (mut sum, mut sum_sq, mut max) = (0.0, 0.0, 0.0f64);
        for d in distances.iter().map(|d| d.abs()) {
            sum += d;
            sum_sq += d * d;
            max = max.max(d);
        }
        let pct = if diagonal > 0.0 {
            100.0 / diagonal
        } else {
            0.0
        };
        let (e_avg, e_rms) = (sum / n, (sum_sq / n).sqrt());
        ErrorStats {
            e_avg,
            e_max: max,
            e_rms,
            e_avg_pct: e_avg * pct,
            e_max_pct: max * pct,
            e_rms_pct: e_rms * pct,
        }
    }
}

/// The state after one iteration, as the report's `history` lists it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IterationRecord {
    /// Iteration number, from 1.
    pub iter: usize,
    /// Control points after the iteration.
    pub control_points: usize,
    /// E_avg, %.
    pub e_avg_pct: f64,
    /// E_max, %.
    pub e_max_pct: f64,
    /// E_rms, %.
    pub e_rms_pct: f64,
    /// Wall time of the iteration, ms.
    pub ms: f64,
    /// Whether the control mesh was refined (or knots inserted) in this iteration.
    pub refined: bool,
    /// Surface → data: the largest distance of a sample of the surface to the data, % (absent
    /// where the fit measures none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub e_back_max_pct: Option<f64>,
    /// Surface → data: the 99th-percentile distance, %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub e_back_p99_pct: Option<f64>,
    /// Where the iteration's time went (subdivision fits).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phases: Option<PhaseTimes>,
}

/// Where one iteration of a subdivision fit spent its time, ms; the rest of the iteration's
/// `ms` is bookkeeping (statistics, weights, the stall rule). Kept per iteration in the report
/// so that a speed-up is judged by the phase it targets (`scripts/bench_fit.sh` tabulates it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PhaseTimes {
    /// Working out the move: stencils and conjugate gradients (or the weighted error sums).
    pub moves_ms: f64,
    /// Refilling the patch data for the moved control points (damping retries included).
    pub refill_ms: f64,
    /// Foot points on the moved surface (Newton from the last ones), damping retries included.
    pub feet_ms: f64,
    /// The surface → data measure: evaluating samples and finding their nearest data.
    pub back_ms: f64,
    /// Refinement: splits, flips, the rebuilt patches and their foot points.
    pub refine_ms: f64,
}

impl PhaseTimes {
    /// Adds the milliseconds since `start` to the phase `slot` picks.
    pub(crate) fn add(&mut self, slot: fn(&mut PhaseTimes) -> &mut f64, start: web_time::Instant) {
        *slot(self) += start.elapsed().as_secs_f64() * 1e3;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_and_tolerances() {
        let s = ErrorStats::from_distances(&[0.0, -3.0, 4.0], 100.0);
        assert!((s.e_avg - 7.0 / 3.0).abs() < 1e-12);
        assert_eq!(s.e_max, 4.0);
        assert!((s.e_rms - (25.0f64 / 3.0).sqrt()).abs() < 1e-12);
        assert!((s.e_max_pct - 4.0).abs() < 1e-12);
        let tol = Tolerances {
            avg_pct: Some(3.0),
            max_pct: Some(4.0),
            rms_pct: None,
        };
        assert!(tol.met_by(&s));
        assert!(!Tolerances {
            max_pct: Some(3.9),
            ..tol
        }
        .met_by(&s));
    }
}
