//! Doo–Sabin: refinement rules and exact limit evaluation. No installable library offers
//! Doo–Sabin, so it is checked against analytic properties: the refinement weights on a quad
//! grid, the biquadratic B-spline limit of a regular grid, face centroids kept at non-quad
//! faces, and a refined mesh having the same limit surface.

mod common;

use common::meshes::{cube, icosahedron, jitter, quad_grid};
use common::surface_checks::{
    assert_derivatives_match_finite_differences, assert_same_limit_point, close,
    refinement_invariance_tests,
};
use geofit::geom::Point3;
use geofit::mesh::{ControlMesh, PolyMesh};
use geofit::subdiv::{refine, DooSabinSurface, LimitSurface, Scheme, SurfaceParam};
use std::collections::HashMap;

#[test]
fn refinement_uses_the_doo_sabin_weights_and_counts() {
    let n = 3;
    let mesh = jitter(&quad_grid(n, |x, y| x * y), 0.1, 1);
    let cm = ControlMesh::try_new(&mesh).unwrap();
    let r = refine(Scheme::DooSabin, &cm).unwrap();
    // One new point per face corner and two per boundary edge (Chaikin's points of the
    // boundary polygon); faces: one per face, edge and vertex (the ghost ring makes boundary
    // edges and vertices interior).
    assert_eq!(r.num_vertices(), 4 * n * n + 2 * 4 * n);
    assert_eq!(r.num_faces(), n * n + 2 * n * (n + 1) + (n + 1) * (n + 1));
    // Face 4 is the middle quad: its corner points are (9 a + 3 b + c + 3 d) / 16.
    let c: Vec<Point3> = cm
        .face_vertices(4)
        .map(|v| mesh.positions()[v as usize])
        .collect();
    for j in 0..4 {
        let expect =
            (c[j] * 9.0 + c[(j + 1) % 4] * 3.0 + c[(j + 2) % 4] + c[(j + 3) % 4] * 3.0) / 16.0;
        assert!(close(r.positions()[16 + j], expect, 1e-15));
    }
    // Closed meshes keep their Euler characteristic.
    let cube = ControlMesh::try_new(&cube()).unwrap();
    assert_eq!(
        refine(Scheme::DooSabin, &cube)
            .unwrap()
            .euler_characteristic(),
        2
    );
}

fn quadratic(t: f64) -> [f64; 3] {
    [
        (1.0 - t).powi(2) / 2.0,
        (-2.0 * t * t + 2.0 * t + 1.0) / 2.0,
        t * t / 2.0,
    ]
}

/// On a regular grid the Doo–Sabin limit is the biquadratic B-spline surface of the grid.
#[test]
fn regular_grid_limit_is_the_biquadratic_bspline() {
    let n = 5;
    let mesh = jitter(&quad_grid(n, |x, y| 0.2 * x * x - 0.1 * x * y), 0.1, 2);
    let p = |i: usize, j: usize| mesh.positions()[j * (n + 1) + i];
    // The biquadratic B-spline in grid coordinates (x, y), x in [1, n - 1].
    let spline = |x: f64, y: f64| -> Point3 {
        let (i, j) = ((x - 0.5).floor() as usize, (y - 0.5).floor() as usize);
        let (bu, bv) = (quadratic(x - 0.5 - i as f64), quadratic(y - 0.5 - j as f64));
        let mut q = Point3::ZERO;
        for (b, wv) in bv.iter().enumerate() {
            for (a, wu) in bu.iter().enumerate() {
                q += p(i + a - 1 + 1, j + b - 1 + 1) * (wu * wv);
            }
        }
        q
    };
    let s = DooSabinSurface::try_new(&mesh).unwrap();
    let mut checked = 0;
    for patch in 0..s.num_patches() as u32 {
        let (f, v) = s.patch_site(patch).unwrap();
        let (vx, vy) = ((v as usize % (n + 1)) as f64, (v as usize / (n + 1)) as f64);
        let (fx, fy) = ((f as usize % n) as f64 + 0.5, (f as usize / n) as f64 + 0.5);
        if !(2.0..=(n - 2) as f64).contains(&vx) || !(2.0..=(n - 2) as f64).contains(&vy) {
            continue;
        }
        // (0,0) is the face centre, (1,1) the vertex; the axes run along the grid.
        for &(u, w) in &[(0.0, 0.0), (1.0, 1.0), (0.3, 0.7), (0.8, 0.1)] {
            let e = s.eval(SurfaceParam { patch, u, v: w });
            let a = spline(fx + (vx - fx) * u, fy + (vy - fy) * w);
            let b = spline(fx + (vx - fx) * w, fy + (vy - fy) * u);
            assert!(
                close(e.point, a, 1e-12) || close(e.point, b, 1e-12),
                "patch {patch} ({u},{w})"
            );
            checked += 1;
        }
    }
    assert!(checked > 0);
}

