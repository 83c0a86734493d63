//! Tensor-product B-spline and NURBS surfaces (clamped knot vectors).
//!
//! Control point (i, j) — i along u, j along v — is stored at `i * nv + j`. Evaluation gives
//! the partial derivatives up to third order (The NURBS Book A3.6 and, for NURBS, A4.4), which
//! the smoothing energies and Newton foot points need; knots are inserted one at a time per
//! direction (A5.3) in homogeneous coordinates, so the surface does not change.

use super::knots::MAX_DEGREE;
use super::{KnotVector, SplineError};
use crate::geom::{ClosestPoint, Nearest, NewtonOptions, Point3, Vec3};

/// Highest derivative order [`BSplineSurface::derivs`] computes.
pub const MAX_SURFACE_DERIV: usize = 3;

/// Partial derivatives of a surface at one parameter: `skl[k][l]` is ∂^(k+l) S / ∂u^k ∂v^l,
/// filled for `k + l <= order` and zero elsewhere.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceDerivs {
    /// The derivative table.
    pub skl: [[Vec3; MAX_SURFACE_DERIV + 1]; MAX_SURFACE_DERIV + 1],
}

impl SurfaceDerivs {
    /// S(u, v).
    pub fn point(&self) -> Point3 {
        self.skl[0][0]
    }
}

/// The non-zero basis functions of a non-rational surface at one parameter: S(u, v) =
/// Σ_r Σ_s `bu[r]` · `bv[s]` · P[(first_u + r) · nv + first_v + s].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceBasis {
    /// Index along u of the first non-zero basis function.
    pub first_u: usize,
    /// Index along v of the first non-zero basis function.
    pub first_v: usize,
    /// The p + 1 basis values along u.
    pub bu: [f64; MAX_DEGREE + 1],
    /// The q + 1 basis values along v.
    pub bv: [f64; MAX_DEGREE + 1],
}

/// A clamped tensor-product B-spline surface, optionally rational (NURBS).
#[derive(Clone, Debug, PartialEq)]
pub struct BSplineSurface {
    knots_u: KnotVector,
    knots_v: KnotVector,
    control: Vec<Point3>,
    weights: Option<Vec<f64>>,
}

impl BSplineSurface {
    /// A non-rational surface with `knots_u.num_basis() · knots_v.num_basis()` finite control
    /// points, row-major in u (index `i * nv + j`).
    pub fn try_new(
        knots_u: KnotVector,
        knots_v: KnotVector,
        control: Vec<Point3>,
    ) -> Result<BSplineSurface, SplineError> {
        let (nu, nv) = (knots_u.num_basis(), knots_v.num_basis());
        if control.len() != nu * nv {
            return Err(SplineError::ControlPointCount {
                found: control.len(),
                expected: nu * nv,
            });
        }
        if let Some(index) = control.iter().position(|p| !p.is_finite()) {
            return Err(SplineError::NonFiniteControlPoint { index });
        }
        Ok(BSplineSurface {
            knots_u,
            knots_v,
            control,
            weights: None,
        })
    }

