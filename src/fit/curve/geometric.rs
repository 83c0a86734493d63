//! Geometric B-spline curve fitting (SPEC §1.9): Douglas–Peucker initial control points,
//! chord-length parameters, Newton foot points, error vectors spread over the p + 1 control
//! points of the foot point's span by basis value and normalised per control point, with
//! acceleration, damping and knot insertion where the error stays above tolerance.
//!
use super::{check_degree, check_positive, curve_state, details, CurveData};
use crate::fit::accel::Accelerator;
use crate::fit::{
    Acceleration, FitError, FitState, FitStatus, Fitter, Method, Shape, Spline, Tolerances,
};
use crate::geom::{Point3, Vec3};
use crate::spline::BSplineCurve;
use web_time::Instant;

/// Options of the geometric curve fitter. Defaults in brackets on each field.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct CurveFitOptions {
    /// Degree of the curve, 1..=5 [3].
    pub degree: usize,
    /// Fit a closed (periodic) curve through the data in order, back to the first point [false].
    pub closed: bool,
    /// Stop when these are met [E_avg 0.01 %, E_max 0.05 %].
    pub tolerances: Tolerances,
    /// Iteration cap [300].
    pub max_iter: usize,
    /// Douglas–Peucker tolerance for the initial control points, % of the bbox diagonal [1.0].
    pub simplify_pct: f64,
    /// Whether knots are inserted where the tolerance is missed [true].
    pub refine: bool,
    /// Largest number of control points knot insertion may reach [the number of data points].
    pub max_control: Option<usize>,
    /// Insert knots at the latest after this many iterations without meeting the tolerances [8].
    pub refine_interval: usize,
    /// Insert knots earlier when one iteration lowers E_max by less than this fraction [0.02].
    pub stall_ratio: f64,
    /// Acceleration of the iteration [plain: [`Acceleration::None`]]; an accelerated move that
    /// raises E_rms is replaced by the plain one.
    pub acceleration: Acceleration,
    /// Share of the spans above tolerance that get a knot per refinement, worst first, in
    /// (0, 1] [0.34]. Smaller shares give fewer control points for more iterations (bunny
    /// section at E_max 0.01 %: 1.0 → 468 control points in 53 iterations, 0.34 → 350 in 99).
    pub refine_fraction: f64,
    /// Newton iterations per foot point and fitting iteration [8].
    pub newton_iter: usize,
}

impl CurveFitOptions {
    /// The defaults, as each field documents them.
    pub const DEFAULT: CurveFitOptions = CurveFitOptions {
        degree: 3,
        closed: false,
        tolerances: Tolerances::DEFAULT,
        max_iter: 300,
        simplify_pct: 1.0,
        refine: true,
        max_control: None,
        refine_interval: 8,
        stall_ratio: 0.02,
        acceleration: Acceleration::None,
        refine_fraction: 0.34,
        newton_iter: 8,
    };

    /// Checks every option's range.
    pub fn validate(&self) -> Result<(), FitError> {
        let bad = |name, reason: String| Err(FitError::InvalidOption { name, reason });
        check_degree(self.degree)?;
        check_positive("simplify_pct", self.simplify_pct)?;
        if self.refine_interval == 0 {
            return bad("refine_interval", "must be at least 1".into());
        }
        self.tolerances.validate()?;
        self.acceleration.validate()
    }
}

default_is_const!(CurveFitOptions);

setters!(CurveFitOptions {
    /// Sets the iteration cap.
    with_max_iter(max_iter: usize) => |s| s.max_iter;
    /// Sets the Douglas–Peucker tolerance, % of the bbox diagonal.
    with_simplify_pct(simplify_pct: f64) => |s| s.simplify_pct;
    /// Turns knot insertion on or off.
    with_refine(refine: bool) => |s| s.refine;
    /// Sets the control-point budget of knot insertion.
    with_max_control(max_control: Option<usize>) => |s| s.max_control;
    /// Sets the acceleration.
    with_acceleration(acceleration: Acceleration) => |s| s.acceleration;
});

