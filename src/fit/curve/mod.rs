//! Fitting B-spline curves to ordered points (sections, polylines): by error vectors
//! ([`CurveFitter`], SPEC §1.9) or by least squares with knot placement
//! ([`KnotPlacementFitter`], SPEC §3). Both share the data checks, chord-length parameters,
//! foot points and drawable shapes here.

/// The [`Fitter`](crate::fit::Fitter) methods besides `step` of a curve fitter with `state`,
/// `curve` and the foot-point parameters in the field named by the argument.
macro_rules! curve_fitter_methods {
    ($feet:ident) => {
        fn state(&self) -> &FitState {
            &self.state
        }

        fn state_mut(&mut self) -> &mut FitState {
            &mut self.state
        }

        fn foot_points(&self) -> Vec<Point3> {
            self.$feet.iter().map(|&u| self.curve.eval(u)).collect()
        }

        fn num_control_points(&self) -> usize {
            self.curve.control_points().len()
        }

        fn control_shape(&self) -> Shape {
            super::control_polygon(&self.curve)
        }

        fn limit_shape(&self, resolution: usize) -> Shape {
            super::curve_shape(&self.curve, resolution)
        }

        fn spline(&self) -> Option<Spline<'_>> {
            Some(Spline::Curve {
                curve: &self.curve,
                params: &self.$feet,
            })
        }
    };
}

mod geometric;
mod knot_placement;
mod least_squares;

pub use geometric::{CurveFitOptions, CurveFitter};
pub use knot_placement::{KnotFeature, KnotPlacementFitter, KnotPlacementOptions};
pub use least_squares::least_squares_curve;

use super::{FitError, FitState, Method, Scheme, Shape, Tolerances};
use crate::geom::{Aabb, ClosestPoint, Nearest, NewtonOptions, Point3, Vec3};
use crate::spline::{BSplineCurve, MAX_CURVE_DEGREE};

setters!([CurveFitOptions, KnotPlacementOptions] {
    /// Sets the degree.
    with_degree(degree: usize) => |s| s.degree;
    /// Sets whether the curve is closed.
    with_closed(closed: bool) => |s| s.closed;
    /// Sets the tolerances.
    with_tolerances(tolerances: crate::fit::Tolerances) => |s| s.tolerances;
});

/// The degree check both curve fitters share.
fn check_degree(degree: usize) -> Result<(), FitError> {
    if (1..=MAX_CURVE_DEGREE).contains(&degree) {
        return Ok(());
    }
    Err(FitError::InvalidOption {
        name: "degree",
        reason: format!("{degree} is not in 1..={MAX_CURVE_DEGREE}"),
    })
}

/// Fails unless `value` is finite and positive; both curve fitters word it the same.
fn check_positive(name: &'static str, value: f64) -> Result<(), FitError> {
    if value.is_finite() && value > 0.0 {
        return Ok(());
    }
    Err(FitError::InvalidOption {
        name,
        reason: format!("{value} must be positive"),
    })
}

/// The scheme a curve of `degree` is fitted as: Chaikin's corner cutting converges to the
/// quadratic B-spline.
fn scheme_of(degree: usize) -> Scheme {
    if degree == 2 {
        Scheme::ChaikinCurve
    } else {
        Scheme::BsplineCurve
    }
}

/// The state of a fit of `data` by `method` with a curve of `degree`, tolerances `tol`, starting
/// from `initial` control points, set up since `start`.
fn curve_state(
    data: &CurveData,
    degree: usize,
    method: Method,
    tol: Tolerances,
    initial: usize,
    start: web_time::Instant,
) -> FitState {
    FitState::new(
        (scheme_of(degree), method),
        tol,
        data.points.clone(),
        initial,
        start,
    )
}

/// The control polygon of `curve`.
fn control_polygon(curve: &BSplineCurve) -> Shape {
    Shape::Polyline {
        points: curve.control_points().to_vec(),
        closed: curve.is_closed(),
    }
}

/// The curve at `4 · resolution` parameters per control point over its domain, ends included.
fn curve_shape(c: &BSplineCurve, resolution: usize) -> Shape {
    let per_span = 4 * resolution.clamp(1, 64);
    let (a, b) = c.domain();
    let n = (c.control_points().len() * per_span).max(2);
    let points = (0..=n)
        .map(|i| c.eval(a + (b - a) * i as f64 / n as f64))
        .collect();
    Shape::Polyline {
        points,
        closed: false,
    }
}

