//! The fitter on real Loop limit surfaces (the subdivision library's evaluation).

mod common;

use common::linear::sample;
use common::{bumpy_sphere, perturbed, sphere_mesh, Rng};
use geofit::fit::{surface_of, Fitter, SubdivFitOptions, SubdivFitter};
use geofit::geom::Point3;
use geofit::subdiv::{LimitSurface, Scheme, SubdivSurface};

#[test]
fn loop_foot_points_are_orthogonal_and_weights_sum_to_one() {
    let control = perturbed(&sphere_mesh(1), 0.1, &mut Rng(4));
    let mut rng = Rng(8);
    let data: Vec<Point3> = (0..500)
        .map(|_| rng.vec().normalize() * (0.9 + 0.2 * rng.next_f64()))
        .collect();
    let fitter = SubdivFitter::<SubdivSurface>::try_new(
        &data,
        control,
        Scheme::Loop,
        SubdivFitOptions::default(),
    )
    .expect("fitter");
    let surface = fitter.surface();
    let fine = fitter.limit_mesh(12);
    let mut weights = Vec::new();
    for (p, foot) in data.iter().zip(fitter.foot_points()) {
        assert!(foot.converged, "Newton did not converge for {p}");
        let e = surface.eval(foot.param);
        let r = *p - foot.point;
        for t in [e.du, e.dv] {
            assert!(r.dot(t).abs() <= 1e-7 * r.length().max(1e-9) * t.length());
        }
        let nearest = fine
            .positions()
            .iter()
            .map(|s| (*s - *p).length())
            .fold(f64::INFINITY, f64::min);
        assert!(foot.dist_sq.sqrt() <= nearest + 1e-9);
        for patent in [false, true] {
            weights.clear();
            if patent {
                surface.corner_weights(foot.param, &mut weights);
            } else {
                surface.stencil(foot.param, &mut weights);
            }
            let sum: f64 = weights.iter().map(|w| w.1).sum();
            assert!((sum - 1.0).abs() < 1e-9, "weights sum to {sum}");
        }
    }
}

#[test]
fn loop_refinement_with_flips_stays_manifold_and_finite() {
    let data = bumpy_sphere(21, 3000, |d| 0.25 * (5.0 * d.x).sin() * (4.0 * d.y).cos());
    let options = SubdivFitOptions::default()
        .with_max_iter(15)
        .with_max_control(Some(300))
        .with_refine_interval(3);
    let mut fitter =
        SubdivFitter::<SubdivSurface>::try_new(&data, sphere_mesh(1), Scheme::Loop, options)
            .expect("fitter");
    let first = fitter.stats().e_rms_pct;
    fitter.run().expect("run");
    assert!(fitter.history().iter().any(|r| r.refined));
    assert!(fitter.num_control_points() <= 300);
    assert!(fitter.point_errors().iter().all(|e| e.is_finite()));
    assert!(fitter.stats().e_rms_pct < 0.5 * first);
    let mesh = fitter.control_mesh();
    geofit::mesh::check_oriented_edges(&mesh).expect("manifold");
    geofit::mesh::ControlMesh::try_new(&mesh).expect("valid control mesh");
}

/// Splitting with Loop's masks keeps the limit surface exactly when every face is split (one
/// Loop step). A partial red–green split mixes levels at the transition, which moves the
/// surface there (on this very coarse mesh by a few %); the following iterations absorb it.
#[test]
fn loop_split_keeps_the_limit_surface() {
    use geofit::subdiv::adaptive::{split_triangles, SplitRule};
    let control = perturbed(&sphere_mesh(1), 0.1, &mut Rng(31));
    let truth = surface_of(Scheme::Loop, &control, &[]).expect("surface");
    let data = sample(&truth, 20, &mut Rng(32));
    let n = control.num_faces();
    for (marked, bound) in [
        (vec![true; n], 1e-6),
        ((0..n).map(|f| f % 3 == 0).collect(), 5.0),
    ] {
        let refined = split_triangles(&control, &marked, SplitRule::Loop, &[]).expect("split");
        let fitter = SubdivFitter::<SubdivSurface>::try_new(
            &data,
            refined,
            Scheme::Loop,
            SubdivFitOptions::default(),
        )
        .expect("fitter");
        let e = fitter.stats().e_max_pct;
        eprintln!(
            "split of {} faces: E_max {e} %",
            marked.iter().filter(|&&m| m).count()
        );
        assert!(e < bound, "E_max {e} %");
    }
}
