//! Chaikin corner-cutting curves and their exact limit, the uniform quadratic B-spline.
//!
//! Closed polygons use the classic rule (each edge PᵢPᵢ₊₁ gives ¾Pᵢ + ¼Pᵢ₊₁ and ¼Pᵢ + ¾Pᵢ₊₁);
//! its limit is the periodic uniform quadratic B-spline on the polygon. Open polygons keep their
//! end points and cut the first and last edge at the midpoint instead, which is exactly midpoint
//! knot insertion on the clamped uniform quadratic B-spline, so that curve is the limit.

use super::{BSplineCurve, SplineError};
use crate::geom::Point3;

/// A Chaikin curve: a control polygon, open or closed, refined by corner cutting.
#[derive(Clone, Debug, PartialEq)]
pub struct ChaikinCurve {
    points: Vec<Point3>,
    closed: bool,
}

impl ChaikinCurve {
    /// A Chaikin curve on at least 3 finite control points.
    pub fn try_new(points: Vec<Point3>, closed: bool) -> Result<ChaikinCurve, SplineError> {
        if points.len() < 3 {
            return Err(SplineError::ControlPointCount {
                found: points.len(),
                expected: 3,
            });
        }
        if let Some(index) = points.iter().position(|p| !p.is_finite()) {
            return Err(SplineError::NonFiniteControlPoint { index });
        }
        Ok(ChaikinCurve { points, closed })
    }

    /// The control polygon.
    pub fn points(&self) -> &[Point3] {
        &self.points
    }

    /// Whether the polygon is closed.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// One round of corner cutting. The limit curve stays the same; its parameter doubles
    /// (`u` on this curve is `2u` on the result, see [`ChaikinCurve::limit`]).
    pub fn subdivide(&self) -> ChaikinCurve {
        let p = &self.points;
        let n = p.len();
        let cut = |a: Point3, b: Point3| [0.75 * a + 0.25 * b, 0.25 * a + 0.75 * b];
        let mut out = Vec::with_capacity(2 * n);
        if self.closed {
            for i in 0..n {
                out.extend(cut(p[i], p[(i + 1) % n]));
            }
        } else {
            out.push(p[0]);
            out.push(0.5 * (p[0] + p[1]));
            for i in 1..n - 2 {
                out.extend(cut(p[i], p[i + 1]));
            }
            out.push(0.5 * (p[n - 2] + p[n - 1]));
            out.push(p[n - 1]);
        }
        ChaikinCurve {
            points: out,
            closed: self.closed,
        }
    }

    /// The limit curve as a quadratic B-spline with unit knot spacing: closed polygons of n
    /// points give a periodic curve on `[0, n]`, open ones a clamped curve on `[0, n − 2]`.
    pub fn limit(&self) -> Result<BSplineCurve, SplineError> {
        let n = self.points.len();
        if self.closed {
            let tau: Vec<f64> = (0..=n).map(|i| i as f64).collect();
            BSplineCurve::try_periodic(2, &tau, self.points.clone())
        } else {
            let m = n - 2;
            let mut knots = vec![0.0; 3];
            knots.extend((1..m).map(|i| i as f64));
            knots.extend([m as f64; 3]);
            BSplineCurve::try_new(2, knots, self.points.clone())
        }
    }
}
