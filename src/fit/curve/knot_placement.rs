//! Knot placement for least-squares B-spline curve fitting (SPEC §3, seed 004).
//!
//! 1. At every data point, a cubic through the 4 points before it and one through the 4 points
//!    after it (chord-length parameters) are compared. Where their second derivatives differ by
//!    more than a threshold, the curve gets a multiple knot, largest jump first, with at least 2
//!    data points between multiple knots. Where their tangents differ by more than an angle, the
//!    point is a corner: multiplicity p (C0, the tangent jump is kept); otherwise a double knot
//!    (multiplicity p − 1: C1 with a curvature jump).
//! 2. The control points are solved by least squares, each data point's normal deviation (its
//!    distance to its foot point) is measured, and one single knot is inserted at the foot
//!    parameter of the largest deviation — keeping at least 1 data point between knots and 2
//!    next to a multiple knot, otherwise the next largest deviation is tried — until the
//!    tolerances (and the standard deviation bound, when given) are met.
//!
//! Each [`Fitter::step`] is one insertion and one solve.

use super::{check_degree, check_positive, curve_state, details, least_squares_curve, CurveData};
use crate::fit::{FitError, FitState, FitStatus, Fitter, Method, Shape, Spline, Tolerances};
use crate::geom::{Point3, Vec3};
use crate::spline::BSplineCurve;
use web_time::Instant;

/// Options of the knot-placement fitter. Defaults in brackets on each field.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct KnotPlacementOptions {
    /// Degree, 1..=5 [3].
    pub degree: usize,
    /// Closed (periodic) curve [false].
    pub closed: bool,
    /// Stop when these are met [E_avg 0.01 %, E_max 0.05 %].
    pub tolerances: Tolerances,
    /// Also require the standard deviation of the signed normal deviations below this, % of
    /// the bbox diagonal (the seed's criterion) [none].
    pub std_pct: Option<f64>,
    /// Second-derivative jump |S₁'' − S₂''| that makes a double knot, in units of 1 / bbox
    /// diagonal [1000]. Sections of triangle meshes are polylines whose local cubics jump by
    /// a few hundred everywhere, so lower values put double knots on noise.
    pub curvature_jump: f64,
    /// Angle that makes a corner, degrees: both the tangents S₁', S₂' and the polyline's
    /// segments at the point must turn by more [30].
    pub corner_angle_deg: f64,
    /// Cap on single-knot insertions [the number of data points].
    pub max_iter: Option<usize>,
    /// Re-parameterise the data by their foot points after each solve [false]. It can lower
    /// the control-point count, but on noisy sections points may jump to a neighbouring
    /// wiggle and the fit diverges; the seed keeps the chord-length parameters.
    pub parameter_correction: bool,
    /// Newton iterations per foot point [12].
    pub newton_iter: usize,
    /// Insert, per solve, one knot in every knot span whose largest deviation exceeds the
    /// E_max tolerance (each at that span's largest admissible deviation, worst span first)
    /// instead of only at the single largest deviation [true]. The seed's one knot per solve
    /// costs a solve and a measurement per knot; spans far apart barely interact, so their
    /// knots can share a solve (bunny section at E_max 0.01 %: 428 control points in 409
    /// solves one by one).
    pub batch: bool,
}

impl KnotPlacementOptions {
    /// The defaults, as each field documents them.
    pub const DEFAULT: KnotPlacementOptions = KnotPlacementOptions {
        degree: 3,
        closed: false,
        tolerances: Tolerances::DEFAULT,
        std_pct: None,
        curvature_jump: 1000.0,
        corner_angle_deg: 30.0,
        max_iter: None,
        parameter_correction: false,
        newton_iter: 12,
        batch: true,
    };