/// Indices of the points Douglas–Peucker keeps between `first` and `last` (both kept) at
/// distance tolerance `eps`. `at(i)` gives point i; iterative, so long inputs cannot overflow
/// the stack.
fn douglas_peucker(
    at: &dyn Fn(usize) -> Point3,
    first: usize,
    last: usize,
    eps: f64,
) -> Vec<usize> {
    let mut keep = vec![first, last];
    let mut stack = vec![(first, last)];
    while let Some((a, b)) = stack.pop() {
        let (pa, pb) = (at(a), at(b));
        let ab = pb - pa;
        let len_sq = ab.length_squared();
        let dist = |p: Point3| {
            let ap = p - pa;
            if len_sq == 0.0 {
                ap.length()
            } else {
                (ap - ab * (ap.dot(ab) / len_sq).clamp(0.0, 1.0)).length()
            }
        };
        let far = (a + 1..b)
            .map(|i| (i, dist(at(i))))
            .max_by(|x, y| x.1.total_cmp(&y.1));
        if let Some((i, _)) = far.filter(|&(_, d)| d > eps) {
            keep.push(i);
            stack.push((a, i));
            stack.push((i, b));
        }
    }
    keep.sort_unstable();
    keep.dedup();
    keep
}

/// The data indices that become the initial control points: Douglas–Peucker at `eps`, topped
/// up with evenly spread indices when that keeps fewer than `min` points. A closed polyline is
/// split at the point farthest from the first one.
pub(crate) fn initial_indices(data: &CurveData, closed: bool, eps: f64, min: usize) -> Vec<usize> {
    let n = data.points.len();
    let pts = &data.points;
    let mut idx = if closed {
        let far = (0..n)
            .max_by(|&i, &j| {
                let (di, dj) = ((pts[i] - pts[0]).length(), (pts[j] - pts[0]).length());
                di.total_cmp(&dj)
            })
            .unwrap_or(0);
        let at = |i: usize| pts[i % n];
        let mut a = douglas_peucker(&at, 0, far.max(1), eps);
        a.extend(douglas_peucker(&at, far.max(1), n, eps));
        a.retain(|&i| i < n);
        a
    } else {
        douglas_peucker(&|i| pts[i], 0, n - 1, eps)
    };
    if idx.len() < min {
        let count = if closed { min } else { min - 1 };
        idx.extend((0..count).map(|k| k * (n - usize::from(!closed)) / count));
        if !closed {
            idx.push(n - 1);
        }
    }
    idx.sort_unstable();
    idx.dedup();
    idx
}

/// The initial curve on the data points `idx`: those points as control points, knots by
/// averaging their chord-length parameters (The NURBS Book eq. 9.8), periodically for closed
/// curves, so each control point's basis function peaks near its data point.
pub(crate) fn initial_curve(
    data: &CurveData,
    idx: &[usize],
    degree: usize,
    closed: bool,
) -> Result<BSplineCurve, FitError> {
    let ctrl: Vec<Point3> = idx.iter().map(|&i| data.points[i]).collect();
    let s: Vec<f64> = idx.iter().map(|&i| data.chord[i]).collect();
    let n = ctrl.len();
    let p = degree;
    if closed {
        // s extended periodically: s(k) = s[k mod n] + ⌊k / n⌋.
        let se = |k: isize| {
            let q = k.div_euclid(n as isize);
            s[k.rem_euclid(n as isize) as usize] + q as f64
        };
        // Knot t_k sits so that the Greville abscissa of basis k − p + … lands on s.
        let t = |k: isize| {
            let c = k - (p as isize + 1) / 2;
            if p % 2 == 1 {
                se(c)
            } else {
                0.5 * (se(c - 1) + se(c))
            }
        };
        let tau: Vec<f64> = (0..=n).map(|j| t((j + p) as isize)).collect();
        Ok(BSplineCurve::try_periodic(p, &tau, ctrl)?)
    } else {
        let mut knots = vec![0.0; p + 1];
        for j in 1..n - p {
            knots.push(s[j..j + p].iter().sum::<f64>() / p as f64);
        }
        knots.extend(std::iter::repeat_n(1.0, p + 1));
        Ok(BSplineCurve::try_new(p, knots, ctrl)?)
    }
}

