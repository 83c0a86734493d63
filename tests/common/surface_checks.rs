//! Checks shared by the subdivision tests: tolerant comparison, unit normals, and C1 continuity
//! across every interior patch edge.

use geofit::geom::{Point3, Vec3};
use geofit::mesh::PolyMesh;
use geofit::subdiv::{side_param, LimitEval, LimitSurface, SubdivSurface, SurfaceParam};

/// `a` and `b` agree to `tol`, relative to their size (absolute near the origin).
pub fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
    (a - b).length() <= tol * (1.0 + a.length().max(b.length()))
}

/// The unit normal S_u × S_v of an evaluation.
pub fn normal(e: &LimitEval) -> Vec3 {
    e.du.cross(e.dv).normalize()
}

/// Positions and tangent planes of the patches on both sides of every interior control edge
/// agree to 1e-9 at `samples - 1` points along it (patches are the control faces: Loop and
/// Catmull–Clark).
pub fn assert_c1_across_edges(s: &SubdivSurface, samples: usize) {
    let cm = s.control_mesh();
    let domain = s.domain();
    for f in 0..cm.num_faces() as u32 {
        for (k, h) in cm.face_half_edges(f).enumerate() {
            let t = cm.twin(h);
            if t == geofit::mesh::NONE {
                continue;
            }
            let g = cm.face_of(t);
            let kt = cm
                .face_half_edges(g)
                .position(|x| x == t)
                .expect("twin in its face");
            for i in 1..samples {
                let a = i as f64 / samples as f64;
                let (u, v) = side_param(domain, k, a);
                let (ug, vg) = side_param(domain, kt, 1.0 - a);
                let ea = s.eval(SurfaceParam { patch: f, u, v });
                let eb = s.eval(SurfaceParam {
                    patch: g,
                    u: ug,
                    v: vg,
                });
                assert!(
                    close(ea.point, eb.point, 1e-9),
                    "edge of face {f}: position"
                );
                assert!(
                    (normal(&ea) - normal(&eb)).length() < 1e-9,
                    "edge of face {f}: normal"
                );
            }
        }
    }
}

