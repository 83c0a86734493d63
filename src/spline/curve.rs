//! B-spline and NURBS curves in 3D (2D curves have z = 0), open or closed (periodic).
//!
//! A closed curve stores its `n` distinct control points once; its knot vector is the periodic
//! extension of one period of knots, so basis function `i` uses control point `i mod n`. That
//! keeps evaluation, knot insertion and fitting one code path for both kinds.

use super::knots::{KnotVector, MAX_DEGREE};
use super::SplineError;
use crate::geom::{ClosestPoint, Nearest, NewtonOptions, Point3};
use glam::DVec4;

/// Highest derivative order [`BSplineCurve::eval_derivs`] returns.
pub const MAX_DERIV: usize = 3;

/// Highest degree a curve may have. Fitting above quintic is numerically poor.
pub const MAX_CURVE_DEGREE: usize = 5;

/// A B-spline or NURBS curve. Private fields: the constructors check the invariants
/// (knot/control-point counts, finite coordinates, positive weights).
#[derive(Clone, Debug, PartialEq)]
pub struct BSplineCurve {
    knots: KnotVector,
    ctrl: Vec<Point3>,
    weights: Option<Vec<f64>>,
    closed: bool,
}

/// The non-zero basis functions of a curve at one parameter: control point
/// `curve.ctrl_index(first + j)` carries weight `values[j]` for `j` in `0..=degree`.
/// For a NURBS curve these are the rational basis functions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurveBasis {
    /// Index (in the extended, unwrapped numbering) of the first non-zero basis function.
    pub first: usize,
    /// The knot span the parameter lies in.
    pub span: usize,
    /// Basis values; entries above the degree are zero.
    pub values: [f64; MAX_DEGREE + 1],
}

impl BSplineCurve {
    /// An open curve of `degree` on the full knot vector `knots` (clamped or not), with
    /// `knots.len() - degree - 1` control points.
    pub fn try_new(
        degree: usize,
        knots: Vec<f64>,
        ctrl: Vec<Point3>,
    ) -> Result<BSplineCurve, SplineError> {
        check_degree(degree)?;
        let knots = KnotVector::try_new(degree, knots)?;
        check_points(&ctrl, knots.num_basis())?;
        Ok(BSplineCurve {
            knots,
            ctrl,
            weights: None,
            closed: false,
        })
    }

    /// An open curve whose ends interpolate the first and last control points (clamped knot
    /// vector) with uniform interior knots on `[0, 1]`.
    pub fn try_clamped_uniform(
        degree: usize,
        ctrl: Vec<Point3>,
    ) -> Result<BSplineCurve, SplineError> {
        check_degree(degree)?;
        check_count(ctrl.len(), degree + 1)?;
        let knots = KnotVector::clamped_uniform(degree, ctrl.len())?;
        BSplineCurve::try_new(degree, knots.knots().to_vec(), ctrl)
    }

    /// A closed (periodic) curve with `n = ctrl.len()` control points and one period of knots
    /// `period_knots = [τ_0, …, τ_n]` (non-decreasing, τ_n > τ_0, the period being τ_n − τ_0).
    /// The curve is C^(p−m) at a knot of multiplicity m, including the seam.
    pub fn try_periodic(
        degree: usize,
        period_knots: &[f64],
        ctrl: Vec<Point3>,
    ) -> Result<BSplineCurve, SplineError> {
        check_degree(degree)?;
        check_count(ctrl.len(), degree + 1)?;
        if period_knots.len() != ctrl.len() + 1 {
            return Err(SplineError::ControlPointCount {
                found: ctrl.len(),
                expected: period_knots.len().saturating_sub(1),
            });
        }
        let knots = KnotVector::try_new(degree, extend_periodic(degree, period_knots)?)?;
        check_periodic_multiplicity(degree, knots.knots())?;
        check_points(&ctrl, ctrl.len())?;
        Ok(BSplineCurve {
            knots,
            ctrl,
            weights: None,
            closed: true,
        })
    }