    /// A NURBS surface: like [`BSplineSurface::try_new`], with one finite positive weight per
    /// control point.
    pub fn try_new_rational(
        knots_u: KnotVector,
        knots_v: KnotVector,
        control: Vec<Point3>,
        weights: Vec<f64>,
    ) -> Result<BSplineSurface, SplineError> {
        let mut s = BSplineSurface::try_new(knots_u, knots_v, control)?;
        if weights.len() != s.control.len() {
            let (nu, nv) = s.num_control();
            return Err(SplineError::ControlPointCount {
                found: weights.len(),
                expected: nu * nv,
            });
        }
        if let Some(index) = weights.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
            let value = weights[index];
            return Err(SplineError::BadWeight { index, value });
        }
        s.weights = Some(weights);
        Ok(s)
    }

    /// Knot vector along u.
    pub fn knots_u(&self) -> &KnotVector {
        &self.knots_u
    }

    /// Knot vector along v.
    pub fn knots_v(&self) -> &KnotVector {
        &self.knots_v
    }

    /// Control-point counts (nu, nv).
    pub fn num_control(&self) -> (usize, usize) {
        (self.knots_u.num_basis(), self.knots_v.num_basis())
    }

    /// The control points, index `i * nv + j`.
    pub fn control_points(&self) -> &[Point3] {
        &self.control
    }

    /// The weights, or `None` for a non-rational surface.
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }

    /// Replaces the control points (same count). Non-finite points are rejected.
    pub fn set_control_points(&mut self, control: &[Point3]) -> Result<(), SplineError> {
        let (nu, nv) = self.num_control();
        if control.len() != self.control.len() {
            return Err(SplineError::ControlPointCount {
                found: control.len(),
                expected: nu * nv,
            });
        }
        if let Some(index) = control.iter().position(|p| !p.is_finite()) {
            return Err(SplineError::NonFiniteControlPoint { index });
        }
        self.control.copy_from_slice(control);
        Ok(())
    }

    /// The parameter domain `((u0, u1), (v0, v1))`.
    pub fn domain(&self) -> ((f64, f64), (f64, f64)) {
        (self.knots_u.domain(), self.knots_v.domain())
    }

    /// The non-zero (non-rational) basis functions at (u, v), clamped into the domain. For a
    /// NURBS surface these are the B-spline basis values without the weights.
    pub fn basis(&self, u: f64, v: f64) -> SurfaceBasis {
        let (first_u, bu) = self.knots_u.basis(u);
        let (first_v, bv) = self.knots_v.basis(v);
        SurfaceBasis {
            first_u,
            first_v,
            bu,
            bv,
        }
    }

    /// S(u, v), with (u, v) clamped into the domain.
    pub fn eval(&self, u: f64, v: f64) -> Point3 {
        self.derivs(u, v, 0).point()
    }

    /// The partial derivatives up to total order `order` (at most [`MAX_SURFACE_DERIV`]) at (u, v),
    /// clamped into the domain. On a knot the derivatives are those of the span to the right
    /// (the last span at the domain end).
    pub fn derivs(&self, u: f64, v: f64, order: usize) -> SurfaceDerivs {
        let d = order.min(MAX_SURFACE_DERIV);
        let (p, q) = (self.knots_u.degree(), self.knots_v.degree());
        let nv = self.knots_v.num_basis();
        let (su, sv) = (self.knots_u.find_span(u), self.knots_v.find_span(v));
        let mut bu = [[0.0; MAX_DEGREE + 1]; MAX_SURFACE_DERIV + 1];
        let mut bv = [[0.0; MAX_DEGREE + 1]; MAX_SURFACE_DERIV + 1];
        self.knots_u.basis_ders(su, u, d, &mut bu);
        self.knots_v.basis_ders(sv, v, d, &mut bv);
        let (fu, fv) = (su - p, sv - q);
        let Some(weights) = &self.weights else {
            return self.polynomial_derivs(&bu, &bv, (fu, fv), d);
        };
        // Homogeneous sums: a[k][l] = Σ N^(k) M^(l) w P, w[k][l] = Σ N^(k) M^(l) w.
        let mut a = [[Vec3::ZERO; MAX_SURFACE_DERIV + 1]; MAX_SURFACE_DERIV + 1];
        let mut w = [[0.0; MAX_SURFACE_DERIV + 1]; MAX_SURFACE_DERIV + 1];
        for k in 0..=d {
            // temp[s][l] over v-derivatives for this u-derivative order.
            let mut temp = [(Vec3::ZERO, 0.0); MAX_DEGREE + 1];
            for (s, t) in temp.iter_mut().enumerate().take(q + 1) {
                for r in 0..=p {
                    let idx = (fu + r) * nv + fv + s;
                    t.0 += bu[k][r] * weights[idx] * self.control[idx];
                    t.1 += bu[k][r] * weights[idx];
                }
            }
            for l in 0..=(d - k) {
                for (s, t) in temp.iter().enumerate().take(q + 1) {
                    a[k][l] += bv[l][s] * t.0;
                    w[k][l] += bv[l][s] * t.1;
                }
            }
        }
        let mut out = SurfaceDerivs::default();
        rational_derivs(&a, &w, d, &mut out);
        out
    }

    /// The derivatives of a non-rational surface from the basis derivatives `bu`, `bv` of the
    /// span whose first control point is (`fu`, `fv`): per control row, the v-sums first (one pass
    /// over the row's q + 1 points), then the u-sums.
    fn polynomial_derivs(
        &self,
        bu: &[[f64; MAX_DEGREE + 1]; MAX_SURFACE_DERIV + 1],
        bv: &[[f64; MAX_DEGREE + 1]; MAX_SURFACE_DERIV + 1],
        (fu, fv): (usize, usize),
        d: usize,
    ) -> SurfaceDerivs {
        let (p, q) = (self.knots_u.degree(), self.knots_v.degree());
        let nv = self.knots_v.num_basis();
        let mut out = SurfaceDerivs::default();
        for r in 0..=p {
            let start = (fu + r) * nv + fv;
            let row = &self.control[start..=start + q];
            let mut c = [Vec3::ZERO; MAX_SURFACE_DERIV + 1];
            for (l, cl) in c.iter_mut().enumerate().take(d + 1) {
                for (s, pt) in row.iter().enumerate() {
                    *cl += bv[l][s] * *pt;
                }
            }
            for (k, sk) in out.skl.iter_mut().enumerate().take(d + 1) {
                let b = bu[k][r];
                for (l, cl) in c.iter().enumerate().take(d + 1 - k) {
                    sk[l] += b * *cl;
                }
            }
        }
        out
    }

    fn weight(&self, index: usize) -> f64 {
        self.weights.as_ref().map_or(1.0, |w| w[index])
    }

    /// Inserts the knot `u` once into the u knot vector (A5.3); the surface is unchanged.
    /// `u` must lie strictly inside the domain and its multiplicity must stay at most p.
    pub fn insert_knot_u(&mut self, u: f64) -> Result<(), SplineError> {
        let (nu, nv) = self.num_control();
        let (new_knots, alphas, k, s) = insertion_plan(&self.knots_u, u)?;
        let p = self.knots_u.degree();
        let get = |i: usize, j: usize| i * nv + j;
        let out = self.rebuild(nu + 1, nv, |src, i, j| {
            combine(src, i, k, s, p, &alphas, |ii| get(ii, j))
        });
        self.finish_insertion(out, Some(new_knots), None)
    }

    /// Inserts the knot `v` once into the v knot vector (A5.3); the surface is unchanged.
    pub fn insert_knot_v(&mut self, v: f64) -> Result<(), SplineError> {
        let (nu, nv) = self.num_control();
        let (new_knots, alphas, k, s) = insertion_plan(&self.knots_v, v)?;
        let q = self.knots_v.degree();
        let get = |i: usize, j: usize| i * nv + j;
        let out = self.rebuild(nu, nv + 1, |src, i, j| {
            combine(src, j, k, s, q, &alphas, |jj| get(i, jj))
        });
        self.finish_insertion(out, None, Some(new_knots))
    }

    /// Homogeneous control points `(w·P, w)`, rebuilt on an `rows × cols` grid by `f`.
    fn rebuild<F>(&self, rows: usize, cols: usize, f: F) -> Vec<(Vec3, f64)>
    where
        F: Fn(&[(Vec3, f64)], usize, usize) -> (Vec3, f64),
    {
        let src: Vec<(Vec3, f64)> = (0..self.control.len())
            .map(|i| {
                let w = self.weight(i);
                (self.control[i] * w, w)
            })
            .collect();
        let mut out = Vec::with_capacity(rows * cols);
        for i in 0..rows {
            for j in 0..cols {
                out.push(f(&src, i, j));
            }
        }
        out
    }

    fn finish_insertion(
        &mut self,
        homogeneous: Vec<(Vec3, f64)>,
        knots_u: Option<KnotVector>,
        knots_v: Option<KnotVector>,
    ) -> Result<(), SplineError> {
        if let Some(k) = knots_u {
            self.knots_u = k;
        }
        if let Some(k) = knots_v {
            self.knots_v = k;
        }
        self.control = homogeneous.iter().map(|(pw, w)| *pw / *w).collect();
        if self.weights.is_some() {
            self.weights = Some(homogeneous.iter().map(|(_, w)| *w).collect());
        }
        Ok(())
    }
}

