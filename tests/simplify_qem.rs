//! QEM simplification: exact counts, manifold output, unchanged topology, no fold-overs, kept
//! boundaries, determinism, accuracy on the bunny, and typed errors for bad input.

mod common;

use common::manifold::{assert_manifold, boundary_edges, boundary_loops, euler_characteristic};
use geofit::geom::{Point3, Vec3};
use geofit::mesh::deviation;
use geofit::mesh::{
    simplify, simplify_with, simplify_with_report, ControlMesh, PolyMesh, SimplifyError,
    SimplifyOptions,
};
use std::collections::BTreeMap;

/// A mesh from the shared scans.
fn load(name: &str) -> PolyMesh {
    geofit::io::read_path(&common::data_file(name))
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .mesh
}

/// An n×n grid of a wavy unit square whose outline is flat (one boundary loop, χ = 1).
fn wavy_grid(n: u32) -> PolyMesh {
    let pos = (0..n * n)
        .map(|k| {
            let (x, y) = (
                (k % n) as f64 / (n - 1) as f64,
                (k / n) as f64 / (n - 1) as f64,
            );
            let bump = (std::f64::consts::PI * x).sin() * (std::f64::consts::PI * y).sin();
            Point3::new(x, y, 0.3 * bump * (3.0 * x).cos())
        })
        .collect();
    let mut faces = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i;
            faces.push([a, a + 1, a + n + 1]);
            faces.push([a, a + n + 1, a + n]);
        }
    }
    PolyMesh::try_new(pos, faces).unwrap()
}