    /// A closed curve with uniform knots on `[0, 1]`.
    pub fn try_periodic_uniform(
        degree: usize,
        ctrl: Vec<Point3>,
    ) -> Result<BSplineCurve, SplineError> {
        let n = ctrl.len().max(1);
        let tau: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).collect();
        BSplineCurve::try_periodic(degree, &tau, ctrl)
    }

    /// The same curve made rational (NURBS) with one positive finite weight per control point.
    pub fn try_with_weights(mut self, weights: Vec<f64>) -> Result<BSplineCurve, SplineError> {
        if weights.len() != self.ctrl.len() {
            return Err(SplineError::ControlPointCount {
                found: weights.len(),
                expected: self.ctrl.len(),
            });
        }
        if let Some(index) = weights.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
            return Err(SplineError::BadWeight {
                index,
                value: weights[index],
            });
        }
        self.weights = Some(weights);
        Ok(self)
    }

    /// The degree p.
    pub fn degree(&self) -> usize {
        self.knots.degree()
    }

    /// The knot vector; for a closed curve, the periodic extension (n + 2p + 1 knots).
    pub fn knots(&self) -> &KnotVector {
        &self.knots
    }

    /// One period of knots τ_0..=τ_n of a closed curve, or all knots of an open one.
    pub fn period_knots(&self) -> &[f64] {
        let k = self.knots.knots();
        if self.closed {
            let p = self.degree();
            &k[p..k.len() - p]
        } else {
            k
        }
    }

    /// The distinct control points.
    pub fn control_points(&self) -> &[Point3] {
        &self.ctrl
    }

    /// The control points, for fitters that move them. Callers keep them finite.
    pub fn control_points_mut(&mut self) -> &mut [Point3] {
        &mut self.ctrl
    }

    /// The weights of a NURBS curve, `None` for a polynomial B-spline.
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }

    /// Whether the curve is closed (periodic).
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// The parameter domain `[a, b]`; a closed curve has period b − a.
    pub fn domain(&self) -> (f64, f64) {
        self.knots.domain()
    }

    /// Index of the control point that basis function `i` (extended numbering) multiplies.
    pub fn ctrl_index(&self, i: usize) -> usize {
        i % self.ctrl.len()
    }

    /// `u` mapped into the domain: wrapped by the period for closed curves, clamped for open
    /// ones. NaN maps to the domain start.
    pub fn normalize_param(&self, u: f64) -> f64 {
        let (a, b) = self.domain();
        if !u.is_finite() {
            return a;
        }
        if self.closed {
            if (a..b).contains(&u) {
                // Already in the period (every Newton step but those crossing the seam).
                return u;
            }
            let t = a + (u - a).rem_euclid(b - a);
            if t >= b {
                a
            } else {
                t
            }
        } else {
            u.clamp(a, b)
        }
    }

    /// The non-zero (rational) basis functions at `u`.
    pub fn basis(&self, u: f64) -> CurveBasis {
        let u = self.normalize_param(u);
        let span = self.knots.find_span(u);
        let mut nd = [[0.0; MAX_DEGREE + 1]; 1];
        self.knots.basis_ders(span, u, 0, &mut nd);
        let p = self.degree();
        let first = span - p;
        let mut values = nd[0];
        if let Some(w) = &self.weights {
            let mut sum = 0.0;
            for (j, v) in values.iter_mut().enumerate().take(p + 1) {
                *v *= w[self.ctrl_index(first + j)];
                sum += *v;
            }
            for v in values.iter_mut().take(p + 1) {
                *v /= sum;
            }
        }
        CurveBasis {
            first,
            span,
            values,
        }
    }

    /// The point C(u).
    pub fn eval(&self, u: f64) -> Point3 {
        self.eval_derivs(u, 0)[0]
    }

    /// C(u) and its derivatives up to order `d` (at most [`MAX_DERIV`]); entries above `d`
    /// are zero. At a knot the derivatives are those of the span to the right.
    pub fn eval_derivs(&self, u: f64, d: usize) -> [Point3; MAX_DERIV + 1] {
        let d = d.min(MAX_DERIV);
        let u = self.normalize_param(u);
        let p = self.degree();
        let span = self.knots.find_span(u);
        let mut nd = [[0.0; MAX_DEGREE + 1]; MAX_DERIV + 1];
        self.knots.basis_ders(span, u, d, &mut nd);
        let mut a = [Point3::ZERO; MAX_DERIV + 1];
        let mut w = [0.0; MAX_DERIV + 1];
        let n = self.ctrl.len();
        let mut idx = self.ctrl_index(span - p);
        for j in 0..=p {
            if j > 0 {
                // The next control point, wrapping for a closed curve (one division per call).
                idx = if idx + 1 == n { 0 } else { idx + 1 };
            }
            let wt = self.weights.as_ref().map_or(1.0, |w| w[idx]);
            for ((ak, wk), row) in a.iter_mut().zip(w.iter_mut()).zip(&nd).take(d + 1) {
                *ak += row[j] * wt * self.ctrl[idx];
                *wk += row[j] * wt;
            }
        }
        if self.weights.is_none() {
            return a;
        }
        // A4.2: C^(k) = (A^(k) − Σ_{i=1..k} C(k,i) w^(i) C^(k−i)) / w.
        let mut c = [Point3::ZERO; MAX_DERIV + 1];
        for k in 0..=d {
            let mut v = a[k];
            for i in 1..=k {
                v -= binomial(k, i) * w[i] * c[k - i];
            }
            c[k] = v / w[0];
        }
        c
    }

    /// The foot point of `p`, seeded from the best of `samples_per_span` samples in every knot
    /// span; use it when no good starting parameter is known.
    pub fn closest_point(&self, p: Point3, samples_per_span: usize) -> Nearest<f64> {
        let mut best = (self.domain().0, f64::INFINITY);
        for u in self.sample_params(samples_per_span.max(1)) {
            let d = (self.eval(u) - p).length_squared();
            if d < best.1 {
                best = (u, d);
            }
        }
        self.closest_point_from(p, best.0, &NewtonOptions::DEFAULT.with_max_iter(30))
    }

    /// `count` (at least 2) parameters evenly spread over the domain, ends included, with the
    /// curve's points there, as `[u, x, y, z]`: what reports and interoperability checks
    /// compare.
    pub fn samples(&self, count: usize) -> Vec<[f64; 4]> {
        let (a, b) = self.domain();
        let count = count.max(2);
        (0..count)
            .map(|i| {
                let u = a + (b - a) * i as f64 / (count - 1) as f64;
                let p = self.eval(u);
                [u, p.x, p.y, p.z]
            })
            .collect()
    }

    /// Parameters spread over every non-empty knot span (span starts and interior samples),
    /// plus the domain end of an open curve.
    pub fn sample_params(&self, per_span: usize) -> Vec<f64> {
        let k = self.knots.knots();
        let p = self.degree();
        let n = self.knots.num_basis();
        let mut out = Vec::new();
        for i in p..n {
            if k[i + 1] > k[i] {
                for s in 0..per_span {
                    out.push(k[i] + (k[i + 1] - k[i]) * s as f64 / per_span as f64);
                }
            }
        }
        if !self.closed {
            out.push(self.domain().1);
        }
        out
    }

    fn nearest(
        &self,
        u: f64,
        c: &[Point3; MAX_DERIV + 1],
        dist_sq: f64,
        iterations: usize,
        converged: bool,
    ) -> Nearest<f64> {
        Nearest {
            param: u,
            point: c[0],
            dist_sq,
            direction: c[1],
            iterations: u32::try_from(iterations).unwrap_or(u32::MAX),
            converged,
        }
    }

    /// The same curve with the knot `u` inserted once (Boehm's algorithm, The NURBS Book A5.1):
    /// one more control point, identical shape. Fails when `u` is outside the domain or already
    /// has multiplicity p.
    pub fn insert_knot(&self, u: f64) -> Result<BSplineCurve, SplineError> {
        if !u.is_finite() {
            return Err(SplineError::BadKnotInsertion { value: u });
        }
        let (a, b) = self.domain();
        if self.closed {
            self.insert_knot_periodic(self.normalize_param(u))
        } else if u < a || u > b {
            Err(SplineError::BadKnotInsertion { value: u })
        } else {
            let (knots, pw) = boehm(self.knots.knots(), self.degree(), &self.homogeneous(), u)?;
            self.rebuilt_from_homogeneous(knots, pw, false)
        }
    }

    /// An open, clamped curve with the same shape over the same domain. For an open clamped
    /// curve this is a copy; a closed curve gets its seam knots raised to multiplicity p.
    pub fn to_clamped(&self) -> Result<BSplineCurve, SplineError> {
        let p = self.degree();
        let (a, b) = self.domain();
        let mut knots = self.knots.knots().to_vec();
        let ext: Vec<usize> = (0..self.knots.num_basis())
            .map(|i| self.ctrl_index(i))
            .collect();
        let mut pw: Vec<DVec4> = ext.iter().map(|&i| self.homogeneous_point(i)).collect();
        for u in [a, b] {
            while multiplicity(&knots, u) < p {
                (knots, pw) = boehm(&knots, p, &pw, u)?;
            }
        }
        // The run of `a` (p or p + 1 copies) starts the clamped vector p + 1 knots before its
        // end; likewise for `b`. Knots outside do not affect the domain.
        let run_a = multiplicity(&knots, a);
        let run_b = multiplicity(&knots, b);
        let ia = knots.iter().position(|&t| t == a).unwrap_or(0);
        let ie = knots.iter().rposition(|&t| t == b).unwrap_or(0);
        let bad = SplineError::BadKnotInsertion { value: a };
        let s0 = (ia + run_a).checked_sub(p + 1).ok_or(bad.clone())?;
        let e0 = ie + (p + 1) - run_b;
        if e0 >= knots.len() || e0 < s0 + 2 * p + 1 {
            return Err(bad);
        }
        let mut clamped = knots[s0..=e0].to_vec();
        clamped[0] = a;
        clamped[e0 - s0] = b;
        let pw = pw[s0..e0 - p].to_vec();
        self.rebuilt_from_homogeneous(clamped, pw, false)
    }

    /// Periodic Boehm insertion: the p − s affected control points wrap modulo n.
    fn insert_knot_periodic(&self, u: f64) -> Result<BSplineCurve, SplineError> {
        let p = self.degree();
        let n = self.ctrl.len();
        let t = self.knots.knots();
        let k = self.knots.find_span(u);
        let s = multiplicity(&t[..=k], u);
        if s >= p {
            return Err(SplineError::BadKnotInsertion { value: u });
        }
        let pw: Vec<DVec4> = (0..n).map(|i| self.homogeneous_point(i)).collect();
        let old = |i: usize| pw[i % n];
        let mut q = vec![DVec4::ZERO; n + 1];
        for i in k + 1 - p..=k + 1 - p + n {
            let qi = if i <= k - s {
                let alpha = (u - t[i]) / (t[i + p] - t[i]);
                alpha * old(i) + (1.0 - alpha) * old(i + n - 1)
            } else {
                old(i - 1)
            };
            q[i % (n + 1)] = qi;
        }
        let mut tau = self.period_knots().to_vec();
        tau.insert(k + 1 - p, u);
        let knots = extend_periodic(p, &tau)?;
        self.rebuilt_from_homogeneous(knots, q, true)
    }

    fn homogeneous_point(&self, i: usize) -> DVec4 {
        let w = self.weights.as_ref().map_or(1.0, |w| w[i]);
        (self.ctrl[i] * w).extend(w)
    }

    fn homogeneous(&self) -> Vec<DVec4> {
        (0..self.ctrl.len())
            .map(|i| self.homogeneous_point(i))
            .collect()
    }

    fn rebuilt_from_homogeneous(
        &self,
        knots: Vec<f64>,
        pw: Vec<DVec4>,
        closed: bool,
    ) -> Result<BSplineCurve, SplineError> {
        let ctrl: Vec<Point3> = pw.iter().map(|h| h.truncate() / h.w).collect();
        let knots = KnotVector::try_new(self.degree(), knots)?;
        check_points(&ctrl, ctrl.len())?;
        let weights = self
            .weights
            .as_ref()
            .map(|_| pw.iter().map(|h| h.w).collect());
        Ok(BSplineCurve {
            knots,
            ctrl,
            weights,
            closed,
        })
    }
}

