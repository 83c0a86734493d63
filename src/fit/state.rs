//! What every engine keeps the same way: the data points and their scale, each point's signed
//! error and the statistics of those errors, the tolerances, the scheme and method, and the
//! [`FitLog`]. [`Fitter`](super::Fitter) reads all of it from here, so an engine implements
//! only its iteration and its shapes.

use super::reference::{BackStats, DataSurface};
use super::{ErrorStats, FitLog, Method, Scheme, Tolerances};
use crate::geom::{Aabb, Point3};
use std::sync::Arc;
use web_time::Instant;

/// The shared state of a fit.
#[derive(Clone, Debug)]
pub struct FitState {
    scheme: Scheme,
    method: Method,
    tolerances: Tolerances,
    data: Vec<Point3>,
    diagonal: f64,
    errors: Vec<f64>,
    stats: ErrorStats,
    log: FitLog,
    reference: Option<Arc<DataSurface>>,
    back: Option<BackStats>,
}

/// A fit has converged only while no sample of its surface lies farther from the data than
/// this many E_max tolerances (SPEC §6: sheets or spikes away from the data are not a fit).
pub const BACK_TOLERANCE_FACTOR: f64 = 2.0;

impl FitState {
    /// The state of a fit of `data` (finite points) that starts with `initial_control`
    /// control points, set up since `start`. Errors are zero until [`FitState::set_errors`].
    pub(crate) fn new(
        (scheme, method): (Scheme, Method),
        tolerances: Tolerances,
        data: Vec<Point3>,
        initial_control: usize,
        start: Instant,
    ) -> FitState {
        let diagonal = Aabb::from_points(&data).map_or(0.0, |b| b.diagonal());
        FitState {
            scheme,
            method,
            tolerances,
            errors: vec![0.0; data.len()],
            data,
            diagonal: if diagonal > 0.0 { diagonal } else { 1.0 },
            stats: ErrorStats::default(),
            log: FitLog::new(initial_control, start),
            reference: None,
            back: None,
        }
    }

    /// Measures the surface → data distance against `reference` from now on.
    pub(crate) fn set_reference(&mut self, reference: Option<DataSurface>) {
        self.reference = reference.map(Arc::new);
    }

    /// Whether the surface → data distance is measured.
    pub(crate) fn has_reference(&self) -> bool {
        self.reference.is_some()
    }

    /// The distance to the data and the nearest data point of each of `samples` (`None` over a
    /// hole; empty when no reference is set), leaving the statistics alone.
    pub(crate) fn closest_data(&self, samples: &[Point3]) -> Vec<Option<(f64, Point3)>> {
        let Some(reference) = &self.reference else {
            return Vec::new();
        };
        super::parallel::map(samples, |&p| reference.closest(p))
    }

    /// Sets the surface → data statistics to those of `closest` (from
    /// [`FitState::closest_data`]), of which the first `uniform` sample the surface evenly
    /// ([`BackStats::of_mixed`]); none when no reference is set.
    pub(crate) fn set_back(&mut self, closest: &[Option<(f64, Point3)>], uniform: usize) {
        let distances: Vec<Option<f64>> = closest.iter().map(|c| c.map(|(d, _)| d)).collect();
        self.set_back_distances(&distances, uniform);
    }

    /// [`FitState::set_back`] from the distances alone.
    pub(crate) fn set_back_distances(&mut self, distances: &[Option<f64>], uniform: usize) {
        if self.reference.is_none() {
            return;
        }
        self.back = Some(BackStats::of_mixed(distances, uniform, self.diagonal));
    }

    /// The distance to the data of every one of `points` (points of the fitted surface, such
    /// as its display tessellation), model units, `None` over a hole of the data or beyond its
    /// outline; `None` as a whole when this fit measures no surface → data distance. Leaves
    /// the fit's own statistics alone: this is for views (a surface coloured by its distance).
    pub fn distances_to_data(&self, points: &[Point3]) -> Option<Vec<Option<f64>>> {
        self.reference.as_ref().map(|r| r.distances(points))
    }

    /// The last surface → data statistics, when they are measured.
    pub fn back(&self) -> Option<BackStats> {
        self.back
    }

    /// The scheme fitted.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }

    /// The method fitted with.
    pub fn method(&self) -> Method {
        self.method
    }

    /// The tolerances the fit stops at.
    pub fn tolerances(&self) -> Tolerances {
        self.tolerances
    }

    /// The data points, in input order.
    pub fn data(&self) -> &[Point3] {
        &self.data
    }

    /// Diagonal of the data's bounding box (1 for data without extent): what the `_pct` figures
    /// are relative to.
    pub fn diagonal(&self) -> f64 {
        self.diagonal
    }

