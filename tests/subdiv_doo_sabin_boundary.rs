//! Doo–Sabin at open boundaries and creases (issue 3), and walking across patches.
//!
//! The boundary rule is the ghost ring of `subdiv::doo_sabin`: the boundary polygon is refined
//! by Chaikin's rule, so the boundary limit curve must be the uniform quadratic B-spline of the
//! boundary control polygon; a tagged crease is a boundary for both sides.

mod common;

use common::meshes::{jitter, quad_grid, tri_grid};
use geofit::fit::SubdivFitOptions;
use geofit::geom::ClosestPoint;
use geofit::geom::{Point3, Vec3};
use geofit::mesh::{ControlMesh, PolyMesh};
use geofit::subdiv::{refine, DooSabinSurface, LimitSurface, Scheme, SurfaceParam};

/// (u, v) on side `j` of the unit square at `s` along it (sides 0: v = 0, 1: u = 1, 2: v = 1,
/// 3: u = 0) and the outward direction.
fn on_side(j: usize, s: f64) -> ((f64, f64), (f64, f64)) {
    match j {
        0 => ((s, 0.0), (0.0, -1.0)),
        1 => ((1.0, s), (1.0, 0.0)),
        2 => ((1.0 - s, 1.0), (0.0, 1.0)),
        _ => ((0.0, 1.0 - s), (-1.0, 0.0)),
    }
}

/// Whether side `j` of `patch` has no patch behind it (a boundary or crease curve): a point just
/// outside it is clamped back onto the same patch.
fn is_open_side(s: &DooSabinSurface, patch: u32, j: usize) -> bool {
    let ((u, v), (du, dv)) = on_side(j, 0.5);
    s.relocate(patch, u + 1e-3 * du, v + 1e-3 * dv).patch == patch
}

/// The uniform quadratic B-spline segment around control point `b` of the polygon `a, b, c`.
fn quadratic(a: Point3, b: Point3, c: Point3, t: f64) -> Point3 {
    a * ((1.0 - t).powi(2) / 2.0) + b * ((-2.0 * t * t + 2.0 * t + 1.0) / 2.0) + c * (t * t / 2.0)
}

/// The boundary loop of an n × n grid, counter-clockwise.
fn grid_boundary(n: usize) -> Vec<u32> {
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut b: Vec<u32> = (0..n).map(|i| id(i, 0)).collect();
    b.extend((0..n).map(|j| id(n, j)));
    b.extend((0..n).map(|i| id(n - i, n)));
    b.extend((0..n).map(|j| id(0, n - j)));
    b
}

#[test]
fn boundary_limit_curve_is_the_quadratic_bspline_of_the_boundary_polygon() {
    let n = 4;
    let flat = quad_grid(n, |_, _| 0.0);
    let mut p = jitter(&flat, 0.2, 7).positions().to_vec();
    for q in &mut p {
        q.z = 0.0;
    }
    let mesh = PolyMesh::try_new(p.clone(), flat.faces()).unwrap();
    let s = DooSabinSurface::try_new(&mesh).unwrap();
    let lp = grid_boundary(n);
    let mut sides = 0;
    for patch in 0..s.num_patches() as u32 {
        let (_, v) = s.patch_site(patch).unwrap();
        for j in 0..4 {
            if !is_open_side(&s, patch, j) {
                continue;
            }
            sides += 1;
            // The side runs over half the segment of the boundary curve around its vertex.
            let k = lp.iter().position(|&x| x == v).expect("a boundary vertex");
            let m = lp.len();
            let (a, b, c) = (
                p[lp[(k + m - 1) % m] as usize],
                p[v as usize],
                p[lp[(k + 1) % m] as usize],
            );
            for i in 0..=10 {
                let t = i as f64 / 10.0;
                let ((u, w), _) = on_side(j, t);
                let x = s.eval(SurfaceParam { patch, u, v: w }).point;
                let best = [0.5 + t / 2.0, 0.5 - t / 2.0, 1.0 - t / 2.0, t / 2.0]
                    .iter()
                    .map(|&tt| (quadratic(a, b, c, tt) - x).length())
                    .fold(f64::INFINITY, f64::min);
                assert!(best < 1e-12, "patch {patch} side {j} t {t}: off by {best}");
            }
        }
    }
    // Two half segments per boundary vertex.
    assert_eq!(sides, 2 * lp.len());
}

