//! Patch (knot-span cell) bookkeeping shared by the B-spline surface fitters: which patch a
//! point falls in, per-patch errors under the two tolerance modes of SPEC §2, worst-first
//! splitting by knot insertion, and parameter correction (re-projection by Newton).

use crate::geom::Point3;
use crate::geom::{ClosestPoint, NewtonOptions};
use crate::spline::{BSplineSurface, KnotVector};

/// How a patch is judged against the tolerance TOL (SPEC §2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TolMode {
    /// Noise-free data: ERR = largest distance of the patch's points; passes if ERR ≤ TOL.
    Exact,
    /// Noisy data: a patch passes if more than 95 % of its points lie within TOL; otherwise its
    /// ERR = mean + sqrt(variance) of the distances, and it passes if ERR ≤ TOL (seed 002 §3.4:
    /// the fit is done when every ERR ≤ TOL). The default.
    #[default]
    Noisy,
}

named_enum!(TolMode, "tolMode", { Exact => "exact", Noisy => "noisy" });

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

/// How patches are judged: the absolute tolerance, its mode and the smallest patch whose own
/// points make a sample of the noisy test (see [`patch_errors`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Criterion {
    /// TOL, absolute.
    pub(crate) tol: f64,
    /// How ERR is computed and compared.
    pub(crate) mode: TolMode,
    /// In [`TolMode::Noisy`], patches with fewer points are judged on the points of their
    /// 3 × 3 patch neighbourhood.
    pub(crate) min_sample: usize,
}

/// Sums of the distances of a set of points (a patch, a knot span of a family of sections):
/// count, points within TOL, sum, sum of squares, max.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Acc {
    pub(crate) count: usize,
    inliers: usize,
    sum: f64,
    sum_sq: f64,
    max: f64,
}

impl Acc {
    /// Counts one point at distance `d` (either sign) from the fit, against `tol`.
    pub(crate) fn push(&mut self, d: f64, tol: f64) {
        let d = d.abs();
        self.count += 1;
        self.inliers += usize::from(d <= tol);
        self.sum += d;
        self.sum_sq += d * d;
        self.max = self.max.max(d);
    }

    fn add(&mut self, o: &Acc) {
        self.count += o.count;
        self.inliers += o.inliers;
        self.sum += o.sum;
        self.sum_sq += o.sum_sq;
        self.max = self.max.max(o.max);
    }

    /// (pass, ERR) of these points under `mode`.
    pub(crate) fn judge(&self, tol: f64, mode: TolMode) -> (bool, f64) {
        let n = self.count as f64;
        match mode {
            TolMode::Exact => (self.max <= tol, self.max),
            TolMode::Noisy => {
                let mean = self.sum / n;
                let err = mean + (self.sum_sq / n - mean * mean).max(0.0).sqrt();
                (
                    self.inliers as f64 > NOISY_INLIER_SHARE * n || err <= tol,
                    err,
                )
            }
        }
    }
}

/// ERR and pass/fail of every patch under `crit`.
///
/// In [`TolMode::Noisy`] a patch holding fewer than `crit.min_sample` points is judged on the
/// pooled points of its 3 × 3 neighbourhood: on two or three points the 95 % share and the
/// standard deviation say nothing about noise (one stray border point would fail the patch).
/// Tensor-product splitting cuts whole rows and columns of patches, so a fine fit has many such
/// patches, and judged alone they kept the fit from converging on bun000.ply.
pub(crate) fn patch_errors(
    surface: &BSplineSurface,
    grid: &PatchGrid,
    uv: &[[f64; 2]],
    dist: &[f64],
    active: &[bool],
    crit: Criterion,
) -> Vec<PatchError> {
    let mut acc = vec![Acc::default(); grid.len()];
    for ((&[u, v], &d), _) in uv.iter().zip(dist).zip(active).filter(|(_, &a)| a) {
        acc[grid.patch(surface, u, v)].push(d, crit.tol);
    }
    let (nu, nv) = (grid.u.len(), grid.v.len());
    (0..acc.len())
        .map(|i| {
            let own = acc[i];
            if own.count == 0 {
                return PatchError::default_pass();
            }
            let pooled = if crit.mode == TolMode::Noisy && own.count < crit.min_sample {
                let (cu, cv) = (i / nv, i % nv);
                let mut sum = Acc::default();
                for a in cu.saturating_sub(1)..(cu + 2).min(nu) {
                    for b in cv.saturating_sub(1)..(cv + 2).min(nv) {
                        sum.add(&acc[a * nv + b]);
                    }
                }
                sum
            } else {
                own
            };
            let (pass, err) = pooled.judge(crit.tol, crit.mode);
            PatchError {
                count: own.count,
                err: if pass { 0.0 } else { err },
                pass,
            }
        })
        .collect()
}