    /// Checks every option's range.
    pub fn validate(&self) -> Result<(), FitError> {
        let bad = |name, reason: String| Err(FitError::InvalidOption { name, reason });
        check_degree(self.degree)?;
        check_positive("curvatureJump", self.curvature_jump)?;
        if !(self.corner_angle_deg > 0.0 && self.corner_angle_deg <= 180.0) {
            return bad(
                "cornerAngle",
                format!("{} is not in (0, 180]", self.corner_angle_deg),
            );
        }
        if let Some(s) = self.std_pct.filter(|s| !(s.is_finite() && *s >= 0.0)) {
            return bad("std_pct", format!("{s} is not a non-negative percentage"));
        }
        self.tolerances.validate()
    }
}

default_is_const!(KnotPlacementOptions);

setters!(KnotPlacementOptions {
    /// Sets the standard-deviation bound, %.
    with_std_pct(std_pct: Option<f64>) => |s| s.std_pct;
    /// Sets the second-derivative jump threshold (units of 1 / bbox diagonal).
    with_curvature_jump(curvature_jump: f64) => |s| s.curvature_jump;
    /// Sets the corner angle, degrees.
    with_corner_angle_deg(corner_angle_deg: f64) => |s| s.corner_angle_deg;
    /// Sets the cap on insertions.
    with_max_iter(max_iter: Option<usize>) => |s| s.max_iter;
    /// Sets whether knots are inserted in every failing span per solve.
    with_batch(batch: bool) => |s| s.batch;
    /// Sets whether parameters are corrected between solves.
    with_parameter_correction(parameter_correction: bool) => |s| s.parameter_correction;
});

/// A data point where the shape is not C2: it gets a multiple knot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KnotFeature {
    /// Index of the data point.
    pub index: usize,
    /// Its chord-length parameter, the knot value.
    pub param: f64,
    /// Knot multiplicity: p for a corner, p − 1 for a curvature jump.
    pub multiplicity: usize,
    /// |S₁'' − S₂''| times the bbox diagonal.
    pub jump: f64,
    /// The smaller of the angle between S₁' and S₂' and the polyline's turn there, degrees.
    pub angle_deg: f64,
}

/// Value, first and second derivative at `x` of the cubic through `(xs[k], ys[k])`, by Newton
/// divided differences.
fn cubic_derivs(xs: [f64; 4], ys: [Point3; 4], x: f64) -> (Vec3, Vec3) {
    let d1: Vec<Vec3> = (0..3)
        .map(|k| (ys[k + 1] - ys[k]) / (xs[k + 1] - xs[k]))
        .collect();
    let d2: Vec<Vec3> = (0..2)
        .map(|k| (d1[k + 1] - d1[k]) / (xs[k + 2] - xs[k]))
        .collect();
    let d3 = (d2[1] - d2[0]) / (xs[3] - xs[0]);
    let (a, b, c) = (x - xs[0], x - xs[1], x - xs[2]);
    let first = d1[0] + d2[0] * (a + b) + d3 * (a * b + a * c + b * c);
    let second = 2.0 * d2[0] + 2.0 * d3 * (a + b + c);
    (first, second)
}

