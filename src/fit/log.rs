//! The bookkeeping every engine shares: one record per iteration, the status, the set-up time
//! and what happened to the data on intake.

use super::reference::BackStats;
use super::{
    CreaseReport, ErrorStats, FitStatus, IterationRecord, ReconstructionReport, StrayPoints,
};
use crate::mesh::SimplifyReport;
use web_time::Instant;

/// History and status of a fit, kept the same way by every engine.
#[derive(Clone, Debug)]
pub struct FitLog {
    history: Vec<IterationRecord>,
    status: FitStatus,
    initial_control: usize,
    precompute_s: f64,
    fit_s: f64,
    reconstruction: Option<ReconstructionReport>,
    simplification: Option<SimplifyReport>,
    creases: Option<CreaseReport>,
    strays: Option<StrayPoints>,
    went_back_to: Option<usize>,
}

impl FitLog {
    /// A log of a fit that starts with `initial_control` control points, set up since `start`.
    pub(crate) fn new(initial_control: usize, start: Instant) -> FitLog {
        FitLog {
            history: Vec::new(),
            status: FitStatus::Running,
            initial_control,
            precompute_s: start.elapsed().as_secs_f64(),
            fit_s: 0.0,
            reconstruction: None,
            simplification: None,
            creases: None,
            strays: None,
            went_back_to: None,
        }
    }

    /// Closes the iteration that began at `start`: records its figures and sets the status.
    /// Returns the status.
    pub(crate) fn record(
        &mut self,
        start: Instant,
        control_points: usize,
        stats: &ErrorStats,
        back: Option<BackStats>,
        refined: bool,
        status: FitStatus,
    ) -> FitStatus {
        let seconds = start.elapsed().as_secs_f64();
        self.fit_s += seconds;
        self.history.push(IterationRecord {
            iter: self.history.len() + 1,
            control_points,
            e_avg_pct: stats.e_avg_pct,
            e_max_pct: stats.e_max_pct,
            e_rms_pct: stats.e_rms_pct,
            ms: seconds * 1e3,
            refined,
            e_back_max_pct: back.map(|b| b.max_pct),
            e_back_p99_pct: back.map(|b| b.p99_pct),
            phases: None,
        });
        self.status = status;
        status
    }

    /// Replaces the surface → data figures of the last record with `back`.
    pub(crate) fn amend_back(&mut self, back: Option<BackStats>) {
        if let Some(last) = self.history.last_mut() {
            last.e_back_max_pct = back.map(|b| b.max_pct);
            last.e_back_p99_pct = back.map(|b| b.p99_pct);
        }
    }

    /// Replaces the data → surface figures of the last record with `stats` (the state a
    /// stopped fit ends in when it goes back to a better iteration).
    pub(crate) fn amend_stats(&mut self, stats: &ErrorStats) {
        if let Some(last) = self.history.last_mut() {
            last.e_avg_pct = stats.e_avg_pct;
            last.e_max_pct = stats.e_max_pct;
            last.e_rms_pct = stats.e_rms_pct;
        }
    }

    /// Adds `seconds` spent closing the fit after its last record (going back to the best
    /// iteration, the final dense measure) to that record, as surface → data time, and to the
    /// fit's time: a report's `total_s` is what the user waited.
    pub(crate) fn amend_time(&mut self, seconds: f64) {
        self.fit_s += seconds;
        if let Some(last) = self.history.last_mut() {
            last.ms += seconds * 1e3;
            if let Some(p) = last.phases.as_mut() {
                p.back_ms += seconds * 1e3;
            }
        }
    }

    /// Sets where the last iteration's time went.
    pub(crate) fn set_phases(&mut self, phases: super::PhaseTimes) {
        if let Some(last) = self.history.last_mut() {
            last.phases = Some(phases);
        }
    }

    /// Sets the status without an iteration (a fit found converged or stuck before moving).
    pub(crate) fn stop(&mut self, status: FitStatus) -> FitStatus {
        self.status = status;
        status
    }

    /// One record per iteration so far.
    pub fn history(&self) -> &[IterationRecord] {
        &self.history
    }

    /// Iterations run so far.
    pub fn iterations(&self) -> usize {
        self.history.len()
    }

    /// Where the fit stands.
    pub fn status(&self) -> FitStatus {
        self.status
    }

    /// Control points at the start.
    pub fn initial_control_points(&self) -> usize {
        self.initial_control
    }