/// Boehm's single knot insertion on homogeneous control points over a full knot vector; `u`
/// must lie where p + 1 knots on each side exist.
fn boehm(t: &[f64], p: usize, pw: &[DVec4], u: f64) -> Result<(Vec<f64>, Vec<DVec4>), SplineError> {
    let bad = SplineError::BadKnotInsertion { value: u };
    // Span k: t[k] <= u < t[k+1], searched over the whole vector so unclamped ends work.
    let k = t
        .partition_point(|&x| x <= u)
        .checked_sub(1)
        .ok_or(bad.clone())?;
    let s = multiplicity(&t[..=k], u);
    if k < p || k + 1 >= t.len() || s >= p || k - s >= pw.len() {
        return Err(bad);
    }
    let mut q = Vec::with_capacity(pw.len() + 1);
    q.extend_from_slice(&pw[..=k - p]);
    for i in k - p + 1..=k - s {
        let alpha = (u - t[i]) / (t[i + p] - t[i]);
        q.push(alpha * pw[i] + (1.0 - alpha) * pw[i - 1]);
    }
    q.extend_from_slice(&pw[k - s..]);
    let mut knots = t.to_vec();
    knots.insert(k + 1, u);
    Ok((knots, q))
}

/// How many of `knots` equal `u`.
fn multiplicity(knots: &[f64], u: f64) -> usize {
    knots.iter().filter(|&&t| t == u).count()
}

