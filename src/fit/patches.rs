//! Patch (knot-span cell) bookkeeping shared by the B-spline surface fitters: which patch a
//! point falls in, per-patch errors under the two tolerance modes of SPEC §2, worst-first
//! splitting by knot insertion, and parameter correction (re-projection by Newton).

use crate::geom::Point3;
use crate::spline::{BSplineSurface, KnotVector, NewtonOptions};
use serde::{Deserialize, Serialize};

/// How a patch is judged against the tolerance TOL (SPEC §2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TolMode {
    /// Noise-free data: ERR = largest distance of the patch's points; passes if ERR ≤ TOL.
    Exact,
    /// Noisy data: passes if more than 95 % of the patch's points lie within TOL; otherwise
    /// ERR = mean + sqrt(variance) of the distances. The default.
    #[default]
    Noisy,
}

/// Share of a patch's points that must lie within TOL in [`TolMode::Noisy`].
const NOISY_INLIER_SHARE: f64 = 0.95;

/// The non-empty knot spans of one direction, as knot indices, in order.
#[derive(Clone, Debug)]
pub(crate) struct Spans(Vec<usize>);

impl Spans {
    pub(crate) fn of(kv: &KnotVector) -> Spans {
        let k = kv.knots();
        let p = kv.degree();
        Spans((p..kv.num_basis()).filter(|&i| k[i] < k[i + 1]).collect())
    }

    pub(crate) fn len(&self) -> usize {
        self.0.len()
    }

    /// Knot index of the `cell`-th span.
    pub(crate) fn knot_index(&self, cell: usize) -> usize {
        self.0[cell]
    }

    /// Cell of parameter `t`.
    pub(crate) fn cell(&self, kv: &KnotVector, t: f64) -> usize {
        let span = kv.find_span(t);
        self.0.partition_point(|&s| s < span).min(self.0.len() - 1)
    }
}

/// The patch grid of a surface.
#[derive(Clone, Debug)]
pub(crate) struct PatchGrid {
    pub(crate) u: Spans,
    pub(crate) v: Spans,
}

impl PatchGrid {
    pub(crate) fn of(surface: &BSplineSurface) -> PatchGrid {
        PatchGrid {
            u: Spans::of(surface.knots_u()),
            v: Spans::of(surface.knots_v()),
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.u.len() * self.v.len()
    }

    /// Flat patch index of (u, v).
    pub(crate) fn patch(&self, surface: &BSplineSurface, u: f64, v: f64) -> usize {
        self.u.cell(surface.knots_u(), u) * self.v.len() + self.v.cell(surface.knots_v(), v)
    }
}

/// Error summary of one patch.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct PatchError {
    /// Points (taking part in the fit) in the patch.
    pub(crate) count: usize,
    /// ERR of the tolerance mode (0 for a passing patch).
    pub(crate) err: f64,
    /// Whether the patch meets TOL.
    pub(crate) pass: bool,
}

/// ERR and pass/fail of every patch for absolute tolerance `tol`.
pub(crate) fn patch_errors(
    surface: &BSplineSurface,
    grid: &PatchGrid,
    uv: &[[f64; 2]],
    dist: &[f64],
    active: &[bool],
    tol: f64,
    mode: TolMode,
) -> Vec<PatchError> {
    // Per patch: count, inliers, sum, sum of squares, max.
    let mut acc = vec![(0usize, 0usize, 0.0f64, 0.0f64, 0.0f64); grid.len()];
    for ((&[u, v], &d), _) in uv.iter().zip(dist).zip(active).filter(|(_, &a)| a) {
        let a = &mut acc[grid.patch(surface, u, v)];
        let d = d.abs();
        a.0 += 1;
        a.1 += usize::from(d <= tol);
        a.2 += d;
        a.3 += d * d;
        a.4 = a.4.max(d);
    }
    acc.iter()
        .map(|&(count, inliers, sum, sum_sq, max)| {
            if count == 0 {
                return PatchError {
                    count,
                    err: 0.0,
                    pass: true,
                };
            }
            let pass = match mode {
                TolMode::Exact => max <= tol,
                TolMode::Noisy => inliers as f64 > NOISY_INLIER_SHARE * count as f64,
            };
            let n = count as f64;
            let err = match mode {
                TolMode::Exact => max,
                TolMode::Noisy => {
                    let mean = sum / n;
                    mean + (sum_sq / n - mean * mean).max(0.0).sqrt()
                }
            };
            PatchError {
                count,
                err: if pass { 0.0 } else { err },
                pass,
            }
        })
        .collect()
}

