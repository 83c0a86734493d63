//! The half-edge control mesh: validation, adjacency, flips, splits, local 1→4 refinement, and
//! element counts after refinement.

mod common;

use common::meshes::{cube, icosahedron, octahedron, tri_grid};
use geofit::geom::Point3;
use geofit::mesh::{ControlMesh, PolyMesh, TopologyError};
use geofit::subdiv::{
    build, refine, refine_levels, PatchDomain, Scheme, SubdivError, SurfaceParam,
};
use proptest::prelude::*;

fn pts(n: usize) -> Vec<Point3> {
    (0..n)
        .map(|i| Point3::new(i as f64, (i * i) as f64 * 0.1, 0.0))
        .collect()
}

#[test]
fn non_manifold_input_is_rejected_with_the_offending_element() {
    // Three triangles on edge (0, 1).
    let m = PolyMesh::try_new(pts(5), [[0, 1, 2], [1, 0, 3], [0, 1, 4]]).unwrap();
    assert!(matches!(
        ControlMesh::try_new(&m),
        Err(TopologyError::NonManifoldEdge { faces: 3, .. })
    ));
    // Two faces with the same orientation on edge (0, 1).
    let m = PolyMesh::try_new(pts(4), [[0, 1, 2], [0, 1, 3]]).unwrap();
    assert!(matches!(
        ControlMesh::try_new(&m),
        Err(TopologyError::InconsistentOrientation { a: 0, b: 1 })
    ));
    // Two fans touching at vertex 0 (a bow tie).
    let m = PolyMesh::try_new(pts(5), [[0, 1, 2], [0, 3, 4]]).unwrap();
    assert!(matches!(
        ControlMesh::try_new(&m),
        Err(TopologyError::NonManifoldVertex { vertex: 0, .. })
    ));
    // A face using a vertex twice.
    let m = PolyMesh::try_new(pts(3), [[0, 1, 1]]).unwrap();
    assert!(matches!(
        ControlMesh::try_new(&m),
        Err(TopologyError::DegenerateFace { face: 0, vertex: 1 })
    ));
    // The errors reach the surface constructors, and schemes check face shapes.
    let bad = PolyMesh::try_new(pts(5), [[0, 1, 2], [0, 3, 4]]).unwrap();
    assert!(matches!(
        build(Scheme::Loop, &bad),
        Err(SubdivError::Topology(_))
    ));
    assert!(matches!(
        build(Scheme::Loop, &cube()),
        Err(SubdivError::WrongFaceSize {
            face: 0,
            len: 4,
            ..
        })
    ));
    assert!(matches!(
        build(Scheme::Loop, &PolyMesh::from_points(pts(3)).unwrap()),
        Err(SubdivError::NoFaces)
    ));
}

#[test]
fn adjacency_valence_and_one_ring() {
    let cm = ControlMesh::try_new(&octahedron()).unwrap();
    for v in 0..6 {
        assert_eq!(cm.valence(v), 4);
        assert!(!cm.is_boundary_vertex(v));
    }
    let mut ring = Vec::new();
    cm.one_ring(4, &mut ring);
    assert_eq!(ring.len(), 4);
    assert_eq!(cm.euler_characteristic(), 2);
    let grid = ControlMesh::try_new(&tri_grid(3, |_, _| 0.0)).unwrap();
    assert!(grid.is_boundary_vertex(0));
    assert_eq!(grid.valence(0), 2); // corner of the grid: edges to (1,0) and (0,1) ... and the diagonal
    ring.clear();
    grid.one_ring(5, &mut ring); // interior vertex (1, 1)
    assert_eq!(ring.len(), 6);
    assert_eq!(grid.euler_characteristic(), 1);
}

