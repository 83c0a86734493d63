//! Point clouds to meshes: open range scans (grid and Delaunay), closed objects (implicit
//! surface), and degenerate inputs.

mod common;

use common::manifold::{assert_manifold, boundary_loops, euler_characteristic};
use geofit::cloud::{reconstruct, ReconstructError, ReconstructOptions, SurfaceKind};
use geofit::geom::Point3;
use geofit::mesh::simplify::deviation;
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
        assert!(used as f64 > 0.9 * points.len() as f64, "{name}: {used}");
        let coarse = simplify(&r.mesh, 400).unwrap();
        assert_manifold(&coarse);
    }
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
