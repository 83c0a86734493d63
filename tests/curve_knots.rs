//! Knot placement with least squares (SPEC §3): exact reproduction, the bunny section, and
//! sharp corners on the fandisk sections.

mod common;

use common::{max_only, section};
use geofit::fit::{
    least_squares_curve, CurveFitOptions, CurveFitter, FitStatus, Fitter, KnotPlacementFitter,
    KnotPlacementOptions,
};
use geofit::geom::Point3;
use geofit::spline::BSplineCurve;

#[test]
fn least_squares_reproduces_an_exact_bspline() {
    let ctrl: Vec<Point3> = (0..9)
        .map(|i| {
            let t = i as f64 * 0.7;
            Point3::new(t.cos() * (1.0 + 0.1 * t), t.sin(), 0.3 * t)
        })
        .collect();
    let tau = [0.0, 0.1, 0.25, 0.3, 0.3, 0.55, 0.7, 0.8, 0.9, 1.0];
    let mut knots = vec![0.0; 4];
    knots.extend([0.2, 0.2, 0.45, 0.6, 0.8]);
    knots.extend([1.0; 4]);
    let curves = [
        BSplineCurve::try_new(3, knots, ctrl.clone()).unwrap(),
        BSplineCurve::try_periodic(3, &tau, ctrl.clone()).unwrap(),
        BSplineCurve::try_periodic(2, &tau, ctrl.clone()).unwrap(),
        BSplineCurve::try_clamped_uniform(5, ctrl.clone()).unwrap(),
    ];
    for exact in curves {
        let (a, b) = exact.domain();
        let params: Vec<f64> = (0..200)
            .map(|i| a + (b - a) * (i as f64 + 0.5) / 200.0)
            .collect();
        let samples: Vec<Point3> = params.iter().map(|&u| exact.eval(u)).collect();
        // Start from a deliberately wrong set of control points.
        let mut template = exact.clone();
        for c in template.control_points_mut() {
            *c = Point3::ZERO;
        }
        let fitted = least_squares_curve(&template, &samples, &params).unwrap();
        for (c, e) in fitted.control_points().iter().zip(exact.control_points()) {
            assert!(
                (*c - *e).length() < 1e-9,
                "degree {}: {c:?} vs {e:?}",
                exact.degree()
            );
        }
    }
}

fn run_knots(name: &str, pct: f64) -> KnotPlacementFitter {
    let pts = section(name);
    let opts = KnotPlacementOptions::default()
        .with_closed(true)
        .with_tolerances(max_only(pct));
    let mut fit = KnotPlacementFitter::try_new(&pts, opts).unwrap();
    let status = fit.run().unwrap();
    eprintln!(
        "{name} knots: {status:?} features {} (corners {}) ctrl {} e_max {:.5} % e_rms {:.5} % std {:.5} %",
        fit.features().len(),
        fit.features().iter().filter(|f| f.multiplicity == 3).count(),
        fit.curve().control_points().len(),
        fit.stats().e_max_pct,
        fit.stats().e_rms_pct,
        fit.std_pct(),
    );
    fit
}

#[test]
fn bunny_section_knot_placement_reaches_one_hundredth_percent() {
    let fit = run_knots("bunny_section.xyz", 0.01);
    assert_eq!(fit.status(), FitStatus::Converged);
    assert!(fit.stats().e_max_pct <= 0.01);
}

#[test]
fn batched_insertion_needs_fewer_solves_than_one_knot_per_solve() {
    let pts = section("fandisk_section_x.xyz");
    let run = |batch: bool| {
        let opts = KnotPlacementOptions::default()
            .with_closed(true)
            .with_tolerances(max_only(0.01))
            .with_batch(batch);
        let mut fit = KnotPlacementFitter::try_new(&pts, opts).unwrap();
        assert_eq!(fit.run().unwrap(), FitStatus::Converged, "batch {batch}");
        assert!(fit.stats().e_max_pct <= 0.01);
        (fit.history().len(), fit.curve().control_points().len())
    };
    let (single, batched) = (run(false), run(true));
    eprintln!("one by one: {single:?} (solves, control points), batched: {batched:?}");
    assert!(batched.0 < single.0, "{batched:?} vs {single:?}");
}