    /// Signed distance of every data point to the surface or curve, model units.
    pub fn errors(&self) -> &[f64] {
        &self.errors
    }

    /// Statistics of [`FitState::errors`].
    pub fn stats(&self) -> ErrorStats {
        self.stats
    }

    /// The history and status.
    pub fn log(&self) -> &FitLog {
        &self.log
    }

    /// The history and status, to record an iteration or add set-up time.
    pub fn log_mut(&mut self) -> &mut FitLog {
        &mut self.log
    }

    /// Whether the statistics meet every tolerance, and no surface sample lies farther from the
    /// data than [`BACK_TOLERANCE_FACTOR`] E_max tolerances.
    pub(crate) fn met(&self) -> bool {
        self.tolerances.met_by(&self.stats) && self.back_met()
    }

    /// Whether no measured surface sample lies farther from the data than the bound
    /// ([`FitState::back_bound`]); true while nothing is measured.
    pub(crate) fn back_met(&self) -> bool {
        match (self.back, self.tolerances.max_pct) {
            (Some(b), Some(tol)) => b.max_pct <= BACK_TOLERANCE_FACTOR * tol,
            _ => true,
        }
    }

    /// The largest surface → data distance a converged fit may have, model units:
    /// [`BACK_TOLERANCE_FACTOR`] E_max tolerances (`None` without an E_max tolerance).
    pub(crate) fn back_bound(&self) -> Option<f64> {
        let tol = self.tolerances.max_pct?;
        Some(BACK_TOLERANCE_FACTOR * tol / 100.0 * self.diagonal)
    }

    /// The data points and the errors to overwrite, at once; call
    /// [`FitState::errors_changed`] after.
    pub(crate) fn data_and_errors_mut(&mut self) -> (&[Point3], &mut [f64]) {
        (&self.data, &mut self.errors)
    }

    /// Recomputes the statistics after the errors changed.
    pub(crate) fn errors_changed(&mut self) {
        self.stats = ErrorStats::from_distances(&self.errors, self.diagonal);
    }

    /// Replaces the errors and their statistics.
    pub(crate) fn set_errors(&mut self, errors: Vec<f64>) {
        self.errors = errors;
        self.errors_changed();
    }

    /// Restores errors and statistics saved before a rejected move.
    pub(crate) fn restore(&mut self, errors: Vec<f64>, stats: ErrorStats) {
        self.errors = errors;
        self.stats = stats;
    }

    /// The status after the iteration now ending: converged when `met`, stopped when it is the
    /// `cap`-th, else running on.
    pub(crate) fn status_after(&self, met: bool, cap: usize) -> super::FitStatus {
        if met {
            super::FitStatus::Converged
        } else if self.log.iterations() + 1 >= cap {
            super::FitStatus::MaxIterations
        } else {
            super::FitStatus::Running
        }
    }

    /// Writes the current surface → data statistics into the last iteration's record (a
    /// measure taken after it closed, such as a fit's final dense one).
    pub(crate) fn amend_back(&mut self) {
        self.log.amend_back(self.back);
    }

    /// Adds the time since `start` to the last iteration's record and the fit's time.
    pub(crate) fn amend_time(&mut self, start: Instant) {
        self.log.amend_time(start.elapsed().as_secs_f64());
    }

    /// Writes the current data → surface statistics into the last iteration's record.
    pub(crate) fn amend_stats(&mut self) {
        self.log.amend_stats(&self.stats);
    }

    /// How far the current state is from meeting the tolerances: the largest ratio of a
    /// statistic to its tolerance, E_back's to its bound (E_rms itself without tolerances).
    /// Lower is better; below 1 everything is met.
    pub(crate) fn shortfall(&self) -> f64 {
        let t = self.tolerances;
        let s = self.stats;
        let ratios = [
            t.avg_pct.map(|v| s.e_avg_pct / v),
            t.max_pct.map(|v| s.e_max_pct / v),
            t.rms_pct.map(|v| s.e_rms_pct / v),
            t.max_pct
                .zip(self.back)
                .map(|(v, b)| b.max_pct / (BACK_TOLERANCE_FACTOR * v)),
        ];
        let worst = ratios.into_iter().flatten().fold(f64::NAN, f64::max);
        let worst = if worst.is_nan() { s.e_rms_pct } else { worst };
        if worst.is_nan() {
            f64::INFINITY
        } else {
            worst
        }
    }

    /// Closes the iteration that began at `start` with `control_points` control points.
    pub(crate) fn record(
        &mut self,
        start: Instant,
        control_points: usize,
        refined: bool,
        status: super::FitStatus,
    ) -> super::FitStatus {
        self.log.record(
            start,
            control_points,
            &self.stats,
            self.back,
            refined,
            status,
        )
    }
}
