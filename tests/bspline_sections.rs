//! Skinning fit (`--method sections`): crease sharpness, the bottle of the paper's form, the
//! bunny's range grid, rows detection and bad inputs.

use geofit::fit::{
    detect_rows, FitData, FitError, FitSpec, FitStatus, Fitter, Method, Scheme, SectionsFitter,
    SectionsOptions, TolMode,
};
use geofit::geom::{Point3, Vec3};
use geofit::mesh::PolyMesh;

#[path = "../examples/sections_bottle/bottle.rs"]
mod bottle;
use bottle::bottle;

/// A roof: z = 0.4·|x − c(y)| over [0, 1]², the crease x = c(y) = 0.45 + 0.1·y crossing every
/// row; 41 rows of 41 points, rows along x. Normals of the two planes differ by
/// 2·atan(0.4) ≈ 43.6°.
fn roof(n: usize) -> Vec<Point3> {
    (0..n)
        .flat_map(|r| {
            (0..n).map(move |c| {
                let (x, y) = (c as f64 / (n - 1) as f64, r as f64 / (n - 1) as f64);
                Point3::new(x, y, 0.4 * (x - 0.45 - 0.1 * y).abs())
            })
        })
        .collect()
}

fn rows_of(n: usize, per: usize) -> Vec<std::ops::Range<usize>> {
    (0..n).map(|r| r * per..(r + 1) * per).collect()
}

/// Unit normal of the surface at (u, v).
fn normal(f: &SectionsFitter, u: f64, v: f64) -> Vec3 {
    let d = f.surface().derivs(u, v, 1);
    d.skl[1][0].cross(d.skl[0][1]).normalize()
}

#[test]
fn roof_crease_stays_sharp_and_tolerance_is_met() {
    let pts = roof(41);
    let mut fit = SectionsFitter::try_new(&pts, rows_of(41, 41), SectionsOptions::DEFAULT).unwrap();
    let status = fit.run().unwrap();
    assert_eq!(status, FitStatus::Converged, "{:?}", fit.stats());
    assert!(fit.stats().e_max_pct <= 0.1);
    let data_angle = 2.0 * 0.4f64.atan();
    // On the middle row (y = 0.5) the crease is at x = 0.5: compare normals 0.02 either side.
    let (u0, u1) = (0.48, 0.52);
    let turn = normal(&fit, u0, 0.5).angle_between(normal(&fit, u1, 0.5));
    assert!(
        turn >= 0.8 * data_angle,
        "normal turns {:.1}° of the data's {:.1}°",
        turn.to_degrees(),
        data_angle.to_degrees()
    );
}

#[test]
fn bottle_meets_threshold_and_keeps_the_shoulder() {
    let pts = bottle();
    let diag = geofit::geom::Aabb::from_points(&pts).unwrap().diagonal();
    let tol_pct = 0.1 / diag * 100.0; // 0.1 mm
                                      // The paper's threshold bounds every point: noise-free sections are judged exactly.
    let opts = SectionsOptions::DEFAULT
        .with_tol_pct(tol_pct)
        .with_tol_mode(TolMode::Exact);
    let mut fit = SectionsFitter::try_new(&pts, rows_of(51, 51), opts).unwrap();
    let first = fit.sigma_features();
    assert_eq!(fit.run().unwrap(), FitStatus::Converged);
    let e_max = fit.stats().e_max_pct / 100.0 * diag;
    assert!(e_max <= 0.1 + 1e-9, "E_max {e_max} mm");
    assert!(
        fit.sigma() < first,
        "σ {} after {} first",
        fit.sigma(),
        first
    );
    // Shoulder crease at z = 60 (u = chord parameter there): the profile turns by 58°.
    let data_angle = (48.0f64 / 30.0).atan();
    let row = &pts[25 * 51..26 * 51];
    let chord: Vec<f64> = std::iter::once(0.0)
        .chain(row.windows(2).scan(0.0, |a, w| {
            *a += (w[1] - w[0]).length();
            Some(*a)
        }))
        .collect();
    let u = |k: usize| chord[k] / chord[50];
    let turn = normal(&fit, u(29), 0.5).angle_between(normal(&fit, u(31), 0.5));
    assert!(turn >= 0.8 * data_angle, "turn {:.1}°", turn.to_degrees());
}

