//! Repair on intake (issue 15): hostile meshes — non-manifold vertices and edges, duplicate and
//! zero-area faces, several components, inconsistent orientation, a single triangle, one huge
//! and many tiny faces, a vertex of valence 100 — come out as oriented manifolds that the
//! control-mesh validation accepts, with a report that counts what was done; every mesh of the
//! shared data and corpus does too.

mod common;

use common::manifold::{assert_manifold, boundary_loops, euler_characteristic};
use common::{sphere_mesh, Rng};
use geofit::geom::Point3;
use geofit::mesh::{repair, repair_with, ControlMesh, PolyMesh, RepairOptions, Repaired};
use proptest::prelude::*;

/// Repairs `mesh` and checks what every repair must give: a valid control mesh, the input's
/// vertices first and unmoved, copies that sit on the vertex they came from.
fn repaired(mesh: &PolyMesh) -> Repaired {
    let out = repair(mesh).expect("repair");
    if let Err(e) = ControlMesh::try_new(&out.mesh) {
        panic!("not a control mesh ({e}); {}", out.report.summary);
    }
    let n = mesh.num_vertices();
    assert_eq!(out.vertex_origin.len(), out.mesh.num_vertices());
    assert_eq!(&out.mesh.positions()[..n], mesh.positions());
    for (v, &o) in out.vertex_origin.iter().enumerate() {
        assert!(v < n && o as usize == v || v >= n && (o as usize) < n);
        assert_eq!(out.mesh.positions()[v], mesh.positions()[o as usize]);
    }
    assert_eq!(
        out.report.vertices_added,
        out.mesh.num_vertices() - n,
        "{}",
        out.report.summary
    );
    out
}

fn mesh(pos: Vec<Point3>, faces: &[[u32; 3]]) -> PolyMesh {
    PolyMesh::try_new(pos, faces).unwrap()
}

/// A closed square pyramid with its apex at `apex` pointing along `dir` (±1 in z).
fn pyramid(pos: &mut Vec<Point3>, faces: &mut Vec<[u32; 3]>, apex: u32, dir: f64) {
    let b = pos.len() as u32;
    for k in 0..4 {
        let a = k as f64 * std::f64::consts::FRAC_PI_2;
        pos.push(Point3::new(a.cos(), a.sin(), -dir));
    }
    for k in 0..4 {
        let (p, q) = (b + k, b + (k + 1) % 4);
        faces.push(if dir > 0.0 {
            [apex, p, q]
        } else {
            [apex, q, p]
        });
    }
    faces.push(if dir > 0.0 {
        [b, b + 2, b + 1]
    } else {
        [b, b + 1, b + 2]
    });
    faces.push(if dir > 0.0 {
        [b, b + 3, b + 2]
    } else {
        [b, b + 2, b + 3]
    });
}

#[test]
fn two_cones_touching_at_their_tips_are_split_there() {
    let mut pos = vec![Point3::ZERO];
    let mut faces = Vec::new();
    pyramid(&mut pos, &mut faces, 0, 1.0);
    pyramid(&mut pos, &mut faces, 0, -1.0);
    let out = repaired(&mesh(pos, &faces));
    let r = &out.report;
    assert_eq!(r.non_manifold_vertices.first, vec![0]);
    assert_eq!(r.vertices_added, 1);
    assert_eq!(r.components.count, 2);
    assert_eq!(r.flipped_faces.count, 0);
    assert_eq!(r.summary, "repaired: 1 non-manifold vertices split");
    assert_manifold(&out.mesh);
    assert_eq!(euler_characteristic(&out.mesh), 4);
}

