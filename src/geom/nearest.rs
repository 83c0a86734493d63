//! The one closest-point query of the crate: [`ClosestPoint`], answered with a [`Nearest`] and
//! steered by [`NewtonOptions`]. Subdivision surfaces, B-spline surfaces and curves implement
//! it (kurbo's `ParamCurveNearest` is the model), so the fitters, the benchmarks and the tests
//! ask every shape the same way.

use super::{Point3, Vec3};

/// Where a Newton search for the point of a shape nearest to a query point ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest<P> {
    /// The parameter of the foot point (a patch and local `(u, v)`, a `[u, v]` pair or a curve
    /// parameter, as the shape defines it).
    pub param: P,
    /// The foot point on the shape.
    pub point: Point3,
    /// Squared distance from the query point to `point`.
    pub dist_sq: f64,
    /// The direction that gives the distance a sign: a surface's unit normal S_u × S_v (zero
    /// where degenerate), a curve's tangent C'(u) (not normalised).
    pub direction: Vec3,
    /// Newton iterations used.
    pub iterations: u32,
    /// Whether Newton's step fell under the tolerance (a point clamped at an open boundary
    /// counts once it stops moving).
    pub converged: bool,
}

/// Settings of a Newton closest-point search.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct NewtonOptions {
    /// Iteration cap. Default 20.
    pub max_iter: usize,
    /// Converged when a step is below this. Each shape says what it is relative to
    /// ([`ClosestPoint::closest_point_from`]): the parameter domain of a B-spline, model units
    /// for a subdivision surface. Default 1e-12.
    pub step_tol: f64,
    /// Largest parameter step of one iteration (a trust region), in parameter units. Default
    /// unbounded.
    pub max_step: f64,
}

impl NewtonOptions {
    /// The defaults: 20 iterations, step tolerance 1e-12, no step bound.
    pub const DEFAULT: NewtonOptions = NewtonOptions {
        max_iter: 20,
        step_tol: 1e-12,
        max_step: f64::INFINITY,
    };

    /// Sets the iteration cap (a `const fn`, for options built in constants).
    pub const fn with_max_iter(mut self, n: usize) -> Self {
        self.max_iter = n;
        self
    }

    /// Sets the step tolerance (a `const fn`).
    pub const fn with_step_tol(mut self, tol: f64) -> Self {
        self.step_tol = tol;
        self
    }

    /// Whether every field is usable: at least one iteration, positive finite tolerance and
    /// step bound (the bound may be infinite).
    pub fn is_valid(&self) -> bool {
        self.max_iter >= 1
            && self.step_tol.is_finite()
            && self.step_tol > 0.0
            && self.max_step > 0.0
            && !self.max_step.is_nan()
    }
}

default_is_const!(NewtonOptions);

/// A shape that finds its point nearest to a query point by Newton's method from a starting
/// parameter.
pub trait ClosestPoint {
    /// How a point of the shape is addressed.
    type Param: Copy;

    /// The foot point of `p`, by Newton's method from `start`. Never NaN: a query that cannot
    /// be answered ends where it started, unconverged.
    fn closest_point_from(
        &self,
        p: Point3,
        start: Self::Param,
        options: &NewtonOptions,
    ) -> Nearest<Self::Param>;

    /// A hint that a search from `at` comes soon: the shape may ask the processor to load the
    /// data evaluation there reads (see [`crate::geom::prefetch`]). Changes no result.
    fn prefetch(&self, _at: &Self::Param) {}
}