#[test]
fn flips_and_splits_keep_a_valid_mesh() {
    let mut cm = ControlMesh::try_new(&tri_grid(3, |_, _| 0.0)).unwrap();
    // Interior diagonal of the first square: (1, 0)–(0, 1) = vertices 1 and 4.
    cm.flip_edge(1, 4).unwrap();
    assert!(cm.find_half_edge(0, 5).is_some() || cm.find_half_edge(5, 0).is_some());
    assert!(matches!(
        cm.flip_edge(0, 1),
        Err(TopologyError::CannotFlip { .. })
    ));
    let faces = cm.num_faces();
    let m = cm.split_edge(5, 6, Point3::new(1.5, 1.0, 0.0)).unwrap();
    assert_eq!(cm.num_faces(), faces + 2);
    assert_eq!(cm.valence(m), 4);
    let b = cm.split_edge(0, 1, Point3::new(0.5, 0.0, 0.0)).unwrap();
    assert!(cm.is_boundary_vertex(b));
    assert_eq!(cm.euler_characteristic(), 1);
    // The result is still a valid control mesh: rebuild it from scratch.
    let rebuilt = ControlMesh::try_new(&cm.to_poly_mesh().unwrap()).unwrap();
    assert_eq!(rebuilt.num_edges(), cm.num_edges());
    assert!(build(Scheme::Loop, &cm.to_poly_mesh().unwrap()).is_ok());
}

#[test]
fn local_refinement_splits_one_to_four_and_keeps_conformity() {
    let mut cm = ControlMesh::try_new(&icosahedron()).unwrap();
    let created = cm.refine_triangles(&[0, 7]).unwrap();
    // Faces 0 and 7 share no edge: 6 new vertices; each refined face gives 4, each of the 6
    // neighbours 2.
    assert_eq!(created.len(), 6);
    assert_eq!(cm.num_faces(), 20 - 2 + 8 - 6 + 12);
    assert_eq!(cm.euler_characteristic(), 2);
    assert!(cm.is_triangle_mesh());
    assert!(matches!(
        cm.refine_triangles(&[999]),
        Err(TopologyError::NoSuchFace { face: 999, .. })
    ));
}

#[test]
fn build_gives_working_surfaces_for_both_schemes() {
    let s = build(Scheme::Loop, &icosahedron()).unwrap();
    assert_eq!(s.domain(), PatchDomain::Triangle);
    assert_eq!(s.num_patches(), 20);
    // A triangle mesh is converted into quads for Catmull–Clark.
    let s = build(Scheme::CatmullClark, &icosahedron()).unwrap();
    assert_eq!(s.domain(), PatchDomain::Square);
    assert_eq!(s.num_patches(), 60);
    let e = s.eval(SurfaceParam {
        patch: 3,
        u: 0.5,
        v: 0.5,
    });
    assert!(e.point.is_finite() && e.du.cross(e.dv).length() > 0.0);
    let s = build(Scheme::DooSabin, &icosahedron()).unwrap();
    assert_eq!(s.num_patches(), 60);
    assert!(s
        .eval(SurfaceParam {
            patch: 7,
            u: 0.3,
            v: 0.6
        })
        .point
        .is_finite());
}

#[test]
fn relocate_walks_across_edges_and_clamps_at_the_boundary() {
    for (scheme, mesh) in [
        (Scheme::Loop, tri_grid(4, |x, y| 0.1 * x * y)),
        (
            Scheme::CatmullClark,
            common::meshes::quad_grid(4, |x, y| 0.1 * x * y),
        ),
    ] {
        let s = build(scheme, &mesh).unwrap();
        // A point just beyond an interior edge lands on a neighbour with the same position.
        let f = if scheme == Scheme::Loop {
            2 * (4 + 1)
        } else {
            4 + 1
        };
        let inside = s.eval(SurfaceParam {
            patch: f,
            u: 0.3,
            v: 0.0,
        });
        let beyond = s.relocate(f, 0.3, -0.2);
        assert_ne!(beyond.patch, f);
        let e = s.eval(beyond);
        assert!((e.point - inside.point).length() < 0.5);
        let a = s.eval(SurfaceParam {
            patch: f,
            u: 0.3,
            v: -1e-9,
        });
        let r = s.relocate(f, 0.3, -1e-9);
        assert!((s.eval(r).point - a.point).length() < 1e-7, "{scheme:?}");
        // Walking far off the grid clamps onto its boundary.
        let out = s.relocate(0, -5.0, -5.0);
        assert!(out.u >= 0.0 && out.v >= 0.0 && out.u <= 1.0 && out.v <= 1.0);
        // Garbage parameters give a valid parameter, never NaN.
        let nan = s.relocate(0, f64::NAN, f64::INFINITY);
        assert!(nan.u.is_finite() && nan.v.is_finite());
        assert!(s
            .eval(SurfaceParam {
                patch: 0,
                u: f64::NAN,
                v: 0.2
            })
            .point
            .is_finite());
    }
}

