//! Fitting engines. Every engine — subdivision surfaces, B-spline surfaces (geometric or least
//! squares) and B-spline curves (geometric or knot placement) — is built from a [`FitSpec`] and
//! driven the same way through [`Fitter`]: [`Fitter::step`] for one iteration (the page animates
//! this) or [`Fitter::run`] to the end; statistics, per-point errors and the current shapes can
//! be read at any time, and [`FitReport::of`] summarises any of them.
//!
//! | module | what it holds |
//! |---|---|
//! | `spec` | [`FitSpec`]: what to fit and how, with every default and its validation |
//! | `subdiv` | [`SubdivFitter`]: Loop, Catmull–Clark and Doo–Sabin limit surfaces (SPEC §1) |
//! | `surface` | [`GeometricSurfaceFitter`], [`LsqSurfaceFitter`], [`SectionsFitter`]: one B-spline surface (SPEC §1, §2, §3 skinning) |
//! | `curve` | [`CurveFitter`], [`KnotPlacementFitter`]: B-spline curves (SPEC §1.9, §3) |
//! | `state`, `log` | [`FitState`], [`FitLog`]: data, errors, history and status, kept alike by every engine |
//! | `report` | [`FitReport`]: the machine-readable summary of any fit |
//! | `stall` | when a fit that can no longer refine gives up ([`FitStatus::Stalled`]) |

mod accel;
mod curve;
mod deviation;
mod error;
mod log;
pub(crate) mod parallel;
mod reference;
mod report;
mod spec;
mod stall;
mod state;
mod stats;
mod strays;
mod subdiv;
mod surface;
mod surfels;

pub use accel::Acceleration;
pub use curve::{
    least_squares_curve, CurveFitOptions, CurveFitter, KnotFeature, KnotPlacementFitter,
    KnotPlacementOptions,
};
pub use deviation::{DeviationHistogram, DeviationStats};
pub use error::FitError;
pub use log::FitLog;
pub use parallel::{max_threads, set_max_threads};
pub use reference::{BackStats, DataSurface};
pub use report::{within_tolerance_pct, FitReport};
pub use spec::{Cloud, FitData, FitSpec, Method, OptionInfo, Scheme, OPTION_TABLE};
pub use state::{FitState, BACK_TOLERANCE_FACTOR};
pub use stats::{ErrorStats, IterationRecord, PhaseTimes, Tolerances};
pub use strays::StrayPoints;
pub use subdiv::{
    default_initial_count, initial_control, surface_of, ControlSurface, CreaseReport,
    FootPointBench, FootPointTiming, ReconstructionReport, SubdivFitOptions, SubdivFitter,
    Weighting,
};
pub use surface::{
    detect_rows, energies, grid_rows, parameterize, parameterize_on_surface, CreaseKnot,
    CreaseKnots, FoldPolicy, GeometricSurfaceFitter, GeometricSurfaceOptions, LsqSurfaceFitter,
    LsqSurfaceOptions, ParamOptions, Parameterization, SectionsFitter, SectionsOptions,
    SurfaceGrid, SurfaceTrim, TolMode, JUMP_FACTOR,
};

use crate::geom::Point3;
use crate::mesh::PolyMesh;
use crate::spline::{BSplineCurve, BSplineSurface};
pub(crate) use surface::outline_on;

/// What one call of [`Fitter::step`] left the fit in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FitStatus {
    /// Tolerances not met yet; more iterations may help.
    Running,
    /// Every tolerance given is met.
    Converged,
    /// The iteration cap was reached first (or nothing could be refined any more).
    MaxIterations,
    /// The tolerances are out of reach: no refinement is left (the control budget is spent,
    /// or refinement is off) and the errors stopped falling, or fall too slowly to meet the
    /// tolerances within the iteration cap (the rule is in `src/fit/stall.rs`).
    Stalled,
}

/// A drawable shape of a fit: its control net or its fitted surface or curve.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// Faces (drawn shaded; their edges drawn as lines).
    Mesh(PolyMesh),
    /// Points joined in order, back to the first when closed.
    Polyline {
        /// The vertices.
        points: Vec<Point3>,
        /// Whether the last joins the first.
        closed: bool,
    },
}

/// The fitted spline of a fit that has one (for CAD export), with the data points' foot-point
/// parameters on it, in data order.
#[derive(Clone, Copy, Debug)]
pub enum Spline<'a> {
    /// A tensor-product B-spline / NURBS surface.
    Surface {
        /// The surface.
        surface: &'a BSplineSurface,
        /// (u, v) of every data point's foot point.
        params: &'a [[f64; 2]],
    },
    /// A B-spline / NURBS curve.
    Curve {
        /// The curve.
        curve: &'a BSplineCurve,
        /// u of every data point's foot point.
        params: &'a [f64],
    },
}

