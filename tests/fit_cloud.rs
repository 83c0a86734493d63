//! Fitting bare point clouds end to end: points without faces are reconstructed into a mesh
//! (open or closed), simplified by QEM and fitted, through the library entry point
//! `FitSpec::build` and through `geofit fit`; degenerate clouds give clear errors.

mod common;

use common::{geofit, geofit_ok, read_json, Rng};
use geofit::fit::{
    DataSurface, FitData, FitError, FitReport, FitSpec, FitStatus, Fitter, ReconstructionReport,
    Scheme, Shape,
};
use geofit::geom::Point3;
use geofit::mesh::PolyMesh;
use std::path::{Path, PathBuf};

/// `n` points spread evenly (Fibonacci spiral) over an ellipsoid with half-axes 1, 0.8, 0.6.
fn ellipsoid(n: usize) -> Vec<Point3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let a = golden * i as f64;
            Point3::new(r * a.cos(), 0.8 * r * a.sin(), 0.6 * z)
        })
        .collect()
}

/// A noisy wavy height field over a 40 × 40 grid (jittered), plus two stray points far above.
fn noisy_sheet() -> Vec<Point3> {
    let mut rng = Rng(7);
    let mut points: Vec<Point3> = (0..1600)
        .map(|k| {
            let x = (k % 40) as f64 + 0.3 * rng.next_f64();
            let y = (k / 40) as f64 + 0.3 * rng.next_f64();
            let z = 2.0 * (x / 8.0).sin() * (y / 10.0).cos() + 0.02 * (rng.next_f64() - 0.5);
            Point3::new(x, y, z)
        })
        .collect();
    points.push(Point3::new(20.0, 20.0, 30.0));
    points.push(Point3::new(5.0, 30.0, -25.0));
    points
}

fn spec(avg: f64, max: f64) -> FitSpec {
    FitSpec::new(Scheme::Loop)
        .with_tol_avg(Some(avg))
        .with_tol_max(Some(max))
        .with_max_iter(Some(40))
        .with_max_control(Some(1_000))
}

/// The fitter of `spec` for the bare `points`, with what its reconstruction reported.
fn build_from_points(spec: &FitSpec, points: &[Point3]) -> (Box<dyn Fitter>, ReconstructionReport) {
    let data = PolyMesh::from_points(points.to_vec()).expect("finite points");
    let fitter = spec.build(&FitData::points(&data)).expect("a fitter");
    let rec = fitter
        .log()
        .reconstruction()
        .cloned()
        .expect("reconstructed");
    (fitter, rec)
}

#[test]
fn closed_cloud_with_duplicates_is_reconstructed_and_fitted() {
    let mut points = ellipsoid(2_000);
    // Every tenth point twice: duplicates must not disturb normals or the fit.
    let twice: Vec<Point3> = points.iter().step_by(10).copied().collect();
    points.extend(twice);
    let (mut fitter, rec) = build_from_points(&spec(0.05, 0.3).with_initial(Some(80)), &points);
    assert_eq!((rec.kind, rec.method), ("closed", "implicit"));
    assert!(rec.triangles > 500, "{rec:?}");
    assert_eq!(
        fitter.data().len(),
        points.len(),
        "the original points are fitted"
    );
    assert_eq!(fitter.num_control_points(), 80);
    let status = fitter.run().expect("iterates");
    let stats = fitter.stats();
    assert_eq!(status, FitStatus::Converged, "{stats:?}");
    assert!(
        stats.e_avg_pct <= 0.05 && stats.e_max_pct <= 0.3,
        "{stats:?}"
    );
    let report = FitReport::of(fitter.as_ref());
    assert_eq!(report.within_tolerance_pct, Some(100.0));
    // The deviation figures: of every point, the largest |d| is E_max, within the tolerance.
    let d = report.deviation;
    assert_eq!(d.within_tolerance_pct, report.within_tolerance_pct);
    assert_eq!(d.points, points.len());
    let e_max = stats.e_max_pct / 100.0 * fitter.diagonal();
    assert!((d.max - e_max).abs() <= 1e-9 * e_max, "{d:?} vs {stats:?}");
    assert!(
        d.p50 <= d.p90 && d.p90 <= d.p95 && d.p95 <= d.p99 && d.p99 <= d.max,
        "{d:?}"
    );
    assert!(d.tolerance.is_some_and(|t| d.max <= t), "{d:?}");
}

