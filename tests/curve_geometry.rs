//! B-spline / NURBS curve geometry: derivatives, knot insertion, periodic seams, Chaikin limits,
//! and the typed errors for bad input.

use geofit::geom::Point3;
use geofit::spline::{BSplineCurve, ChaikinCurve, SplineError};
use proptest::prelude::*;

fn wavy_points(n: usize, seed: f64) -> Vec<Point3> {
    (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let r = 1.0 + 0.3 * (3.0 * t + seed).sin();
            Point3::new(r * t.cos(), r * t.sin(), 0.2 * (2.0 * t + seed).cos())
        })
        .collect()
}

/// The curves every property below must hold for: open and closed, polynomial and rational,
/// degrees 1 to 5, with a repeated interior knot.
fn sample_curves(seed: f64) -> Vec<BSplineCurve> {
    let mut out = Vec::new();
    for p in 1..=5 {
        let ctrl = wavy_points(9, seed);
        out.push(BSplineCurve::try_clamped_uniform(p, ctrl.clone()).unwrap());
        out.push(BSplineCurve::try_periodic_uniform(p, ctrl.clone()).unwrap());
        let w: Vec<f64> = (0..9)
            .map(|i| 0.5 + (i as f64 * 0.7 + seed).sin().abs())
            .collect();
        out.push(
            BSplineCurve::try_periodic_uniform(p, ctrl.clone())
                .unwrap()
                .try_with_weights(w.clone())
                .unwrap(),
        );
        out.push(
            BSplineCurve::try_clamped_uniform(p, ctrl)
                .unwrap()
                .try_with_weights(w)
                .unwrap(),
        );
    }
    let mut knots = vec![0.0; 4];
    knots.extend([0.2, 0.5, 0.5, 0.7]);
    knots.extend([1.0; 4]);
    out.push(BSplineCurve::try_new(3, knots, wavy_points(8, seed)).unwrap());
    let tau = [0.0, 0.1, 0.3, 0.3, 0.6, 0.8, 1.2];
    out.push(BSplineCurve::try_periodic(3, &tau, wavy_points(6, seed)).unwrap());
    out
}

fn near_knot(c: &BSplineCurve, u: f64, gap: f64) -> bool {
    c.knots().knots().iter().any(|&k| (k - u).abs() < gap)
}

proptest! {
    #[test]
    fn derivatives_match_finite_differences(s in 0.0f64..1.0, seed in 0.0f64..6.0) {
        for c in sample_curves(seed) {
            let (a, b) = c.domain();
            let u = a + (b - a) * (0.02 + 0.96 * s);
            let h = 1e-6 * (b - a);
            prop_assume!(!near_knot(&c, u, 1e-4 * (b - a)));
            let d = c.eval_derivs(u, 3);
            let dp = c.eval_derivs(u + h, 3);
            let dm = c.eval_derivs(u - h, 3);
            let scale = 1.0 + d[0].length();
            for k in 0..3 {
                let fd = (dp[k] - dm[k]) / (2.0 * h);
                let tol = 1e-5 * (1.0 + d[k + 1].length()) * scale * (b - a).recip().max(1.0).powi(k as i32 + 1);
                prop_assert!((fd - d[k + 1]).length() < tol,
                    "degree {} closed {} order {}: fd {:?} vs {:?}", c.degree(), c.is_closed(), k + 1, fd, d[k + 1]);
            }
            prop_assert!((c.eval(u) - d[0]).length() < 1e-14);
        }
    }

    #[test]
    fn knot_insertion_keeps_the_shape(s in 0.0f64..1.0, seed in 0.0f64..6.0) {
        for c in sample_curves(seed) {
            let (a, b) = c.domain();
            let u = a + (b - a) * s;
            let refined = match c.insert_knot(u) {
                Ok(r) => r,
                // Only a knot already at full multiplicity may be refused.
                Err(SplineError::BadKnotInsertion { .. }) => {
                    prop_assert!(c.knots().knots().iter().filter(|&&k| k == u).count() >= c.degree());
                    continue;
                }
                Err(e) => return Err(TestCaseError::fail(e.to_string())),
            };
            prop_assert_eq!(refined.control_points().len(), c.control_points().len() + 1);
            prop_assert_eq!(refined.domain(), c.domain());
            for i in 0..=40 {
                let t = a + (b - a) * i as f64 / 40.0;
                let (p, q) = (c.eval(t), refined.eval(t));
                prop_assert!((p - q).length() < 1e-12 * (1.0 + p.length()),
                    "degree {} closed {} at {}: {:?} vs {:?}", c.degree(), c.is_closed(), t, p, q);
            }
        }
    }
}

#[test]
fn periodic_curves_are_smooth_across_the_seam() {
    for c in sample_curves(0.3).into_iter().filter(|c| c.is_closed()) {
        let (a, b) = c.domain();
        let p = c.degree();
        // Multiplicity m at the seam leaves C^(p-m); the uniform ones have m = 1.
        let m = c.period_knots().iter().filter(|&&k| k == a).count();
        let start = c.eval_derivs(a, 3);
        let end = c.eval_derivs(b - 1e-13 * (b - a), 3);
        let just_before = c.eval_derivs(b, 3);
        assert_eq!(just_before[0], start[0], "the period wraps");
        for k in 0..=(p - m).min(3) {
            let scale = 1.0 + start[k].length();
            assert!(
                (start[k] - end[k]).length() < 1e-7 * scale,
                "degree {p}: derivative {k} jumps at the seam: {:?} vs {:?}",
                start[k],
                end[k]
            );
        }
    }
}

