//! B-spline and NURBS curves and surfaces.
//!
//! [`KnotVector`] holds a checked knot sequence with its degree and evaluates the B-spline basis
//! and its derivatives (The NURBS Book, algorithms A2.1–A2.3); curves and surfaces build on it.
//! [`BSplineCurve`] is an open or closed (periodic) B-spline or NURBS curve; [`ChaikinCurve`] is a
//! corner-cutting curve evaluated exactly through its quadratic B-spline limit. [`TrimRegion`] is the part of a surface's (u, v) domain its data covers.

mod chaikin;
mod curve;
mod error;
mod knots;
mod surface;
mod trim;

pub use chaikin::ChaikinCurve;
pub use curve::{BSplineCurve, CurveBasis, MAX_CURVE_DEGREE, MAX_DERIV};
pub use error::SplineError;
pub use knots::{KnotVector, MAX_DEGREE};
pub use surface::{BSplineSurface, SurfaceBasis, SurfaceDerivs, MAX_SURFACE_DERIV};
pub use trim::{Outline, TrimError, TrimOptions, TrimRegion};
