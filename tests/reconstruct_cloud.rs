//! Point clouds to meshes: open range scans (grid and Delaunay), closed objects (implicit
//! surface), and degenerate inputs.

mod common;

use common::manifold::{assert_manifold, boundary_loops, euler_characteristic};
use geofit::cloud::{reconstruct, ReconstructError, ReconstructOptions, SurfaceKind};
use geofit::geom::Point3;
use geofit::mesh::deviation;
use geofit::mesh::{simplify, ControlMesh};
use std::time::Instant;

fn load(name: &str) -> geofit::io::LoadedFile {
    geofit::io::read_path(&common::data_file(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn range_scan_by_grid_and_by_delaunay() {
    let scan = load("bun000.ply");
    let points = scan.mesh.positions();
    let diag = scan.mesh.bbox().unwrap().diagonal();
    let grid = scan.range_grid.as_ref().expect("bun000 has a range grid");
    let start = Instant::now();
    let by_grid = reconstruct(points, Some(grid), &ReconstructOptions::default()).unwrap();
    let t_grid = start.elapsed();
    let start = Instant::now();
    let by_plane = reconstruct(points, None, &ReconstructOptions::default()).unwrap();
    let t_plane = start.elapsed();
    for (name, r, t) in [("grid", &by_grid, t_grid), ("delaunay", &by_plane, t_plane)] {
        assert_eq!(r.kind, SurfaceKind::Open, "{name}");
        assert_manifold(&r.mesh);
        ControlMesh::try_new(&r.mesh).expect("usable by the fitter");
        let used = r
            .mesh
            .triangles()
            .iter()
            .flatten()
            .collect::<std::collections::BTreeSet<_>>()
            .len();
        let dev = deviation(points, &r.mesh).unwrap().percent_of(diag);
        println!(
            "bun000 by {name}: {} triangles over {used} of {} points, {} boundary loops, {t:?}, points to mesh {dev:?}",
            r.mesh.num_triangles(),
            points.len(),
            boundary_loops(&r.mesh)
        );
        // Every piece of the scan stays (by the grid, the near ear and a front foot are cut
        // off by depth jumps; only 174 grazing samples are left out), so the fit has no data
        // to pull webs out to.
        let share = if name == "grid" { 0.99 } else { 0.9 };
        assert!(used as f64 > share * points.len() as f64, "{name}: {used}");
        let coarse = simplify(&r.mesh, 400).unwrap();
        assert_manifold(&coarse);
    }
}

/// Points that look like an open scan (their normals face one side of their plane) but are
/// no height field over it lose their folds to the triangulation in projection; they are
/// meshed as a closed object instead, and the report says why: the corpus's car body
/// (beetle-alt's vertices), whose sides fold under its roof. A range scan's points without
/// their grid leave a few grazing points out in projection and stay an open scan, as does a
/// height field.
#[test]
fn points_that_are_no_height_field_are_meshed_as_a_closed_object() {
    let Ok(car) = geofit::io::read_path(&common::data_dir().join("corpus/beetle-alt.obj")) else {
        eprintln!("skipped: no corpus/beetle-alt.obj");
        return;
    };
    let points = car.mesh.positions();
    let auto = reconstruct(points, None, &ReconstructOptions::default()).unwrap();
    assert_eq!(auto.kind, SurfaceKind::Closed);
    let left = auto.open_uncovered.expect("the reason is reported");
    println!(
        "beetle-alt: {left} of {} points in no triangle in projection",
        points.len()
    );
    assert!(
        left * geofit::cloud::MAX_UNCOVERED_SHARE > points.len(),
        "{left}"
    );
    assert_manifold(&auto.mesh);
    ControlMesh::try_new(&auto.mesh).expect("usable by the fitter");
    // Forced open, it stays open.
    let open = ReconstructOptions::default().with_kind(Some(SurfaceKind::Open));
    let forced = reconstruct(points, None, &open).unwrap();
    assert_eq!(
        (forced.kind, forced.open_uncovered),
        (SurfaceKind::Open, None)
    );

    let scan = load("bun000.ply");
    let without_grid = reconstruct(scan.mesh.positions(), None, &Default::default()).unwrap();
    assert_eq!(
        (without_grid.kind, without_grid.open_uncovered),
        (SurfaceKind::Open, None)
    );
    let bowl: Vec<Point3> = (0..900)
        .map(|k| {
            let (x, y) = ((k % 30) as f64, (k / 30) as f64);
            Point3::new(x, y, 0.01 * ((x - 14.5).powi(2) + (y - 14.5).powi(2)))
        })
        .collect();
    let r = reconstruct(&bowl, None, &ReconstructOptions::default()).unwrap();
    assert_eq!((r.kind, r.open_uncovered), (SurfaceKind::Open, None));
}

#[test]
fn bunny_vertices_as_bare_points_give_a_closed_manifold() {
    let bunny = load("stanford-bunny.obj").mesh;
    let points = bunny.positions();
    let diag = bunny.bbox().unwrap().diagonal();
    let start = Instant::now();
    let r = reconstruct(points, None, &ReconstructOptions::default()).unwrap();
    let t = start.elapsed();
    assert_eq!(r.kind, SurfaceKind::Closed);
    assert_manifold(&r.mesh);
    ControlMesh::try_new(&r.mesh).expect("usable by the fitter");
    let dev = deviation(points, &r.mesh).unwrap().percent_of(diag);
    println!(
        "bunny points: {} vertices, {} triangles, chi {}, {} boundary loops, {t:?}, points to mesh {dev:?}",
        r.mesh.num_vertices(),
        r.mesh.num_triangles(),
        euler_characteristic(&r.mesh),
        boundary_loops(&r.mesh)
    );
    assert!(dev.rms < 0.2, "{dev:?}");
    let coarse = simplify(&r.mesh, 612).unwrap();
    assert_manifold(&coarse);
}

#[test]
fn degenerate_inputs_give_clear_errors() {
    let o = ReconstructOptions::default();
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    assert!(matches!(
        reconstruct(
            &[p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(0.0, 1.0, 0.0)],
            None,
            &o
        ),
        Err(ReconstructError::TooFewPoints { count: 3, min: 4 })
    ));
    let line: Vec<Point3> = (0..50).map(|i| p(i as f64, 2.0 * i as f64, 0.0)).collect();
    assert!(matches!(
        reconstruct(&line, None, &o),
        Err(ReconstructError::Degenerate { what: "collinear" })
    ));
    // Off the axes, the rounding of the eigenvalues must not pass for a width.
    let diagonal: Vec<Point3> = (0..20).map(|i| Point3::splat(i as f64)).collect();
    assert!(matches!(
        reconstruct(&diagonal, None, &o),
        Err(ReconstructError::Degenerate { what: "collinear" })
    ));
    let same = vec![p(1.0, 2.0, 3.0); 10];
    assert!(matches!(
        reconstruct(&same, None, &o),
        Err(ReconstructError::Degenerate { .. })
    ));
    let mut nan = line.clone();
    nan[7].y = f64::NAN;
    assert!(matches!(
        reconstruct(&nan, None, &o),
        Err(ReconstructError::NonFinitePoint { index: 7 })
    ));
}

#[test]
fn coplanar_and_duplicated_points_make_an_open_sheet() {
    let mut points: Vec<Point3> = (0..30 * 30)
        .map(|k| Point3::new((k % 30) as f64, (k / 30) as f64, 0.0))
        .collect();
    points.extend_from_within(0..100); // duplicates
    let r = reconstruct(&points, None, &ReconstructOptions::default()).unwrap();
    assert_eq!(r.kind, SurfaceKind::Open);
    assert_manifold(&r.mesh);
    assert_eq!(euler_characteristic(&r.mesh), 1);
}

#[test]
fn outlier_removal_drops_stray_points() {
    let mut points: Vec<Point3> = (0..25 * 25)
        .map(|k| {
            let (x, y) = ((k % 25) as f64, (k / 25) as f64);
            Point3::new(
                x,
                y,
                0.05 * ((x - 12.0).powi(2) + (y - 12.0).powi(2)) / 12.0,
            )
        })
        .collect();
    points.extend([Point3::new(5.0, 5.0, 40.0), Point3::new(-30.0, 8.0, 3.0)]);
    let options = ReconstructOptions::default().with_outlier_std_ratio(Some(3.0));
    let r = reconstruct(&points, None, &options).unwrap();
    assert_eq!(r.outliers, 2);
    assert_eq!(r.kind, SurfaceKind::Open);
    let used: std::collections::BTreeSet<u32> = r.mesh.triangles().into_iter().flatten().collect();
    assert!(!used.contains(&625) && !used.contains(&626));
    assert_manifold(&r.mesh);
}

mod never_panics {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Random small clouds (duplicates, flat and collinear ones included) give a mesh or a
        /// typed error, never a panic, for either kind.
        #[test]
        fn on_random_clouds(
            coords in prop::collection::vec((-4i32..4, -4i32..4, -1i32..2), 0..60),
            closed in any::<bool>(),
        ) {
            let points: Vec<Point3> = coords
                .iter()
                .map(|&(x, y, z)| Point3::new(x as f64, y as f64, z as f64 * 0.5))
                .collect();
            let kind = if closed { SurfaceKind::Closed } else { SurfaceKind::Open };
            let options = ReconstructOptions::default().with_kind(Some(kind));
            if let Ok(r) = reconstruct(&points, None, &options) {
                assert_manifold(&r.mesh);
                prop_assert!(r.mesh.positions().iter().all(|p| p.is_finite()));
            }
        }
    }
}