/// The four uniform cubic B-spline basis functions at `t` in [0, 1].
pub fn bspline(t: f64) -> [f64; 4] {
    [
        (1.0 - t).powi(3) / 6.0,
        (3.0 * t.powi(3) - 6.0 * t * t + 4.0) / 6.0,
        (-3.0 * t.powi(3) + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
        t.powi(3) / 6.0,
    ]
}

/// Evaluates `coarse` at `(patch, u, v)` and `fine` at `(child, u, v)`, asserts that the two
/// points agree to 1e-10 (`what` names the place in the message), and returns both evaluations.
pub fn assert_same_limit_point(
    coarse: &SubdivSurface,
    (patch, pu, pv): (u32, f64, f64),
    fine: &SubdivSurface,
    (child, u, v): (u32, f64, f64),
    what: std::fmt::Arguments,
) -> (LimitEval, LimitEval) {
    let a = coarse.eval(SurfaceParam {
        patch,
        u: pu,
        v: pv,
    });
    let b = fine.eval(SurfaceParam { patch: child, u, v });
    assert!(
        close(a.point, b.point, 1e-10),
        "{what}: {:?} vs {:?}",
        a.point,
        b.point
    );
    (a, b)
}

/// For each face of `mesh` (the control mesh of `s`), the limit point at the parameters
/// `corners[k]` is the limit position of the face's vertex k, to 1e-12.
pub fn assert_corners_are_limit_points(s: &SubdivSurface, mesh: &PolyMesh, corners: &[(f64, f64)]) {
    let limits = s.limit_positions();
    for f in 0..mesh.num_faces() {
        for (k, &(u, v)) in corners.iter().enumerate() {
            let e = s.eval(SurfaceParam {
                patch: f as u32,
                u,
                v,
            });
            assert!(
                close(e.point, limits[mesh.face(f)[k] as usize], 1e-12),
                "face {f} corner {k}"
            );
        }
    }
}

/// The first and second derivatives of [`bspline`]'s basis functions.
fn bspline_derivatives(t: f64) -> [[f64; 4]; 2] {
    [
        [
            -(1.0 - t).powi(2) / 2.0,
            (3.0 * t * t - 4.0 * t) / 2.0,
            (-3.0 * t * t + 2.0 * t + 1.0) / 2.0,
            t * t / 2.0,
        ],
        [1.0 - t, 3.0 * t - 2.0, 1.0 - 3.0 * t, t],
    ]
}

/// The limit curve along edge 0 of the patches `patch(i)` is the uniform cubic B-spline of the
/// polyline `row`: checked for the segments i in 1..row.len() - 2 at `steps + 1` parameters
/// each, the point to `tol`, its first and second derivatives along the edge to 1e-9 of the
/// row's extent (the second derivative on an open boundary was off by up to 1 % of its size
/// while boundary patches were evaluated by subdividing 40 levels towards the edge).
pub fn assert_edge_curve_is_cubic_bspline(
    s: &SubdivSurface,
    row: &[Point3],
    steps: usize,
    patch: impl Fn(usize) -> u32,
    tol: f64,
) {
    let extent = row
        .iter()
        .map(|p| (*p - row[0]).length())
        .fold(0.0f64, f64::max);
    for i in 1..row.len() - 2 {
        for k in 0..=steps {
            let t = k as f64 / steps as f64;
            let e = s.eval(SurfaceParam {
                patch: patch(i),
                u: t,
                v: 0.0,
            });
            let b = bspline(t);
            let c: Point3 = (0..4).map(|j| row[i + j - 1] * b[j]).sum();
            assert!(
                close(e.point, c, tol),
                "segment {i} t {t}: {:?} vs {c:?}",
                e.point
            );
            let [d1, d2] = bspline_derivatives(t);
            let c1: Vec3 = (0..4).map(|j| row[i + j - 1] * d1[j]).sum();
            let c2: Vec3 = (0..4).map(|j| row[i + j - 1] * d2[j]).sum();
            let scale = 1e-9 * extent;
            assert!(
                close(e.du, c1, scale),
                "segment {i} t {t}: du {:?} vs {c1:?}",
                e.du
            );
            assert!(
                close(e.duu, c2, scale),
                "segment {i} t {t}: duu {:?} vs {c2:?}",
                e.duu
            );
        }
    }
}

/// Central differences with step `h` of an evaluation: ∂/∂u and ∂/∂v of S, S_u and S_v.
pub struct CentralDifferences {
    pub point_u: Vec3,
    pub point_v: Vec3,
    pub du_u: Vec3,
    pub du_v: Vec3,
    pub dv_v: Vec3,
}

/// At each of `params` on each of `patches`, S_u and S_v agree with central differences of step
/// 1e-6 to 1e-6, and `second(e, d)` holds (the second derivatives a scheme's test compares with
/// the differences `d`).
pub fn assert_derivatives_match_finite_differences(
    s: &SubdivSurface,
    patches: impl IntoIterator<Item = u32>,
    params: &[(f64, f64)],
    second: impl Fn(&LimitEval, &CentralDifferences) -> bool,
) {
    let h = 1e-6;
    for patch in patches {
        for &(u, v) in params {
            let e = s.eval(SurfaceParam { patch, u, v });
            let at = |u: f64, v: f64| s.eval(SurfaceParam { patch, u, v });
            let d = CentralDifferences {
                point_u: (at(u + h, v).point - at(u - h, v).point) / (2.0 * h),
                point_v: (at(u, v + h).point - at(u, v - h).point) / (2.0 * h),
                du_u: (at(u + h, v).du - at(u - h, v).du) / (2.0 * h),
                du_v: (at(u, v + h).du - at(u, v - h).du) / (2.0 * h),
                dv_v: (at(u, v + h).dv - at(u, v - h).dv) / (2.0 * h),
            };
            assert!(
                close(d.point_u, e.du, 1e-6) && close(d.point_v, e.dv, 1e-6),
                "patch {patch} ({u},{v})"
            );
            assert!(second(&e, &d), "patch {patch} ({u},{v}) second");
        }
    }
}

/// One `#[test]` per `name: mesh;`, each checking with the calling file's
/// `check_refinement_invariance` that the once-refined mesh has the same limit surface.
#[allow(unused_macros)]
macro_rules! refinement_invariance_tests {
    ($($test:ident: $mesh:expr;)*) => {$(
        #[test]
        fn $test() {
            check_refinement_invariance(&$mesh);
        }
    )*};
}
#[allow(unused_imports)]
pub(crate) use refinement_invariance_tests;