/// Candidate steps (Δu, Δv) for min ½|S − p|²: the Newton step where the Hessian is positive
/// definite, then the Gauss–Newton step; empty at a stationary point or when neither exists.
fn newton_steps(d: &SurfaceDerivs, p: Point3) -> [Option<(f64, f64)>; 2] {
    let r = d.skl[0][0] - p;
    let (su, sv) = (d.skl[1][0], d.skl[0][1]);
    let g = [su.dot(r), sv.dot(r)];
    if !(g[0].is_finite() && g[1].is_finite()) || (g[0] == 0.0 && g[1] == 0.0) {
        return [None, None];
    }
    let gn = [su.dot(su), su.dot(sv), sv.dot(sv)];
    let full = [
        gn[0] + d.skl[2][0].dot(r),
        gn[1] + d.skl[1][1].dot(r),
        gn[2] + d.skl[0][2].dot(r),
    ];
    [solve_2x2(full, g), solve_2x2(gn, g)]
}

/// Solves the symmetric positive-definite system [[h0, h1], [h1, h2]] x = −g.
fn solve_2x2(h: [f64; 3], g: [f64; 2]) -> Option<(f64, f64)> {
    let det = h[0] * h[2] - h[1] * h[1];
    let tiny = f64::EPSILON * (h[0] * h[2]).abs().max(h[1] * h[1]);
    if !(h[0] > 0.0 && det > tiny && det.is_finite()) {
        return None;
    }
    let x = (-g[0] * h[2] + g[1] * h[1]) / det;
    let y = (-g[1] * h[0] + g[0] * h[1]) / det;
    (x.is_finite() && y.is_finite()).then_some((x, y))
}