/// The range scan: noisy (depths quantised to 0.095 % of the diagonal, rows staggered by half
/// a pixel), with depth jumps at the ears' and the head's outlines. The fit must not chase the
/// noise (the union of every row's knots gave 383,541 control points for 20,160 points, an
/// interpolating surface 2.1 % away from the data), and it meets the tolerance at nearly
/// every point of the largest rectangle without a jump.
#[test]
fn bunny_range_grid_fits() {
    let file = geofit::io::read_path(std::path::Path::new("../shared/data/bun000.ply")).unwrap();
    let grid = file.range_grid.as_ref().unwrap();
    let positions = file.mesh.positions();
    let (indices, rows) = geofit::fit::grid_rows(grid, positions);
    let spacing = grid.spacing(positions).unwrap();
    for r in rows.windows(2) {
        for (&a, &b) in indices[r[0].clone()].iter().zip(&indices[r[1].clone()]) {
            let step = positions[a as usize].distance(positions[b as usize]);
            assert!(
                step <= geofit::fit::JUMP_FACTOR * spacing,
                "a jump inside the rows"
            );
        }
    }
    let spec = FitSpec::new(Scheme::BsplineSurface).with_method(Some(Method::Sections));
    let mut fit = spec.build(&FitData::from(&file)).unwrap();
    let status = fit.run().unwrap();
    assert_ne!(status, FitStatus::Running);
    let details = fit.details();
    assert_eq!(details["rows"].as_u64().unwrap() as usize, rows.len());
    let points = fit.point_errors().len();
    assert_eq!(points, indices.len());
    assert!(fit.num_control_points() < points / 2, "{details:?}");
    let tol = 0.1 / 100.0 * fit.state().diagonal();
    let within = fit.point_errors().iter().filter(|e| e.abs() <= tol).count();
    assert!(
        within as f64 >= 0.95 * points as f64,
        "{within} of {points}"
    );
    let back = fit.state().back().unwrap().max_pct;
    assert!(back < 1.0, "E_back {back} %");
    assert!(details["sigma_pct"].as_f64().unwrap() < 0.1, "{details:?}");
}

#[test]
fn rows_from_jumps_and_from_count_through_the_spec() {
    let pts = roof(21);
    assert_eq!(detect_rows(&pts, None), rows_of(21, 21));
    let mesh = PolyMesh::from_points(pts).unwrap();
    for rows in [None, Some(21)] {
        let mut spec = FitSpec::new(Scheme::BsplineSurface).with_method(Some(Method::Sections));
        spec.rows = rows;
        spec.tol_mode = TolMode::Exact;
        let mut fit = spec.build(&FitData::points(&mesh)).unwrap();
        // The skinned surface holds the points within the tolerance (E_max 0.053 % of
        // 0.1 %), but its status is the surface → data gate's: bare points are measured
        // against their own discs, which tilt across the roof's crease, so the surface
        // measures beyond the bound there and stalls. The rows are what this test is about.
        let status = fit.run().unwrap();
        assert_ne!(status, FitStatus::Running);
        assert!(fit.stats().e_max_pct <= 0.1, "{:?}", fit.stats());
        assert_eq!(fit.details()["rows"], 21);
    }
}

#[test]
fn bad_inputs_are_typed_errors() {
    let o = SectionsOptions::DEFAULT;
    let pts = roof(21);
    let few = SectionsFitter::try_new(&pts[..21 * 5], rows_of(5, 21), o).err();
    assert!(
        matches!(few, Some(FitError::TooFewRows { found: 5, .. })),
        "{few:?}"
    );
    let mut ragged = rows_of(21, 21);
    ragged[3] = 63..83;
    ragged[4] = 83..105;
    let err = SectionsFitter::try_new(&pts, ragged, o).err();
    assert!(
        matches!(err, Some(FitError::RaggedRows { row: 3, .. })),
        "{err:?}"
    );
    let mut nan = pts.clone();
    nan[30].y = f64::NAN;
    let err = SectionsFitter::try_new(&nan, rows_of(21, 21), o).err();
    assert!(
        matches!(err, Some(FitError::NonFinitePoint { .. })),
        "{err:?}"
    );
    let one: Vec<Point3> = (0..20).map(|i| Point3::new(0.0, i as f64, 0.0)).collect();
    let err = SectionsFitter::try_new(&one, rows_of(20, 1), o).err();
    assert!(
        matches!(err, Some(FitError::TooFewPoints { found: 1, .. })),
        "{err:?}"
    );
    let bad = o.with_tol_pct(-1.0);
    assert!(SectionsFitter::try_new(&pts, rows_of(21, 21), bad).is_err());
    let spec = FitSpec::new(Scheme::BsplineSurface)
        .with_method(Some(Method::Sections))
        .with_initial(Some(64));
    assert!(matches!(
        spec.validate(),
        Err(FitError::NotApplicable {
            name: "initial",
            ..
        })
    ));
    assert!(Scheme::BsplineSurface.methods().contains(&Method::Sections));
}

#[test]
fn cli_fits_an_xyz_in_rows_and_exports_step() {
    let dir = std::env::temp_dir().join(format!("geofit-sections-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let xyz = dir.join("bottle.xyz");
    let text: String = bottle()
        .iter()
        .map(|p| format!("{} {} {}\n", p.x, p.y, p.z))
        .collect();
    std::fs::write(&xyz, text).unwrap();
    for rows in [None, Some("51")] {
        let json = dir.join("r.json");
        let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_geofit"));
        cmd.arg("fit").arg(&xyz).args([
            "--scheme",
            "bspline",
            "--method",
            "sections",
            "--tol-max",
            "0.08",
            "--json",
        ]);
        cmd.arg(&json).arg("--step").arg(dir.join("b.stp"));
        if let Some(n) = rows {
            cmd.args(["--rows", n]);
        }
        let out = cmd.output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let r: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        assert_eq!(r["converged"], true, "{r}");
        assert_eq!(r["rows"], 51, "{r}");
        assert!(std::fs::read_to_string(dir.join("b.stp"))
            .unwrap()
            .contains("B_SPLINE_SURFACE"));
    }
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_geofit"))
        .arg("fit")
        .arg(&xyz)
        .args([
            "--scheme", "bspline", "--method", "sections", "--rows", "50",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("row"));
}