#[test]
fn clamped_equivalent_of_a_closed_curve_has_the_same_shape() {
    for c in sample_curves(1.1) {
        let open = c.to_clamped().unwrap();
        assert!(!open.is_closed());
        let (a, b) = c.domain();
        assert_eq!(open.domain(), (a, b));
        let k = open.knots().knots();
        let p = c.degree();
        assert!(k[..=p].iter().all(|&t| t == a) && k[k.len() - p - 1..].iter().all(|&t| t == b));
        for i in 0..=50 {
            let t = a + (b - a) * i as f64 / 50.0;
            let (x, y) = (c.eval(t), open.eval(t));
            assert!(
                (x - y).length() < 1e-12,
                "degree {p} at {t}: {x:?} vs {y:?}"
            );
        }
    }
}

#[test]
fn chaikin_limit_is_the_quadratic_bspline() {
    for closed in [false, true] {
        let mut chaikin = ChaikinCurve::try_new(wavy_points(7, 0.4), closed).unwrap();
        let limit = chaikin.limit().unwrap();
        let (a, b) = limit.domain();
        let mut scale = 1.0;
        let mut prev_gap = f64::INFINITY;
        for round in 1..=6 {
            chaikin = chaikin.subdivide();
            scale *= 2.0;
            let refined = chaikin.limit().unwrap();
            // Corner cutting is knot insertion: the refined polygon has the same limit.
            for i in 0..=60 {
                let u = a + (b - a) * i as f64 / 60.0;
                let d = (limit.eval(u) - refined.eval(u * scale)).length();
                assert!(d < 1e-12, "closed {closed}, round {round}, u {u}: {d}");
            }
            // And the polygon itself converges onto the limit, ~4x closer per round.
            let gap = chaikin
                .points()
                .iter()
                .map(|&p| limit.closest_point(p, 8).dist_sq.sqrt())
                .fold(0.0, f64::max);
            assert!(
                gap < prev_gap / 3.0,
                "round {round}: {gap} after {prev_gap}"
            );
            prev_gap = gap;
        }
    }
}

#[test]
fn closest_point_residual_is_normal_to_the_curve() {
    // Degree 1 curves have corners at every knot, where no normal exists.
    for c in sample_curves(2.0).into_iter().filter(|c| c.degree() > 1) {
        for i in 0..20 {
            let q = Point3::new(1.5 * (i as f64).cos(), 1.2 * (i as f64 * 0.7).sin(), 0.1);
            let near = c.closest_point(q, 16);
            let d = c.eval_derivs(near.param, 1);
            let (a, b) = c.domain();
            let at_end = !c.is_closed() && (near.param == a || near.param == b);
            let cos = (q - d[0]).normalize_or_zero().dot(d[1].normalize_or_zero());
            assert!(
                at_end || cos.abs() < 1e-6 || near.dist_sq < 1e-20,
                "degree {} closed {}: cos {cos} at u {} ({:?})",
                c.degree(),
                c.is_closed(),
                near.param,
                near
            );
        }
    }
}

#[test]
fn bad_input_gives_typed_errors() {
    let pts = wavy_points(5, 0.0);
    assert!(matches!(
        BSplineCurve::try_clamped_uniform(0, pts.clone()),
        Err(SplineError::BadDegree { .. })
    ));
    assert!(matches!(
        BSplineCurve::try_clamped_uniform(6, wavy_points(9, 0.0)),
        Err(SplineError::BadDegree { degree: 6, .. })
    ));
    assert!(matches!(
        BSplineCurve::try_clamped_uniform(3, pts[..3].to_vec()),
        Err(SplineError::ControlPointCount { found: 3, .. })
    ));
    let mut nan = pts.clone();
    nan[2].y = f64::NAN;
    assert!(matches!(
        BSplineCurve::try_periodic_uniform(2, nan),
        Err(SplineError::NonFiniteControlPoint { index: 2 })
    ));
    assert!(matches!(
        BSplineCurve::try_new(2, vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], pts.clone()),
        Err(SplineError::ControlPointCount { .. })
    ));
    let c = BSplineCurve::try_clamped_uniform(2, pts.clone()).unwrap();
    assert!(matches!(
        c.clone().try_with_weights(vec![1.0, 1.0, -1.0, 1.0, 1.0]),
        Err(SplineError::BadWeight { index: 2, .. })
    ));
    assert!(matches!(
        c.insert_knot(f64::NAN),
        Err(SplineError::BadKnotInsertion { .. })
    ));
    assert!(matches!(
        c.insert_knot(1.5),
        Err(SplineError::BadKnotInsertion { .. })
    ));
    assert!(matches!(
        BSplineCurve::try_periodic(3, &[0.0, 0.5, 0.5, 0.5, 0.5, 1.0], pts.clone()),
        Err(SplineError::KnotMultiplicity { .. })
    ));
    assert!(ChaikinCurve::try_new(pts[..2].to_vec(), false).is_err());
    // Evaluation never returns NaN, even for NaN parameters.
    assert!(c.eval(f64::NAN).is_finite());
    assert!(c.eval(f64::INFINITY).is_finite());
}
