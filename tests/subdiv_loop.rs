//! Loop subdivision: refinement rules and exact limit evaluation (regular, extraordinary,
//! boundary), checked against each other and against closed forms.

mod common;

use common::meshes::{icosahedron, jitter, octahedron, tri_grid};
use common::surface_checks::{
    assert_c1_across_edges, assert_corners_are_limit_points,
    assert_derivatives_match_finite_differences, assert_edge_curve_is_cubic_bspline,
    assert_same_limit_point, close, refinement_invariance_tests,
};
use geofit::geom::Point3;
use geofit::mesh::{ControlMesh, PolyMesh};
use geofit::subdiv::{refine, refine_levels, LimitSurface, LoopSurface, Scheme, SurfaceParam};

fn loop_surface(mesh: &PolyMesh) -> LoopSurface {
    LoopSurface::try_new(mesh).expect("valid control mesh")
}

fn refined(mesh: &PolyMesh) -> LoopSurface {
    let cm = ControlMesh::try_new(mesh).unwrap();
    LoopSurface::from_control_mesh(refine(Scheme::Loop, &cm).unwrap()).unwrap()
}

/// Parent parameters of child `c` of a triangle (the order refinement makes them in).
fn to_parent(c: usize, u: f64, v: f64) -> (f64, f64, f64) {
    match c {
        0 => (u / 2.0, v / 2.0, 0.5),
        1 => (0.5 + u / 2.0, v / 2.0, 0.5),
        2 => (u / 2.0, 0.5 + v / 2.0, 0.5),
        _ => (0.5 - u / 2.0, 0.5 - v / 2.0, -0.5),
    }
}

fn samples() -> Vec<(f64, f64)> {
    let mut out = vec![
        (0.0, 0.0),
        (1.0, 0.0),
        (0.0, 1.0),
        (0.5, 0.5),
        (1e-7, 2e-7),
        (0.3, 0.0),
        (0.0, 0.7),
    ];
    for i in 0..6 {
        for j in 0..6 - i {
            out.push((i as f64 / 6.0 + 0.013, j as f64 / 6.0 + 0.007));
        }
    }
    out.retain(|&(u, v)| u + v <= 1.0);
    out
}

/// The surface of the once-refined mesh is the same surface: exact evaluation must agree
/// everywhere, including at extraordinary vertices and boundaries.
fn check_refinement_invariance(mesh: &PolyMesh) {
    let s0 = loop_surface(mesh);
    let s1 = refined(mesh);
    assert_eq!(s1.num_patches(), 4 * s0.num_patches());
    for f in 0..s0.num_patches() as u32 {
        for c in 0..4 {
            for &(u, v) in &samples() {
                let (pu, pv, scale) = to_parent(c, u, v);
                let (a, b) = assert_same_limit_point(
                    &s0,
                    (f, pu, pv),
                    &s1,
                    (4 * f + c as u32, u, v),
                    format_args!("patch {f} child {c} ({u},{v})"),
                );
                // Near extraordinary vertices derivatives of the two parameterisations differ
                // only by the chain rule.
                // Derivatives at an extraordinary vertex depend on the parameterisation's
                // degeneracy there; compare them inside the sub-patch.
                if u > 0.0 && v > 0.0 && u + v < 1.0 {
                    assert!(
                        close(a.du * scale, b.du, 1e-8),
                        "du patch {f} child {c} ({u},{v}): {:?} vs {:?}",
                        a.du * scale,
                        b.du
                    );
                    assert!(
                        close(a.dv * scale, b.dv, 1e-8),
                        "dv patch {f} child {c} ({u},{v})"
                    );
                    assert!(
                        close(a.duu * 0.25, b.duu, 1e-7),
                        "duu patch {f} child {c} ({u},{v})"
                    );
                }
            }
        }
    }
}

refinement_invariance_tests! {
    refined_icosahedron_has_the_same_limit_surface: jitter(&icosahedron(), 0.2, 1);
    refined_octahedron_has_the_same_limit_surface: jitter(&octahedron(), 0.2, 2);
    refined_open_grid_has_the_same_limit_surface:
        jitter(&tri_grid(4, |x, y| (x * 0.7).sin() + 0.3 * y * y), 0.1, 3);
}

#[test]
fn limit_at_control_vertices_equals_limit_masks() {
    for mesh in [
        jitter(&icosahedron(), 0.2, 4),
        jitter(&tri_grid(4, |x, y| x * y * 0.1), 0.1, 5),
    ] {
        let s = loop_surface(&mesh);
        assert_corners_are_limit_points(&s, &mesh, &[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]);
    }
}

/// Regular patches are quartic box splines (with reflected phantom points at a straight
/// boundary): compare the closed form with the limit-mask positions of the twice-refined mesh
/// at the matching dyadic parameters. Interior vertices of the refined mesh use the interior
/// limit mask, so this checks the phantom construction off the boundary too.
#[test]
fn regular_and_boundary_patches_match_refined_limit_points() {
    let mesh = jitter(
        &tri_grid(6, |x, y| 0.2 * (x - 3.0).powi(2) - 0.1 * x * y),
        0.05,
        6,
    );
    let s0 = loop_surface(&mesh);
    let cm = ControlMesh::try_new(&mesh).unwrap();
    let twice =
        LoopSurface::from_control_mesh(refine_levels(Scheme::Loop, &cm, 2).unwrap()).unwrap();
    let limits = twice.limit_positions();
    // Face 2 * (6 * 2 + 2) is an interior patch; face 4 has a boundary edge.
    for f in [2 * (6 * 2 + 2), 4] {
        for c in 0..4u32 {
            for g in 0..4u32 {
                let grandchild = 16 * f + 4 * c + g;
                let corners = twice
                    .control_mesh()
                    .face_vertices(grandchild)
                    .collect::<Vec<_>>();
                for (k, &(u, v)) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)].iter().enumerate() {
                    let (cu, cv, _) = to_parent(g as usize, u, v);
                    let (pu, pv, _) = to_parent(c as usize, cu, cv);
                    let a = s0.eval(SurfaceParam {
                        patch: f,
                        u: pu,
                        v: pv,
                    });
                    let b = limits[corners[k] as usize];
                    assert!(
                        close(a.point, b, 1e-12),
                        "face {f} ({pu},{pv}): {:?} vs {b:?}",
                        a.point
                    );
                }
            }
        }
    }
}