#[test]
fn corner_weights_are_barycentric_or_bilinear() {
    let s = build(Scheme::Loop, &icosahedron()).unwrap();
    let mut w = Vec::new();
    s.corner_weights(
        SurfaceParam {
            patch: 0,
            u: 0.2,
            v: 0.3,
        },
        &mut w,
    );
    assert_eq!(w, vec![(0, 0.5), (11, 0.2), (5, 0.3)]);
    let s = build(Scheme::CatmullClark, &cube()).unwrap();
    w.clear();
    s.corner_weights(
        SurfaceParam {
            patch: 0,
            u: 0.5,
            v: 0.5,
        },
        &mut w,
    );
    assert!(w.iter().all(|&(_, x)| (x - 0.25).abs() < 1e-15));
}

fn euler(mesh: &ControlMesh) -> i64 {
    mesh.euler_characteristic()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Refinement keeps the Euler characteristic and gives the expected element counts.
    #[test]
    fn refinement_counts(n in 1usize..5, levels in 1usize..3, tri in any::<bool>()) {
        let (scheme, mesh) = if tri {
            (Scheme::Loop, tri_grid(n, |x, y| x * y))
        } else {
            (Scheme::CatmullClark, common::meshes::quad_grid(n, |x, y| x - y))
        };
        let cm = ControlMesh::try_new(&mesh).unwrap();
        let (v0, e0, f0) = (cm.num_vertices(), cm.num_edges(), cm.num_faces());
        let one = refine(scheme, &cm).unwrap();
        prop_assert_eq!(euler(&one), euler(&cm));
        if tri {
            prop_assert_eq!(one.num_vertices(), v0 + e0);
            prop_assert_eq!(one.num_faces(), 4 * f0);
            prop_assert_eq!(one.num_edges(), 2 * e0 + 3 * f0);
        } else {
            prop_assert_eq!(one.num_vertices(), v0 + e0 + f0);
            prop_assert_eq!(one.num_faces(), 4 * f0);
            prop_assert_eq!(one.num_edges(), 2 * e0 + 4 * f0);
        }
        let more = refine_levels(scheme, &cm, levels).unwrap();
        prop_assert_eq!(euler(&more), euler(&cm));
        prop_assert_eq!(more.num_faces(), f0 * 4usize.pow(levels as u32));
    }

    /// Random face lists never panic: they build or give a typed error.
    #[test]
    fn random_faces_never_panic(faces in proptest::collection::vec(proptest::collection::vec(0u32..8, 3..5), 1..12)) {
        if let Ok(mesh) = PolyMesh::try_new(pts(8), &faces) {
            match ControlMesh::try_new(&mesh) {
                Ok(cm) => {
                    let _ = refine(Scheme::CatmullClark, &cm);
                    if let Ok(s) = build(Scheme::CatmullClark, &mesh) {
                        let e = s.eval(SurfaceParam { patch: 0, u: 0.3, v: 0.4 });
                        prop_assert!(e.point.is_finite());
                    }
                }
                Err(e) => prop_assert!(!e.to_string().is_empty()),
            }
        }
    }
}