/// A torus as an n×m quad grid wrapped both ways (closed, χ = 0), faces as quads.
fn torus(n: u32, m: u32) -> PolyMesh {
    let mut pos = Vec::new();
    for j in 0..m {
        for i in 0..n {
            let (u, v) = (
                i as f64 / n as f64 * std::f64::consts::TAU,
                j as f64 / m as f64 * std::f64::consts::TAU,
            );
            let r = 1.0 + 0.35 * v.cos();
            pos.push(Point3::new(r * u.cos(), r * u.sin(), 0.35 * v.sin()));
        }
    }
    let id = |i: u32, j: u32| (j % m) * n + (i % n);
    let mut faces = Vec::new();
    for j in 0..m {
        for i in 0..n {
            faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh::try_new(pos, faces).unwrap()
}

/// Asserts that no face of `coarse` points against the original surface it covers: the
/// area-weighted normal of the original faces (every `stride`-th) whose centroids lie closest
/// to it. A folded face points backwards (−1); faces bridging a groove or cutting a sharp
/// corner may lie sideways (near 0), so the bound is −0.5.
fn assert_no_foldover(original: &PolyMesh, coarse: &PolyMesh, stride: usize) {
    let cp = coarse.positions();
    let coarse_tris: Vec<[Point3; 3]> = coarse
        .triangles()
        .iter()
        .map(|t| t.map(|i| cp[i as usize]))
        .collect();
    let singles: Vec<PolyMesh> = coarse_tris
        .iter()
        .map(|t| PolyMesh::try_new(t.to_vec(), [[0u32, 1, 2]]).unwrap())
        .collect();
    // Bounding spheres (centroid, radius) give a lower bound that prunes most triangles.
    let spheres: Vec<(Point3, f64)> = coarse_tris
        .iter()
        .map(|t| {
            let c = (t[0] + t[1] + t[2]) / 3.0;
            (c, t.iter().map(|p| p.distance(c)).fold(0.0, f64::max))
        })
        .collect();
    let mut covered = vec![Vec3::ZERO; coarse_tris.len()];
    let op = original.positions();
    for t in original.triangles().into_iter().step_by(stride) {
        let [a, b, c] = t.map(|i| op[i as usize]);
        let centroid = (a + b + c) / 3.0;
        let mut order: Vec<(f64, usize)> = spheres
            .iter()
            .enumerate()
            .map(|(k, (s, r))| (s.distance(centroid) - r, k))
            .collect();
        order.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut best = (f64::INFINITY, 0);
        for (bound, k) in order {
            if bound > best.0 {
                break;
            }
            let d = deviation(&[centroid], &singles[k]).unwrap().max;
            if d < best.0 {
                best = (d, k);
            }
        }
        covered[best.1] += (b - a).cross(c - a);
    }
    for (k, t) in coarse_tris.iter().enumerate() {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
        let dot = n.dot(covered[k].normalize_or_zero());
        assert!(
            dot > -0.5,
            "face {k} is folded over: {dot} against the surface it covers"
        );
    }
}

/// Distance from `p` to the segment a–b.
fn segment_distance(p: Point3, a: Point3, b: Point3) -> f64 {
    let d = b - a;
    let t = ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    p.distance(a + d * t)
}

/// Largest distance from an original boundary vertex to the simplified boundary.
fn boundary_drift(original: &PolyMesh, coarse: &PolyMesh) -> f64 {
    let segs: Vec<(Point3, Point3)> = boundary_edges(coarse)
        .into_iter()
        .map(|(a, b)| {
            (
                coarse.positions()[a as usize],
                coarse.positions()[b as usize],
            )
        })
        .collect();
    boundary_edges(original)
        .into_iter()
        .map(|(a, _)| {
            let p = original.positions()[a as usize];
            segs.iter()
                .map(|&(s, t)| segment_distance(p, s, t))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

#[test]
fn grid_keeps_its_disc_topology_and_boundary() {
    let grid = wavy_grid(30);
    for target in [300, 60, 12] {
        let coarse = simplify(&grid, target).unwrap();
        assert_eq!(coarse.num_vertices(), target);
        assert_manifold(&coarse);
        assert_eq!(euler_characteristic(&coarse), 1);
        assert_eq!(boundary_loops(&coarse), 1);
        assert_no_foldover(&grid, &coarse, 1);
    }
    // The outline (a flat unit square) survives: its corners and sides stay in place, to
    // rounding with stiff boundary planes, and within a fraction of a percent by default.
    let coarse = simplify(&grid, 60).unwrap();
    let drift = boundary_drift(&grid, &coarse);
    assert!(drift < 0.005, "{drift}");
    let stiff = SimplifyOptions::default().with_boundary_weight(1000.0);
    let coarse = simplify_with(&grid, 60, &stiff).unwrap();
    let drift = boundary_drift(&grid, &coarse);
    assert!(drift < 0.002, "{drift}");
}

#[test]
fn closed_torus_stays_a_closed_torus() {
    let torus = torus(40, 16);
    let coarse = simplify(&torus, 100).unwrap();
    assert_eq!(coarse.num_vertices(), 100);
    assert_manifold(&coarse);
    assert_eq!(euler_characteristic(&coarse), 0);
    assert_eq!(boundary_loops(&coarse), 0);
    assert_no_foldover(&torus, &coarse, 1);
    let dev = deviation(torus.positions(), &coarse).unwrap();
    assert!(dev.max < 0.05, "{dev:?}");
}

#[test]
fn output_is_deterministic() {
    let torus = torus(30, 12);
    let a = simplify(&torus, 50).unwrap();
    let b = simplify(&torus, 50).unwrap();
    assert_eq!(a, b);
}

#[test]
fn bunny_to_612_is_manifold_accurate_and_keeps_its_five_holes() {
    let bunny = load("stanford-bunny.obj");
    let coarse = simplify(&bunny, 612).unwrap();
    assert_eq!(coarse.num_vertices(), 612);
    assert_manifold(&coarse);
    ControlMesh::try_new(&coarse).expect("a valid control mesh for the fitter");
    assert_eq!(euler_characteristic(&coarse), euler_characteristic(&bunny));
    assert_eq!(boundary_loops(&coarse), boundary_loops(&bunny));
    assert_eq!(boundary_loops(&bunny), 5);
    assert_no_foldover(&bunny, &coarse, 5);
    let diag = bunny.bbox().unwrap().diagonal();
    // MeshLab's QEM gives max 0.76 %, rms 0.157 % of the diagonal (SPEC §5); the queue-based
    // simplifier this one replaced gave max 0.752 %, rms 0.143 % (issue 15 asks for no worse).
    let dev = deviation(bunny.positions(), &coarse)
        .unwrap()
        .percent_of(diag);
    println!("bunny -> 612: {dev:?}");
    assert!(dev.max <= 0.752 && dev.rms <= 0.143, "{dev:?}");
    let drift = boundary_drift(&bunny, &coarse) / diag * 100.0;
    println!("bunny -> 612: hole outlines within {drift:.3} % of the diagonal");
    // The scanned hole outlines are jagged; a few coarse vertices follow them within ~1 %.
    assert!(drift < 1.0, "{drift}");
}

#[test]
fn bad_input_gives_typed_errors() {
    let grid = wavy_grid(5);
    assert_eq!(
        simplify(&PolyMesh::default(), 4),
        Err(SimplifyError::NoFaces)
    );
    let cloud = PolyMesh::from_points(grid.positions().to_vec()).unwrap();
    assert_eq!(simplify(&cloud, 4), Err(SimplifyError::NoFaces));
    // Faces that repair must drop leave nothing to simplify.
    let flat = PolyMesh::try_new(vec![Point3::ZERO, Point3::X, Point3::X * 2.0], [[0, 1, 2]]);
    assert_eq!(simplify(&flat.unwrap(), 3), Err(SimplifyError::NoFaces));
    let bad = SimplifyOptions::default().with_max_normal_change_deg(f64::NAN);
    assert!(matches!(
        simplify_with(&grid, 10, &bad),
        Err(SimplifyError::InvalidOption {
            name: "max_normal_change_deg",
            ..
        })
    ));
    let bad = SimplifyOptions::default().with_boundary_weight(-1.0);
    assert!(matches!(
        simplify_with(&grid, 10, &bad),
        Err(SimplifyError::InvalidOption {
            name: "boundary_weight",
            ..
        })
    ));
    let bad = SimplifyOptions::default().with_max_valence(3);
    assert!(matches!(
        simplify_with(&grid, 10, &bad),
        Err(SimplifyError::InvalidOption {
            name: "max_valence",
            ..
        })
    ));
}

#[test]
fn targets_out_of_reach_give_the_floor_or_everything() {
    // A disc goes down to one triangle; a target above the vertex count keeps them all.
    let grid = wavy_grid(5);
    let low = simplify_with_report(&grid, 0, &SimplifyOptions::default()).unwrap();
    assert_eq!(low.mesh.num_vertices(), 3);
    let note = low.report.floor_note.expect("a note");
    assert!(note.contains("stopped at 3 vertices"), "{note}");
    assert!(
        note.contains("1 components, Euler characteristic 1, 1 boundary loops"),
        "{note}"
    );
    let high = simplify_with_report(&grid, 26, &SimplifyOptions::default()).unwrap();
    assert_eq!(high.mesh.num_vertices(), 25);
    assert_eq!(high.report.floor_note, None);
    let tri = PolyMesh::try_new(vec![Point3::ZERO, Point3::X, Point3::Y], [[0, 1, 2]]).unwrap();
    assert_eq!(simplify(&tri, 4).unwrap().num_vertices(), 3);
}

#[test]
fn minimal_components_stop_at_their_floor() {
    // Two separate tetrahedra: neither can lose a vertex and stay a closed surface.
    let mut pos = Vec::new();
    let mut faces = Vec::new();
    for k in 0..2 {
        let o = Point3::new(3.0 * k as f64, 0.0, 0.0);
        let b = 4 * k;
        pos.extend([o, o + Vec3::X, o + Vec3::Y, o + Vec3::Z]);
        faces.extend([
            [b, b + 2, b + 1],
            [b, b + 1, b + 3],
            [b, b + 3, b + 2],
            [b + 1, b + 2, b + 3],
        ]);
    }
    let two = PolyMesh::try_new(pos, faces).unwrap();
    let out = simplify_with_report(&two, 4, &SimplifyOptions::default()).unwrap();
    assert_eq!(out.mesh.num_triangles(), 8);
    assert_eq!(out.report.vertices, 8);
    let note = out.report.floor_note.unwrap();
    assert!(
        note.contains("2 components, Euler characteristic 4, 0 boundary loops"),
        "{note}"
    );
}

#[test]
fn unreferenced_vertices_duplicate_and_degenerate_faces_are_dropped() {
    let grid = wavy_grid(6);
    let mut pos = grid.positions().to_vec();
    pos.push(Point3::new(5.0, 5.0, 5.0)); // in no face
    let mut faces: Vec<Vec<u32>> = grid.faces().map(|f| f.to_vec()).collect();
    faces.push(faces[0].clone()); // duplicate
    faces.push(vec![0, 0, 1]); // degenerate
    let messy = PolyMesh::try_new(pos, faces).unwrap();
    let coarse = simplify(&messy, 20).unwrap();
    assert_eq!(coarse.num_vertices(), 20);
    assert_manifold(&coarse);
    let by_pos: BTreeMap<[u64; 3], ()> = coarse
        .positions()
        .iter()
        .map(|p| (p.to_array().map(f64::to_bits), ()))
        .collect();
    assert!(!by_pos.contains_key(&[5.0f64, 5.0, 5.0].map(f64::to_bits)));
}