#[test]
fn a_book_of_three_pages_keeps_two_and_detaches_the_third() {
    // Three triangles on edge 0–1, each a page fanning out; the third page's other corners
    // belong to it alone, so detaching it leaves it a piece of its own.
    let pos = vec![
        Point3::ZERO,
        Point3::Z,
        Point3::X,
        Point3::Y,
        Point3::new(-1.0, -1.0, 0.0),
    ];
    let out = repaired(&mesh(pos, &[[0, 1, 2], [1, 0, 3], [0, 1, 4]]));
    let r = &out.report;
    assert_eq!(r.non_manifold_edges.first, vec![[0, 1]]);
    assert_eq!(r.detached_faces.first, vec![2]);
    assert_eq!(r.vertices_added, 2);
    // The detached page is a component of one face: left to the data only by default.
    assert_eq!(r.components.count, 2);
    assert_eq!(r.components.data_only.first, vec![2]);
    assert_eq!(out.mesh.num_faces(), 2);
}

#[test]
fn a_crowded_edge_whose_pages_meet_again_loses_the_extra_page() {
    // Around edge 0–1 three faces; the third is glued to the first through a fourth face at
    // vertex 0 and at vertex 1, so detaching it at the edge does not separate it.
    let pos = vec![
        Point3::ZERO,
        Point3::X,
        Point3::new(0.5, 1.0, 0.0),
        Point3::new(0.5, -1.0, 0.0),
        Point3::new(0.5, 0.0, 1.0),
    ];
    let faces = [[0, 1, 2], [1, 0, 3], [0, 1, 4], [0, 4, 2], [1, 2, 4]];
    let out = repaired(&mesh(pos, &faces));
    let r = &out.report;
    assert_eq!(r.non_manifold_edges.count, 1);
    assert!(r.dropped_faces.count + r.detached_faces.count >= 1, "{r:?}");
    assert_manifold(&out.mesh);
}

#[test]
fn duplicate_and_degenerate_faces_are_dropped() {
    let sphere = sphere_mesh(2);
    let mut pos = sphere.positions().to_vec();
    let mut faces: Vec<Vec<u32>> = sphere.faces().map(|f| f.to_vec()).collect();
    let n = faces.len();
    faces.push(faces[3].iter().rev().copied().collect()); // the same face, reversed
    faces.push(vec![faces[7][1], faces[7][2], faces[7][0]]); // the same face, rotated
    faces.push(vec![0, 0, 5]); // a repeated index
    faces.push(vec![1, 2, 1, 3]); // pinched
                                  // A zero-area face on three new collinear points.
    pos.extend([Point3::ZERO, Point3::X * 0.1, Point3::X * 0.2]);
    let k = pos.len() as u32 - 3;
    faces.push(vec![k, k + 1, k + 2]);
    let soup = PolyMesh::try_new(pos, &faces).unwrap();
    let out = repaired(&soup);
    let r = &out.report;
    assert_eq!(r.duplicate_faces.first, vec![n, n + 1]);
    assert_eq!(r.degenerate_faces.first, vec![n + 2, n + 3]);
    assert_eq!(r.zero_area_faces.first, vec![n + 4]);
    assert_eq!(r.unreferenced_vertices.count, 3);
    assert_eq!(out.mesh.num_faces(), n);
    assert_eq!(euler_characteristic(&out.mesh), 2);
    assert!(r.summary.starts_with(
        "repaired: 2 degenerate faces dropped, 1 zero-area faces dropped, 2 duplicate faces dropped"
    ));
}

#[test]
fn randomly_flipped_faces_are_turned_back() {
    let sphere = sphere_mesh(3);
    let mut rng = Rng(7);
    let mut flipped = Vec::new();
    let faces: Vec<Vec<u32>> = sphere
        .faces()
        .enumerate()
        .map(|(f, face)| {
            let mut face = face.to_vec();
            if rng.next_f64() < 0.2 {
                face.reverse();
                flipped.push(f);
            }
            face
        })
        .collect();
    let soup = PolyMesh::try_new(sphere.positions().to_vec(), &faces).unwrap();
    assert!(ControlMesh::try_new(&soup).is_err());
    let out = repaired(&soup);
    assert_eq!(out.report.flipped_faces.count, flipped.len());
    assert_eq!(out.report.flipped_faces.first, flipped[..5]);
    // The majority (outward) orientation is kept: the result is the sphere itself.
    let tris = |m: &PolyMesh| {
        let mut t: Vec<[u32; 3]> = m.triangles();
        for x in &mut t {
            let k = (0..3).min_by_key(|&k| x[k]).unwrap();
            x.rotate_left(k);
        }
        t.sort_unstable();
        t
    };
    assert_eq!(tris(&out.mesh), tris(&sphere));
}