/// The multiple-knot features of `data` (SPEC §3 step 1), largest first and spaced.
pub(crate) fn detect_features(
    data: &CurveData,
    closed: bool,
    degree: usize,
    options: &KnotPlacementOptions,
) -> Vec<KnotFeature> {
    let pts = &data.points;
    let n = pts.len();
    // Arc length along the polyline (unnormalised), so S'' is a curvature vector.
    let len: Vec<f64> = data.chord.iter().map(|c| c * data.length).collect();
    let at = |k: isize| -> (f64, Point3) {
        let q = k.div_euclid(n as isize) as f64;
        let i = k.rem_euclid(n as isize) as usize;
        (len[i] + q * data.length, pts[i])
    };
    let range = if closed { 0..n } else { 3..n.saturating_sub(3) };
    let mut found: Vec<KnotFeature> = Vec::new();
    for i in range {
        let i_s = i as isize;
        let side = |ks: [isize; 4]| {
            let v: Vec<(f64, Point3)> = ks.iter().map(|&k| at(k)).collect();
            cubic_derivs(
                [v[0].0, v[1].0, v[2].0, v[3].0],
                [v[0].1, v[1].1, v[2].1, v[3].1],
                at(i_s).0,
            )
        };
        let (t1, s1) = side([i_s - 3, i_s - 2, i_s - 1, i_s]);
        let (t2, s2) = side([i_s, i_s + 1, i_s + 2, i_s + 3]);
        let jump = (s1 - s2).length() * data.diagonal;
        // A corner must show in the local cubics' tangents and in the polyline's own turn at
        // the point: unevenly spaced points alone can tilt a cubic's end tangent, and a
        // tangent-continuous fillet end turns the polyline only a little.
        let (prev, here, next) = (at(i_s - 1).1, pts[i], at(i_s + 1).1);
        let turn = (here - prev).angle_between(next - here).to_degrees();
        let angle_deg = t1.angle_between(t2).to_degrees().min(turn);
        let corner = angle_deg > options.corner_angle_deg;
        if corner || jump > options.curvature_jump {
            found.push(KnotFeature {
                index: i,
                param: data.chord[i],
                multiplicity: if corner { degree } else { (degree - 1).max(1) },
                jump,
                angle_deg,
            });
        }
    }
    // Corners first, then by jump; keep ≥ 2 data points between accepted features.
    found.sort_by(|a, b| {
        b.multiplicity
            .cmp(&a.multiplicity)
            .then(b.jump.total_cmp(&a.jump))
    });
    let gap = |a: usize, b: usize| {
        let d = a.abs_diff(b);
        if closed {
            d.min(n - d)
        } else {
            d
        }
    };
    let mut kept: Vec<KnotFeature> = Vec::new();
    for f in found {
        if kept.iter().all(|k| gap(k.index, f.index) >= 3) {
            kept.push(f);
        }
    }
    kept.sort_by(|a, b| a.param.total_cmp(&b.param));
    kept
}

/// One knot value with its multiplicity, as the fitter tracks them.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Knot {
    value: f64,
    multiplicity: usize,
}

/// The knot-placement least-squares fitter (SPEC §3), driven through [`Fitter`].
#[derive(Clone, Debug)]
pub struct KnotPlacementFitter {
    data: CurveData,
    options: KnotPlacementOptions,
    features: Vec<KnotFeature>,
    /// Interior knots (open) or one period of knots from the seam (closed), sorted.
    knots: Vec<Knot>,
    curve: BSplineCurve,
    params: Vec<f64>,
    /// Foot-point parameters on the current curve (the warm start of the next measurement).
    feet: Vec<f64>,
    state: FitState,
}

impl KnotPlacementFitter {
    /// Detects the features of the ordered `points`, places their multiple knots and solves
    /// the first least-squares curve.
    pub fn try_new(
        points: &[Point3],
        options: KnotPlacementOptions,
    ) -> Result<KnotPlacementFitter, FitError> {
        let start = Instant::now();
        options.validate()?;
        let p = options.degree;
        let data = CurveData::try_new(points, options.closed, (2 * p + 2).max(8))?;
        let features = detect_features(&data, options.closed, p, &options);
        let mut knots: Vec<Knot> = features
            .iter()
            .map(|f| Knot {
                value: f.param,
                multiplicity: f.multiplicity,
            })
            .collect();
        if options.closed {
            top_up_periodic(&mut knots, &data.chord, p + 1);
        }
        let params = data.chord.clone();
        let template = template_curve(&knots, p, options.closed, &data.points)?;
        let curve = least_squares_curve(&template, &data.points, &params)?;
        let n = curve.control_points().len();
        let mut fitter = KnotPlacementFitter {
            state: curve_state(
                &data,
                p,
                Method::KnotPlacement,
                options.tolerances,
                n,
                start,
            ),
            data,
            options,
            features,
            knots,
            curve,
            params,
            feet: Vec::new(),
        };
        fitter.measure();
        if fitter.met() {
            fitter.state.log_mut().stop(FitStatus::Converged);
        }
        Ok(fitter)
    }