/// The limit at a face's corner of the patch domain is the face centroid (kept by every step),
/// and at the vertex corner it is the vertex limit.
#[test]
fn patch_corners_are_face_centroids_and_vertex_limits() {
    let mesh = jitter(&icosahedron(), 0.2, 3);
    let s = DooSabinSurface::try_new(&mesh).unwrap();
    let limits = s.limit_positions();
    for patch in 0..s.num_patches() as u32 {
        let (f, v) = s.patch_site(patch).unwrap();
        let c: Point3 = mesh
            .face(f as usize)
            .iter()
            .map(|&i| mesh.positions()[i as usize])
            .sum::<Point3>()
            / 3.0;
        assert!(
            close(
                s.eval(SurfaceParam {
                    patch,
                    u: 0.0,
                    v: 0.0
                })
                .point,
                c,
                1e-12
            ),
            "patch {patch}"
        );
        assert!(close(
            s.eval(SurfaceParam {
                patch,
                u: 1.0,
                v: 1.0
            })
            .point,
            limits[v as usize],
            1e-12
        ));
    }
}

fn site_index(s: &DooSabinSurface) -> HashMap<(u32, u32), u32> {
    (0..s.num_patches() as u32)
        .map(|p| (s.patch_site(p).unwrap(), p))
        .collect()
}

/// The refined mesh has the same limit surface: patch (f, v) of the coarse mesh is split into
/// the four patches around the refined point of corner (f, v).
fn check_refinement_invariance(mesh: &PolyMesh) {
    let cm = ControlMesh::try_new(mesh).unwrap();
    let s0 = DooSabinSurface::from_control_mesh(cm.clone()).unwrap();
    let fine = refine(Scheme::DooSabin, &cm).unwrap();
    let s1 = DooSabinSurface::from_control_mesh(fine.clone()).unwrap();
    let sites1 = site_index(&s1);
    let mut starts = vec![0u32];
    for f in 0..cm.num_faces() as u32 {
        starts.push(starts[f as usize] + cm.face_len(f) as u32);
    }
    let to_parent = |c: usize, u: f64, v: f64| match c {
        0 => (u / 2.0, v / 2.0),
        1 => (1.0 - v / 2.0, u / 2.0),
        2 => (1.0 - u / 2.0, 1.0 - v / 2.0),
        _ => (v / 2.0, 1.0 - u / 2.0),
    };
    for patch in 0..s0.num_patches() as u32 {
        let (f, v) = s0.patch_site(patch).unwrap();
        let corner = cm.face_vertices(f).position(|x| x == v).unwrap() as u32;
        let p = starts[f as usize] + corner;
        // Faces around p counter-clockwise, starting with the face made from face f.
        let out: Vec<u32> = fine.outgoing(p).collect();
        let k = out.iter().position(|&h| fine.face_of(h) == f).unwrap();
        for c in 0..4 {
            let g = fine.face_of(out[(k + c) % out.len()]);
            let child = sites1[&(g, p)];
            for &(u, w) in &[(0.0, 0.0), (0.5, 0.5), (0.2, 0.9), (1.0, 0.3)] {
                let (pu, pv) = to_parent(c, u, w);
                assert_same_limit_point(
                    &s0,
                    (patch, pu, pv),
                    &s1,
                    (child, u, w),
                    format_args!("patch {patch} child {c} ({u},{w})"),
                );
            }
        }
    }
}

refinement_invariance_tests! {
    refined_icosahedron_has_the_same_limit_surface: jitter(&icosahedron(), 0.2, 4);
    refined_cube_has_the_same_limit_surface: jitter(&cube(), 0.1, 5);
}

#[test]
fn derivatives_match_finite_differences() {
    let s = DooSabinSurface::try_new(&jitter(&icosahedron(), 0.2, 6)).unwrap();
    assert_derivatives_match_finite_differences(
        &s,
        (0..s.num_patches() as u32).step_by(7),
        &[(0.2, 0.3), (0.05, 0.1), (0.6, 0.9)],
        |_, _| true,
    );
}