/// Share of the patches holding points that miss TOL (0 when no patch holds points).
pub(crate) fn failing_share(errors: &[PatchError]) -> f64 {
    let judged = errors.iter().filter(|e| e.count > 0).count();
    let failing = errors.iter().filter(|e| !e.pass).count();
    failing as f64 / judged.max(1) as f64
}

impl PatchError {
    /// An empty patch: nothing to judge, it passes.
    fn default_pass() -> PatchError {
        PatchError {
            count: 0,
            err: 0.0,
            pass: true,
        }
    }
}

/// Splits failing patches worst first by inserting knots into their u and v spans (each span
/// once), while the control-point count stays within `max_control`: the midpoint, or the three
/// quarter points when the patch's ERR exceeds `quarter_above`. Returns the number of knots
/// inserted.
///
/// Why quarters: on smooth data a degree-p fit's error falls like h^(p + 1), so halving a span
/// divides ERR by about 2^(p + 1); a patch whose ERR exceeds that many times TOL needs two
/// halvings anyway, and doing both at once saves a round of solves (the least-squares fit
/// passes 2^(p + 1)·TOL; the geometric fit, whose errors early on are those of an unconverged
/// iteration, passes infinity).
pub(crate) fn split_worst(
    surface: &mut BSplineSurface,
    grid: &PatchGrid,
    errors: &[PatchError],
    max_control: usize,
    quarter_above: f64,
) -> usize {
    let mut failing: Vec<usize> = (0..errors.len()).filter(|&i| !errors[i].pass).collect();
    failing.sort_by(|&a, &b| errors[b].err.total_cmp(&errors[a].err).then(a.cmp(&b)));
    let (mut nu, mut nv) = surface.num_control();
    // Pieces each span is cut into (1: left alone).
    let mut pieces_u = vec![1usize; grid.u.len()];
    let mut pieces_v = vec![1usize; grid.v.len()];
    for patch in failing {
        let (cu, cv) = (patch / grid.v.len(), patch % grid.v.len());
        let want = if errors[patch].err > quarter_above {
            4
        } else {
            2
        };
        if pieces_u[cu] < want {
            let added = want - pieces_u[cu];
            if (nu + added) * nv <= max_control {
                pieces_u[cu] = want;
                nu += added;
            } else if pieces_u[cu] == 1 && (nu + 1) * nv <= max_control {
                pieces_u[cu] = 2;
                nu += 1;
            }
        }
        if pieces_v[cv] < want {
            let added = want - pieces_v[cv];
            if nu * (nv + added) <= max_control {
                pieces_v[cv] = want;
                nv += added;
            } else if pieces_v[cv] == 1 && nu * (nv + 1) <= max_control {
                pieces_v[cv] = 2;
                nv += 1;
            }
        }
    }
    let cuts = |spans: &Spans, kv: &KnotVector, pieces: &[usize]| -> Vec<f64> {
        let k = kv.knots();
        (0..spans.len())
            .flat_map(|c| {
                let s = spans.knot_index(c);
                let (a, b, n) = (k[s], k[s + 1], pieces[c]);
                (1..n).map(move |i| a + (b - a) * i as f64 / n as f64)
            })
            .collect()
    };
    let new_u = cuts(&grid.u, surface.knots_u(), &pieces_u);
    let new_v = cuts(&grid.v, surface.knots_v(), &pieces_v);
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
/// Newton stops at a parameter step of 1e-7 of the domain: the distance, stationary at the foot
/// point, is then off by a second-order amount far below any fitting tolerance, and the last,
/// confirming evaluation of a tighter threshold (a quarter of the work) is saved.
pub(crate) fn correct_parameters(
    surface: &BSplineSurface,
    points: &[Point3],
    uv: &mut [[f64; 2]],
    dist: &mut [f64],
    iterations: usize,
) {
    let opts = NewtonOptions::DEFAULT
        .with_max_iter(iterations)
        .with_step_tol(1e-7);
    // Each point's foot point depends on that point alone: the same result on any number of
    // threads.
    crate::fit::parallel::zip_chunks(points, uv, dist, |points, uv, dist| {
        for ((p, t), d) in points.iter().zip(uv.iter_mut()).zip(dist.iter_mut()) {
            let near = surface.closest_point_from(*p, *t, &opts);
            *t = near.param;
            let e = *p - near.point;
            let len = e.length();
            *d = if e.dot(near.direction) < 0.0 {
                -len
            } else {
                len
            };
        }
    });
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

    /// A flat bilinear surface over [0, 1]² with 3 × 3 patches.
    fn grid3() -> BSplineSurface {
        let kv = KnotVector::clamped_uniform(1, 4).expect("knots");
        let ctrl = (0..16)
            .map(|i| Point3::new((i / 4) as f64 / 3.0, (i % 4) as f64 / 3.0, 0.0))
            .collect();
        BSplineSurface::try_new(kv.clone(), kv, ctrl).expect("surface")
    }

    /// Points at the centre of patch (cu, cv) with the given distances.
    fn put(uv: &mut Vec<[f64; 2]>, dist: &mut Vec<f64>, (cu, cv): (usize, usize), d: &[f64]) {
        for &x in d {
            uv.push([(cu as f64 + 0.5) / 3.0, (cv as f64 + 0.5) / 3.0]);
            dist.push(x);
        }
    }

    fn judge(uv: &[[f64; 2]], dist: &[f64], mode: TolMode, min_sample: usize) -> Vec<PatchError> {
        let s = grid3();
        let active = vec![true; uv.len()];
        let crit = Criterion {
            tol: 1.0,
            mode,
            min_sample,
        };
        patch_errors(&s, &PatchGrid::of(&s), uv, dist, &active, crit)
    }

    #[test]
    fn noisy_patch_passes_on_mean_plus_deviation_below_tol() {
        // 80 % inliers (fails the 95 % share); mean 0.64 + σ 0.28 = 0.92 ≤ TOL passes.
        let (mut uv, mut dist) = (Vec::new(), Vec::new());
        put(&mut uv, &mut dist, (1, 1), &[0.5; 8]);
        put(&mut uv, &mut dist, (1, 1), &[-1.2, 1.2]);
        let e = judge(&uv, &dist, TolMode::Noisy, 1);
        assert!(e[4].pass, "{:?}", e[4]);
        assert!(!judge(&uv, &dist, TolMode::Exact, 1)[4].pass);
        // Two points at 2 TOL: mean 0.8 + σ 0.6 = 1.4 > TOL fails, with ERR 1.4.
        dist[8] = -2.0;
        dist[9] = 2.0;
        let e = judge(&uv, &dist, TolMode::Noisy, 1);
        assert!(!e[4].pass);
        assert!((e[4].err - 1.4).abs() < 1e-12, "{:?}", e[4]);
    }

    #[test]
    fn small_noisy_patch_is_judged_with_its_neighbours() {
        let (mut uv, mut dist) = (Vec::new(), Vec::new());
        for cu in 0..3 {
            for cv in 0..3 {
                if (cu, cv) != (1, 1) {
                    put(&mut uv, &mut dist, (cu, cv), &[0.1; 10]);
                }
            }
        }
        put(&mut uv, &mut dist, (1, 1), &[0.1, 3.0]);
        // Alone, the centre fails (1 of 2 points out, mean + σ = 3.05).
        assert!(!judge(&uv, &dist, TolMode::Noisy, 2)[4].pass);
        // Below the sample size it is judged on 82 points, 81 within TOL: it passes.
        let e = judge(&uv, &dist, TolMode::Noisy, 16);
        assert!(e.iter().all(|p| p.pass), "{e:?}");
        // The exact mode never pools.
        assert!(!judge(&uv, &dist, TolMode::Exact, 16)[4].pass);
    }

    #[test]
    fn far_failing_patches_are_quartered() {
        let fail = |err: f64| PatchError {
            count: 10,
            err,
            pass: false,
        };
        let mut errors = vec![PatchError::default_pass(); 9];
        errors[0] = fail(5.0); // beyond quarter_above: u and v spans cut in four
        errors[8] = fail(2.0); // within: halved
        let mut s = grid3();
        let grid = PatchGrid::of(&s);
        let inserted = split_worst(&mut s, &grid, &errors, usize::MAX, 4.0);
        assert_eq!(inserted, 8);
        let u: Vec<f64> = s.knots_u().knots().to_vec();
        let third = 1.0 / 3.0;
        let expected = [
            0.0,
            0.0,
            third / 4.0,
            third / 2.0,
            third * 3.0 / 4.0,
            third,
            2.0 * third,
            2.5 * third,
            1.0,
            1.0,
        ];
        assert!(
            u.iter().zip(&expected).all(|(a, b)| (a - b).abs() < 1e-12),
            "{u:?}"
        );
        assert_eq!(s.knots_v().knots().len(), u.len());
        // Within a budget of 5 × 4 control points: the worst patch is only halved.
        let mut s = grid3();
        let inserted = split_worst(&mut s, &grid, &errors, 20, 4.0);
        assert_eq!(s.num_control(), (5, 4), "{inserted}");
    }
}