/// NURBS derivatives from homogeneous ones (A4.4).
fn rational_derivs(
    a: &[[Vec3; MAX_SURFACE_DERIV + 1]; MAX_SURFACE_DERIV + 1],
    w: &[[f64; MAX_SURFACE_DERIV + 1]; MAX_SURFACE_DERIV + 1],
    d: usize,
    out: &mut SurfaceDerivs,
) {
    const BINOM: [[f64; 4]; 4] = [
        [1.0, 0.0, 0.0, 0.0],
        [1.0, 1.0, 0.0, 0.0],
        [1.0, 2.0, 1.0, 0.0],
        [1.0, 3.0, 3.0, 1.0],
    ];
    for k in 0..=d {
        for l in 0..=(d - k) {
            let mut v = a[k][l];
            for j in 1..=l {
                v -= BINOM[l][j] * w[0][j] * out.skl[k][l - j];
            }
            for i in 1..=k {
                v -= BINOM[k][i] * w[i][0] * out.skl[k - i][l];
                let mut v2 = Vec3::ZERO;
                for j in 1..=l {
                    v2 += BINOM[l][j] * w[i][j] * out.skl[k - i][l - j];
                }
                v -= BINOM[k][i] * v2;
            }
            out.skl[k][l] = v / w[0][0];
        }
    }
}

/// For inserting `t` once into `kv`: the new knot vector, the blending factors α_i for
/// i in k−p+1 ..= k−s (indexed from k−p+1), the span k and the multiplicity s of `t`.
fn insertion_plan(
    kv: &KnotVector,
    t: f64,
) -> Result<(KnotVector, Vec<f64>, usize, usize), SplineError> {
    let (a, b) = kv.domain();
    if !(t > a && t < b) {
        return Err(SplineError::BadKnotInsertion { value: t });
    }
    let p = kv.degree();
    let knots = kv.knots();
    let k = kv.find_span(t);
    let s = knots.iter().filter(|&&x| x == t).count();
    if s >= p {
        return Err(SplineError::BadKnotInsertion { value: t });
    }
    let alphas = ((k - p + 1)..=(k - s))
        .map(|i| (t - knots[i]) / (knots[i + p] - knots[i]))
        .collect();
    let mut new_knots = Vec::with_capacity(knots.len() + 1);
    new_knots.extend_from_slice(&knots[..=k]);
    new_knots.push(t);
    new_knots.extend_from_slice(&knots[k + 1..]);
    Ok((KnotVector::try_new(p, new_knots)?, alphas, k, s))
}