/// The periodic extension t of one period τ_0..=τ_n: t[p + j] = τ_j, continued on both sides
/// by the knot spacings of the neighbouring period.
fn extend_periodic(p: usize, tau: &[f64]) -> Result<Vec<f64>, SplineError> {
    if let Some(index) = tau.iter().position(|k| !k.is_finite()) {
        return Err(SplineError::NonFiniteKnot { index });
    }
    let n = tau.len() - 1;
    let period = tau[n] - tau[0];
    if period.is_nan() || period <= 0.0 || n < p {
        return Err(SplineError::EmptyDomain {
            start: tau[0],
            end: tau[n],
        });
    }
    let mut t = Vec::with_capacity(n + 2 * p + 1);
    for i in 0..p {
        t.push(tau[n - p + i] - period);
    }
    t.extend_from_slice(tau);
    t.extend(tau[1..=p].iter().map(|&k| k + period));
    Ok(t)
}

/// A closed curve must stay continuous: no knot (the seam included) above multiplicity p.
fn check_periodic_multiplicity(p: usize, knots: &[f64]) -> Result<(), SplineError> {
    let mut start = 0;
    for i in 1..=knots.len() {
        if i == knots.len() || knots[i] != knots[start] {
            if i - start > p {
                return Err(SplineError::KnotMultiplicity {
                    index: start,
                    value: knots[start],
                    multiplicity: i - start,
                    limit: p,
                });
            }
            start = i;
        }
    }
    Ok(())
}

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