    /// The current curve.
    pub fn curve(&self) -> &BSplineCurve {
        &self.curve
    }

    /// The detected features (multiple knots).
    pub fn features(&self) -> &[KnotFeature] {
        &self.features
    }

    /// The foot-point parameter of every data point.
    pub fn params(&self) -> &[f64] {
        &self.params
    }

    /// Standard deviation of the signed normal deviations, % of the bbox diagonal.
    pub fn std_pct(&self) -> f64 {
        let errors = self.state.errors();
        let n = errors.len().max(1) as f64;
        let mean = errors.iter().sum::<f64>() / n;
        let var = errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / n;
        var.sqrt() / self.state.diagonal() * 100.0
    }

    fn met(&self) -> bool {
        self.state.met() && self.options.std_pct.is_none_or(|s| self.std_pct() <= s)
    }

    /// Foot points (normal deviations) of the data on the current curve, Newton started from
    /// the previous foot points: one knot changes the curve only a little, so this takes a
    /// step or two where the chord-length start took several.
    fn measure(&mut self) {
        if self.feet.len() != self.params.len() {
            self.feet = self.params.clone();
        }
        let errors = self
            .data
            .foot_points(&self.curve, &mut self.feet, self.options.newton_iter);
        if self.options.parameter_correction {
            self.params.clone_from(&self.feet);
        }
        self.state.set_errors(errors);
    }

    /// Inserts the knots of one step: at the largest admissible deviation (per the spacing
    /// rules) and, with [`KnotPlacementOptions::batch`], at the largest admissible deviation
    /// above the E_max tolerance of every other knot span. Returns how many were inserted.
    fn insert_knots(&mut self) -> usize {
        let errors = self.state.errors();
        let mut order: Vec<usize> = (0..errors.len()).collect();
        order.sort_by(|&a, &b| errors[b].abs().total_cmp(&errors[a].abs()));
        let mut sorted: Vec<f64> = self
            .params
            .iter()
            .map(|&t| self.curve.normalize_param(t))
            .collect();
        sorted.sort_by(f64::total_cmp);
        let tol = (self.options.tolerances.max_pct)
            .map_or(f64::INFINITY, |t| t / 100.0 * self.data.diagonal);
        let spans: Vec<f64> = self.knots.iter().map(|k| k.value).collect();
        let mut used: Vec<usize> = Vec::new();
        for i in order {
            if !used.is_empty() && (!self.options.batch || errors[i].abs() <= tol) {
                break;
            }
            let u = self.curve.normalize_param(self.params[i]);
            let span = spans.partition_point(|&k| k < u);
            if used.contains(&span) || !self.admissible(u, &sorted) {
                continue;
            }
            used.push(span);
            // Knot values live in the curve's domain (a closed curve's period starts at its
            // first knot), so sorted insertion keeps the seam first.
            let pos = self.knots.partition_point(|k| k.value < u);
            self.knots.insert(
                pos,
                Knot {
                    value: u,
                    multiplicity: 1,
                },
            );
        }
        used.len()
    }

    /// Whether a single knot at `u` keeps ≥ 1 data point to each neighbouring knot (2 to a
    /// multiple knot). A point exactly at a knot counts for the span on its left, so knots at
    /// the foot points of consecutive data points remain possible. `sorted` holds the data
    /// parameters in the domain, sorted; the knots are sorted too (a closed curve's period
    /// starts at its first knot), so both lookups are binary searches.
    fn admissible(&self, u: f64, sorted: &[f64]) -> bool {
        let (a, b) = self.curve.domain();
        let k = self.knots.partition_point(|k| k.value < u);
        if self.knots.get(k).is_some_and(|n| n.value == u) {
            return false;
        }
        let seam = |end: f64| Knot {
            value: end,
            multiplicity: match self.knots.first() {
                Some(f) if self.options.closed && f.value == a => f.multiplicity,
                _ => 1,
            },
        };
        let left = k.checked_sub(1).map_or(seam(a), |i| self.knots[i]);
        let right = self.knots.get(k).copied().unwrap_or(seam(b));
        let need = |k: &Knot| if k.multiplicity > 1 { 2 } else { 1 };
        let upto = |x: f64| sorted.partition_point(|&t| t <= x);
        upto(u) - upto(left.value) >= need(&left) && upto(right.value) - upto(u) >= need(&right)
    }
}