/// Splits failing patches worst first by inserting a knot in the middle of their u and v spans
/// (each span once), while the control-point count stays within `max_control` and the patch
/// holds at least `min_points` points. Returns the number of knots inserted.
pub(crate) fn split_worst(
    surface: &mut BSplineSurface,
    grid: &PatchGrid,
    errors: &[PatchError],
    max_control: usize,
    min_points: usize,
) -> usize {
    let mut failing: Vec<usize> = (0..errors.len())
        .filter(|&i| !errors[i].pass && errors[i].count >= min_points)
        .collect();
    failing.sort_by(|&a, &b| errors[b].err.total_cmp(&errors[a].err).then(a.cmp(&b)));
    let (mut nu, mut nv) = surface.num_control();
    let mut split_u = vec![false; grid.u.len()];
    let mut split_v = vec![false; grid.v.len()];
    for patch in failing {
        let (cu, cv) = (patch / grid.v.len(), patch % grid.v.len());
        if !split_u[cu] && (nu + 1) * nv <= max_control {
            split_u[cu] = true;
            nu += 1;
        }
        if !split_v[cv] && nu * (nv + 1) <= max_control {
            split_v[cv] = true;
            nv += 1;
        }
    }
    let mids = |spans: &Spans, kv: &KnotVector, marks: &[bool]| -> Vec<f64> {
        let k = kv.knots();
        (0..spans.len())
            .filter(|&c| marks[c])
            .map(|c| {
                let s = spans.knot_index(c);
                0.5 * (k[s] + k[s + 1])
            })
            .collect()
    };
    let new_u = mids(&grid.u, surface.knots_u(), &split_u);
    let new_v = mids(&grid.v, surface.knots_v(), &split_v);
    let mut inserted = 0;
    for t in new_u {
        inserted += usize::from(surface.insert_knot_u(t).is_ok());
    }
    for t in new_v {
        inserted += usize::from(surface.insert_knot_v(t).is_ok());
    }
    inserted
}

/// Parameter correction: moves each point's (u, v) to its foot point on `surface` by Newton
/// from the current value and stores the signed distance (positive on the side of S_u × S_v).
/// Newton stops at a parameter step of 1e-9 of the domain: far below any fitting tolerance.
pub(crate) fn correct_parameters(
    surface: &BSplineSurface,
    points: &[Point3],
    uv: &mut [[f64; 2]],
    dist: &mut [f64],
    iterations: usize,
) {
    let opts = NewtonOptions::default()
        .with_max_iterations(iterations)
        .with_param_tolerance(1e-9);
    for ((p, t), d) in points.iter().zip(uv.iter_mut()).zip(dist.iter_mut()) {
        let near = surface.closest_point(*p, t[0], t[1], opts);
        *t = [near.u, near.v];
        let e = *p - near.point;
        let len = e.length();
        *d = if e.dot(near.normal) < 0.0 { -len } else { len };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_skip_repeated_knots() {
        let kv =
            KnotVector::try_new(2, vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0]).expect("valid");
        let s = Spans::of(&kv);
        assert_eq!(s.len(), 2);
        assert_eq!(s.cell(&kv, 0.2), 0);
        assert_eq!(s.cell(&kv, 0.5), 1);
        assert_eq!(s.cell(&kv, 1.0), 1);
    }
}