#[test]
fn a_moebius_strip_is_cut_open_and_reported() {
    // A strip of 12 quads, split into triangles, whose ends are glued with a half twist.
    let n = 12u32;
    let mut pos = Vec::new();
    for k in 0..n {
        let t = k as f64 / n as f64 * std::f64::consts::TAU;
        let (c, s) = ((t / 2.0).cos(), (t / 2.0).sin());
        for w in [-0.3, 0.3] {
            let r = 1.0 + w * c;
            pos.push(Point3::new(r * t.cos(), r * t.sin(), w * s));
        }
    }
    let mut faces = Vec::new();
    for k in 0..n {
        let (a, b) = (2 * k, 2 * k + 1);
        let (c, d) = if k + 1 < n {
            (2 * k + 2, 2 * k + 3)
        } else {
            (1, 0) // the twist
        };
        faces.push([a, c, d]);
        faces.push([a, d, b]);
    }
    let out = repaired(&mesh(pos, &faces));
    let r = &out.report;
    assert_eq!(r.non_orientable_components, 1);
    assert!(r.cut_edges.count >= 1);
    assert_manifold(&out.mesh);
    assert!(r
        .summary
        .contains("edges cut to orient non-orientable parts"));
}

#[test]
fn tiny_components_are_left_to_the_data_only() {
    let sphere = sphere_mesh(2);
    let mut pos = sphere.positions().to_vec();
    let mut faces: Vec<[u32; 3]> = sphere.triangles();
    for k in 0..3 {
        let b = pos.len() as u32;
        let o = Point3::new(5.0 + k as f64, 0.0, 0.0);
        pos.extend([o, o + Point3::X * 0.1, o + Point3::Y * 0.1]);
        faces.push([b, b + 1, b + 2]);
    }
    let soup = mesh(pos, &faces);
    let out = repaired(&soup);
    let c = &out.report.components;
    assert_eq!((c.count, c.data_only.count, c.data_only_faces), (4, 3, 3));
    assert_eq!(c.largest_faces, vec![sphere.num_faces(), 1, 1, 1]);
    assert_eq!(out.report.unreferenced_vertices.count, 9);
    assert_eq!(out.mesh.num_faces(), sphere.num_faces());
    let keep = repair_with(&soup, &RepairOptions::default().with_data_only_faces(0)).unwrap();
    assert_eq!(keep.mesh.num_faces(), faces.len());
}

#[test]
fn a_single_triangle_stays() {
    let out = repaired(&mesh(
        vec![Point3::ZERO, Point3::X, Point3::Y],
        &[[0, 1, 2]],
    ));
    assert_eq!(out.mesh.num_faces(), 1);
    assert_eq!(out.report.summary, "nothing to repair");
    assert!(!out.report.changed());
}

#[test]
fn one_huge_face_among_many_tiny_ones_is_kept() {
    // A fan of 200 slivers around vertex 0, closed by one huge triangle over their rim.
    let mut pos = vec![Point3::ZERO];
    for k in 0..=200 {
        let t = k as f64 / 200.0 * 1e-3;
        pos.push(Point3::new(t.cos(), t.sin(), 0.0) * 1e-3);
    }
    let mut faces: Vec<[u32; 3]> = (1..=200).map(|k| [0, k, k + 1]).collect();
    pos.push(Point3::new(0.0, 0.0, 1e3));
    faces.push([0, 201, 202]);
    let out = repaired(&mesh(pos, &faces));
    assert_eq!(out.mesh.num_faces(), faces.len());
}

