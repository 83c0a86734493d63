//! The machine-readable summary of a fit (`geofit fit --json`).

use super::build::ReconstructionReport;
use super::subdiv::{ControlSurface, SubdivFitter};
use super::{FitStatus, Fitter, IterationRecord};
use serde::Serialize;

/// What `geofit fit --json REPORT.json` writes: the set-up, the final errors, the times and one
/// entry per iteration.
#[derive(Clone, Debug, Serialize)]
pub struct FitReport {
    /// Scheme name (`loop`, `catmull-clark`, `doo-sabin`, ...).
    pub scheme: String,
    /// Number of data points.
    pub points: usize,
    /// Control points at the start.
    pub initial_control_points: usize,
    /// Control points at the end.
    pub final_control_points: usize,
    /// Iterations run.
    pub iterations: usize,
    /// Final E_avg, % of the bounding-box diagonal.
    pub e_avg_pct: f64,
    /// Final E_max, %.
    pub e_max_pct: f64,
    /// Final E_rms, %.
    pub e_rms_pct: f64,
    /// Whether every tolerance was met.
    pub converged: bool,
    /// Share of the data points within the E_max tolerance of the surface, % (`None` without
    /// an E_max tolerance): the figure that matters for noisy scans, whose E_max is noise.
    pub within_tolerance_pct: Option<f64>,
    /// What was reconstructed from bare points before simplification (absent for meshes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reconstruction: Option<ReconstructionReport>,
    /// Seconds before the first iteration (initial control mesh, surface set-up, first foot
    /// points), including what the caller adds (reading, simplification).
    pub precompute_s: f64,
    /// Seconds spent iterating.
    pub fit_s: f64,
    /// `precompute_s + fit_s`.
    pub total_s: f64,
    /// One record per iteration.
    pub history: Vec<IterationRecord>,
}

impl FitReport {
    /// The report of `fitter` now; `extra_precompute_s` is set-up time spent outside the fitter
    /// (e.g. simplification for the initial control mesh) and `fit_s` the iteration time.
    pub fn of<S: ControlSurface>(
        fitter: &SubdivFitter<S>,
        extra_precompute_s: f64,
        fit_s: f64,
    ) -> FitReport {
        let stats = fitter.stats();
        let precompute_s = extra_precompute_s + fitter.precompute_seconds();
        FitReport {
            scheme: fitter.surface().scheme_name().to_string(),
            points: fitter.data().len(),
            initial_control_points: fitter.initial_control_points(),
            final_control_points: fitter.num_control_points(),
            iterations: fitter.history().len(),
            e_avg_pct: stats.e_avg_pct,
            e_max_pct: stats.e_max_pct,
            e_rms_pct: stats.e_rms_pct,
            converged: fitter.status() == FitStatus::Converged,
            within_tolerance_pct: fitter
                .options()
                .tolerances
                .max_pct
                .map(|tol| within_tolerance_pct(fitter.point_errors(), fitter.diagonal(), tol)),
            reconstruction: None,
            precompute_s,
            fit_s,
            total_s: precompute_s + fit_s,
            history: fitter.history().to_vec(),
        }
    }
}

/// The share of `errors` (distances in model units, signed or not) at most `tol_pct` % of
/// `diagonal` in size, in % (100 when there are none). SPEC §2 judges noisy scans this way
/// ("94.7 % within ±0.1 mm").
pub fn within_tolerance_pct(errors: &[f64], diagonal: f64, tol_pct: f64) -> f64 {
    if errors.is_empty() {
        return 100.0;
    }
    let limit = tol_pct / 100.0 * diagonal;
    let within = errors.iter().filter(|e| e.abs() <= limit).count();
    100.0 * within as f64 / errors.len() as f64
}