fn check_degree(degree: usize) -> Result<(), SplineError> {
    if degree == 0 || degree > MAX_CURVE_DEGREE {
        return Err(SplineError::BadDegree {
            degree,
            max: MAX_CURVE_DEGREE,
        });
    }
    Ok(())
}

fn check_count(found: usize, needed: usize) -> Result<(), SplineError> {
    if found < needed {
        return Err(SplineError::ControlPointCount {
            found,
            expected: needed,
        });
    }
    Ok(())
}

fn check_points(ctrl: &[Point3], expected: usize) -> Result<(), SplineError> {
    if ctrl.len() != expected {
        return Err(SplineError::ControlPointCount {
            found: ctrl.len(),
            expected,
        });
    }
    if let Some(index) = ctrl.iter().position(|c| !c.is_finite()) {
        return Err(SplineError::NonFiniteControlPoint { index });
    }
    Ok(())
}

/// The foot point of `p` on the curve by Newton's method on (C(u) − p)·C'(u) = 0, started at
/// `u0`, for at most `max_iter` steps. Each step is damped until the distance
/// does not grow; the parameter is wrapped (closed) or clamped (open) into the domain.
/// Converged when a step is below `step_tol` of the domain plus 1e-9 of the
/// distance (over |C'|). A fit, which re-projects every point each iteration, can stop at a
/// looser step than the default 1e-12: the distance is stationary at the foot point, so a
/// small parameter error changes it by a second-order amount.
impl ClosestPoint for BSplineCurve {
    type Param = f64;

