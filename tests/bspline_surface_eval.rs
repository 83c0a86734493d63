//! Tensor-product B-spline / NURBS surfaces: derivatives against finite differences, knot
//! insertion leaves the surface unchanged, foot points are orthogonal, bad input is typed.

use geofit::geom::Point3;
use geofit::geom::{ClosestPoint, NewtonOptions};
use geofit::spline::{BSplineSurface, KnotVector, SplineError};
use proptest::prelude::*;

fn knots_u() -> KnotVector {
    KnotVector::try_new(3, vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.55, 1.0, 1.0, 1.0, 1.0]).unwrap()
}

fn knots_v() -> KnotVector {
    KnotVector::try_new(2, vec![0.0, 0.0, 0.0, 0.4, 0.7, 1.0, 1.0, 1.0]).unwrap()
}

/// A wavy 6 × 5 control net.
fn control() -> Vec<Point3> {
    (0..30)
        .map(|k| {
            let (i, j) = ((k / 5) as f64, (k % 5) as f64);
            Point3::new(i, j, (0.7 * i).sin() + 0.3 * (1.3 * j).cos() + 0.1 * i * j)
        })
        .collect()
}

fn weights() -> Vec<f64> {
    (0..30)
        .map(|k| 0.5 + ((k * 7) % 11) as f64 / 10.0)
        .collect()
}

fn surfaces() -> [BSplineSurface; 2] {
    [
        BSplineSurface::try_new(knots_u(), knots_v(), control()).unwrap(),
        BSplineSurface::try_new_rational(knots_u(), knots_v(), control(), weights()).unwrap(),
    ]
}

fn near_knot(t: f64, kv: &KnotVector) -> bool {
    kv.knots().iter().any(|&k| (k - t).abs() < 2e-3)
}

proptest! {
    #[test]
    fn derivatives_match_finite_differences(u in 0.01f64..0.99, v in 0.01f64..0.99) {
        for s in surfaces() {
            prop_assume!(!near_knot(u, s.knots_u()) && !near_knot(v, s.knots_v()));
            let h = 1e-5;
            let d = s.derivs(u, v, 3);
            let du_p = s.derivs(u + h, v, 3);
            let du_m = s.derivs(u - h, v, 3);
            let dv_p = s.derivs(u, v + h, 3);
            let dv_m = s.derivs(u, v - h, 3);
            // Every derivative of order k+l ≤ 3 against central differences of order k+l−1.
            for k in 0..=3usize {
                for l in 0..=(3 - k) {
                    if k + l == 0 {
                        continue;
                    }
                    let fd = if k > 0 {
                        (du_p.skl[k - 1][l] - du_m.skl[k - 1][l]) / (2.0 * h)
                    } else {
                        (dv_p.skl[k][l - 1] - dv_m.skl[k][l - 1]) / (2.0 * h)
                    };
                    let scale = 1.0 + d.skl[k][l].length();
                    prop_assert!((fd - d.skl[k][l]).length() < 1e-5 * scale * 10.0,
                        "order ({k},{l}): analytic {:?} vs fd {:?}", d.skl[k][l], fd);
                }
            }
            prop_assert!((d.point() - s.eval(u, v)).length() < 1e-14);
        }
    }

    #[test]
    fn knot_insertion_keeps_the_surface(t in 0.02f64..0.98, u in 0.0f64..=1.0, v in 0.0f64..=1.0) {
        for s in surfaces() {
            let mut su = s.clone();
            su.insert_knot_u(t).unwrap();
            let mut sv = s.clone();
            sv.insert_knot_v(t).unwrap();
            prop_assert_eq!(su.num_control(), (7, 5));
            prop_assert_eq!(sv.num_control(), (6, 6));
            let p = s.eval(u, v);
            prop_assert!((su.eval(u, v) - p).length() < 1e-12);
            prop_assert!((sv.eval(u, v) - p).length() < 1e-12);
        }
    }

    #[test]
    fn foot_points_are_orthogonal(u in 0.05f64..0.95, v in 0.05f64..0.95, off in -0.3f64..0.3) {
        for s in surfaces() {
            let d = s.derivs(u, v, 1);
            let n = d.skl[1][0].cross(d.skl[0][1]).normalize();
            let q = d.point() + n * off;
            let near = s.closest_point_from(q, [(u + 0.03).min(1.0), (v - 0.03).max(0.0)], &NewtonOptions::DEFAULT);
            prop_assert!(near.converged);
            let [nu, nv] = near.param;
            prop_assert!(nu.is_finite() && nv.is_finite());
            let dd = s.derivs(nu, nv, 1);
            let r = q - near.point;
            let interior = nu > 0.0 && nu < 1.0 && nv > 0.0 && nv < 1.0;
            if interior {
                prop_assert!(r.dot(dd.skl[1][0]).abs() < 1e-9 * (1.0 + dd.skl[1][0].length()));
                prop_assert!(r.dot(dd.skl[0][1]).abs() < 1e-9 * (1.0 + dd.skl[0][1].length()));
            }
            prop_assert!(near.dist_sq <= off * off + 1e-12);
        }
    }
}

#[test]
fn clamped_corners_interpolate() {
    let s = &surfaces()[0];
    let c = control();
    assert!((s.eval(0.0, 0.0) - c[0]).length() < 1e-14);
    assert!((s.eval(1.0, 1.0) - c[29]).length() < 1e-14);
    assert!((s.eval(1.0, 0.0) - c[25]).length() < 1e-14);
    // Outside the domain is clamped, never NaN.
    assert!(s.eval(f64::NAN, 7.0).is_finite());
    let near = s.closest_point_from(Point3::NAN, [0.5, 0.5], &NewtonOptions::DEFAULT);
    assert!(near.param.iter().all(|t| t.is_finite()));
}

#[test]
fn bad_input_is_rejected() {
    let mut c = control();
    assert!(matches!(
        BSplineSurface::try_new(knots_u(), knots_v(), c[..29].to_vec()),
        Err(SplineError::ControlPointCount {
            found: 29,
            expected: 30,
        })
    ));
    c[4].y = f64::NAN;
    assert!(matches!(
        BSplineSurface::try_new(knots_u(), knots_v(), c),
        Err(SplineError::NonFiniteControlPoint { index: 4 })
    ));
    let mut w = weights();
    w[3] = 0.0;
    assert!(matches!(
        BSplineSurface::try_new_rational(knots_u(), knots_v(), control(), w),
        Err(SplineError::BadWeight { index: 3, .. })
    ));
    let mut s = surfaces()[0].clone();
    assert!(matches!(
        s.insert_knot_u(1.0),
        Err(SplineError::BadKnotInsertion { .. })
    ));
    assert!(matches!(
        s.insert_knot_v(f64::NAN),
        Err(SplineError::BadKnotInsertion { .. })
    ));
    // Multiplicity is capped at the degree.
    s.insert_knot_v(0.4).unwrap();
    assert!(matches!(
        s.insert_knot_v(0.4),
        Err(SplineError::BadKnotInsertion { .. })
    ));
}