/// The geometric curve fitter (SPEC §1.9), driven through [`Fitter`].
#[derive(Clone, Debug)]
pub struct CurveFitter {
    data: CurveData,
    options: CurveFitOptions,
    curve: BSplineCurve,
    params: Vec<f64>,
    state: FitState,
    accel: Accelerator,
    since_refine: usize,
}

impl CurveFitter {
    /// Sets up a fit of the ordered points `points` (a polyline; closed curves wrap from the
    /// last point to the first): validates the input, builds the initial curve and its foot
    /// points.
    pub fn try_new(points: &[Point3], options: CurveFitOptions) -> Result<CurveFitter, FitError> {
        let start = Instant::now();
        options.validate()?;
        let p = options.degree;
        let data = CurveData::try_new(points, options.closed, p + 2)?;
        let eps = options.simplify_pct / 100.0 * data.diagonal;
        let idx = initial_indices(&data, options.closed, eps, p + 1);
        let curve = initial_curve(&data, &idx, p, options.closed)?;
        // Chord parameters wrap into a periodic domain that need not start at 0.
        let mut params: Vec<f64> = data
            .chord
            .iter()
            .map(|&c| curve.normalize_param(c))
            .collect();
        let errors = data.foot_points(&curve, &mut params, options.newton_iter);
        let n = curve.control_points().len();
        let mut state = curve_state(&data, p, Method::Geometric, options.tolerances, n, start);
        state.set_errors(errors);
        let mut fitter = CurveFitter {
            accel: Accelerator::new(options.acceleration),
            state,
            data,
            options,
            curve,
            params,
            since_refine: 0,
        };
        if fitter.state.met() {
            fitter.state.log_mut().stop(FitStatus::Converged);
        }
        Ok(fitter)
    }

    /// The current curve.
    pub fn curve(&self) -> &BSplineCurve {
        &self.curve
    }

    /// The foot-point parameter of every data point.
    pub fn params(&self) -> &[f64] {
        &self.params
    }

    /// Per control point, the basis-weighted mean of the error vectors of the foot points in
    /// its support: d_j = Σ N_j(u_i) e_i / Σ N_j(u_i).
    fn moves(&self) -> Vec<Vec3> {
        let n = self.curve.control_points().len();
        let p = self.curve.degree();
        let mut sum = vec![Vec3::ZERO; n];
        let mut weight = vec![0.0; n];
        for (&q, &u) in self.data.points.iter().zip(&self.params) {
            let e = q - self.curve.eval(u);
            let b = self.curve.basis(u);
            for j in 0..=p {
                let c = self.curve.ctrl_index(b.first + j);
                sum[c] += b.values[j] * e;
                weight[c] += b.values[j];
            }
        }
        sum.iter()
            .zip(&weight)
            .map(|(s, &w)| if w > 0.0 { *s / w } else { Vec3::ZERO })
            .collect()
    }

    /// Moves the control points to `ctrl` and recomputes foot points and statistics.
    fn apply(&mut self, ctrl: &[Point3], params: &[f64]) {
        self.curve.control_points_mut().copy_from_slice(ctrl);
        self.params.copy_from_slice(params);
        let errors = self
            .data
            .foot_points(&self.curve, &mut self.params, self.options.newton_iter);
        self.state.set_errors(errors);
    }

    /// One move of the control points, accelerated, undone and taken plain when it raised
    /// E_rms.
    fn iterate(&mut self) {
        let x = self.curve.control_points().to_vec();
        let params = self.params.clone();
        let before = self.state.stats().e_rms;
        let d = self.moves();
        let proposal = self.accel.propose(&x, &d);
        self.apply(&proposal, &params);
        if self.state.stats().e_rms > before && self.options.acceleration != Acceleration::None {
            self.accel.reset();
            let plain: Vec<Point3> = x.iter().zip(&d).map(|(p, v)| *p + *v).collect();
            self.apply(&plain, &params);
        }
    }