/// Angle between the one-sided tangents of `curve` at `u`, degrees.
fn tangent_jump(curve: &BSplineCurve, u: f64) -> f64 {
    let (a, b) = curve.domain();
    let h = 1e-9 * (b - a);
    let before = curve.eval_derivs(u - h, 1)[1];
    let after = curve.eval_derivs(u + h, 1)[1];
    before.angle_between(after).to_degrees()
}

#[test]
fn fandisk_corners_stay_sharp() {
    for name in ["fandisk_section_x.xyz", "fandisk_section_z.xyz"] {
        let fit = run_knots(name, 0.01);
        assert_eq!(fit.status(), FitStatus::Converged, "{name}");
        let corners: Vec<_> = fit
            .features()
            .iter()
            .filter(|f| f.multiplicity == 3)
            .collect();
        assert!(corners.len() >= 5, "{name}: {} corners", corners.len());
        for c in corners {
            let jump = tangent_jump(fit.curve(), c.param);
            // The fitted curve turns at the corner knot by at least about the data's angle
            // (measured over 3 neighbours, so an adjacent fillet makes it smaller).
            assert!(
                jump > 0.8 * c.angle_deg,
                "{name}: corner at point {} turns {jump:.2}° on the curve, {:.2}° in the data",
                c.index,
                c.angle_deg
            );
        }
    }
}

#[test]
fn fandisk_geometric_method_reaches_one_hundredth_percent() {
    for name in ["fandisk_section_x.xyz", "fandisk_section_z.xyz"] {
        let opts = CurveFitOptions::default()
            .with_closed(true)
            .with_tolerances(max_only(0.01))
            .with_max_iter(1000);
        let mut fit = CurveFitter::try_new(&section(name), opts).unwrap();
        let status = fit.run().unwrap();
        eprintln!(
            "{name} geometric: {status:?} ctrl {} iters {} e_max {:.5} %",
            fit.curve().control_points().len(),
            fit.history().len(),
            fit.stats().e_max_pct
        );
        assert_eq!(status, FitStatus::Converged, "{name}");
    }
}

#[test]
fn smooth_data_gets_no_multiple_knots_and_bad_options_are_refused() {
    let pts: Vec<Point3> = (0..200)
        .map(|i| {
            let t = i as f64 / 200.0 * std::f64::consts::TAU;
            Point3::new(2.0 * t.cos(), t.sin(), 0.0)
        })
        .collect();
    let opts = KnotPlacementOptions::default()
        .with_closed(true)
        .with_tolerances(max_only(0.001));
    let mut fit = KnotPlacementFitter::try_new(&pts, opts).unwrap();
    assert!(fit.features().is_empty());
    assert_eq!(fit.run().unwrap(), FitStatus::Converged);
    // Open data: the curve interpolates the end points' neighbourhood within tolerance.
    let open = KnotPlacementOptions::default().with_tolerances(max_only(0.001));
    let mut fit = KnotPlacementFitter::try_new(&pts[..150], open).unwrap();
    assert_eq!(fit.run().unwrap(), FitStatus::Converged);
    for bad in [
        KnotPlacementOptions::default().with_degree(0),
        KnotPlacementOptions::default().with_curvature_jump(-1.0),
        KnotPlacementOptions::default().with_corner_angle_deg(f64::NAN),
        KnotPlacementOptions::default().with_std_pct(Some(-0.1)),
    ] {
        assert!(matches!(
            KnotPlacementFitter::try_new(&pts, bad),
            Err(geofit::fit::FitError::InvalidOption { .. })
        ));
    }
    assert!(matches!(
        KnotPlacementFitter::try_new(&pts[..5], KnotPlacementOptions::default()),
        Err(geofit::fit::FitError::TooFewPoints { .. })
    ));
}