/// A jittered open grid with a hexagon, a triangle and a pentagon next to the boundary.
fn mixed_open_mesh() -> PolyMesh {
    let g = jitter(&quad_grid(4, |x, y| 0.1 * x * y - 0.05 * x * x), 0.15, 11);
    let mut faces: Vec<Vec<u32>> = g.faces().map(|f| f.to_vec()).collect();
    // Merge faces 0 and 1 (a hexagon), split face 5 into two triangles, and merge 10 and 11.
    let merge = |a: &[u32], b: &[u32]| -> Vec<u32> { vec![a[0], a[1], b[1], b[2], a[2], a[3]] };
    let hex = merge(&faces[0], &faces[1]);
    let hex2 = merge(&faces[10], &faces[11]);
    let f5 = faces[5].clone();
    let mut out = vec![
        hex,
        hex2,
        vec![f5[0], f5[1], f5[2]],
        vec![f5[0], f5[2], f5[3]],
    ];
    for (i, f) in faces.drain(..).enumerate() {
        if ![0, 1, 5, 10, 11].contains(&i) {
            out.push(f);
        }
    }
    PolyMesh::try_new(g.positions().to_vec(), out).unwrap()
}

fn test_meshes() -> Vec<PolyMesh> {
    vec![
        jitter(&quad_grid(4, |x, y| 0.2 * x * x - 0.1 * x * y), 0.1, 3),
        jitter(&tri_grid(3, |x, y| 0.1 * x * y), 0.1, 4),
        mixed_open_mesh(),
    ]
}

