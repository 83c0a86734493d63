//! One knot vector for a family of sections (the rows, or the columns of their control
//! points): the sections' multiple knots that fit, and single knots placed to the tolerance for
//! all of them at once.

use super::SectionsOptions;
use crate::fit::surface::patches::Acc;
use crate::fit::FitError;
use crate::geom::{Point3, Vec3};
use crate::spline::BSplineCurve;

/// A family of sections fitted on one knot vector: each section's points (an index range
/// into `points`) with their parameters on [0, 1], increasing along the section.
pub(super) struct Family<'a> {
    pub(super) points: &'a [Point3],
    pub(super) sections: &'a [std::ops::Range<usize>],
    pub(super) params: &'a [f64],
    /// The surface's unit normal at every point (zero where unknown; empty when the family
    /// is judged on other data): deviations are measured along it. Within the surface a section may wander sideways without the surface leaving
    /// the data: bun000's samples zigzag by half a pixel from row to row, so its columns of
    /// control points did too, by twice the columns' tolerance.
    pub(super) normals: &'a [Vec3],
}

impl Family<'_> {
    /// The multiple knots of `candidates` (value, multiplicity; the sections' features) that
    /// fit on one knot vector, corners first: each is taken when it leaves every section
    /// [`MIN_SPAN_POINTS`] points on either side within its span ([`Family::splits`]), so the
    /// same crease found a little apart in neighbouring sections gives one knot, and no span
    /// is left without data of some section (its least-squares fit would be undetermined and
    /// its control points, which the columns are fitted to, wild). Sorted by value.
    fn admit(&self, mut candidates: Vec<(f64, usize)>) -> Vec<(f64, usize)> {
        candidates.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.total_cmp(&b.0)));
        let mut knots: Vec<(f64, usize)> = Vec::new();
        for (t, m) in candidates.into_iter().filter(|k| k.0 > 0.0 && k.0 < 1.0) {
            let at = knots.partition_point(|k| k.0 < t);
            let a = at.checked_sub(1).map_or(0.0, |i| knots[i].0);
            let b = knots.get(at).map_or(1.0, |k| k.0);
            if t > a && t < b && self.splits(a, t, b) {
                knots.insert(at, (t, m));
            }
        }
        knots
    }

    /// Whether a knot at `m` in the span [a, b) leaves every section at least
    /// [`MIN_SPAN_POINTS`] points on either side within the span (the least-squares fits
    /// stay determined by their data).
    pub(super) fn splits(&self, a: f64, m: f64, b: f64) -> bool {
        self.sections.iter().all(|r| {
            let t = &self.params[r.clone()];
            let below = |x: f64| t.partition_point(|&s| s < x);
            let end = if b >= 1.0 { t.len() } else { below(b) };
            below(m) - below(a) >= MIN_SPAN_POINTS && end - below(m) >= MIN_SPAN_POINTS
        })
    }
}

/// Points every section keeps on either side of a new knot within the span it halves.
const MIN_SPAN_POINTS: usize = 2;

