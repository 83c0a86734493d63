//! Foot points on limit surfaces: the closest point of a subdivision surface to a data point by
//! Newton's method on the distance (SPEC §1.4), walking across patch edges as it goes.

use super::{LimitEval, LimitSurface, PatchDomain, SubdivSurface, SurfaceParam};
use crate::geom::{ClosestPoint, Nearest, NewtonOptions, Point3};

/// `step_tol` is in model units (see [`newton_foot`]).
impl ClosestPoint for SubdivSurface {
    type Param = SurfaceParam;

    fn closest_point_from(
        &self,
        p: Point3,
        start: SurfaceParam,
        options: &NewtonOptions,
    ) -> Nearest<SurfaceParam> {
        newton_foot(self, p, start, options)
    }

    fn prefetch(&self, at: &SurfaceParam) {
        self.prefetch_patch(*at);
    }
}

/// The foot point of `p` on `surface` by a damped Newton iteration from `start`.
///
/// Minimises f(u, v) = ½‖S(u, v) − p‖². The step solves H Δ = −∇f with the full Hessian
/// (first and second derivatives), falling back to the Gauss–Newton matrix JᵀJ (Marinov &
/// Kobbelt's linearisation) where H is not positive definite. Steps are capped at
/// `options.max_step` in parameter units and halved until f does not grow; a step that leaves the
/// patch is carried onto the neighbouring patch (or clamped at an open boundary) by
/// [`LimitSurface::relocate`]. `options.step_tol` is in model units: converged when a step
/// moves the surface point by less.
///
/// The last step is taken without evaluating the surface again when Newton is plainly in its
/// quadratic phase: the step before it was a full Newton step, and the step shrank so fast
/// (ratio ρ ≤ [`QUADRATIC_RATIO`]) that the one after it, about ρ² times as long, would move
/// the point by less than `step_tol` with a wide margin ([`PREDICTION_MARGIN`]). The point and tangents there come from the second-order
/// Taylor expansion at the current evaluation (error of the order of the step cubed). A warm
/// start — the previous iteration's foot point after a small move of the surface — so takes two
/// evaluations instead of three.
pub fn newton_foot<S: LimitSurface + ?Sized>(
    surface: &S,
    p: Point3,
    start: SurfaceParam,
    options: &NewtonOptions,
) -> Nearest<SurfaceParam> {
    let mut at = surface.relocate(start.patch, start.u, start.v);
    let mut e = surface.eval(at);
    let mut f = (e.point - p).length_squared();
    let tol = options.step_tol;
    let mut converged = false;
    let mut iterations = 0;
    // How far the last step moved the point, if it was a full, undamped Newton step.
    let mut last_full: Option<f64> = None;
    while (iterations as usize) < options.max_iter && !converged {
        iterations += 1;
        let Some(step) = newton_step(&e, p, options.max_step) else {
            converged = true; // zero gradient: a stationary point
            break;
        };
        let (mut su, mut sv) = (step.u, step.v);
        let moves = (e.du * su + e.dv * sv).length();
        if moves <= tol {
            converged = true; // the next step would not move the point: done, save the eval
            break;
        }
        if let Some(prev) = last_full.filter(|_| step.full) {
            let ratio = moves / prev;
            if ratio <= QUADRATIC_RATIO && moves * ratio * ratio * PREDICTION_MARGIN <= tol {
                let (u, v) = (at.u + su, at.v + sv);
                if inside(surface.domain(), u, v) {
                    at = SurfaceParam { u, v, ..at };
                    e = taylor(&e, su, sv);
                    f = (e.point - p).length_squared();
                    converged = true;
                    break;
                }
            }
        }
        let mut accepted = false;
        last_full = None;
        for halvings in 0..8 {
            let cand = surface.relocate(at.patch, at.u + su, at.v + sv);
            let ec = surface.eval(cand);
            let fc = (ec.point - p).length_squared();
            if fc.is_finite() && fc <= f * (1.0 + 1e-12) + f64::MIN_POSITIVE {
                converged = (ec.point - e.point).length() <= tol;
                if step.full && halvings == 0 {
                    last_full = Some(moves);
                }
                (at, e, f) = (cand, ec, fc);
                accepted = true;
                break;
            }
            su *= 0.5;
            sv *= 0.5;
        }
        if !accepted {
            // No descent along the step: we sit at a minimum up to rounding.
            converged = (e.du * su + e.dv * sv).length() <= tol;
            break;
        }
    }
    Nearest {
        param: at,
        point: e.point,
        dist_sq: f,
        direction: e.du.cross(e.dv).normalize_or_zero(),
        iterations,
        converged,
    }
}

