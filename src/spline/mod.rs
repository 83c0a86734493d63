//! B-spline and NURBS curves and surfaces.
//!
//! [`KnotVector`] holds a checked knot sequence with its degree and evaluates the B-spline basis
//! and its derivatives (The NURBS Book, algorithms A2.1–A2.3); curves and surfaces build on it.

mod error;
mod knots;

pub use error::SplineError;
pub use knots::KnotVector;