/// The sections of `family` fitted by least squares on one knot vector: the multiple knots of
/// `features` that fit ([`Family::admit`]), plus single knots halving every span whose
/// deviations miss the tolerance (`failing(curves, span bounds)`, per span), round after
/// round, until every span passes or cannot be halved ([`Family::splits`]). An infinite `tol`
/// fits on the multiple knots alone.
pub(super) fn place_common_knots(
    family: &Family<'_>,
    features: Vec<(f64, usize)>,
    options: &SectionsOptions,
    tol: f64,
    failing: impl Fn(&[BSplineCurve], &[f64]) -> Result<Vec<bool>, FitError>,
) -> Result<Vec<BSplineCurve>, FitError> {
    let mut knots = family.admit(features);
    loop {
        let curves = family
            .sections
            .iter()
            .map(|r| {
                let (points, params) = (&family.points[r.clone()], &family.params[r.clone()]);
                refit(&knots, options.degree, points, params)
            })
            .collect::<Result<Vec<_>, _>>()?;
        if !tol.is_finite() {
            return Ok(curves);
        }
        let bounds = span_bounds(&knots);
        let halves: Vec<f64> = failing(&curves, &bounds)?
            .iter()
            .enumerate()
            .filter(|(_, &fails)| fails)
            .map(|(s, _)| (bounds[s], 0.5 * (bounds[s] + bounds[s + 1]), bounds[s + 1]))
            .filter(|&(a, m, b)| family.splits(a, m, b))
            .map(|(_, m, _)| m)
            .collect();
        if halves.is_empty() {
            return Ok(curves);
        }
        knots.extend(halves.into_iter().map(|m| (m, 1)));
        knots.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
}

/// The distinct knot values of `knots` inside (0, 1), with 0 and 1: the spans' bounds.
fn span_bounds(knots: &[(f64, usize)]) -> Vec<f64> {
    let mut bounds = vec![0.0];
    for &(value, _) in knots.iter().filter(|k| k.0 > 0.0 && k.0 < 1.0) {
        if bounds.last() != Some(&value) {
            bounds.push(value);
        }
    }
    bounds.push(1.0);
    bounds
}

/// The deviations of every section's points from its curve, summed per span of `bounds`:
/// along the surface's normal at the point, or without one the distance of the point from the
/// curve's tangent line at its parameter (the first-order foot point; the residual at a fixed
/// parameter would count the parameter's slip along the curve as error).
pub(super) fn span_errors(
    family: &Family<'_>,
    curves: &[BSplineCurve],
    bounds: &[f64],
    tol: f64,
) -> Vec<Acc> {
    let mut spans = vec![Acc::default(); bounds.len() - 1];
    for (r, curve) in family.sections.iter().zip(curves) {
        let points = family.points[r.clone()]
            .iter()
            .zip(&family.normals[r.clone()]);
        for (&t, (&q, &n)) in family.params[r.clone()].iter().zip(points) {
            let [at, d1, ..] = curve.eval_derivs(t, 1);
            let e = q - at;
            let tangent = d1.normalize_or_zero();
            let d = if n == Vec3::ZERO {
                (e - tangent * e.dot(tangent)).length()
            } else {
                e.dot(n)
            };
            let s = bounds.partition_point(|&b| b <= t).clamp(1, spans.len()) - 1;
            spans[s].push(d, tol);
        }
    }
    spans
}

/// The least-squares curve of `degree` on the clamped knots `knots` (interior, with
/// multiplicities) through `points` at `params`.
fn refit(
    knots: &[(f64, usize)],
    degree: usize,
    points: &[Point3],
    params: &[f64],
) -> Result<BSplineCurve, FitError> {
    let mut all = vec![0.0; degree + 1];
    for &(value, m) in knots.iter().filter(|k| k.0 > 0.0 && k.0 < 1.0) {
        all.extend(std::iter::repeat_n(value, m.min(degree)));
    }
    all.extend(std::iter::repeat_n(1.0, degree + 1));
    let n = all.len() - degree - 1;
    let ctrl = (0..n).map(|i| points[i * points.len() / n]).collect();
    let template = BSplineCurve::try_new(degree, all, ctrl)?;
    crate::fit::least_squares_curve(&template, points, params)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn features_become_knots_where_every_section_keeps_data_around_them() {
        // Two sections of 11 points at 0, 0.1, …, 1; a corner found at 0.5 in one and at 0.52
        // in the other is one knot; a double knot 0.1 from it would leave one point between.
        let points = vec![Point3::ZERO; 22];
        let params: Vec<f64> = (0..22).map(|i| (i % 11) as f64 / 10.0).collect();
        let family = Family {
            points: &points,
            sections: &[0..11, 11..22],
            params: &params,
            normals: &[Vec3::ZERO; 22],
        };
        let knots = family.admit(vec![(0.6, 2), (0.52, 3), (0.5, 3), (0.25, 2)]);
        assert_eq!(knots, vec![(0.25, 2), (0.5, 3)]);
    }
}
