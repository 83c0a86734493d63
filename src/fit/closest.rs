//! Foot points: the closest point of the limit surface to a data point, by Newton's method on
//! the distance (SPEC §1.4), seeded from a spatial index over a tessellation of the surface.

use super::options::NewtonOptions;
use crate::geom::{Point3, Vec3};
use crate::subdiv::{LimitEval, LimitSurface, PatchDomain, SurfaceParam};
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;

/// The result of a closest-point query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FootPoint {
    /// Where on the surface.
    pub param: SurfaceParam,
    /// S(param).
    pub point: Point3,
    /// Squared distance from the query point to `point`.
    pub dist_sq: f64,
    /// Unit surface normal at `point` (S_u × S_v normalised; zero where degenerate).
    pub normal: Vec3,
    /// Newton iterations used.
    pub iterations: u32,
    /// Whether Newton met its step tolerance (a clamped boundary point counts as converged when
    /// it stops moving).
    pub converged: bool,
}

/// Finds the foot point of `p` on `surface` by a damped Newton iteration from `start`.
///
/// Minimises f(u, v) = ½‖S(u, v) − p‖². The step solves H Δ = −∇f with the full Hessian
/// (first and second derivatives), falling back to the Gauss–Newton matrix JᵀJ (Marinov &
/// Kobbelt's linearisation) where H is not positive definite. Steps are capped at
/// `options.max_step` in parameter units and halved until f does not grow; a step that leaves the
/// patch is carried onto the neighbouring patch (or clamped at an open boundary) by
/// [`LimitSurface::relocate`]. `scale` is the model size that `options.step_tol` refers to.
pub fn closest_point<S: LimitSurface + ?Sized>(
    surface: &S,
    p: Point3,
    start: SurfaceParam,
    options: &NewtonOptions,
    scale: f64,
) -> FootPoint {
    let mut at = surface.relocate(start.patch, start.u, start.v);
    let mut e = surface.eval(at);
    let mut f = (e.point - p).length_squared();
    let tol = options.step_tol * scale;
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
    FootPoint {
        param: at,
        point: e.point,
        dist_sq: f,
        normal: e.du.cross(e.dv).normalize_or_zero(),
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

/// A k-d tree over points of the limit surface (a few per patch), giving each data point a
/// starting parameter for Newton that is near the global closest point.
pub struct SurfaceIndex {
    tree: ImmutableKdTree<f64, u64, 3, 32>,
    params: Vec<SurfaceParam>,
}

impl SurfaceIndex {
    /// Samples every patch at `resolution`² interior points (centres of the cells of a
    /// `resolution` grid: no sample is shared by two patches, so the tree never holds
    /// duplicates) and indexes them. Non-finite samples are skipped.
    pub fn build<S: LimitSurface + ?Sized>(surface: &S, resolution: usize) -> SurfaceIndex {
        let cells = patch_cell_centres(surface.domain(), resolution.max(1));
        let mut points = Vec::with_capacity(surface.num_patches() * cells.len());
        let mut params = Vec::with_capacity(points.capacity());
        for patch in 0..surface.num_patches() as u32 {
            for &(u, v) in &cells {
                let at = SurfaceParam { patch, u, v };
                let s = surface.eval(at).point;
                if s.is_finite() {
                    points.push(s.to_array());
                    params.push(at);
                }
            }
        }
        SurfaceIndex {
            tree: ImmutableKdTree::new_from_slice(&points),
            params,
        }
    }

    /// The indexed sample nearest to `p`, or `None` when the index is empty.
    pub fn nearest(&self, p: Point3) -> Option<SurfaceParam> {
        if self.params.is_empty() || !p.is_finite() {
            return None;
        }
        let hit = self.tree.nearest_one::<SquaredEuclidean>(&p.to_array());
        self.params.get(hit.item as usize).copied()
    }
}

/// Parameters of the centres of the cells of a `r`-grid over one patch domain.
pub(crate) fn patch_cell_centres(domain: PatchDomain, r: usize) -> Vec<(f64, f64)> {
    let h = 1.0 / r as f64;
    let mut out = Vec::new();
    match domain {
        PatchDomain::Square => {
            for i in 0..r {
                for j in 0..r {
                    out.push(((i as f64 + 0.5) * h, (j as f64 + 0.5) * h));
                }
            }
        }
        PatchDomain::Triangle => {
            for i in 0..r {
                for j in 0..r - i {
                    let (u, v) = (i as f64, j as f64);
                    out.push(((u + 1.0 / 3.0) * h, (v + 1.0 / 3.0) * h));
                    if i + j + 1 < r {
                        out.push(((u + 2.0 / 3.0) * h, (v + 2.0 / 3.0) * h));
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_centres_lie_inside_and_count_r_squared() {
        for r in 1..6 {
            let tri = patch_cell_centres(PatchDomain::Triangle, r);
            assert_eq!(tri.len(), r * r);
            assert!(tri.iter().all(|&(u, v)| u > 0.0 && v > 0.0 && u + v < 1.0));
            let sq = patch_cell_centres(PatchDomain::Square, r);
            assert_eq!(sq.len(), r * r);
        }
    }

    #[test]
    fn singular_systems_give_no_step() {
        assert!(solve_pd((0.0, 0.0, 0.0), 1.0, 1.0).is_none());
        assert!(solve_pd((1.0, 1.0, 1.0), 1.0, 1.0).is_none());
        let (x, y) = solve_pd((2.0, 0.0, 4.0), 2.0, -4.0).expect("regular");
        assert!((x + 1.0).abs() < 1e-15 && (y - 1.0).abs() < 1e-15);
    }
}
