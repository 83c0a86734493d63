//! The subdivision fitting engine, checked on a piecewise-linear surface (exact, easy to reason
//! about) and synthetic data.

mod common;

use common::linear::{sample, Linear};
use common::{bump_grid, bumpy_sphere, perturbed_z, sphere_mesh, Rng};
use geofit::fit::{
    Acceleration, FitStatus, Fitter, SubdivFitOptions, SubdivFitter, Tolerances, Weighting,
};
use geofit::geom::Point3;
use geofit::mesh::PolyMesh;
use geofit::subdiv::LimitSurface;

fn linear(mesh: PolyMesh) -> Linear {
    Linear::try_new(&mesh).expect("triangle mesh")
}

fn exact_tol() -> Tolerances {
    Tolerances {
        avg_pct: None,
        max_pct: Some(1e-6),
        rms_pct: None,
    }
}

fn reproduce(weighting: Weighting, accel: Acceleration, max_iter: usize) -> (f64, usize) {
    // Flat: a piecewise-linear surface has kinks, along which orthogonal distances pin the
    // control points only weakly (that is tested on smooth schemes); flat data keeps the test
    // exact and fast while the start is far off (every point moved along z).
    let truth = bump_grid(6, 0.0);
    let surface = Linear::try_new(&truth).expect("surface");
    let data = sample(&surface, 12, &mut Rng(1));
    let start = perturbed_z(&truth, 0.05, &mut Rng(2));
    let options = SubdivFitOptions::default()
        .with_tolerances(exact_tol())
        .with_max_iter(max_iter)
        .with_refine(false)
        .with_weighting(weighting)
        .with_acceleration(accel);
    let mut fitter = SubdivFitter::with_surface(&data, linear(start), options).expect("fitter");
    let status = fitter.run().expect("run");
    assert_eq!(
        status,
        FitStatus::Converged,
        "{:?}",
        fitter.history().last()
    );
    (fitter.stats().e_max_pct, fitter.history().len())
}

#[test]
fn exact_reproduction_with_basis_weights_and_anderson() {
    let (e, iters) = reproduce(Weighting::Basis, Acceleration::Anderson { depth: 5 }, 300);
    assert!(e < 1e-6, "E_max {e} % after {iters}");
}

#[test]
fn exact_reproduction_with_frozen_parameter_cg() {
    let (e, iters) = reproduce(Weighting::Basis, Acceleration::Cg { inner: 10 }, 100);
    assert!(e < 1e-6, "E_max {e} % after {iters}");
}

#[test]
fn exact_reproduction_with_patent_weights() {
    let (e, iters) = reproduce(Weighting::Patent, Acceleration::None, 2000);
    assert!(e < 1e-6, "E_max {e} % after {iters}");
}

#[test]
fn foot_points_are_local_minima() {
    let control = sphere_mesh(2);
    let mut rng = Rng(7);
    let data: Vec<Point3> = (0..400)
        .map(|_| rng.vec().normalize() * (1.0 + 0.05 * rng.next_f64()))
        .collect();
    let fitter = SubdivFitter::with_surface(&data, linear(control), SubdivFitOptions::default())
        .expect("fitter");
    let surface = fitter.surface();
    let converged = fitter.foot_points().iter().filter(|f| f.converged).count();
    assert!(
        converged * 10 >= data.len() * 8,
        "{converged} of {} converged",
        data.len()
    );
    let fine = fitter.limit_mesh(16);
    for (p, foot) in data.iter().zip(fitter.foot_points()) {
        let e = surface.eval(foot.param);
        let r = *p - foot.point;
        let (u, v) = (foot.param.u, foot.param.v);
        // Newton may stop short of convergence only at a kink of the piecewise-linear surface;
        // those feet are still checked against the samples below.
        let interior = foot.converged && u > 1e-6 && v > 1e-6 && u + v < 1.0 - 1e-6;
        if interior {
            for t in [e.du, e.dv] {
                assert!(r.dot(t).abs() <= 1e-9 * r.length().max(1e-12) * t.length());
            }
        }
        let d = foot.dist_sq.sqrt();
        let nearest_sample = fine
            .positions()
            .iter()
            .map(|s| (*s - *p).length())
            .fold(f64::INFINITY, f64::min);
        assert!(
            d <= nearest_sample + 1e-12,
            "foot {d} vs sample {nearest_sample}"
        );
    }
}

