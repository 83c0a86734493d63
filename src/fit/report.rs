//! The machine-readable summary of a fit (`geofit fit --json`, `Fitter.reportJson()`): one
//! builder, [`FitReport::of`], for every engine.

use super::{
    CreaseReport, DeviationStats, FitStatus, Fitter, IterationRecord, ReconstructionReport,
    StrayPoints,
};
use crate::mesh::SimplifyReport;
use serde::Serialize;

/// The set-up, the final errors, the times and one entry per iteration of a fit.
#[derive(Clone, Debug, Serialize)]
pub struct FitReport {
    /// Scheme name (`loop`, `catmull-clark`, `doo-sabin`, `bspline-surface`, ...).
    pub scheme: String,
    /// Method name (`geometric`, `least-squares`, `knots`).
    pub method: String,
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
    /// Final E_back max (surface → data), %; absent where not measured. Also for a fit that
    /// converged before its first iteration, which has no `history` row to carry it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub e_back_max_pct: Option<f64>,
    /// Final 99th percentile of E_back, %.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub e_back_p99_pct: Option<f64>,
    /// Whether every tolerance was met.
    pub converged: bool,
    /// How the fit ended (or `running`).
    pub status: FitStatus,
    /// Share of the data points within the E_max tolerance of the surface, % (`None` without
    /// an E_max tolerance): the figure that matters for noisy scans, whose E_max is noise.
    pub within_tolerance_pct: Option<f64>,
    /// The distribution of the signed point deviations (model units): mean, σ, percentiles of
    /// |d|, the share within the E_max tolerance (the same figure as `within_tolerance_pct`).
    pub deviation: DeviationStats,
    /// What was reconstructed from bare points before simplification (absent for meshes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reconstruction: Option<ReconstructionReport>,
    /// How the initial control mesh was made by QEM, with what repairing the data mesh
    /// changed (`simplification.repair`); absent when a control mesh was given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub simplification: Option<SimplifyReport>,
    /// The sharp features found on the data and kept sharp on the initial control mesh
    /// (absent when crease detection is off or the fit is no subdivision fit).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub creases: Option<CreaseReport>,
    /// The data points left out as strays (absent when there were none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub strays: Option<StrayPoints>,
    /// The iteration whose control points a fit that stopped unconverged went back to, being
    /// better than where it stopped (absent when it ends where it stopped).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ended_at_iteration: Option<usize>,
    /// What happened to the data before the first iteration, for people
    /// ([`FitLog::intake_notes`](super::FitLog::intake_notes)).
    pub intake: Vec<String>,
    /// Seconds before the first iteration (reading, meshing, simplification, the engine's
    /// set-up and first foot points).
    pub precompute_s: f64,
    /// Seconds spent iterating.
    pub fit_s: f64,
    /// `precompute_s + fit_s`.
    pub total_s: f64,
    /// What only this engine reports ([`Fitter::details`]), written beside the common fields.
    #[serde(flatten)]
    pub details: serde_json::Map<String, serde_json::Value>,
    /// One record per iteration.
    pub history: Vec<IterationRecord>,
}

impl FitReport {
    /// The report of `fitter` now.
    pub fn of(fitter: &dyn Fitter) -> FitReport {
        let log = fitter.log();
        let stats = fitter.stats();
        let precompute_s = log.precompute_seconds();
        let fit_s = log.fit_seconds();
        let deviation = DeviationStats::of(
            fitter.point_errors(),
            fitter.diagonal(),
            fitter.tolerances().max_pct,
        );
        FitReport {
            scheme: fitter.scheme().to_string(),
            method: fitter.method().to_string(),
            points: fitter.data().len(),
            initial_control_points: log.initial_control_points(),
            final_control_points: fitter.num_control_points(),
            iterations: log.iterations(),
            e_avg_pct: stats.e_avg_pct,
            e_max_pct: stats.e_max_pct,
            e_rms_pct: stats.e_rms_pct,
            e_back_max_pct: fitter.state().back().map(|b| b.max_pct),
            e_back_p99_pct: fitter.state().back().map(|b| b.p99_pct),
            converged: log.status() == FitStatus::Converged,
            status: log.status(),
            within_tolerance_pct: deviation.within_tolerance_pct,
            deviation,
            reconstruction: log.reconstruction().cloned(),
            simplification: log.simplification().cloned(),
            creases: log.creases().cloned(),
            strays: log.strays().cloned(),
            ended_at_iteration: log.went_back_to(),
            intake: log.intake_notes(),
            precompute_s,
            fit_s,
            total_s: precompute_s + fit_s,
            details: fitter.details(),
            history: log.history().to_vec(),
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
