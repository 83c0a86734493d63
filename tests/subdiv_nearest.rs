//! Foot points on limit surfaces (`subdiv::newton_foot`): the shortcuts of the foot-point search
//! (issue 17) give what a full search gives.
//!
//! - The last Newton step taken without evaluating the surface (Taylor expansion in Newton's
//!   quadratic phase) must land where the search would: the reported point is the surface's
//!   point at the reported parameter, and a search restarted from the result does not move.

mod common;

use common::Rng;
use geofit::geom::NewtonOptions;
use geofit::mesh::PolyMesh;
use geofit::subdiv::{build, newton_foot, LimitSurface, PatchDomain, Scheme, SurfaceParam};

fn bunny() -> PolyMesh {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/subdiv/bunny_coarse.obj"
    );
    geofit::io::read_path(std::path::Path::new(path))
        .expect("bunny_coarse.obj")
        .mesh
}

fn options(scale: f64) -> NewtonOptions {
    let mut o = NewtonOptions::DEFAULT
        .with_max_iter(12)
        .with_step_tol(1e-10 * scale);
    o.max_step = 0.5;
    o
}

fn random_param(surface: &dyn LimitSurface, rng: &mut Rng) -> SurfaceParam {
    let patch = ((rng.next_f64() * surface.num_patches() as f64) as u32)
        .min(surface.num_patches() as u32 - 1);
    let (mut u, mut v) = (rng.next_f64(), rng.next_f64());
    if surface.domain() == PatchDomain::Triangle && u + v > 1.0 {
        (u, v) = (1.0 - u, 1.0 - v);
    }
    SurfaceParam { patch, u, v }
}

/// Warm starts near the foot (as in a fit's iterations, where the surface moved a little): the
/// results that end with an extrapolated step are as good as a converged search.
#[test]
fn extrapolated_last_steps_land_on_the_foot_point() {
    let mesh = bunny();
    let scale = 0.25; // about the bunny's diagonal
    let opts = options(scale);
    for scheme in [Scheme::Loop, Scheme::CatmullClark, Scheme::DooSabin] {
        let surface = build(scheme, &mesh).expect("surface");
        let mut rng = Rng(17);
        let mut extrapolated = 0;
        let n = 3000;
        for _ in 0..n {
            let at = random_param(surface.as_ref(), &mut rng);
            let e = surface.eval(at);
            let normal = e.du.cross(e.dv).normalize_or_zero();
            // A data point off the surface by up to 0.1 % of the scale, and a start nearby.
            let p = e.point + normal * (scale * 1e-3 * (2.0 * rng.next_f64() - 1.0));
            let start = surface.relocate(
                at.patch,
                at.u + 0.01 * (2.0 * rng.next_f64() - 1.0),
                at.v + 0.01 * (2.0 * rng.next_f64() - 1.0),
            );
            let foot = newton_foot(surface.as_ref(), p, start, &opts);
            if !foot.converged {
                continue;
            }
            // An extrapolated point differs from the evaluated one in the last bits.
            extrapolated += usize::from(foot.point != surface.eval(foot.param).point);
            // The point reported is the surface's point at the parameter reported.
            let exact = surface.eval(foot.param);
            assert!(
                (exact.point - foot.point).length() <= 1e-3 * opts.step_tol,
                "{scheme:?} {at:?}: reported {} but S = {}",
                foot.point,
                exact.point
            );
            assert!(((p - exact.point).length_squared() - foot.dist_sq).abs() <= 1e-12 * scale);
            // And it is the foot point: a search from there moves it by less than the step
            // tolerance (as after a search that evaluated its last step).
            let again = newton_foot(surface.as_ref(), p, foot.param, &opts);
            assert!(
                (again.point - foot.point).length() <= opts.step_tol,
                "{scheme:?} {at:?}: restart moved by {}",
                (again.point - foot.point).length()
            );
            assert!((again.dist_sq.sqrt() - foot.dist_sq.sqrt()).abs() <= opts.step_tol);
        }
        // Many of these starts end with the extrapolated step: the checks above are about it.
        assert!(
            extrapolated > n / 4,
            "{scheme:?}: {extrapolated} of {n} extrapolated"
        );
    }
}
