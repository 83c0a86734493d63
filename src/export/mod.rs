//! CAD export of B-spline and NURBS geometry: IGES 5.3 (entities 126 and 128) and STEP AP214
//! (`B_SPLINE_CURVE_WITH_KNOTS`, `B_SPLINE_SURFACE_WITH_KNOTS`, rational complex forms).
//!
//! The writers take plain descriptions ([`CurveDesc`], [`SurfaceDesc`]) so any fitted curve or
//! surface exports by converting itself into one; [`BSplineCurve`] does so with
//! [`CurveDesc::from_curve`]. Closed (periodic) curves are written as their exact clamped
//! equivalent with the closed flag set, which every CAD reader accepts. Coordinates are written
//! in millimetres, unscaled, with round-trip precision.

mod cage;
mod fitted;
pub mod iges;
pub mod step;

pub use cage::{cage_creases_json, cage_usda, CageCreases, INFINITE_SHARPNESS};
pub use fitted::{
    cad_model, cage_obj, exports_for, glb_of, iges_of, step_of, surface_mesh, surface_shape,
    EXPORT_RESOLUTION,
};

use crate::geom::Point3;
use crate::spline::{BSplineCurve, KnotVector, SplineError, TrimRegion};
use thiserror::Error;

/// Why geometry could not be exported.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ExportError {
    /// Counts of knots, control points, weights or grid size do not agree.
    #[error("{what}: {found} given where {expected} are needed")]
    Count {
        /// Which list is wrong (e.g. "surface 0 knots_u").
        what: String,
        /// Entries given.
        found: usize,
        /// Entries needed.
        expected: usize,
    },
    /// A number is NaN or infinite, or a weight not positive, or knots decrease.
    #[error("{what} is not valid: {reason}")]
    Invalid {
        /// Which entry (e.g. "curve 1 knot 4").
        what: String,
        /// What is wrong.
        reason: String,
    },
    /// The curve could not be converted (closed curve clamping).
    #[error(transparent)]
    Spline(#[from] SplineError),
    /// The fit has nothing of this kind to export (the message says what to export instead).
    #[error("{what}")]
    Unsupported {
        /// What was asked for and why it cannot be given.
        what: String,
    },
}

/// A clamped B-spline or NURBS curve as the writers need it.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveDesc {
    /// Degree p ≥ 1.
    pub degree: usize,
    /// Full knot vector, `control_points.len() + degree + 1` knots.
    pub knots: Vec<f64>,
    /// Control points.
    pub control_points: Vec<Point3>,
    /// Positive weights for a NURBS curve, one per control point.
    pub weights: Option<Vec<f64>>,
    /// The curve is geometrically closed (its ends meet).
    pub closed: bool,
}

/// A tensor-product B-spline or NURBS surface as the writers need it.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceDesc {
    /// Degree in u.
    pub degree_u: usize,
    /// Degree in v.
    pub degree_v: usize,
    /// Knots in u, `num_u + degree_u + 1`.
    pub knots_u: Vec<f64>,
    /// Knots in v, `num_v + degree_v + 1`.
    pub knots_v: Vec<f64>,
    /// Control points along u.
    pub num_u: usize,
    /// Control points along v.
    pub num_v: usize,
    /// Control grid, `num_u × num_v`, row-major: point (i, j) at `i * num_v + j`, i along u.
    pub control_points: Vec<Point3>,
    /// Positive weights for a NURBS surface, in the same order.
    pub weights: Option<Vec<f64>>,
    /// The part of the (u, v) domain the face covers; `None` for the whole rectangle. STEP
    /// writes a trimmed surface as an `ADVANCED_FACE` bounded by its loops, IGES as entity 144.
    pub trim: Option<TrimRegion>,
}

/// What one export file holds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExportModel {
    /// Curves.
    pub curves: Vec<CurveDesc>,
    /// Surfaces.
    pub surfaces: Vec<SurfaceDesc>,
}

impl CurveDesc {
    /// The description of `curve`: closed curves become their clamped equivalent.
    pub fn from_curve(curve: &BSplineCurve) -> Result<CurveDesc, ExportError> {
        let clamped = curve.to_clamped()?;
        Ok(CurveDesc {
            degree: clamped.degree(),
            knots: clamped.knots().knots().to_vec(),
            control_points: clamped.control_points().to_vec(),
            weights: clamped.weights().map(<[f64]>::to_vec),
            closed: curve.is_closed(),
        })
    }

    /// The degree-1 B-spline through `points`, vertex k at parameter k; a closed one repeats
    /// the first vertex at the end.
    pub(crate) fn polyline(mut points: Vec<Point3>, closed: bool) -> CurveDesc {
        if closed {
            if let Some(&first) = points.first() {
                points.push(first);
            }
        }
        let m = points.len().saturating_sub(1);
        let mut knots = vec![0.0];
        knots.extend((0..=m).map(|k| k as f64));
        knots.push(m as f64);
        CurveDesc {
            degree: 1,
            knots,
            control_points: points,
            weights: None,
            closed,
        }
    }