/// For a closed curve: at least `min` control points (knots per period), by adding single
/// knots at evenly spread data parameters away from the existing ones.
fn top_up_periodic(knots: &mut Vec<Knot>, chord: &[f64], min: usize) {
    let total = |k: &[Knot]| k.iter().map(|k| k.multiplicity).sum::<usize>();
    let n = chord.len();
    let mut slots = 2 * min;
    while total(knots) < min && slots <= n {
        knots.retain(|k| k.multiplicity > 1);
        for s in 0..slots {
            let u = chord[s * n / slots];
            let near = knots
                .iter()
                .any(|k| (k.value - u).abs() < 0.5 / slots as f64);
            if !near {
                knots.push(Knot {
                    value: u,
                    multiplicity: 1,
                });
            }
        }
        knots.sort_by(|a, b| a.value.total_cmp(&b.value));
        slots *= 2;
    }
}

/// A curve with the given knots (control points placed on the data, only as a starting value
/// for the ridge term of the least-squares solve).
fn template_curve(
    knots: &[Knot],
    p: usize,
    closed: bool,
    points: &[Point3],
) -> Result<BSplineCurve, FitError> {
    let mut flat: Vec<f64> = Vec::new();
    for k in knots {
        flat.extend(std::iter::repeat_n(k.value, k.multiplicity));
    }
    let ctrl_at = |count: usize| -> Vec<Point3> {
        (0..count)
            .map(|i| points[i * points.len() / count.max(1)])
            .collect()
    };
    if closed {
        let mut tau = flat.clone();
        tau.push(flat[0] + 1.0);
        let n = flat.len();
        Ok(BSplineCurve::try_periodic(p, &tau, ctrl_at(n))?)
    } else {
        let mut all = vec![0.0; p + 1];
        all.extend(flat.iter().filter(|&&v| v > 0.0 && v < 1.0));
        all.extend(std::iter::repeat_n(1.0, p + 1));
        let n = all.len() - p - 1;
        Ok(BSplineCurve::try_new(p, all, ctrl_at(n))?)
    }
}

impl Fitter for KnotPlacementFitter {
    fn step(&mut self) -> Result<FitStatus, FitError> {
        if self.status() != FitStatus::Running {
            return Ok(self.status());
        }
        let start = Instant::now();
        let cap = self.options.max_iter.unwrap_or(self.data.points.len());
        if self.insert_knots() == 0 {
            return Ok(self.state.log_mut().stop(FitStatus::MaxIterations));
        }
        let template = template_curve(
            &self.knots,
            self.options.degree,
            self.options.closed,
            &self.data.points,
        )?;
        self.curve = least_squares_curve(&template, &self.data.points, &self.params)?;
        self.measure();
        let status = self.state.status_after(self.met(), cap);
        let n = self.curve.control_points().len();
        Ok(self.state.record(start, n, true, status))
    }

    curve_fitter_methods!(feet);

    fn details(&self) -> serde_json::Map<String, serde_json::Value> {
        let mut m = details(&self.curve);
        let corners = self
            .features
            .iter()
            .filter(|f| f.multiplicity == self.options.degree)
            .count();
        m.insert("features".into(), self.features.len().into());
        m.insert("corners".into(), corners.into());
        m.insert("std_pct".into(), self.std_pct().into());
        m
    }
}