/// A crease tagged along a grid line is the cubic B-spline curve of its vertices, and the
/// surface stays exact (refinement keeps the limit) on both sides.
#[test]
fn crease_limit_curve_is_the_cubic_bspline_of_the_crease() {
    let n = 6;
    let mesh = jitter(
        &tri_grid(n, |x, y| 0.3 * (x * 0.9).sin() + 0.2 * y),
        0.05,
        11,
    );
    let mut cm = ControlMesh::try_new(&mesh).unwrap();
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for i in 0..n {
        cm.set_sharp(id(i, 3), id(i + 1, 3), true).unwrap();
    }
    let s = LoopSurface::from_control_mesh(cm.clone()).unwrap();
    let crease: Vec<Point3> = (0..=n)
        .map(|i| mesh.positions()[id(i, 3) as usize])
        .collect();
    // Face 2 (3 n + i) has edge 0 from (i, 3) to (i + 1, 3).
    assert_edge_curve_is_cubic_bspline(&s, &crease, 4, |i| (2 * (3 * n + i)) as u32, 1e-10);
    let s1 = LoopSurface::from_control_mesh(refine(Scheme::Loop, &cm).unwrap()).unwrap();
    for f in 0..s.num_patches() as u32 {
        for c in 0..4 {
            let (pu, pv, _) = to_parent(c, 0.3, 0.2);
            assert_same_limit_point(
                &s,
                (f, pu, pv),
                &s1,
                (4 * f + c as u32, 0.3, 0.2),
                format_args!("face {f} child {c}"),
            );
        }
    }
}

/// Vertices of the k-times refined mesh approach their limit positions like 4^-k (the control
/// net of a smooth subdivision surface converges quadratically).
#[test]
fn refined_vertices_approach_the_limit_at_the_expected_rate() {
    let mesh = jitter(&icosahedron(), 0.2, 12);
    let mut cm = ControlMesh::try_new(&mesh).unwrap();
    let mut errors = Vec::new();
    for _ in 0..5 {
        cm = refine(Scheme::Loop, &cm).unwrap();
        let s = LoopSurface::from_control_mesh(cm.clone()).unwrap();
        let lim = s.limit_positions();
        let worst = cm
            .positions()
            .iter()
            .zip(&lim)
            .map(|(p, q)| (*p - *q).length())
            .fold(0.0, f64::max);
        errors.push(worst);
    }
    for w in errors.windows(2) {
        let ratio = w[0] / w[1];
        assert!(ratio > 3.0 && ratio < 5.0, "ratio {ratio} in {errors:?}");
    }
}

/// Positions and tangent planes agree across every shared edge (C1) to 1e-9.
#[test]
fn limit_surface_is_c1_across_patch_edges() {
    for mesh in [
        jitter(&icosahedron(), 0.2, 7),
        jitter(&tri_grid(4, |x, y| (x + y).sin()), 0.1, 8),
    ] {
        assert_c1_across_edges(&loop_surface(&mesh), 10);
    }
}

#[test]
fn open_boundary_limit_curve_is_the_cubic_bspline_of_the_boundary() {
    let n = 6;
    let mesh = tri_grid(n, |x, y| 0.1 * x * x - 0.05 * y);
    let s = loop_surface(&mesh);
    // Bottom row faces 2 * i have edge 0 from vertex i to i + 1 on the boundary.
    assert_edge_curve_is_cubic_bspline(&s, &mesh.positions()[..=n], 8, |i| 2 * i as u32, 1e-9);
}

#[test]
fn derivatives_match_finite_differences() {
    let mesh = jitter(&icosahedron(), 0.2, 9);
    let s = loop_surface(&mesh);
    assert_derivatives_match_finite_differences(
        &s,
        0..mesh.num_faces() as u32,
        &[(0.2, 0.3), (0.05, 0.1), (0.6, 0.2), (0.3, 0.6)],
        |e, d| close(d.du_u, e.duu, 1e-5) && close(d.du_v, e.duv, 1e-5),
    );
}

#[test]
fn stencil_reproduces_eval() {
    let mesh = jitter(&tri_grid(4, |x, y| (x * y).cos()), 0.1, 10);
    let s = loop_surface(&mesh);
    let mut st = Vec::new();
    for f in 0..mesh.num_faces() as u32 {
        for &(u, v) in &[(0.0, 0.0), (0.2, 0.3), (0.5, 0.0), (1e-9, 0.0)] {
            st.clear();
            s.stencil(SurfaceParam { patch: f, u, v }, &mut st);
            let p: Point3 = st
                .iter()
                .map(|&(i, w)| mesh.positions()[i as usize] * w)
                .sum();
            let sum: f64 = st.iter().map(|&(_, w)| w).sum();
            assert!((sum - 1.0).abs() < 1e-12);
            assert!(
                close(p, s.eval(SurfaceParam { patch: f, u, v }).point, 1e-12),
                "face {f} ({u},{v})"
            );
        }
    }
}
