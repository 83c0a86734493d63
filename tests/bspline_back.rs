//! A B-spline surface fit converges only when its delivered (trimmed) surface stays on the data
//! too (SPEC §6): a closed object fitted as one sheet holds its points but folds over itself
//! far from them, and used to report "converged" (spot 8.1 %, cow 9.1 %, fandisk 21.5 % from the
//! data for a bound of 0.2 %). The page's range-scan sample does converge, and then no vertex
//! of its trimmed tessellation lies beyond the bound.

mod common;

use geofit::fit::{FitData, FitReport, FitSpec, FitStatus, Method, Scheme, Shape};
use geofit::io::read_path;

/// Fits `path` as a B-spline surface by `method` with `tol_max` and `initial` (the defaults
/// when `None`); returns the report, the bound (2 × the E_max tolerance) and the largest
/// distance of the trimmed 16-segment tessellation's vertices to the data, % of the diagonal.
fn fit(
    path: &std::path::Path,
    method: Method,
    tol_max: Option<f64>,
    initial: Option<usize>,
) -> (FitReport, f64, f64) {
    let mesh = read_path(path).expect("the file reads").mesh;
    let mut spec = FitSpec::new(Scheme::BsplineSurface).with_tol_max(tol_max);
    spec.method = Some(method);
    spec.initial = initial;
    let mut fit = spec.build(&FitData::points(&mesh)).expect("the fit starts");
    fit.run().expect("the fit runs");
    let Some(Shape::Mesh(trimmed)) = fit.trimmed_limit_shape(16) else {
        panic!("a surface fit of a scan has a trim");
    };
    let mut used = vec![false; trimmed.positions().len()];
    for face in trimmed.faces() {
        for &v in face {
            used[v as usize] = true;
        }
    }
    let drawn: Vec<_> = (trimmed.positions().iter().zip(&used))
        .filter(|x| *x.1)
        .map(|x| *x.0)
        .collect();
    let worst = fit
        .distances_to_data(&drawn)
        .expect("measured against the data's triangles")
        .into_iter()
        .flatten()
        .fold(0.0, f64::max);
    let bound = geofit::fit::BACK_TOLERANCE_FACTOR * fit.tolerances().max_pct.expect("E_max");
    (
        FitReport::of(fit.as_ref()),
        bound,
        100.0 * worst / fit.diagonal(),
    )
}

#[test]
fn a_closed_object_fitted_as_one_sheet_does_not_converge() {
    let path = common::data_file("spot.obj");
    if !path.exists() {
        eprintln!("skipped: no {}", path.display());
        return;
    }
    for method in [Method::LeastSquares, Method::Geometric] {
        let (report, bound, _) = fit(&path, method, None, None);
        let back = report.e_back_max_pct.expect("E_back measured");
        println!("spot {method:?}: {:?}, E_back {back:.3} %", report.status);
        assert_ne!(report.status, FitStatus::Converged, "{method:?}");
        assert!(back > bound, "{method:?}: {back} % within {bound} %");
    }
}

#[test]
fn the_range_scan_sample_converges_on_its_data() {
    // The page's sample with its preset: converged after 4 iterations with E_back 0.87 % (bound
    // 1 %), the 16-segment tessellation 0.90 %. Measured on half-span cells, whose trim reaches
    // further past the outline than any tessellation the page draws or the exports write, it
    // had read 1.32 %, and the fit held it stiff for 5 more iterations.
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("www/samples/bun000-points.xyz");
    let (report, bound, worst) = fit(&path, Method::LeastSquares, Some(0.5), Some(200));
    let back = report.e_back_max_pct.expect("E_back measured");
    println!(
        "bun000-points: {:?} after {} iterations, E_back {back:.3} %, tessellation {worst:.3} %",
        report.status, report.iterations
    );
    assert_eq!(report.status, FitStatus::Converged);
    assert!(
        back <= bound && worst <= bound,
        "{back} / {worst} % > {bound} %"
    );
}

/// The fit's E_back is taken where its exports tessellate (4 segments per knot span), more
/// finely where the surface comes near the bound; at the knots and span midpoints alone it
/// read beetle's straying surface at 0.74 % where its 16-segment tessellation is at 1.04 %.
#[test]
fn the_reported_distance_is_that_of_the_delivered_surface() {
    let path = common::data_file("corpus/beetle.obj");
    if !path.exists() {
        eprintln!("skipped: no {}", path.display());
        return;
    }
    let (report, bound, worst) = fit(&path, Method::LeastSquares, None, None);
    let back = report.e_back_max_pct.expect("E_back measured");
    println!(
        "beetle: {:?}, E_back {back:.3} %, 16-segment tessellation {worst:.3} %",
        report.status
    );
    assert!(back > bound, "beetle's single sheet strays: {back} %");
    assert!(
        back >= 0.8 * worst,
        "reported {back} %, tessellation {worst} %"
    );
}
