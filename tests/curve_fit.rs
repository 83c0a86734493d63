//! Geometric curve fitting (SPEC §1.9) on synthetic curves and on the committed sections of the
//! bunny and the fandisk (tests/data/*_section*.xyz, made by scripts/make_sections.py).

mod common;

use common::{max_only, section};
use geofit::fit::{CurveFitOptions, CurveFitter, FitError, FitStatus, Fitter};
use geofit::geom::Point3;

fn ellipse(n: usize) -> Vec<Point3> {
    (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            Point3::new(2.0 * t.cos(), t.sin() + 0.2 * (3.0 * t).sin(), 0.0)
        })
        .collect()
}

#[test]
fn bunny_section_closed_reaches_one_hundredth_percent() {
    let pts = section("bunny_section.xyz");
    assert_eq!(pts.len(), 615);
    let opts = CurveFitOptions::default()
        .with_closed(true)
        .with_tolerances(max_only(0.01))
        .with_max_iter(1000);
    let mut fit = CurveFitter::try_new(&pts, opts).unwrap();
    let status = fit.run().unwrap();
    for h in fit
        .history()
        .iter()
        .filter(|h| h.refined || h.iter % 20 == 0)
    {
        eprintln!("{h:?}");
    }
    let s = fit.stats();
    eprintln!(
        "bunny geometric: {:?} ctrl {} iters {} e_max {:.5} % e_rms {:.5} %",
        status,
        fit.curve().control_points().len(),
        fit.history().len(),
        s.e_max_pct,
        s.e_rms_pct
    );
    assert_eq!(status, FitStatus::Converged);
    assert!(s.e_max_pct <= 0.01);
}

#[test]
fn open_curve_converges_and_errors_do_not_explode() {
    let pts: Vec<Point3> = ellipse(400)[..300].to_vec();
    let opts = CurveFitOptions::default().with_tolerances(max_only(0.001));
    let mut fit = CurveFitter::try_new(&pts, opts).unwrap();
    assert_eq!(fit.run().unwrap(), FitStatus::Converged);
    assert!(fit
        .point_errors()
        .iter()
        .all(|e| e.abs() <= 1e-5 * 2.5 * 2.0));
    // E_max never grows by more than the damping allows between knot insertions.
    let h = fit.history();
    assert!(h.last().unwrap().e_max_pct < h[0].e_max_pct);
}

#[test]
fn bad_input_gives_typed_errors() {
    let pts = ellipse(50);
    let mut nan = pts.clone();
    nan[7].x = f64::NAN;
    assert!(matches!(
        CurveFitter::try_new(&nan, CurveFitOptions::default()),
        Err(FitError::NonFinitePoint { index: 7 })
    ));
    let mut dup = pts.clone();
    dup[9] = dup[8];
    assert!(matches!(
        CurveFitter::try_new(&dup, CurveFitOptions::default()),
        Err(FitError::DuplicatePoint { index: 9 })
    ));
    assert!(matches!(
        CurveFitter::try_new(&pts[..4], CurveFitOptions::default()),
        Err(FitError::TooFewPoints {
            found: 4,
            needed: 5
        })
    ));
    for degree in [0, 6] {
        assert!(matches!(
            CurveFitter::try_new(&pts, CurveFitOptions::default().with_degree(degree)),
            Err(FitError::InvalidOption { name: "degree", .. })
        ));
    }
    assert!(matches!(
        CurveFitter::try_new(&pts, CurveFitOptions::default().with_simplify_pct(f64::NAN)),
        Err(FitError::InvalidOption { .. })
    ));
    // A closed polyline with its first point repeated at the end is accepted.
    let mut looped = pts.clone();
    looped.push(pts[0]);
    let fit = CurveFitter::try_new(&looped, CurveFitOptions::default().with_closed(true)).unwrap();
    assert_eq!(fit.data().len(), pts.len());
}