/// New homogeneous control point `i` along the insertion direction (A5.1 with r = 1); `at`
/// maps an old index along that direction to the flat index.
fn combine<G: Fn(usize) -> usize>(
    src: &[(Vec3, f64)],
    i: usize,
    k: usize,
    s: usize,
    p: usize,
    alphas: &[f64],
    at: G,
) -> (Vec3, f64) {
    if i <= k - p {
        src[at(i)]
    } else if i > k - s {
        src[at(i - 1)]
    } else {
        let alpha = alphas[i - (k - p + 1)];
        let (p1, w1) = src[at(i)];
        let (p0, w0) = src[at(i - 1)];
        (
            p1 * alpha + p0 * (1.0 - alpha),
            w1 * alpha + w0 * (1.0 - alpha),
        )
    }
}

/// Foot points by Newton's method on the gradient of ½|S − p|², with the full Hessian where it
/// is positive definite and the Gauss–Newton matrix otherwise, steps clamped into the domain.
/// `step_tol` is a fraction of the larger side of the parameter domain. Never returns NaN: a
/// non-finite query or seed falls back to the domain start.
impl ClosestPoint for BSplineSurface {
    type Param = [f64; 2];

    fn closest_point_from(
        &self,
        p: Point3,
        [u0, v0]: [f64; 2],
        opts: &NewtonOptions,
    ) -> Nearest<[f64; 2]> {
        let (du_dom, dv_dom) = self.domain();
        let mut u = self.knots_u.clamp(u0);
        let mut v = self.knots_v.clamp(v0);
        let scale = (du_dom.1 - du_dom.0).max(dv_dom.1 - dv_dom.0);
        let mut iterations = 0u32;
        let mut converged = false;
        let mut current = self.derivs(u, v, 2);
        let mut dist_sq = (current.point() - p).length_squared();
        while (iterations as usize) < opts.max_iter {
            iterations += 1;
            let steps = newton_steps(&current, p);
            if steps.iter().all(Option::is_none) {
                converged = true;
                break;
            }
            // A step under the tolerance is the remaining parameter error (Newton converges
            // quadratically): stop here without evaluating the surface once more.
            let tiny_step = |st: &(f64, f64)| st.0.abs().max(st.1.abs()) <= opts.step_tol * scale;
            if steps.iter().flatten().next().is_some_and(tiny_step) {
                converged = true;
                break;
            }
            // Backtracking on the Newton step, then on the Gauss–Newton step: halve until the
            // distance does not grow (a few ulps of slack: near the minimum rounding hides the
            // true decrease).
            let mut accepted = None;
            'search: for (su, sv) in steps.into_iter().flatten() {
                // A tiny full step is taken as it is: there the distance no longer resolves
                // the decrease, and Newton converges quadratically.
                let tiny = su.abs().max(sv.abs()) <= 1e-6 * scale;
                let mut t = 1.0;
                for _ in 0..12 {
                    let nu = self.knots_u.clamp(u + t * su);
                    let nv = self.knots_v.clamp(v + t * sv);
                    let d = self.derivs(nu, nv, 2);
                    let dsq = (d.point() - p).length_squared();
                    if dsq <= dist_sq * (1.0 + 8.0 * f64::EPSILON) || (tiny && t == 1.0) {
                        accepted = Some((nu, nv, d, dsq));
                        break 'search;
                    }
                    t *= 0.5;
                }
            }
            let Some((nu, nv, d, dsq)) = accepted else {
                converged = true;
                break;
            };
            let moved = (nu - u).abs().max((nv - v).abs());
            (u, v, current, dist_sq) = (nu, nv, d, dsq);
            if moved <= opts.step_tol * scale {
                converged = true;
                break;
            }
        }
        let point = current.point();
        let dist_sq = if p.is_finite() { dist_sq } else { f64::MAX };
        let normal = current.skl[1][0]
            .cross(current.skl[0][1])
            .normalize_or_zero();
        Nearest {
            param: [u, v],
            point,
            dist_sq,
            direction: normal,
            iterations,
            converged,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_2x2_rejects_indefinite() {
        assert!(solve_2x2([1.0, 2.0, 1.0], [1.0, 1.0]).is_none());
        let (x, y) = solve_2x2([2.0, 0.0, 4.0], [2.0, 4.0]).expect("definite");
        assert!((x + 1.0).abs() < 1e-15 && (y + 1.0).abs() < 1e-15);
    }
}