#[test]
fn a_vertex_of_valence_100_is_kept() {
    let mut pos = vec![Point3::ZERO];
    for k in 0..100 {
        let t = k as f64 / 100.0 * std::f64::consts::TAU;
        pos.push(Point3::new(t.cos(), t.sin(), 0.1 * (3.0 * t).sin()));
    }
    let faces: Vec<[u32; 3]> = (0..100).map(|k| [0, 1 + k, 1 + (k + 1) % 100]).collect();
    let out = repaired(&mesh(pos, &faces));
    assert_eq!(out.report.summary, "nothing to repair");
    assert_eq!(boundary_loops(&out.mesh), 1);
}

#[test]
fn quads_and_ngons_are_kept() {
    // A cube of quads with one face split into a pentagon and a triangle.
    let pos: Vec<Point3> = (0..8)
        .map(|k| Point3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2) as f64))
        .chain([Point3::new(0.5, 0.0, 0.0)])
        .collect();
    let faces: Vec<Vec<u32>> = vec![
        vec![0, 2, 3, 1, 8],
        vec![0, 8, 4],
        vec![8, 1, 5, 4],
        vec![4, 5, 7, 6],
        vec![0, 4, 6, 2],
        vec![1, 3, 7, 5],
        vec![2, 6, 7, 3],
    ];
    let soup = PolyMesh::try_new(pos, &faces).unwrap();
    let out = repaired(&soup);
    assert_eq!(out.report.polygons, 6);
    assert_eq!(out.report.summary, "nothing to repair");
    assert_eq!(out.mesh, soup);
}

#[test]
fn every_shared_mesh_comes_out_valid() {
    let Some(files) = common::shared_meshes() else {
        return;
    };
    for path in files {
        let mesh = geofit::io::read_path(&path).unwrap().mesh;
        let out = repaired(&mesh);
        println!(
            "{}: {} faces -> {}; {}; components {:?}",
            path.file_name().unwrap().to_string_lossy(),
            mesh.num_faces(),
            out.mesh.num_faces(),
            out.report.summary,
            out.report.components
        );
    }
}

/// Any polygon soup over up to 10 points: repeated, flipped, crowded and pinched faces.
fn soup() -> impl Strategy<Value = PolyMesh> {
    (3usize..10).prop_flat_map(|n| {
        (
            prop::collection::vec(
                (-4i32..4, -4i32..4, -4i32..4)
                    .prop_map(|(x, y, z)| Point3::new(x as f64, y as f64, z as f64)),
                n,
            ),
            prop::collection::vec(prop::collection::vec(0u32..n as u32, 3..5), 1..40),
        )
            .prop_map(|(pos, faces)| PolyMesh::try_new(pos, faces).expect("indices in range"))
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn any_soup_repairs_to_a_control_mesh(mesh in soup()) {
        let out = repaired(&mesh);
        let again = repair(&out.mesh).unwrap();
        prop_assert!(!again.report.changed(), "{}", again.report.summary);
    }

    #[test]
    fn a_sphere_with_holes_and_flips_keeps_its_topology(seed in any::<u64>()) {
        // Drop and flip faces at random; the repaired mesh keeps every face left.
        let sphere = sphere_mesh(2);
        let mut rng = Rng(seed);
        let mut faces: Vec<Vec<u32>> = Vec::new();
        for f in sphere.faces() {
            if rng.next_f64() > 0.1 {
                let mut f = f.to_vec();
                if rng.next_f64() < 0.3 {
                    f.reverse();
                }
                faces.push(f);
            }
        }
        let soup = PolyMesh::try_new(sphere.positions().to_vec(), &faces).unwrap();
        let out = repair_with(&soup, &RepairOptions::default().with_data_only_faces(0)).unwrap();
        ControlMesh::try_new(&out.mesh).unwrap();
        prop_assert_eq!(out.mesh.num_faces(), faces.len());
        // Holes can pinch a vertex between two fans: each copy adds one to V − E + F.
        prop_assert_eq!(
            euler_characteristic(&out.mesh),
            euler_characteristic(&soup) + out.report.vertices_added as i64
        );
    }
}
