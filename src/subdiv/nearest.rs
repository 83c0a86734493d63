//! Foot points on limit surfaces: the closest point of a subdivision surface to a data point by
//! Newton's method on the distance (SPEC §1.4), walking across patch edges as it goes.

use super::{LimitEval, LimitSurface, SubdivSurface, SurfaceParam};
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
    while (iterations as usize) < options.max_iter && !converged {
        iterations += 1;
        let Some((mut su, mut sv)) = newton_step(&e, p, options.max_step) else {
            converged = true; // zero gradient: a stationary point
            break;
        };
        if (e.du * su + e.dv * sv).length() <= tol {
            converged = true; // the next step would not move the point: done, save the eval
            break;
        }
        let mut accepted = false;
        for _ in 0..8 {
            let cand = surface.relocate(at.patch, at.u + su, at.v + sv);
            let ec = surface.eval(cand);
            let fc = (ec.point - p).length_squared();
            if fc.is_finite() && fc <= f * (1.0 + 1e-12) + f64::MIN_POSITIVE {
                converged = (ec.point - e.point).length() <= tol;
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

/// The Newton (or Gauss–Newton) parameter step at `e` towards `p`, capped at `max_step`; `None`
/// when the gradient vanishes or both systems are singular.
fn newton_step(e: &LimitEval, p: Point3, max_step: f64) -> Option<(f64, f64)> {
    let r = e.point - p;
    let (gu, gv) = (e.du.dot(r), e.dv.dot(r));
    if gu == 0.0 && gv == 0.0 {
        return None;
    }
    let (a, b, c) = (e.du.dot(e.du), e.du.dot(e.dv), e.dv.dot(e.dv));
    let full = (a + e.duu.dot(r), b + e.duv.dot(r), c + e.dvv.dot(r));
    let step = solve_pd(full, gu, gv).or_else(|| solve_pd((a, b, c), gu, gv))?;
    // Not `hypot`: its overflow care costs 3 % of a fit, and a finite step cannot overflow here.
    let len = (step.0 * step.0 + step.1 * step.1).sqrt();
    if !len.is_finite() {
        return None;
    }
    let k = if len > max_step { max_step / len } else { 1.0 };
    Some((step.0 * k, step.1 * k))
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
