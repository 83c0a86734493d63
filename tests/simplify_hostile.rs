//! Hostile inputs for QEM (issue 15): a single triangle, a vertex of valence 100, one huge
//! face among many slivers, several components and inconsistent orientation — each simplifies
//! to a manifold without error, and the valence cap keeps collapses from building fans.

mod common;

use common::manifold::assert_manifold;
use common::{sphere_mesh, Rng};
use geofit::geom::Point3;
use geofit::mesh::{simplify_with_report, PolyMesh, SimplifyOptions};

fn run(mesh: &PolyMesh, target: usize) -> geofit::mesh::Simplified {
    let out = simplify_with_report(mesh, target, &SimplifyOptions::default()).unwrap();
    assert_manifold(&out.mesh);
    out
}

#[test]
fn a_single_triangle_is_its_own_floor() {
    let tri = PolyMesh::try_new(vec![Point3::ZERO, Point3::X, Point3::Y], [[0, 1, 2]]).unwrap();
    let out = run(&tri, 1);
    assert_eq!(out.mesh.num_faces(), 1);
    assert!(out
        .report
        .floor_note
        .unwrap()
        .contains("stopped at 3 vertices"));
}

/// A wavy disc: a hub of valence `n` fanned to a rim, then three rings of a regular grid.
fn fan_disc(n: u32) -> PolyMesh {
    let mut pos = vec![Point3::ZERO];
    for r in 1..=4 {
        for k in 0..n {
            let t = k as f64 / n as f64 * std::f64::consts::TAU;
            let rr = r as f64;
            pos.push(Point3::new(
                rr * t.cos(),
                rr * t.sin(),
                0.2 * (3.0 * t).sin() * rr,
            ));
        }
    }
    let id = |r: u32, k: u32| 1 + (r - 1) * n + k % n;
    let mut faces: Vec<[u32; 3]> = (0..n).map(|k| [0, id(1, k), id(1, k + 1)]).collect();
    for r in 1..4 {
        for k in 0..n {
            faces.push([id(r, k), id(r + 1, k), id(r + 1, k + 1)]);
            faces.push([id(r, k), id(r + 1, k + 1), id(r, k + 1)]);
        }
    }
    PolyMesh::try_new(pos, faces).unwrap()
}

#[test]
fn collapses_never_build_a_vertex_above_the_valence_cap() {
    let disc = fan_disc(100);
    for target in [300, 120, 60, 20] {
        let out = run(&disc, target);
        assert_eq!(out.mesh.num_vertices(), target);
        // The hub starts at 100; only collapses that lower it or keep it may touch it, and
        // no other vertex may pass the cap of 16.
        let mut valence = vec![std::collections::BTreeSet::new(); out.mesh.num_vertices()];
        for t in out.mesh.triangles() {
            for k in 0..3 {
                valence[t[k] as usize].insert(t[(k + 1) % 3]);
                valence[t[k] as usize].insert(t[(k + 2) % 3]);
            }
        }
        let mut v: Vec<usize> = valence.iter().map(|s| s.len()).collect();
        v.sort_unstable();
        let second = v[v.len() - 2];
        assert!(
            second <= 16,
            "target {target}: valences {:?}",
            &v[v.len() - 3..]
        );
        assert!(v[v.len() - 1] <= 100);
        assert_eq!(out.report.max_valence, v[v.len() - 1]);
    }
}

#[test]
fn one_huge_face_among_slivers_and_flipped_pieces_simplify() {
    // A sphere with a fifth of its faces flipped, a second sphere far away, and a fan of
    // 200 slivers closed by one huge triangle.
    let sphere = sphere_mesh(3);
    let n = sphere.num_vertices() as u32;
    let mut rng = Rng(3);
    let mut pos: Vec<Point3> = sphere.positions().to_vec();
    pos.extend(sphere.positions().iter().map(|p| *p + Point3::X * 5.0));
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for shift in [0, n] {
        for f in sphere.faces() {
            let mut f: Vec<u32> = f.iter().map(|v| v + shift).collect();
            if rng.next_f64() < 0.2 {
                f.reverse();
            }
            faces.push(f);
        }
    }
    let hub = pos.len() as u32;
    pos.push(Point3::new(0.0, 0.0, 10.0));
    for k in 0..=200 {
        let t = k as f64 / 200.0 * 1e-3;
        pos.push(Point3::new(t.cos(), t.sin(), 10.0 * 1e3) * 1e-3);
    }
    faces.extend((1..=200).map(|k| vec![hub, hub + k, hub + k + 1]));
    pos.push(Point3::new(0.0, 0.0, 1e3));
    faces.push(vec![hub, hub + 201, hub + 202]);
    let mesh = PolyMesh::try_new(pos, &faces).unwrap();
    let out = run(&mesh, 60);
    assert_eq!(out.mesh.num_vertices(), 60);
    assert!(out.report.repair.flipped_faces.count > 0);
    assert_eq!(out.report.repair.components.count, 3);
}
