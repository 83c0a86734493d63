//! Stray points and extreme coordinates (issue 15, item 5): a point far from the rest is left
//! out before the bounding-box diagonal is taken, so the fit is the fit of the rest; a
//! coordinate beyond the f32 range is a typed error naming the point; and no statistic of a
//! fit is NaN or infinite at extreme scales and offsets.

use geofit::fit::{FitData, FitReport, FitSpec, Scheme};
use geofit::geom::Point3;
use geofit::io::{read_bytes, read_path};
use geofit::mesh::PolyMesh;
use std::path::Path;

/// The page's bundled bunny sample (2,007 points, 3,986 triangles).
fn bunny() -> PolyMesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("www/samples/bunny.obj");
    read_path(&path).expect("the sample reads").mesh
}

/// Fits `mesh` with `scheme` at the page sample's tolerances (0.1 % / 0.5 %), at most 40 iterations.
fn fit(mesh: &PolyMesh, scheme: Scheme) -> FitReport {
    // The B-spline surface fit has one tolerance (the maximum); the others take both.
    let tol_avg = (scheme != Scheme::BsplineSurface).then_some(0.1);
    let spec = FitSpec::new(scheme)
        .with_tol_avg(tol_avg)
        .with_tol_max(Some(0.5))
        .with_max_iter(Some(40));
    let mut fit = spec.build(&FitData::points(mesh)).expect("the fit starts");
    fit.run().expect("the fit runs");
    FitReport::of(fit.as_ref())
}

/// `points` with `stray` inserted first.
fn with_stray_first(points: &[Point3], stray: Point3) -> PolyMesh {
    let mut p = vec![stray];
    p.extend_from_slice(points);
    PolyMesh::from_points(p).expect("in range")
}

#[test]
fn a_stray_point_is_left_out_and_the_fit_is_the_fit_of_the_rest() {
    let points = bunny().positions().to_vec();
    let clean = PolyMesh::from_points(points.clone()).unwrap();
    for scheme in [Scheme::Loop, Scheme::BsplineSurface] {
        let reference = fit(&clean, scheme);
        assert!(reference.strays.is_none());
        for stray in [
            Point3::new(50.0, 0.0, 0.0),
            Point3::new(0.0, -f32::MAX as f64, 0.0),
            Point3::splat(1e30),
        ] {
            let report = fit(&with_stray_first(&points, stray), scheme);
            let strays = report.strays.as_ref().expect("the stray is found");
            assert_eq!(strays.indices, vec![0], "{scheme:?} {stray}");
            assert!(report.intake[0].starts_with("left out 1 stray point"));
            assert_eq!(report.points, reference.points);
            assert_eq!(report.status, reference.status, "{scheme:?} {stray}");
            assert_eq!(report.e_max_pct, reference.e_max_pct, "{scheme:?} {stray}");
            assert_eq!(report.final_control_points, reference.final_control_points);
        }
    }
}

#[test]
fn a_stray_vertex_of_a_mesh_is_left_out_with_its_faces() {
    let mesh = bunny();
    let mut pos = mesh.positions().to_vec();
    pos[0].x = 1e30;
    let faces: Vec<&[u32]> = mesh.faces().collect();
    let spiked = PolyMesh::try_new(pos, faces).unwrap();
    let report = fit(&spiked, Scheme::Loop);
    assert_eq!(
        report.strays.as_ref().map(|s| s.indices.clone()),
        Some(vec![0])
    );
    assert_eq!(report.points, 2006);
    assert!(report.converged, "{:?}", report.status);
    assert!(report.e_max_pct <= 0.5);
}

#[test]
fn a_coordinate_beyond_the_f32_range_is_an_error_naming_the_point() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("www/samples/bunny.obj"),
    )
    .unwrap();
    let at = text.find("\nv ").unwrap() + 3;
    let end = at + text[at..].find(' ').unwrap();
    let huge = format!("{}-1e308{}", &text[..at], &text[end..]);
    let err = read_bytes(huge.as_bytes(), Some("bunny.obj")).unwrap_err();
    assert!(
        err.to_string().contains("vertex 0 has coordinate -1e308"),
        "{err}"
    );
    let xyz = b"0 0 0\n1 0 0\n0 1 3.5e38\n";
    let err = read_bytes(xyz, Some("p.xyz")).unwrap_err();
    assert!(
        err.to_string().contains("vertex 2 has coordinate 3.5e38"),
        "{err}"
    );
}

/// Every figure of `report` that is a statistic, by name.
fn statistics(report: &FitReport) -> Vec<(String, f64)> {
    let mut out = vec![
        ("e_avg_pct".to_string(), report.e_avg_pct),
        ("e_max_pct".to_string(), report.e_max_pct),
        ("e_rms_pct".to_string(), report.e_rms_pct),
        (
            "within_tolerance_pct".to_string(),
            report.within_tolerance_pct.unwrap_or(0.0),
        ),
    ];
    for r in &report.history {
        let i = r.iter;
        out.push((format!("history[{i}].e_avg_pct"), r.e_avg_pct));
        out.push((format!("history[{i}].e_max_pct"), r.e_max_pct));
        out.push((format!("history[{i}].e_rms_pct"), r.e_rms_pct));
        out.push((
            format!("history[{i}].e_back_max_pct"),
            r.e_back_max_pct.unwrap_or(0.0),
        ));
        out.push((
            format!("history[{i}].e_back_p99_pct"),
            r.e_back_p99_pct.unwrap_or(0.0),
        ));
    }
    out
}

#[test]
fn no_statistic_is_nan_or_infinite_at_extreme_scales_and_offsets() {
    let mesh = bunny();
    let faces: Vec<&[u32]> = mesh.faces().collect();
    // Tiny and huge units, and survey coordinates far from the origin (LAS files in UTM).
    let placements = [
        (1e-30, Point3::ZERO),
        (1e30, Point3::ZERO),
        (1.0, Point3::new(5e5, 4e6, 1e3)),
    ];
    for (scale, offset) in placements {
        let pos = mesh
            .positions()
            .iter()
            .map(|&p| p * scale + offset)
            .collect();
        let moved = PolyMesh::try_new(pos, faces.clone()).unwrap();
        for scheme in [
            Scheme::Loop,
            Scheme::CatmullClark,
            Scheme::DooSabin,
            Scheme::BsplineSurface,
        ] {
            let report = fit(&moved, scheme);
            assert!(!report.history.is_empty() || report.converged);
            for (name, value) in statistics(&report) {
                assert!(
                    value.is_finite(),
                    "{scheme:?} at scale {scale:e}, offset {offset}: {name} = {value}"
                );
            }
            assert!(
                report.e_max_pct < 5.0,
                "{scheme:?} at scale {scale:e}: E_max {}",
                report.e_max_pct
            );
        }
    }
}
