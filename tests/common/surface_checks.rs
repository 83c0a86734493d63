//! Checks shared by the subdivision tests: tolerant comparison, unit normals, and C1 continuity
//! across every interior patch edge.

use geofit::geom::Vec3;
use geofit::subdiv::{LimitEval, LimitSurface, PatchDomain, SubdivSurface, SurfaceParam};

/// `a` and `b` agree to `tol`, relative to their size (absolute near the origin).
pub fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
    (a - b).length() <= tol * (1.0 + a.length().max(b.length()))
}

/// The unit normal S_u × S_v of an evaluation.
pub fn normal(e: &LimitEval) -> Vec3 {
    e.du.cross(e.dv).normalize()
}

/// Parameters at fraction `a` along side `k` of a patch domain, from corner k to corner k + 1.
pub fn side_param(domain: PatchDomain, k: usize, a: f64) -> (f64, f64) {
    match (domain, k) {
        (_, 0) => (a, 0.0),
        (PatchDomain::Triangle, 1) => (1.0 - a, a),
        (PatchDomain::Triangle, _) => (0.0, 1.0 - a),
        (PatchDomain::Square, 1) => (1.0, a),
        (PatchDomain::Square, 2) => (1.0 - a, 1.0),
        (PatchDomain::Square, _) => (0.0, 1.0 - a),
    }
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