/// What both curve fitters report besides the common figures: degree, closedness, domain,
/// 101 samples of the curve and its clamped (open-knot) form for CAD readers.
fn details(curve: &BSplineCurve) -> serde_json::Map<String, serde_json::Value> {
    let mut m = serde_json::Map::new();
    m.insert("degree".into(), curve.degree().into());
    m.insert("closed".into(), curve.is_closed().into());
    let (a, b) = curve.domain();
    m.insert("domain".into(), serde_json::json!([a, b]));
    m.insert("samples".into(), serde_json::json!(curve.samples(101)));
    if let Ok(clamped) = curve.to_clamped() {
        let points: Vec<[f64; 3]> = clamped
            .control_points()
            .iter()
            .map(|p| p.to_array())
            .collect();
        m.insert(
            "clamped".into(),
            serde_json::json!({
                "degree": clamped.degree(),
                "knots": clamped.knots().knots(),
                "control_points": points,
            }),
        );
    }
    m
}

/// Ordered curve data with its chord-length parameters and scale.
#[derive(Clone, Debug)]
pub(crate) struct CurveData {
    pub points: Vec<Point3>,
    /// Chord-length parameters on [0, 1]; for a closed curve the closing segment counts and the
    /// last point sits before 1.
    pub chord: Vec<f64>,
    pub diagonal: f64,
    /// Length of the polyline (closing segment included for closed curves).
    pub length: f64,
    /// All points share one z: errors get a sign from the in-plane normal.
    pub planar: bool,
}

impl CurveData {
    /// Checks and parameterises `points`: at least `needed`, finite, no point equal to the one
    /// before it. A closed polyline given with its first point repeated at the end loses the
    /// repeat.
    pub fn try_new(points: &[Point3], closed: bool, needed: usize) -> Result<CurveData, FitError> {
        crate::geom::check_coordinates(points)?;
        let mut points = points.to_vec();
        if closed && points.len() > 1 && points.first() == points.last() {
            points.pop();
        }
        if points.len() < needed {
            return Err(FitError::TooFewPoints {
                found: points.len(),
                needed,
            });
        }
        if let Some(i) = (1..points.len()).find(|&i| points[i] == points[i - 1]) {
            return Err(FitError::DuplicatePoint { index: i });
        }
        let bbox = Aabb::from_points(&points).ok_or(FitError::TooFewPoints { found: 0, needed })?;
        let mut chord = vec![0.0];
        for w in points.windows(2) {
            chord.push(chord[chord.len() - 1] + (w[1] - w[0]).length());
        }
        let total = chord[chord.len() - 1]
            + if closed {
                (points[0] - points[points.len() - 1]).length()
            } else {
                0.0
            };
        chord.iter_mut().for_each(|c| *c /= total);
        Ok(CurveData {
            planar: bbox.max.z == bbox.min.z,
            diagonal: bbox.diagonal(),
            length: total,
            points,
            chord,
        })
    }

    /// Foot points of every data point on `curve`, Newton from `params`; returns the distances
    /// (signed for planar data: positive on the left of the direction of travel).
    pub fn foot_points(
        &self,
        curve: &BSplineCurve,
        params: &mut [f64],
        newton_iter: usize,
    ) -> Vec<f64> {
        // As for surfaces (patches::correct_parameters): a step of 1e-7 of the domain is far
        // below any fitting tolerance.
        let opts = NewtonOptions::DEFAULT
            .with_max_iter(newton_iter)
            .with_step_tol(1e-7);
        self.points
            .iter()
            .zip(params.iter_mut())
            .map(|(&p, u)| {
                let near = curve.closest_point_from(p, *u, &opts);
                *u = near.param;
                self.signed_distance(p, &near)
            })
            .collect()
    }

    fn signed_distance(&self, p: Point3, near: &Nearest<f64>) -> f64 {
        let d = near.dist_sq.sqrt();
        if !self.planar {
            return d;
        }
        let tangent = near.direction;
        let normal = Vec3::new(-tangent.y, tangent.x, 0.0);
        if (p - near.point).dot(normal) < 0.0 {
            -d
        } else {
            d
        }
    }
}