#[test]
fn damping_keeps_rms_from_growing() {
    let control = sphere_mesh(1);
    let data = bumpy_sphere(11, 2000, |d| 0.2 * (3.0 * d.x).sin() * d.y);
    for accel in [
        Acceleration::None,
        Acceleration::Relax { omega: 1.9 },
        Acceleration::Anderson { depth: 5 },
    ] {
        let options = SubdivFitOptions::default()
            .with_max_iter(25)
            .with_refine(false)
            .with_acceleration(accel)
            .with_weighting(Weighting::Patent);
        let mut fitter =
            SubdivFitter::with_surface(&data, linear(control.clone()), options).expect("fitter");
        let mut last = fitter.stats().e_rms_pct;
        while fitter.step().expect("step") == FitStatus::Running {
            let now = fitter.stats().e_rms_pct;
            assert!(
                now.is_finite() && now <= last * (1.0 + 1e-12),
                "{accel:?}: {last} -> {now}"
            );
            last = now;
        }
    }
}

#[test]
fn refinement_stays_manifold_conforming_and_within_budget() {
    let control = sphere_mesh(1);
    let data = bumpy_sphere(5, 3000, |d| 0.3 * (4.0 * d.x).sin() * (3.0 * d.z).cos());
    let options = SubdivFitOptions::default()
        .with_max_iter(40)
        .with_max_control(Some(400))
        .with_refine_interval(3);
    let mut fitter = SubdivFitter::with_surface(&data, linear(control), options).expect("fitter");
    fitter.run().expect("run");
    assert!(
        fitter.history().iter().any(|r| r.refined),
        "no refinement happened"
    );
    let mesh = fitter.control_mesh();
    assert!(mesh.num_vertices() <= 400);
    geofit::mesh::check_oriented_edges(&mesh).expect("manifold");
    // Closed and conforming: every edge has exactly two faces, and V − E + F = 2.
    let mut edges = std::collections::HashMap::new();
    for f in mesh.faces() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    assert!(edges.values().all(|&n| n == 2));
    let euler = mesh.num_vertices() as i64 - edges.len() as i64 + mesh.num_faces() as i64;
    assert_eq!(euler, 2);
    for pair in fitter.history().windows(2) {
        assert!(pair[1].control_points >= pair[0].control_points);
    }
}

#[test]
fn deterministic_across_runs() {
    let run = || {
        let control = sphere_mesh(1);
        let mut rng = Rng(3);
        let data: Vec<Point3> = (0..1500)
            .map(|_| rng.vec().normalize() * (1.0 + 0.1 * rng.next_f64()))
            .collect();
        let options = SubdivFitOptions::default()
            .with_max_iter(15)
            .with_refine_interval(4);
        let mut fitter =
            SubdivFitter::with_surface(&data, linear(control), options).expect("fitter");
        fitter.run().expect("run");
        let errors: Vec<u64> = fitter.point_errors().iter().map(|e| e.to_bits()).collect();
        let hist: Vec<(usize, u64)> = fitter
            .history()
            .iter()
            .map(|r| (r.control_points, r.e_rms_pct.to_bits()))
            .collect();
        (errors, hist, fitter.control_mesh())
    };
    assert_eq!(run(), run());
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let control = sphere_mesh(0);
    let data = vec![Point3::new(0.0, f64::NAN, 0.0)];
    assert!(SubdivFitter::with_surface(
        &data,
        linear(control.clone()),
        SubdivFitOptions::default()
    )
    .is_err());
    assert!(
        SubdivFitter::with_surface(&[], linear(control.clone()), SubdivFitOptions::default())
            .is_err()
    );
    let bad = SubdivFitOptions::default().with_max_iter(0);
    assert!(SubdivFitter::with_surface(&[Point3::ZERO], linear(control), bad).is_err());
    let empty = geofit::mesh::PolyMesh::from_points(vec![Point3::ZERO]).expect("points");
    assert!(SubdivFitter::with_surface(
        &[Point3::ZERO],
        linear(empty),
        SubdivFitOptions::default()
    )
    .is_err());
}
