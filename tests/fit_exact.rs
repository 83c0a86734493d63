//! Issue 4's exact reproduction, for every scheme: points sampled densely from a known limit
//! surface, a perturbed control mesh of the same connectivity, E_max < 1e-6 % at the end.

mod common;

use common::linear::sample;
use common::{sphere_mesh, Rng};
use geofit::fit::{
    surface_of, Acceleration, FitStatus, Fitter, SubdivFitOptions, SubdivFitter, Tolerances,
    Weighting,
};
use geofit::mesh::{ControlMesh, PolyMesh};
use geofit::subdiv::{quadrangulate, Scheme, SubdivSurface};

/// Every control point moved along its position vector (the meshes are centred spheres) by up
/// to ±`amount`: a tangential shift changes the surface mostly within itself, which orthogonal
/// distances pin down only slowly.
fn radially_perturbed(mesh: &PolyMesh, amount: f64, rng: &mut Rng) -> PolyMesh {
    let pts = mesh
        .positions()
        .iter()
        .map(|p| *p * (1.0 + amount * (2.0 * rng.next_f64() - 1.0)))
        .collect();
    PolyMesh::try_new(pts, mesh.faces().collect::<Vec<_>>()).expect("same connectivity")
}

/// A closed control mesh for `scheme`: a subdivided icosahedron for Loop, its quadrangulation
/// (extraordinary vertices of valence 5 and 6 among regular ones) for the quad schemes.
fn control_mesh(scheme: Scheme) -> PolyMesh {
    let triangles = sphere_mesh(1);
    match scheme {
        Scheme::Loop => triangles,
        _ => quadrangulate(&ControlMesh::try_new(&triangles).expect("manifold"))
            .expect("quadrangulate")
            .to_poly_mesh()
            .expect("poly mesh"),
    }
}

/// Fits samples of the limit surface of `scheme` over its control mesh, starting from a
/// perturbed copy; returns the status, E_max % and iterations.
///
/// Exact data has no noise to average, so the fit runs close to point-to-plane (tangent weight
/// 1e-4 instead of the default 0.01) with the frozen-parameter CG run further (100 steps
/// instead of 8). With the defaults the error still falls every iteration but only linearly
/// (Loop on a 66-point sphere: 4e-4 % after 200 iterations), because frozen foot parameters
/// slip along the surface; these settings make that slip cheap and converge in tens to a few
/// hundred iterations.
fn reproduce(scheme: Scheme, max_iter: usize) -> (FitStatus, f64, usize) {
    let control = control_mesh(scheme);
    let truth = surface_of(scheme, &control, &[]).expect("limit surface");
    let data = sample(&truth, 40, &mut Rng(9));
    let start = radially_perturbed(&control, 0.05, &mut Rng(10));
    let options = SubdivFitOptions::default()
        .with_tolerances(Tolerances {
            avg_pct: None,
            max_pct: Some(1e-6),
            rms_pct: None,
        })
        .with_refine(false)
        .with_max_iter(max_iter)
        .with_weighting(Weighting::Basis)
        .with_acceleration(Acceleration::Cg { inner: 100 })
        .with_tangent_weight(1e-4);
    let mut fitter =
        SubdivFitter::<SubdivSurface>::try_new(&data, start, scheme, options).expect("fitter");
    let status = fitter.run().expect("run");
    (status, fitter.stats().e_max_pct, fitter.history().len())
}

fn assert_reproduced(scheme: Scheme) {
    let (status, e, iters) = reproduce(scheme, 400);
    assert_eq!(
        status,
        FitStatus::Converged,
        "{scheme:?}: E_max {e} % after {iters}"
    );
    assert!(e < 1e-6, "{scheme:?}: E_max {e} %");
}

#[test]
fn loop_reproduces_its_own_limit_surface() {
    assert_reproduced(Scheme::Loop);
}

#[test]
fn catmull_clark_reproduces_its_own_limit_surface() {
    assert_reproduced(Scheme::CatmullClark);
}

#[test]
fn doo_sabin_reproduces_its_own_limit_surface() {
    assert_reproduced(Scheme::DooSabin);
}
