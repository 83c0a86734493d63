//! Geometric (error-vector) B-spline surface fitting: the error falls, knots are inserted where
//! it stays high, and bad options are typed errors.

use geofit::fit::{
    Acceleration, FitError, FitStatus, Fitter, GeometricSurfaceFitter, GeometricSurfaceOptions,
    LsqSurfaceFitter, LsqSurfaceOptions, ParamOptions, TolMode,
};
use geofit::geom::{Point3, Vec3};

fn wave(n: usize) -> Vec<Point3> {
    (0..n * n)
        .map(|k| {
            let (x, y) = (
                (k / n) as f64 / (n - 1) as f64,
                (k % n) as f64 / (n - 1) as f64,
            );
            Point3::new(x, y, 0.15 * (4.0 * x).sin() * (3.0 * y).cos())
        })
        .collect()
}

fn top() -> ParamOptions {
    ParamOptions::default().with_view(Vec3::Z)
}

#[test]
fn geometric_iteration_lowers_the_error_on_fixed_knots() {
    let pts = wave(40);
    for accel in [Acceleration::None, Acceleration::Anderson { depth: 5 }] {
        let opts = GeometricSurfaceOptions::default()
            .with_control(9, 9)
            .with_fixed_knots(true)
            .with_tolerance(1e-6, TolMode::Exact)
            .with_acceleration(accel)
            .with_max_iterations(60)
            .with_param(top());
        let mut fit = GeometricSurfaceFitter::try_new(&pts, opts).unwrap();
        let start = fit.stats().e_rms_pct;
        fit.run().unwrap();
        let h = fit.history();
        let end = h.last().unwrap().e_rms_pct;
        assert!(end < 0.05 * start, "{accel:?}: {start} -> {end}");
        assert!(h.iter().all(|r| r.control_points == 81));
    }
}

#[test]
fn geometric_fit_approaches_the_least_squares_optimum() {
    let pts = wave(30);
    let g_opts = GeometricSurfaceOptions::default()
        .with_control(7, 7)
        .with_fixed_knots(true)
        .with_tolerance(1e-6, TolMode::Exact)
        .with_max_iterations(150)
        .with_param(top());
    let mut g = GeometricSurfaceFitter::try_new(&pts, g_opts).unwrap();
    g.run().unwrap();
    let l_opts = LsqSurfaceOptions::default()
        .with_control(7, 7)
        .with_fixed_knots(true)
        .with_betas(0.0, 0.0)
        .with_solves_per_knots(3)
        .with_tolerance(1e-6, TolMode::Exact)
        .with_param(top());
    let mut l = LsqSurfaceFitter::try_new(&pts, l_opts).unwrap();
    l.run().unwrap();
    let (ge, le) = (g.stats().e_rms_pct, l.stats().e_rms_pct);
    assert!(ge < 1.5 * le, "geometric {ge} vs least squares {le}");
}

#[test]
fn knots_are_inserted_until_the_tolerance_is_met() {
    let pts = wave(50);
    let opts = GeometricSurfaceOptions::default()
        .with_control(4, 4)
        .with_tolerance(0.05, TolMode::Exact)
        .with_param(top());
    let mut fit = GeometricSurfaceFitter::try_new(&pts, opts).unwrap();
    assert_eq!(
        fit.run().unwrap(),
        FitStatus::Converged,
        "{:?}",
        fit.history().last()
    );
    let last = fit.history().last().unwrap();
    assert!(
        last.e_max_pct <= 0.05 && last.control_points > 16,
        "{last:?}"
    );
    assert!(fit.history().iter().any(|r| r.refined));
}

#[test]
fn bad_options_are_typed_errors() {
    let pts = wave(10);
    let o = GeometricSurfaceOptions::default();
    assert!(matches!(
        GeometricSurfaceFitter::try_new(&pts, o.with_degree(0)),
        Err(FitError::InvalidOption { name: "degree", .. })
    ));
    assert!(matches!(
        GeometricSurfaceFitter::try_new(
            &pts,
            o.with_acceleration(Acceleration::Anderson { depth: 0 })
        ),
        Err(FitError::InvalidOption { .. })
    ));
    assert!(matches!(
        GeometricSurfaceFitter::try_new(&pts[..3], o),
        Err(FitError::TooFewPoints { .. })
    ));
}