#[test]
fn open_noisy_cloud_drops_outliers_and_reports_the_share_within_tolerance() {
    let points = noisy_sheet();
    let mut spec = spec(0.1, 0.5);
    spec.outliers = Some(3.0);
    let (mut fitter, rec) = build_from_points(&spec, &points);
    assert_eq!((rec.kind, rec.method), ("open", "delaunay"));
    assert_eq!(rec.outliers, 2, "{rec:?}");
    assert_eq!(
        fitter.data().len(),
        points.len() - 2,
        "outliers are not fitted"
    );
    let status = fitter.run().expect("iterates");
    assert_eq!(status, FitStatus::Converged, "{:?}", fitter.stats());
    let within = FitReport::of(fitter.as_ref())
        .within_tolerance_pct
        .expect("an E_max tolerance was given");
    assert!((99.0..=100.0).contains(&within), "{within}");
}

#[test]
fn a_control_mesh_for_points_needs_no_reconstruction_only_when_given() {
    let data = PolyMesh::from_points(ellipsoid(500)).expect("finite points");
    // Without the reconstruction, simplification alone cannot start from bare points.
    assert!(matches!(
        geofit::fit::initial_control(&data, Some(50), None, geofit::subdiv::Scheme::Loop),
        Err(FitError::NoFaces)
    ));
    let two = PolyMesh::from_points(ellipsoid(2)).expect("finite points");
    let err = FitSpec::new(Scheme::Loop)
        .build(&FitData::points(&two))
        .err()
        .expect("two points span no surface");
    assert!(matches!(err, FitError::Reconstruct(_)), "{err}");
}

// ---- through `geofit fit` ----

/// A fresh temporary directory for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("geofit-fit-cloud-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn write_xyz(path: &Path, points: &[Point3]) {
    std::fs::write(path, xyz_text(points)).expect("write XYZ");
}