    /// Seconds of set-up before the first iteration: the engine's own (parameters, spatial
    /// index, first foot points) and what builders added ([`FitLog::add_precompute`]).
    pub fn precompute_seconds(&self) -> f64 {
        self.precompute_s
    }

    /// Seconds spent in iterations so far.
    pub fn fit_seconds(&self) -> f64 {
        self.fit_s
    }

    /// Adds set-up time spent before the engine existed (reading, meshing, simplification).
    pub fn add_precompute(&mut self, seconds: f64) {
        self.precompute_s += seconds.max(0.0);
    }

    /// How bare points were meshed before the fit, when they were.
    pub fn reconstruction(&self) -> Option<&ReconstructionReport> {
        self.reconstruction.as_ref()
    }

    /// Records how bare points were meshed before the fit.
    pub fn set_reconstruction(&mut self, report: Option<ReconstructionReport>) {
        self.reconstruction = report;
    }

    /// How the initial control mesh was made by QEM (and what repairing the data mesh on the
    /// way changed), when it was.
    pub fn simplification(&self) -> Option<&SimplifyReport> {
        self.simplification.as_ref()
    }

    /// Records how the initial control mesh was made.
    pub fn set_simplification(&mut self, report: Option<SimplifyReport>) {
        self.simplification = report;
    }

    /// The data points left out as strays, when there were any.
    pub fn strays(&self) -> Option<&StrayPoints> {
        self.strays.as_ref()
    }

    /// The sharp features found on the data and kept on the initial control mesh.
    pub fn creases(&self) -> Option<&CreaseReport> {
        self.creases.as_ref()
    }

    /// Records the control-point count the fit starts from, when set-up changed it after the
    /// log began (a B-spline surface's crease knots).
    pub(crate) fn set_initial_control(&mut self, initial_control: usize) {
        self.initial_control = initial_control;
    }

    /// Records the sharp features found and kept.
    pub(crate) fn set_creases(&mut self, report: Option<CreaseReport>) {
        self.creases = report;
    }

    /// The iteration whose control points the fit went back to when it stopped.
    pub fn went_back_to(&self) -> Option<usize> {
        self.went_back_to
    }

    /// Records that the fit went back to the control points of `iteration`.
    pub(crate) fn set_went_back_to(&mut self, iteration: usize) {
        self.went_back_to = Some(iteration);
    }

    /// Records the data points left out as strays.
    pub(crate) fn set_strays(&mut self, strays: Option<StrayPoints>) {
        self.strays = strays;
    }

    /// What happened to the data before the first iteration, one line each for people (the
    /// CLI prints them, the page shows them): the strays left out, the reconstruction of bare
    /// points, the repair of the mesh, and a simplification that relaxed its guards or stopped
    /// above its target.
    pub fn intake_notes(&self) -> Vec<String> {
        let mut notes: Vec<String> = self.strays.iter().map(StrayPoints::note).collect();
        if let Some(r) = &self.reconstruction {
            if let Some(left) = r.open_uncovered {
                notes.push(format!(
                    "the points look like an open scan, but its triangulation in projection \
                     left {left} of them in no triangle (no height field): meshed as a closed \
                     surface instead"
                ));
            }
            notes.push(format!(
                "reconstructed {} surface ({}): {} triangles, {} outliers removed",
                r.kind, r.method, r.triangles, r.outliers
            ));
            if r.stray_triangles > 0 {
                notes.push(format!(
                    "{} triangles of the implicit surface dropped where no point was near \
                     (holes the fit may span)",
                    r.stray_triangles
                ));
            }
        }
        if let Some(s) = &self.simplification {
            if s.repair.changed() {
                notes.push(s.repair.summary.clone());
            }
            let loose = s.repair.unreferenced_vertices.count;
            if loose > 0 {
                notes.push(format!("{loose} vertices in no face kept as data points"));
            }
            if !s.relaxations.is_empty() {
                notes.push(format!(
                    "simplified to {} vertices, relaxing its shape guards {} times",
                    s.vertices,
                    s.relaxations.len()
                ));
            }
            if let Some(floor) = &s.floor_note {
                notes.push(floor.clone());
            }
        }
        if let Some(c) = self.creases.as_ref().filter(|c| c.edges > 0) {
            let kept = match &c.knot_lines {
                Some(k) => k.summary(),
                None => format!(
                    "{} crease edges tagged on the control mesh",
                    c.control_edges
                ),
            };
            notes.push(format!(
                "sharp features at {}°: {}; {kept}",
                c.angle_deg, c.summary
            ));
        }
        notes
    }
}