    /// Checks counts, finiteness, weights and knot order.
    pub fn validate(&self, what: &str) -> Result<(), ExportError> {
        let n = self.control_points.len();
        check_list(&format!("{what} knots"), &self.knots, n + self.degree + 1)?;
        check_points(what, &self.control_points, self.weights.as_deref(), n)?;
        if self.degree == 0 || n < self.degree + 1 {
            return Err(ExportError::Invalid {
                what: what.to_string(),
                reason: format!("degree {} with {n} control points", self.degree),
            });
        }
        Ok(())
    }

    /// Whether the curve is polynomial (no weights, or all equal).
    pub fn is_polynomial(&self) -> bool {
        uniform(self.weights.as_deref())
    }

    /// The parameter domain of the clamped knot vector.
    pub fn domain(&self) -> (f64, f64) {
        (
            self.knots[self.degree],
            self.knots[self.knots.len() - self.degree - 1],
        )
    }
}

impl SurfaceDesc {
    /// Checks counts, finiteness, weights and knot order.
    pub fn validate(&self, what: &str) -> Result<(), ExportError> {
        let n = self.num_u * self.num_v;
        check_list(
            &format!("{what} knots_u"),
            &self.knots_u,
            self.num_u + self.degree_u + 1,
        )?;
        check_list(
            &format!("{what} knots_v"),
            &self.knots_v,
            self.num_v + self.degree_v + 1,
        )?;
        check_points(what, &self.control_points, self.weights.as_deref(), n)?;
        self.check_trim(what)?;
        if self.degree_u == 0
            || self.degree_v == 0
            || self.num_u <= self.degree_u
            || self.num_v <= self.degree_v
        {
            return Err(ExportError::Invalid {
                what: what.to_string(),
                reason: format!(
                    "degrees {}×{} with a {}×{} grid",
                    self.degree_u, self.degree_v, self.num_u, self.num_v
                ),
            });
        }
        Ok(())
    }

    /// Whether the surface is polynomial (no weights, or all equal).
    pub fn is_polynomial(&self) -> bool {
        uniform(self.weights.as_deref())
    }

    /// S(u, v), by the rational tensor-product formula: the reference values an importing CAD
    /// system must reproduce. Parameters are clamped into the domain.
    pub fn eval(&self, u: f64, v: f64) -> Result<Point3, ExportError> {
        self.validate("surface")?;
        let ku = KnotVector::try_new(self.degree_u, self.knots_u.clone())?;
        let kv = KnotVector::try_new(self.degree_v, self.knots_v.clone())?;
        let (fu, bu) = ku.basis(u);
        let (fv, bv) = kv.basis(v);
        let (mut num, mut den) = (Point3::ZERO, 0.0);
        for (a, nu) in bu.iter().take(self.degree_u + 1).enumerate() {
            for (b, nv) in bv.iter().take(self.degree_v + 1).enumerate() {
                let (i, j) = (fu + a, fv + b);
                let w = nu * nv * self.weight(i, j);
                num += w * self.point(i, j);
                den += w;
            }
        }
        Ok(num / den)
    }

    /// The parameter domain, `((u0, u1), (v0, v1))`.
    pub fn domain(&self) -> ((f64, f64), (f64, f64)) {
        (
            (self.knots_u[self.degree_u], self.knots_u[self.num_u]),
            (self.knots_v[self.degree_v], self.knots_v[self.num_v]),
        )
    }

    /// A trim loop vertex outside the domain is an error (the writers would put the face's
    /// boundary off the surface).
    fn check_trim(&self, what: &str) -> Result<(), ExportError> {
        let Some(trim) = &self.trim else {
            return Ok(());
        };
        if self.knots_u.len() <= self.num_u || self.knots_v.len() <= self.num_v {
            return Ok(());
        }
        let ((u0, u1), (v0, v1)) = self.domain();
        for (k, l) in trim.loops().enumerate() {
            if let Some(i) = l
                .iter()
                .position(|p| !(p[0] >= u0 && p[0] <= u1 && p[1] >= v0 && p[1] <= v1))
            {
                return Err(ExportError::Invalid {
                    what: format!("{what} trim loop {k} vertex {i}"),
                    reason: format!("({}, {}) is outside the domain", l[i][0], l[i][1]),
                });
            }
        }
        Ok(())
    }