#[test]
fn geofit_fit_reconstructs_a_closed_xyz_cloud_and_reports_it() {
    let dir = temp_dir("closed");
    let (file, json) = (dir.join("ellipsoid.xyz"), dir.join("r.json"));
    write_xyz(&file, &ellipsoid(1_500));
    let stdout = geofit_ok(&[
        "fit",
        file.to_str().expect("utf-8"),
        "--cloud",
        "closed",
        "--initial",
        "60",
        "--tol-avg",
        "0.05",
        "--tol-max",
        "0.3",
        "--max-iter",
        "40",
        "--json",
        json.to_str().expect("utf-8"),
    ]);
    assert!(stdout.contains("reconstructed closed surface"), "{stdout}");
    let report = read_json(&json);
    assert_eq!(report["points"], 1_500);
    assert_eq!(report["converged"], true, "{report}");
    assert!(report["e_max_pct"].as_f64().expect("number") <= 0.3);
    assert_eq!(report["within_tolerance_pct"], 100.0);
    let rec = &report["reconstruction"];
    assert_eq!(rec["kind"], "closed");
    let seconds = rec["seconds"].as_f64().expect("seconds");
    assert!(seconds > 0.0 && seconds <= report["precompute_s"].as_f64().expect("number"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn geofit_fit_on_degenerate_clouds_fails_clearly_or_fits_a_sheet() {
    let dir = temp_dir("degenerate");
    let line: Vec<Point3> = (0..20).map(|i| Point3::splat(i as f64)).collect();
    let same = vec![Point3::new(1.0, 2.0, 3.0); 20];
    let cases: [(&str, String, &str); 4] = [
        ("three.xyz", "0 0 0\n1 0 0\n0 1 0\n".into(), "too few"),
        ("line.xyz", xyz_text(&line), "collinear"),
        ("same.xyz", xyz_text(&same), "all at one place"),
        ("nan.xyz", "0 0 0\n1 0 0\n0 1 0\nNaN 1 1\n".into(), "line 4"),
    ];
    for (name, text, expected) in cases {
        let path = dir.join(name);
        std::fs::write(&path, text).expect("write");
        let out = geofit(&["fit", path.to_str().expect("utf-8")]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name} succeeded");
        assert!(
            err.starts_with("geofit: ") && err.contains(expected),
            "{name}: {err}"
        );
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
    // Coplanar points are an open sheet: a sensible (flat) fit, not an error.
    let flat: Vec<Point3> = (0..400)
        .map(|k| Point3::new((k % 20) as f64, (k / 20) as f64, 0.0))
        .collect();
    let path = dir.join("flat.xyz");
    write_xyz(&path, &flat);
    let stdout = geofit_ok(&["fit", path.to_str().expect("utf-8"), "--quiet"]);
    assert!(stdout.contains("converged"), "{stdout}");
    std::fs::remove_dir_all(&dir).ok();
}

fn xyz_text(points: &[Point3]) -> String {
    points
        .iter()
        .map(|p| format!("{} {} {}\n", p.x, p.y, p.z))
        .collect()
}

/// spot's vertices as bare points, and spot's own mesh (the surface they were taken from);
/// `None` (the test skips) without the data directory.
fn spot_points() -> Option<(Vec<Point3>, PolyMesh)> {
    let path = common::data_dir().join("spot.obj");
    let mesh = geofit::io::read_path(&path).ok()?.mesh;
    Some((mesh.positions().to_vec(), mesh))
}

/// Bare points are measured to their own discs, not to the mesh reconstructed from them: the
/// centroids of spot's own triangles (points of the scanned surface, at no data point) lie
/// within 0.4 % of the diagonal of the points' discs (spot's facets are that far from the
/// discs' tangent planes), and up to 1.9 % off the implicit reconstruction of the same points.
#[test]
fn bare_points_are_measured_to_themselves_not_to_their_reconstruction() {
    let Some((points, truth)) = spot_points() else {
        eprintln!("skipped: no spot.obj");
        return;
    };
    let made = geofit::cloud::reconstruct(&points, None, &Default::default()).expect("closed");
    let diagonal = truth.bbox().expect("points").diagonal();
    let centroids: Vec<Point3> = truth
        .triangles()
        .iter()
        .map(|t| t.iter().map(|&i| points[i as usize]).sum::<Point3>() / 3.0)
        .collect();
    let own = DataSurface::of_points(&points, &made.mesh).expect("faces");
    let own = own.measure(&centroids, diagonal);
    let rebuilt = DataSurface::of_mesh(&made.mesh)
        .expect("faces")
        .measure(&centroids, diagonal);
    // The reconstruction is closed but for the few triangles it drops as strays (6 on spot):
    // centroids over those holes are left out of the statistics, and they must be few.
    assert!(
        own.over_holes * 50 <= centroids.len(),
        "{} of {} over holes",
        own.over_holes,
        centroids.len()
    );
    assert!(own.max_pct < 0.5 && own.p99_pct < 0.35, "{own:?}");
    assert!(
        rebuilt.max_pct > 4.0 * own.max_pct,
        "{rebuilt:?} against {own:?}"
    );
}

/// spot's vertices as bare points, fitted with the defaults by every scheme, converge both
/// ways (they stalled at E_back 1.6–2.1 % when E_back was measured to the reconstruction), and
/// the fitted surface lies on spot's own mesh: at most 1.1 % of the diagonal from it at any
/// vertex of its tessellation (2 × the E_max tolerance plus spot's faceting).
#[test]
fn bare_points_of_a_closed_scan_converge_both_ways_onto_the_scanned_surface() {
    let Some((points, truth)) = spot_points() else {
        eprintln!("skipped: no spot.obj");
        return;
    };
    let truth_surface = DataSurface::of_mesh(&truth).expect("faces");
    let diagonal = truth.bbox().expect("points").diagonal();
    let cloud = PolyMesh::from_points(points).expect("finite points");
    for scheme in [Scheme::Loop, Scheme::CatmullClark, Scheme::DooSabin] {
        let spec = FitSpec::defaults(scheme);
        let mut fitter = spec.build(&FitData::points(&cloud)).expect("a fitter");
        let status = fitter.run().expect("runs");
        let back = fitter.back_stats().expect("E_back measured").max_pct;
        let tol = fitter.tolerances().max_pct.expect("an E_max tolerance");
        assert_eq!(status, FitStatus::Converged, "{scheme:?}: E_back {back} %");
        assert!(
            back <= geofit::fit::BACK_TOLERANCE_FACTOR * tol,
            "{scheme:?}: {back}"
        );
        let Shape::Mesh(tess) = fitter.limit_shape(4) else {
            panic!("{scheme:?}: a surface fit has a mesh");
        };
        let worst = tess
            .positions()
            .iter()
            .filter_map(|&p| truth_surface.distance(p))
            .fold(0.0f64, f64::max);
        assert!(100.0 * worst / diagonal <= 1.1, "{scheme:?}: {worst}");
    }
}

/// cheburashka's 6,669 vertices as bare points: sparse (0.8 % of the diagonal apart) and
/// uneven, with thin ears. The implicit surface of such points also has a zero set where no
/// point is; its contour ran up to 9.6 % of the diagonal from cheburashka's own mesh, and a
/// Loop fit from it stalled at E_back 3.0 % with a sheet 3.2 % from the mesh. The stray
/// triangles are dropped (and reported): the reconstruction stays within 3 % of the mesh, and
/// the fit converges both ways.
#[test]
fn sparse_uneven_points_reconstruct_without_stray_sheets_and_fit() {
    let path = common::data_dir().join("corpus/cheburashka.obj");
    let Ok(file) = geofit::io::read_path(&path) else {
        eprintln!("skipped: no corpus/cheburashka.obj");
        return;
    };
    let truth = file.mesh;
    let points = truth.positions().to_vec();
    let truth_surface = DataSurface::of_mesh(&truth).expect("faces");
    let diagonal = truth.bbox().expect("points").diagonal();
    let made = geofit::cloud::reconstruct(&points, None, &Default::default()).expect("closed");
    assert!(made.stray_triangles > 0, "the strays are reported");
    let worst = made
        .mesh
        .positions()
        .iter()
        .filter_map(|&p| truth_surface.distance(p))
        .fold(0.0f64, f64::max);
    assert!(
        100.0 * worst / diagonal <= 3.0,
        "{}",
        100.0 * worst / diagonal
    );

    let cloud = PolyMesh::from_points(points).expect("finite points");
    let mut fitter = FitSpec::defaults(Scheme::Loop)
        .build(&FitData::points(&cloud))
        .expect("a fitter");
    let status = fitter.run().expect("runs");
    let back = fitter.back_stats().expect("E_back measured").max_pct;
    assert_eq!(status, FitStatus::Converged, "E_back {back} %");
    assert!(
        fitter
            .log()
            .intake_notes()
            .iter()
            .any(|n| n.contains("dropped where no point")),
        "{:?}",
        fitter.log().intake_notes()
    );
}

/// A car body's points (the corpus's beetle-alt vertices: roof and bonnet up, sides folding
/// under them, no floor) look like an open scan by their normals, but a triangulation in
/// projection left 18 % of them in no triangle and the fit pulled webs out to them (stalled,
/// E_back 4.0 %). They are meshed as a closed object instead, the report says why, and the
/// fit converges both ways.
#[test]
fn points_that_are_no_height_field_fit_through_the_closed_reconstruction() {
    let path = common::data_dir().join("corpus/beetle-alt.obj");
    let Ok(file) = geofit::io::read_path(&path) else {
        eprintln!("skipped: no corpus/beetle-alt.obj");
        return;
    };
    let cloud = PolyMesh::from_points(file.mesh.positions().to_vec()).expect("finite points");
    let mut fitter = FitSpec::defaults(Scheme::Loop)
        .build(&FitData::points(&cloud))
        .expect("a fitter");
    let status = fitter.run().expect("runs");
    let back = fitter.back_stats().expect("E_back measured").max_pct;
    assert_eq!(status, FitStatus::Converged, "E_back {back} %");
    let notes = fitter.log().intake_notes();
    assert!(
        notes
            .iter()
            .any(|n| n.contains("meshed as a closed surface")),
        "{notes:?}"
    );
}

/// bun000.ply, one range scan of the Stanford bunny, fitted with the defaults through its
/// scanner grid: the grid cuts the near ear and a front foot off the head and body at the depth
/// jumps around them, and a reconstruction that kept only its largest piece left their points
/// in no triangle; the fit pulled webs out from the head to reach them, up to 4.5 % of the
/// diagonal from the bunny's own mesh (which is in the scan's frame). With every piece kept the
/// fitted surface lies within 1.5 % of that mesh wherever the mesh is (measured 0.96 %).
#[test]
fn a_range_scan_cut_into_pieces_by_depth_jumps_fits_without_webs() {
    let dir = common::data_dir();
    let (Ok(scan), Ok(bunny)) = (
        geofit::io::read_path(&dir.join("bun000.ply")),
        geofit::io::read_path(&dir.join("stanford-bunny.obj")),
    ) else {
        eprintln!("skipped: no bun000.ply or stanford-bunny.obj");
        return;
    };
    let truth = DataSurface::of_mesh(&bunny.mesh).expect("faces");
    let diagonal = scan.mesh.bbox().expect("points").diagonal();
    let mut fitter = FitSpec::defaults(Scheme::Loop)
        .build(&FitData::from(&scan))
        .expect("a fitter");
    fitter.run().expect("runs");
    let Shape::Mesh(tess) = fitter.limit_shape(4) else {
        panic!("a surface fit has a mesh");
    };
    let worst = tess
        .positions()
        .iter()
        .filter_map(|&p| truth.distance(p))
        .fold(0.0f64, f64::max);
    println!(
        "bun000 Loop: limit surface to the bunny's mesh {:.3} %",
        100.0 * worst / diagonal
    );
    assert!(
        100.0 * worst / diagonal <= 1.5,
        "{}",
        100.0 * worst / diagonal
    );
}