    /// The absolute distance knot insertion aims below: the E_max tolerance, else E_rms, else
    /// E_avg.
    fn local_tolerance(&self) -> f64 {
        let t = &self.options.tolerances;
        let pct = t.max_pct.or(t.rms_pct).or(t.avg_pct).unwrap_or(0.0);
        pct / 100.0 * self.data.diagonal
    }

    /// Inserts one knot in every span whose largest error exceeds the tolerance, worst first,
    /// within the control-point budget: at the foot parameter of the span's worst point, kept
    /// within the middle half of the span so no knot interval becomes tiny. Returns whether
    /// any was inserted.
    fn refine(&mut self) -> Result<bool, FitError> {
        let tol = self.local_tolerance();
        let knots = self.curve.knots().knots().to_vec();
        // Per span: (span, largest error, its foot parameter).
        let mut per_span: Vec<Option<(f64, f64)>> = vec![None; knots.len()];
        for (&u, &e) in self.params.iter().zip(self.state.errors()) {
            let span = self.curve.knots().find_span(u);
            if per_span[span].is_none_or(|(w, _)| e.abs() > w) {
                per_span[span] = Some((e.abs(), u));
            }
        }
        let mut worst: Vec<(usize, f64, f64)> = per_span
            .iter()
            .enumerate()
            .filter_map(|(s, w)| w.map(|(e, u)| (s, e, u)))
            .filter(|&(_, e, _)| e > tol)
            .collect();
        worst.sort_by(|a, b| b.1.total_cmp(&a.1));
        let budget = if self.options.refine {
            self.options
                .max_control
                .unwrap_or(self.data.points.len())
                .saturating_sub(self.curve.control_points().len())
        } else {
            0
        };
        // Only the worst share of the offending spans: the others often meet the tolerance
        // after a few more iterations, once their neighbours have more freedom.
        let share = (worst.len() as f64 * self.options.refine_fraction).ceil() as usize;
        worst.truncate(budget.min(share.max(1)));
        for &(span, _, u) in &worst {
            let (lo, hi) = (knots[span], knots[span + 1]);
            let at = self
                .curve
                .normalize_param(u)
                .clamp(lo + 0.25 * (hi - lo), hi - 0.25 * (hi - lo));
            self.curve = self.curve.insert_knot(at)?;
        }
        if !worst.is_empty() {
            self.accel.reset();
        }
        Ok(!worst.is_empty())
    }
}

impl Fitter for CurveFitter {
    fn step(&mut self) -> Result<FitStatus, FitError> {
        if self.status() != FitStatus::Running {
            return Ok(self.status());
        }
        let start = Instant::now();
        let before = self.state.stats().e_max;
        self.iterate();
        self.since_refine += 1;
        let met = self.state.met();
        let stalled = self.state.stats().e_max > before * (1.0 - self.options.stall_ratio);
        let due = self.since_refine >= self.options.refine_interval
            || (stalled && self.since_refine >= 2);
        let refined = !met && due && self.refine()?;
        if refined {
            self.since_refine = 0;
        }
        let status = self.state.status_after(met, self.options.max_iter);
        let n = self.curve.control_points().len();
        Ok(self.state.record(start, n, refined, status))
    }

    curve_fitter_methods!(params);

    fn details(&self) -> serde_json::Map<String, serde_json::Value> {
        details(&self.curve)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn douglas_peucker_keeps_corners() {
        let pts = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.01, 0.0),
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(2.0, 1.0, 0.0),
            Point3::new(2.0, 2.0, 0.0),
        ];
        assert_eq!(douglas_peucker(&|i| pts[i], 0, 4, 0.1), vec![0, 2, 4]);
        assert_eq!(douglas_peucker(&|i| pts[i], 0, 4, 0.001), vec![0, 1, 2, 4]);
    }
}