/// Across every patch edge (boundary patches included) positions and tangent planes agree.
#[test]
fn patches_join_c1_across_edges_including_boundary_patches() {
    for (m, mesh) in test_meshes().iter().enumerate() {
        let s = DooSabinSurface::try_new(mesh).unwrap();
        let mut checked = 0;
        for patch in 0..s.num_patches() as u32 {
            for j in 0..4 {
                for &t in &[0.1, 0.5, 0.9] {
                    let ((u, v), (du, dv)) = on_side(j, t);
                    let a = s.eval(SurfaceParam { patch, u, v });
                    let eps = 1e-13;
                    let q = s.relocate(patch, u + eps * du, v + eps * dv);
                    if q.patch == patch {
                        continue;
                    }
                    let b = s.eval(q);
                    let gap = (a.point - b.point).length();
                    assert!(gap < 1e-9, "mesh {m} patch {patch} side {j}: gap {gap}");
                    let (na, nb) = (a.du.cross(a.dv), b.du.cross(b.dv));
                    if na.length() < 1e-6 || nb.length() < 1e-6 {
                        continue; // on a boundary curve the cross derivative vanishes
                    }
                    let turn = na.normalize().cross(nb.normalize()).length();
                    let same = na.dot(nb) > 0.0;
                    assert!(
                        turn < 1e-9 && same,
                        "mesh {m} patch {patch} side {j} t {t}: normals {na:?} {nb:?}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 10 * s.num_patches(), "mesh {m}: {checked} checks");
    }
}

#[test]
fn derivatives_match_finite_differences_on_open_meshes() {
    let h = 1e-6;
    for mesh in test_meshes() {
        let s = DooSabinSurface::try_new(&mesh).unwrap();
        for patch in 0..s.num_patches() as u32 {
            for &(u, v) in &[(0.2, 0.3), (0.05, 0.1), (0.6, 0.9), (0.45, 0.03)] {
                let at = |u: f64, v: f64| s.eval(SurfaceParam { patch, u, v });
                let e = at(u, v);
                let du = (at(u + h, v).point - at(u - h, v).point) / (2.0 * h);
                let dv = (at(u, v + h).point - at(u, v - h).point) / (2.0 * h);
                let duu = (at(u + h, v).du - at(u - h, v).du) / (2.0 * h);
                let dvv = (at(u, v + h).dv - at(u, v - h).dv) / (2.0 * h);
                let duv = (at(u, v + h).du - at(u, v - h).du) / (2.0 * h);
                let close = |a: Vec3, b: Vec3| (a - b).length() <= 1e-5 * (1.0 + b.length());
                assert!(
                    close(du, e.du) && close(dv, e.dv),
                    "patch {patch} ({u},{v})"
                );
                assert!(
                    close(duu, e.duu) && close(dvv, e.dvv) && close(duv, e.duv),
                    "second derivatives, patch {patch} ({u},{v})"
                );
            }
        }
    }
}

/// Newton started on one patch finds a foot point that lies on a neighbouring patch: the
/// parameter walks across the patch edge (and across boundary patches).
#[test]
fn newton_walks_into_neighbouring_patches() {
    let opts = SubdivFitOptions::DEFAULT.newton;
    for mesh in test_meshes() {
        let s = DooSabinSurface::try_new(&mesh).unwrap();
        let mut crossed = 0;
        for patch in 0..s.num_patches() as u32 {
            for j in 0..4 {
                let ((u, v), (du, dv)) = on_side(j, 0.5);
                let q = s.relocate(patch, u + 0.3 * du, v + 0.3 * dv);
                if q.patch == patch {
                    continue;
                }
                let e = s.eval(q);
                let n = e.du.cross(e.dv).normalize_or_zero();
                let target = e.point + n * 0.01;
                let start = SurfaceParam {
                    patch,
                    u: 0.5,
                    v: 0.5,
                };
                let foot = s.closest_point_from(target, start, &opts);
                assert!(foot.converged, "patch {patch} side {j}");
                assert!(
                    (foot.point - e.point).length() < 1e-7,
                    "patch {patch} side {j}: foot {:?} expected {:?}",
                    foot.point,
                    e.point
                );
                assert_ne!(foot.param.patch, patch);
                crossed += 1;
            }
        }
        assert!(crossed > s.num_patches());
    }
}

/// A grid folded along its middle column, with the fold's edges tagged sharp: the fold stays a
/// sharp edge on the limit surface, exactly on the crease polygon's quadratic B-spline (here
/// the fold line), with different normals on its two sides. Untagged, the fold is rounded.
#[test]
fn crease_tags_keep_a_sharp_edge() {
    let n = 6;
    let c = 3.0;
    let folded = jitter(&quad_grid(n, |x, _| 0.5 * (x - c).abs()), 0.0, 1);
    let mut p = folded.positions().to_vec();
    for (k, q) in p.iter_mut().enumerate() {
        let j = (k / (n + 1)) as f64;
        q.y += 0.1 * (j * 1.7).sin(); // uneven spacing along the fold
    }
    let mesh = PolyMesh::try_new(p, folded.faces()).unwrap();
    let mut cm = ControlMesh::try_new(&mesh).unwrap();
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for j in 0..n {
        cm.set_sharp(id(3, j), id(3, j + 1), true).unwrap();
    }
    let on_fold = |x: Point3| (x.x - c).abs() < 1e-12 && x.z.abs() < 1e-12;
    let sharp = DooSabinSurface::from_control_mesh(cm.clone()).unwrap();
    let (mut left, mut right) = (0, 0);
    for patch in 0..sharp.num_patches() as u32 {
        for j in 0..4 {
            if !is_open_side(&sharp, patch, j) {
                continue;
            }
            let ((u, v), (du, dv)) = on_side(j, 0.5);
            let e = sharp.eval(SurfaceParam { patch, u, v });
            if !on_fold(e.point) {
                continue;
            }
            // On the curve itself the cross derivative vanishes: take the normal just inside.
            let inside = SurfaceParam {
                patch,
                u: u - 0.01 * du,
                v: v - 0.01 * dv,
            };
            let e = sharp.eval(inside);
            let nrm = e.du.cross(e.dv).normalize_or_zero();
            // Normals of the two planes z = ±0.5 (x − c): x components of ∓0.447.
            if nrm.x.abs() > 0.4 {
                if nrm.x * nrm.z < 0.0 {
                    right += 1;
                } else {
                    left += 1;
                }
            }
        }
    }
    assert!(left >= n && right >= n, "left {left} right {right}");
    // The crease survives refinement: the refined mesh is tagged and has the same fold.
    let fine = refine(Scheme::DooSabin, &cm).unwrap();
    assert!(fine.creases().len() >= 2 * n);
    let fine_s = DooSabinSurface::from_control_mesh(fine).unwrap();
    let fold_points = (0..fine_s.num_patches() as u32)
        .filter(|&patch| {
            on_fold(
                fine_s
                    .eval(SurfaceParam {
                        patch,
                        u: 0.0,
                        v: 0.0,
                    })
                    .point,
            )
        })
        .count();
    assert!(fold_points > 0);
    // Without tags nothing of the surface reaches the fold line.
    let smooth = DooSabinSurface::try_new(&mesh).unwrap();
    for patch in 0..smooth.num_patches() as u32 {
        for &(u, v) in &[(0.0, 0.0), (1.0, 1.0), (0.5, 0.5), (0.0, 1.0), (1.0, 0.0)] {
            assert!(!on_fold(smooth.eval(SurfaceParam { patch, u, v }).point));
        }
    }
}

/// Refinement reproduces the limit surface at boundaries and creases: points of the coarse
/// surface lie on the refined one.
#[test]
fn refinement_keeps_the_limit_surface_at_boundaries_and_creases() {
    let opts = SubdivFitOptions::DEFAULT.newton;
    for (mesh, n) in test_meshes().into_iter().zip([4, 3, 4]) {
        let mut cm = ControlMesh::try_new(&mesh).unwrap();
        // Tag the grid line x = 2 as a crease (from boundary to boundary).
        let id = |j: usize| (j * (n + 1) + 2) as u32;
        for j in 0..n {
            cm.set_sharp(id(j), id(j + 1), true).unwrap();
        }
        let s0 = DooSabinSurface::from_control_mesh(cm.clone()).unwrap();
        let fine = refine(Scheme::DooSabin, &cm).unwrap();
        let s1 = DooSabinSurface::from_control_mesh(fine).unwrap();
        let index: Vec<(Point3, SurfaceParam)> = (0..s1.num_patches() as u32)
            .flat_map(|patch| {
                [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)].map(|(u, v)| {
                    let at = SurfaceParam { patch, u, v };
                    (s1.eval(at).point, at)
                })
            })
            .collect();
        for patch in 0..s0.num_patches() as u32 {
            for &(u, v) in &[(0.3, 0.6), (0.5, 0.5), (0.9, 0.2)] {
                let x = s0.eval(SurfaceParam { patch, u, v }).point;
                // Newton does not cross creases: start from the nearest samples on all sides.
                let mut near: Vec<&(Point3, SurfaceParam)> = index.iter().collect();
                near.sort_by(|a, b| (a.0 - x).length().total_cmp(&(b.0 - x).length()));
                let foot = near
                    .iter()
                    .take(8)
                    .map(|&&(_, start)| s1.closest_point_from(x, start, &opts))
                    .min_by(|a, b| a.dist_sq.total_cmp(&b.dist_sq))
                    .unwrap();
                assert!(
                    foot.dist_sq.sqrt() < 1e-8,
                    "patch {patch} ({u},{v}): {}",
                    foot.dist_sq.sqrt()
                );
            }
        }
    }
}

/// Bad parameters never give NaN: non-finite and far-off parameters are cleaned and walked.
#[test]
fn no_nan_from_bad_parameters() {
    let s = DooSabinSurface::try_new(&mixed_open_mesh()).unwrap();
    let bad = [f64::NAN, f64::INFINITY, -1e300, 1e300, -7.5, 3.25];
    for patch in [0, 1, s.num_patches() as u32 - 1, u32::MAX] {
        for &u in &bad {
            for &v in &bad {
                let at = s.relocate(patch, u, v);
                assert!((at.patch as usize) < s.num_patches());
                assert!((0.0..=1.0).contains(&at.u) && (0.0..=1.0).contains(&at.v));
                let e = s.eval(at);
                assert!(e.point.is_finite() && e.du.is_finite() && e.dvv.is_finite());
            }
        }
    }
}