    fn closest_point_from(&self, p: Point3, u0: f64, opts: &NewtonOptions) -> Nearest<f64> {
        let max_iter = opts.max_iter;
        let (a, b) = self.domain();
        let mut u = self.normalize_param(u0);
        let mut c = self.eval_derivs(u, 2);
        let mut dist_sq = (c[0] - p).length_squared();
        for it in 0..max_iter {
            let r = c[0] - p;
            let f = r.dot(c[1]);
            let g = c[1].length_squared();
            let fp = g + r.dot(c[2]);
            // Newton where the curve is locally convex towards p, Gauss–Newton elsewhere.
            let denom = if fp > 1e-3 * g { fp } else { g };
            if denom.is_nan() || denom <= 0.0 {
                return self.nearest(u, &c, dist_sq, it, true);
            }
            let speed = g.sqrt();
            let tol =
                opts.step_tol * (b - a) + 1e-9 * dist_sq.sqrt() / speed.max(f64::MIN_POSITIVE);
            let mut du = (-f / denom).clamp(-0.25 * (b - a), 0.25 * (b - a));
            if du.abs() <= tol {
                return self.nearest(u, &c, dist_sq, it, true);
            }
            let mut accepted = false;
            for _ in 0..8 {
                let un = self.normalize_param(u + du);
                let cn = self.eval_derivs(un, 2);
                let dn = (cn[0] - p).length_squared();
                if dn <= dist_sq {
                    accepted = (un - u).abs() > tol;
                    u = un;
                    c = cn;
                    dist_sq = dn;
                    break;
                }
                du *= 0.5;
            }
            if !accepted {
                return self.nearest(u, &c, dist_sq, it + 1, true);
            }
        }
        self.nearest(u, &c, dist_sq, max_iter, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extension_repeats_spacing() {
        let t = extend_periodic(2, &[0.0, 0.25, 0.5, 1.0]).unwrap();
        assert_eq!(t, vec![-0.75, -0.5, 0.0, 0.25, 0.5, 1.0, 1.25, 1.5]);
    }

    #[test]
    fn boehm_rejects_full_multiplicity() {
        let t = [0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0];
        let pw = vec![DVec4::ONE; 5];
        assert!(boehm(&t, 2, &pw, 0.5).is_err());
        assert!(boehm(&t, 2, &pw, 0.25).is_ok());
    }

    #[test]
    fn binomials() {
        assert_eq!(binomial(3, 0), 1.0);
        assert_eq!(binomial(3, 1), 3.0);
        assert_eq!(binomial(3, 2), 3.0);
    }
}