/// The interface every fitting engine offers: iterate, and read where the fit stands.
pub trait Fitter {
    /// Runs one iteration (foot points, error vectors, control-point moves; refinement when
    /// due). Once the fit has stopped it changes nothing and returns the status again.
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

    /// Data, errors, tolerances, scheme and method, history and status.
    fn state(&self) -> &FitState;

    /// The state, for builders that add what they did before the engine existed (reading,
    /// meshing, simplification) to its set-up time and intake.
    fn state_mut(&mut self) -> &mut FitState;

    /// The scheme this engine fits.
    fn scheme(&self) -> Scheme {
        self.state().scheme()
    }

    /// The method it fits with.
    fn method(&self) -> Method {
        self.state().method()
    }

    /// History, status, set-up time and intake of the fit.
    fn log(&self) -> &FitLog {
        self.state().log()
    }

    /// The log, for builders (see [`Fitter::state_mut`]).
    fn log_mut(&mut self) -> &mut FitLog {
        self.state_mut().log_mut()
    }

    /// Where the fit stands after the last step.
    fn status(&self) -> FitStatus {
        self.log().status()
    }

    /// One record per iteration so far; the last is the current state.
    fn history(&self) -> &[IterationRecord] {
        self.log().history()
    }

    /// The tolerances the fit stops at (% of the bounding-box diagonal).
    fn tolerances(&self) -> Tolerances {
        self.state().tolerances()
    }

    /// The data points, in the order of [`Fitter::point_errors`].
    fn data(&self) -> &[Point3] {
        self.state().data()
    }

    /// Bounding-box diagonal of the data: what the `_pct` figures are relative to.
    fn diagonal(&self) -> f64 {
        self.state().diagonal()
    }

    /// Signed distance of every data point to the current surface or curve, in model units
    /// (positive on the side the surface normal points to), in data order.
    fn point_errors(&self) -> &[f64] {
        self.state().errors()
    }

    /// Error statistics of the current surface or curve.
    fn stats(&self) -> ErrorStats {
        self.state().stats()
    }

    /// Surface → data statistics of the current surface, where the fit measures them.
    fn back_stats(&self) -> Option<BackStats> {
        self.state().back()
    }

    /// The surface → data distance of each of `points` ([`FitState::distances_to_data`]).
    fn distances_to_data(&self, points: &[Point3]) -> Option<Vec<Option<f64>>> {
        self.state().distances_to_data(points)
    }

    /// The point of the surface or curve each data point is measured to, in data order.
    fn foot_points(&self) -> Vec<Point3>;

    /// Number of control points now.
    fn num_control_points(&self) -> usize;

    /// The control net: the control mesh, the B-spline control grid, or a curve's polygon.
    fn control_shape(&self) -> Shape;

    /// The fitted shape: a surface tessellated with `resolution` segments per patch (knot
    /// span) edge, or a curve sampled with `4 · resolution` segments per control point.
    /// `resolution` is clamped to 1..=64.
    fn limit_shape(&self, resolution: usize) -> Shape;

    /// The fitted surface cut to the face the CAD exports write: a B-spline surface's
    /// tessellation (as [`Fitter::limit_shape`], on the same points) without the quads beyond
    /// the outline of the data's parameters; `None` for other shapes, or when no outline can be
    /// built (the exports then write the whole surface).
    fn trimmed_limit_shape(&self, resolution: usize) -> Option<Shape> {
        let _ = resolution;
        None
    }

    /// Iso-parameter lines at the knots of a B-spline surface as segment end points (two per
    /// segment, `resolution` segments per knot span); none for other shapes.
    fn iso_lines(&self, resolution: usize) -> Vec<Point3> {
        let _ = resolution;
        Vec::new()
    }

    /// The fitted spline, for IGES and STEP; subdivision surfaces have none.
    fn spline(&self) -> Option<Spline<'_>> {
        None
    }

    /// The fitted subdivision limit surface, for the FEM mesh; other fits have none.
    fn subdiv_surface(&self) -> Option<&crate::subdiv::SubdivSurface> {
        None
    }

    /// What only this engine reports (control grid, fold-overs, features, curve samples), as
    /// JSON fields that [`FitReport`] writes beside the common ones.
    fn details(&self) -> serde_json::Map<String, serde_json::Value> {
        serde_json::Map::new()
    }
}
