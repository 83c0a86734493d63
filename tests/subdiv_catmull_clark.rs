//! Catmull–Clark: exact limit evaluation (bicubic patches, phantom points at boundaries,
//! local subdivision at extraordinary vertices), checked against refinement and closed forms.

mod common;

use common::meshes::{cube, jitter, quad_grid};
use common::surface_checks::{
    assert_c1_across_edges, assert_corners_are_limit_points,
    assert_derivatives_match_finite_differences, assert_edge_curve_is_cubic_bspline,
    assert_same_limit_point, bspline, close, normal, refinement_invariance_tests,
};
use geofit::geom::Point3;
use geofit::mesh::{ControlMesh, PolyMesh};
use geofit::subdiv::{
    quadrangulate, refine, CatmullClarkSurface, LimitSurface, Scheme, SurfaceParam,
};

fn surface(mesh: &PolyMesh) -> CatmullClarkSurface {
    let cm = ControlMesh::try_new(mesh).unwrap();
    let cm = if cm.is_quad_mesh() {
        cm
    } else {
        quadrangulate(&cm).unwrap()
    };
    CatmullClarkSurface::from_control_mesh(cm).unwrap()
}

/// Parent parameters of child `c` of a quad (children start at corner c; see `refine`).
fn to_parent(c: usize, u: f64, v: f64) -> (f64, f64) {
    match c {
        0 => (u / 2.0, v / 2.0),
        1 => (1.0 - v / 2.0, u / 2.0),
        2 => (1.0 - u / 2.0, 1.0 - v / 2.0),
        _ => (v / 2.0, 1.0 - u / 2.0),
    }
}

fn spot_quads() -> PolyMesh {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/subdiv/spot_quads.obj");
    geofit::io::read_path(&path).unwrap().mesh
}

fn check_refinement_invariance(mesh: &PolyMesh) {
    let s0 = surface(mesh);
    let s1 = CatmullClarkSurface::from_control_mesh(
        refine(Scheme::CatmullClark, s0.control_mesh()).unwrap(),
    )
    .unwrap();
    assert_eq!(s1.num_patches(), 4 * s0.num_patches());
    let samples = [
        (0.0, 0.0),
        (1.0, 0.0),
        (0.5, 0.5),
        (0.25, 0.75),
        (1e-8, 3e-8),
        (0.9, 0.1),
        (0.0, 0.6),
    ];
    for f in 0..s0.num_patches() as u32 {
        for c in 0..4 {
            for &(u, v) in &samples {
                let (pu, pv) = to_parent(c, u, v);
                let (a, b) = assert_same_limit_point(
                    &s0,
                    (f, pu, pv),
                    &s1,
                    (4 * f + c as u32, u, v),
                    format_args!("patch {f} child {c} ({u},{v})"),
                );
                if u > 0.0 && v > 0.0 {
                    assert!(
                        (normal(&a) - normal(&b)).length() < 1e-8,
                        "normal patch {f} child {c} ({u},{v})"
                    );
                }
            }
        }
    }
}

refinement_invariance_tests! {
    refined_cube_has_the_same_limit_surface: jitter(&cube(), 0.1, 1);
    refined_open_grid_has_the_same_limit_surface:
        jitter(&quad_grid(4, |x, y| 0.3 * (x * 0.8).sin() * y), 0.1, 2);
    refined_quad_dominant_spot_has_the_same_limit_surface: spot_quads();
}

#[test]
fn limit_at_control_vertices_equals_limit_masks() {
    for mesh in [
        jitter(&cube(), 0.1, 3),
        jitter(&quad_grid(3, |x, y| x * y * 0.1), 0.1, 4),
    ] {
        let s = surface(&mesh);
        assert_corners_are_limit_points(
            &s,
            &mesh,
            &[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)],
        );
    }
}

/// Interior patches of a quad grid are uniform bicubic B-spline patches.
#[test]
fn regular_patch_is_the_bicubic_bspline() {
    let n = 5;
    let mesh = jitter(&quad_grid(n, |x, y| 0.2 * x * x - 0.1 * x * y), 0.1, 5);
    let s = surface(&mesh);
    let p = |i: usize, j: usize| mesh.positions()[j * (n + 1) + i];
    let (i0, j0) = (2, 2);
    for &(u, v) in &[(0.0, 0.0), (0.3, 0.7), (1.0, 0.5), (0.5, 0.5)] {
        let (bu, bv) = (bspline(u), bspline(v));
        let mut q = Point3::ZERO;
        for (b, wv) in bv.iter().enumerate() {
            for (a, wu) in bu.iter().enumerate() {
                q += p(i0 + a - 1, j0 + b - 1) * (wu * wv);
            }
        }
        let e = s.eval(SurfaceParam {
            patch: (j0 * n + i0) as u32,
            u,
            v,
        });
        assert!(close(e.point, q, 1e-13), "({u},{v})");
    }
}

#[test]
fn open_boundary_limit_curve_is_the_cubic_bspline_of_the_boundary() {
    let n = 5;
    let mesh = quad_grid(n, |x, y| 0.1 * x * x - 0.05 * y);
    let s = surface(&mesh);
    assert_edge_curve_is_cubic_bspline(&s, &mesh.positions()[..=n], 8, |i| i as u32, 1e-12);
}

#[test]
fn limit_surface_is_c1_across_patch_edges() {
    for mesh in [jitter(&cube(), 0.1, 6), spot_quads()] {
        assert_c1_across_edges(&surface(&mesh), 8);
    }
}

#[test]
fn derivatives_match_finite_differences() {
    let s = surface(&jitter(&cube(), 0.1, 7));
    assert_derivatives_match_finite_differences(
        &s,
        0..6,
        &[(0.2, 0.3), (0.05, 0.1), (0.6, 0.9), (0.5, 0.5)],
        |e, d| close(d.dv_v, e.dvv, 1e-5) && close(d.du_v, e.duv, 1e-5),
    );
}
