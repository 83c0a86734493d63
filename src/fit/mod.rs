//! Fitting engines. Every engine (subdivision surfaces, B-spline surfaces and curves) is driven
//! the same way through [`Fitter`]: build it from data and options, call [`Fitter::step`] for one
//! iteration (the page animates this) or [`Fitter::run`] to the end, and read statistics and
//! per-point errors at any time.

mod accel;
pub mod bspline_surface;
mod build;
pub mod closest;
pub mod curve;
mod curve_lsq;
mod error;
mod frozen;
pub mod knot_placement;
pub mod lsq_surface;
mod normal_system;
pub mod options;
mod parallel;
pub mod parameterize;
pub mod patches;
pub mod refine;
pub mod refine_ds;
pub mod refine_quad;
pub mod report;
mod scheme;
mod stats;
pub mod subdiv;

pub use bspline_surface::{GeometricSurfaceFitter, GeometricSurfaceOptions};
pub use build::{
    build_subdiv_fitter, default_initial_count, initial_control, ReconstructionReport, SubdivSetup,
};
pub use closest::FootPoint;
pub use curve::{CurveFitOptions, CurveFitter};
pub use curve_lsq::least_squares_curve;
pub use error::FitError;
pub use knot_placement::{KnotPlacementFitter, KnotPlacementOptions};
pub use lsq_surface::{LsqSurfaceFitter, LsqSurfaceOptions};
pub use options::{Acceleration, SubdivFitOptions, Weighting};
pub use parameterize::{FoldPolicy, ParamOptions, Parameterization};
pub use patches::TolMode;
pub use report::{within_tolerance_pct, FitReport};
pub use scheme::surface_of;
pub use stats::{ErrorStats, IterationRecord, Tolerances};
pub use subdiv::{ControlSurface, SubdivFitter};

/// What one call of [`Fitter::step`] left the fit in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FitStatus {
    /// Tolerances not met yet; more iterations may help.
    Running,
    /// Every tolerance given is met.
    Converged,
    /// The iteration cap was reached first.
    MaxIterations,
}

/// The interface every fitting engine offers.
pub trait Fitter {
    /// Runs one iteration (foot points, error vectors, control-point moves; refinement when due).
    fn step(&mut self) -> Result<FitStatus, FitError>;

    /// Iterates until converged or out of iterations.
    fn run(&mut self) -> Result<FitStatus, FitError> {
        loop {
            match self.step()? {
                FitStatus::Running => {}
                done => return Ok(done),
            }
        }
    }

    /// One record per iteration so far; the last is the current state.
    fn history(&self) -> &[IterationRecord];

    /// Signed distance of every data point to the current surface, in model units (positive on
    /// the side the surface normal points to), in data order.
    fn point_errors(&self) -> &[f64];

    /// Error statistics of the current surface.
    fn stats(&self) -> ErrorStats;
}