    /// A trim loop as the writers put it: its vertices in (u, v) (z = 0) and their surface
    /// points, with vertices added along an edge wherever the chord between the surface points
    /// strays from the surface by more than 1e-5 of the control grid's diagonal, so the 3D
    /// polyline and the (u, v) polyline on the surface agree parameter by parameter.
    pub(crate) fn trim_loop(
        &self,
        l: &[[f64; 2]],
    ) -> Result<(Vec<Point3>, Vec<Point3>), ExportError> {
        let (lo, hi) = self.control_points.iter().fold(
            (
                Point3::splat(f64::INFINITY),
                Point3::splat(f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let tol = 1e-5 * (hi - lo).length();
        let (mut uv, mut xyz) = (Vec::new(), Vec::new());
        for k in 0..l.len() {
            let (a, b) = (l[k], l[(k + 1) % l.len()]);
            let mut stack = vec![(0.0, 1.0, self.eval(a[0], a[1])?, self.eval(b[0], b[1])?)];
            // Depth-first, the first half first, so the vertices come out in order.
            while let Some((t0, t1, p0, p1)) = stack.pop() {
                let tm = (t0 + t1) / 2.0;
                let at = |t: f64| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
                let m = at(tm);
                let pm = self.eval(m[0], m[1])?;
                if (pm - (p0 + p1) / 2.0).length() > tol && t1 - t0 > 1.0 / 64.0 {
                    stack.push((tm, t1, pm, p1));
                    stack.push((t0, tm, p0, pm));
                } else {
                    let s = at(t0);
                    uv.push(Point3::new(s[0], s[1], 0.0));
                    xyz.push(p0);
                }
            }
        }
        Ok((uv, xyz))
    }

    /// Control point (i, j).
    pub fn point(&self, i: usize, j: usize) -> Point3 {
        self.control_points[i * self.num_v + j]
    }

    /// Weight of control point (i, j), 1 when polynomial.
    pub fn weight(&self, i: usize, j: usize) -> f64 {
        self.weights.as_ref().map_or(1.0, |w| w[i * self.num_v + j])
    }
}

impl ExportModel {
    /// Checks every curve and surface.
    pub fn validate(&self) -> Result<(), ExportError> {
        for (i, c) in self.curves.iter().enumerate() {
            c.validate(&format!("curve {i}"))?;
        }
        for (i, s) in self.surfaces.iter().enumerate() {
            s.validate(&format!("surface {i}"))?;
        }
        Ok(())
    }

    /// Largest absolute coordinate, for the IGES global section.
    pub(crate) fn max_coordinate(&self) -> f64 {
        let curves = self.curves.iter().flat_map(|c| &c.control_points);
        let surfaces = self.surfaces.iter().flat_map(|s| &s.control_points);
        curves
            .chain(surfaces)
            .map(|p| p.abs().max_element())
            .fold(0.0, f64::max)
    }
}

fn uniform(weights: Option<&[f64]>) -> bool {
    weights.is_none_or(|w| w.iter().all(|&x| x == w[0]))
}

fn check_list(what: &str, knots: &[f64], expected: usize) -> Result<(), ExportError> {
    if knots.len() != expected {
        return Err(ExportError::Count {
            what: what.to_string(),
            found: knots.len(),
            expected,
        });
    }
    for (i, w) in knots.windows(2).enumerate() {
        if !(w[0].is_finite() && w[1].is_finite()) || w[1] < w[0] {
            return Err(ExportError::Invalid {
                what: format!("{what} {}", i + 1),
                reason: format!("knots {} then {}", w[0], w[1]),
            });
        }
    }
    Ok(())
}

fn check_points(
    what: &str,
    points: &[Point3],
    weights: Option<&[f64]>,
    expected: usize,
) -> Result<(), ExportError> {
    if points.len() != expected {
        return Err(ExportError::Count {
            what: format!("{what} control points"),
            found: points.len(),
            expected,
        });
    }
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(ExportError::Invalid {
            what: format!("{what} control point {i}"),
            reason: "not finite".into(),
        });
    }
    if let Some(w) = weights {
        if w.len() != expected {
            return Err(ExportError::Count {
                what: format!("{what} weights"),
                found: w.len(),
                expected,
            });
        }
        if let Some(i) = w.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
            return Err(ExportError::Invalid {
                what: format!("{what} weight {i}"),
                reason: format!("{} is not positive", w[i]),
            });
        }
    }
    Ok(())
}

/// A real number with a decimal point and an exponent, round-trip exact (both formats accept
/// `1.5E-3`; a mantissa without a point, as Rust prints `1E-3`, gets `.0`).
pub(crate) fn real(x: f64) -> String {
    let s = format!("{x:E}");
    match s.find('E') {
        Some(e) if !s[..e].contains('.') => format!("{}.0{}", &s[..e], &s[e..]),
        _ => s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_round_trip_with_a_point() {
        for x in [
            0.0,
            1.0,
            -2.5,
            1e-20,
            123456.789,
            std::f64::consts::PI,
            -0.1,
        ] {
            let s = real(x);
            assert!(s.contains('.') && s.contains('E'), "{s}");
            assert_eq!(s.parse::<f64>().unwrap(), x);
        }
    }
}