/// Largest ratio of two consecutive Newton steps (the later over the earlier, as lengths on the
/// surface) that counts as the quadratic phase of Newton's method, where the next step is about
/// the ratio squared times the last one.
pub const QUADRATIC_RATIO: f64 = 0.1;

/// How far the step after the last one must be predicted below `step_tol` for the last step to
/// be taken without evaluating: the ratio of two consecutive Newton steps predicts the next one
/// only roughly (a test on the bunny found the next step 23 times its prediction).
const PREDICTION_MARGIN: f64 = 1000.0;

/// Whether (u, v) lies in the patch domain (no walk to another patch needed).
fn inside(domain: PatchDomain, u: f64, v: f64) -> bool {
    match domain {
        PatchDomain::Triangle => u >= 0.0 && v >= 0.0 && u + v <= 1.0,
        PatchDomain::Square => (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v),
    }
}

/// The limit point and first derivatives at parameter offset (su, sv) from `e` by Taylor
/// expansion to second order (the second derivatives are kept as they are).
fn taylor(e: &LimitEval, su: f64, sv: f64) -> LimitEval {
    let second = e.duu * (su * su) + e.duv * (2.0 * su * sv) + e.dvv * (sv * sv);
    LimitEval {
        point: e.point + e.du * su + e.dv * sv + second * 0.5,
        du: e.du + e.duu * su + e.duv * sv,
        dv: e.dv + e.duv * su + e.dvv * sv,
        ..*e
    }
}

/// A Newton parameter step.
struct Step {
    u: f64,
    v: f64,
    /// Solved with the full Hessian and not capped: a true Newton step.
    full: bool,
}

/// The Newton (or Gauss–Newton) parameter step at `e` towards `p`, capped at `max_step`; `None`
/// when the gradient vanishes or both systems are singular.
fn newton_step(e: &LimitEval, p: Point3, max_step: f64) -> Option<Step> {
    let r = e.point - p;
    let (gu, gv) = (e.du.dot(r), e.dv.dot(r));
    if gu == 0.0 && gv == 0.0 {
        return None;
    }
    let (a, b, c) = (e.du.dot(e.du), e.du.dot(e.dv), e.dv.dot(e.dv));
    let full = (a + e.duu.dot(r), b + e.duv.dot(r), c + e.dvv.dot(r));
    let (step, newton) = match solve_pd(full, gu, gv) {
        Some(s) => (s, true),
        None => (solve_pd((a, b, c), gu, gv)?, false),
    };
    // Not `hypot`: its overflow care costs 3 % of a fit, and a finite step cannot overflow here.
    let len = (step.0 * step.0 + step.1 * step.1).sqrt();
    if !len.is_finite() {
        return None;
    }
    let k = if len > max_step { max_step / len } else { 1.0 };
    Some(Step {
        u: step.0 * k,
        v: step.1 * k,
        full: newton && k == 1.0,
    })
}

/// Solves [[h00, h01], [h01, h11]] x = −g when the matrix is safely positive definite.
fn solve_pd((h00, h01, h11): (f64, f64, f64), gu: f64, gv: f64) -> Option<(f64, f64)> {
    let det = h00 * h11 - h01 * h01;
    let trace = h00 + h11;
    if !(h00 > 0.0 && h11 > 0.0 && det > 1e-12 * trace * trace) {
        return None;
    }
    Some(((-gu * h11 + gv * h01) / det, (-gv * h00 + gu * h01) / det))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn singular_systems_give_no_step() {
        assert!(solve_pd((0.0, 0.0, 0.0), 1.0, 1.0).is_none());
        assert!(solve_pd((1.0, 1.0, 1.0), 1.0, 1.0).is_none());
        let (x, y) = solve_pd((2.0, 0.0, 4.0), 2.0, -4.0).expect("regular");
        assert!((x + 1.0).abs() < 1e-15 && (y - 1.0).abs() < 1e-15);
    }
}
