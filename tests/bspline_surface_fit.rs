//! Geometric (error-vector) B-spline surface fitting: the error falls, knots are inserted where
//! it stays high, and bad options are typed errors.

mod common;

use geofit::fit::{
    Acceleration, FitData, FitError, FitReport, FitSpec, FitStatus, Fitter, GeometricSurfaceFitter,
    GeometricSurfaceOptions, LsqSurfaceFitter, LsqSurfaceOptions, Method, ParamOptions, Scheme,
    TolMode,
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
            .with_warm_start(false)
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
fn warm_start_begins_near_the_optimum() {
    let pts = wave(40);
    let opts = |warm| {
        GeometricSurfaceOptions::default()
            .with_control(9, 9)
            .with_fixed_knots(true)
            .with_tolerance(1e-6, TolMode::Exact)
            .with_max_iterations(3)
            .with_warm_start(warm)
            .with_param(top())
    };
    let mut cold = GeometricSurfaceFitter::try_new(&pts, opts(false)).unwrap();
    let mut warm = GeometricSurfaceFitter::try_new(&pts, opts(true)).unwrap();
    // Before any iteration the warm start is already a least-squares fit.
    assert!(warm.stats().e_rms_pct < 0.2 * cold.stats().e_rms_pct);
    cold.run().unwrap();
    warm.run().unwrap();
    let (c, w) = (cold.stats(), warm.stats());
    assert!(w.e_rms_pct < c.e_rms_pct, "warm {w:?} cold {c:?}");
    assert!(w.e_max_pct < c.e_max_pct, "warm {w:?} cold {c:?}");
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

#[test]
fn cli_fit_scheme_bspline_writes_the_report() {
    let dir = std::env::temp_dir().join(format!("geofit_bspline_cli_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let data = dir.join("wave.xyz");
    let text: String = wave(30)
        .iter()
        .map(|p| format!("{} {} {}\n", p.x, p.y, p.z))
        .collect();
    std::fs::write(&data, text).unwrap();
    let report = dir.join("r.json");
    let step = dir.join("s.stp");
    for method in ["least-squares", "geometric"] {
        common::geofit_ok(&[
            "fit",
            data.to_str().unwrap(),
            "--scheme",
            "bspline",
            "--ctrl-u",
            "6",
            "--ctrl-v",
            "7",
            "--method",
            method,
            "--json",
            report.to_str().unwrap(),
            "--step",
            step.to_str().unwrap(),
        ]);
        let r = common::read_json(&report);
        assert_eq!(r["scheme"], "bspline-surface");
        assert_eq!(r["points"], 900);
        assert_eq!(r["control_points_u"], 6);
        assert_eq!(r["control_points_v"], 7);
        assert_eq!(r["final_control_points"], 42);
        for key in common::REPORT_NUMBERS {
            assert!(r[key].as_f64().is_some_and(f64::is_finite), "{key}");
        }
        assert!(!r["history"].as_array().unwrap().is_empty());
        assert!(std::fs::read_to_string(&step)
            .unwrap()
            .contains("B_SPLINE_SURFACE_WITH_KNOTS"));
    }
    let bad = common::geofit(&[
        "fit",
        data.to_str().unwrap(),
        "--scheme",
        "bspline",
        "--ctrl",
        "50",
    ]);
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("not a square"));
    // Options of one branch given to the other are errors, not silently ignored.
    for (args, message) in [
        (
            vec!["--scheme", "loop", "--method", "geometric"],
            "--method does not apply to --scheme loop",
        ),
        (
            vec!["--scheme", "bspline", "--tol-avg", "0.01"],
            "--tol-avg does not apply to --scheme bspline",
        ),
        (
            vec!["--scheme", "bspline", "--method", "sections", "--creases"],
            "--creases does not apply to --scheme bspline-surface --method sections (with \
             --scheme bspline-surface it applies to --method least-squares, geometric)",
        ),
    ] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_geofit"))
            .arg("fit")
            .arg(&data)
            .args(args)
            .output()
            .unwrap();
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(message), "{err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_mostly_failing_knot_vector_is_split_early() {
    let pts = wave(40);
    // The iterations that refined, for an early split after 2 iterations at any failing share
    // and for none (split only on a stall or after `iterations_per_knots`).
    let refined = |after: usize, share: f64| {
        let opts = GeometricSurfaceOptions::default()
            .with_control(4, 4)
            .with_tolerance(1e-3, TolMode::Exact)
            .with_early_split(after, share)
            .with_max_iterations(8)
            .with_param(top());
        let mut fit = GeometricSurfaceFitter::try_new(&pts, opts).unwrap();
        fit.run().unwrap();
        let h = fit.history();
        h.iter()
            .filter(|r| r.refined)
            .map(|r| r.iter)
            .collect::<Vec<_>>()
    };
    assert_eq!(refined(2, 0.0), [2, 4, 6]);
    let late = refined(usize::MAX, 1.0);
    assert!(late.first().is_none_or(|&i| i > 2), "{late:?}");
    let bad = GeometricSurfaceOptions::default().with_early_split(2, -0.1);
    let err = GeometricSurfaceFitter::try_new(&pts, bad)
        .err()
        .expect("rejected");
    assert!(err.to_string().contains("early_split_share"), "{err}");
}

/// A B-spline surface fit of `data` by `method` with the defaults, run to its end, and its
/// report.
fn surface_report(data: &geofit::mesh::PolyMesh, method: Method) -> FitReport {
    let spec = FitSpec::new(Scheme::BsplineSurface).with_method(Some(method));
    let mut fit = spec.build(&FitData::points(data)).expect("the fit starts");
    fit.run().expect("the fit runs");
    FitReport::of(fit.as_ref())
}

#[test]
fn the_surface_to_data_distance_is_measured_when_a_surface_fit_stops() {
    let wave = |x: f64, y: f64| 3.0 * (x / 8.0).sin() * (y / 6.0).cos();
    let mesh = common::meshes::tri_grid(40, wave);
    let points = geofit::mesh::PolyMesh::try_new(mesh.positions().to_vec(), Vec::<[u32; 3]>::new())
        .expect("points");
    // A height field, from its faces and from its bare points (the reference is then the
    // points' reconstruction): the surface stays on the data.
    for (what, data) in [("mesh", &mesh), ("points", &points)] {
        for method in [Method::Geometric, Method::LeastSquares] {
            let r = surface_report(data, method);
            assert_eq!(r.status, FitStatus::Converged, "{what} {method:?}");
            let back = r.e_back_max_pct.expect("E_back measured");
            let last = r.history.last().and_then(|h| h.e_back_max_pct);
            println!(
                "{what} {method:?}: E_max {:.4} %, E_back {back:.4} %",
                r.e_max_pct
            );
            assert_eq!(last, Some(back), "the last iteration carries it");
            assert!(back <= 2.0 * 0.1, "{what} {method:?}: E_back {back} %");
        }
    }
    // A closed sphere as one sheet: the sheet holds every point it is fitted to, but folds
    // over itself at the silhouette, far from the data, and E_back says so.
    let ico = common::meshes::refine_flat(&common::meshes::icosahedron(), 3);
    let sphere = geofit::mesh::PolyMesh::try_new(
        ico.positions().iter().map(|p| p.normalize()).collect(),
        ico.triangles(),
    )
    .expect("sphere");
    let r = surface_report(&sphere, Method::Geometric);
    let back = r.e_back_max_pct.expect("E_back measured");
    println!("sphere: E_max {:.4} %, E_back {back:.4} %", r.e_max_pct);
    // On the trimmed face (the disc the points project to): 0.37 % against E_max 0.098 %,
    // beyond the two E_max tolerances (0.1 %) a surface may stray.
    assert!(
        back > 2.0 * 0.1 && back > 3.0 * r.e_max_pct,
        "sphere: E_back {back} %"
    );
}

/// What the page colours a surface by: the distance of any point to the data, `None` beyond
/// the data's outline, and nothing at all for a fit that measures no surface → data distance.
#[test]
fn any_point_s_distance_to_the_data_is_given_for_the_surface_view() {
    let plane = common::meshes::tri_grid(20, |_, _| 0.0);
    let mut fit = FitSpec::new(Scheme::BsplineSurface)
        .build(&FitData::points(&plane))
        .expect("the fit starts");
    fit.run().expect("the fit runs");
    let probes = [
        Point3::new(10.3, 9.7, 0.0),
        Point3::new(10.3, 9.7, 0.25),
        Point3::new(4.0, 15.0, -1.5),
        Point3::new(35.0, 10.0, 0.0),
    ];
    let d = fit
        .distances_to_data(&probes)
        .expect("a surface fit measures it");
    assert!(d[0].is_some_and(|d| d < 1e-9), "{d:?}");
    assert!(d[1].is_some_and(|d| (d - 0.25).abs() < 1e-9), "{d:?}");
    assert!(d[2].is_some_and(|d| (d - 1.5).abs() < 1e-9), "{d:?}");
    assert_eq!(d[3], None, "beyond the outline nothing is measured");
    let section: Vec<Point3> = (0..50)
        .map(|i| Point3::new(i as f64, (i as f64 / 8.0).sin(), 0.0))
        .collect();
    let curve = FitSpec::new(Scheme::BsplineCurve)
        .build(&FitData::points(
            &geofit::mesh::PolyMesh::from_points(section).unwrap(),
        ))
        .expect("the curve fit starts");
    assert_eq!(
        curve.distances_to_data(&probes),
        None,
        "a curve has no reference"
    );
}
