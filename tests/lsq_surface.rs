//! Smoothed least-squares B-spline surface fitting (SPEC §2): exact reproduction, smoothing
//! monotonicity, parameter correction, adaptive splitting, fold detection and typed errors.

use geofit::fit::energies;
use geofit::fit::{parameterize, parameterize_on_surface};
use geofit::fit::{
    FitError, FitStatus, Fitter, FoldPolicy, LsqSurfaceFitter, LsqSurfaceOptions, ParamOptions,
    Parameterization, TolMode,
};
use geofit::geom::{Point3, Vec3};
use geofit::spline::{BSplineSurface, KnotVector};

/// Deterministic pseudo-random numbers in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn reference_surface() -> BSplineSurface {
    let ku =
        KnotVector::try_new(3, vec![0.0, 0.0, 0.0, 0.0, 0.25, 0.6, 1.0, 1.0, 1.0, 1.0]).unwrap();
    let kv = KnotVector::try_new(3, vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0]).unwrap();
    let control = (0..30)
        .map(|k| {
            let (i, j) = ((k / 5) as f64, (k % 5) as f64);
            Point3::new(i * 0.2, j * 0.25, 0.1 * (1.1 * i).sin() * (0.9 * j).cos())
        })
        .collect();
    BSplineSurface::try_new(ku, kv, control).unwrap()
}

fn samples(s: &BSplineSurface, n: usize, rng: &mut Rng) -> (Vec<Point3>, Vec<[f64; 2]>) {
    let uv: Vec<[f64; 2]> = (0..n).map(|_| [rng.next(), rng.next()]).collect();
    (uv.iter().map(|t| s.eval(t[0], t[1])).collect(), uv)
}

fn given(uv: Vec<[f64; 2]>) -> Parameterization {
    let n = uv.len();
    Parameterization {
        uv,
        folded: vec![false; n],
        num_folded: 0,
        frame: None,
    }
}

/// A surface with the reference knots and zero control points: only its knots are used.
fn blank_like(s: &BSplineSurface) -> BSplineSurface {
    let (nu, nv) = s.num_control();
    BSplineSurface::try_new(
        s.knots_u().clone(),
        s.knots_v().clone(),
        vec![Point3::ZERO; nu * nv],
    )
    .unwrap()
}

#[test]
fn reproduces_an_exact_bspline_from_its_samples() {
    let s = reference_surface();
    let (points, uv) = samples(&s, 2000, &mut Rng(7));
    let opts = LsqSurfaceOptions::default()
        .with_betas(0.0, 0.0)
        .with_fixed_knots(true)
        .with_solves_per_knots(1);
    let mut fit =
        LsqSurfaceFitter::with_parameters(&points, given(uv), blank_like(&s), opts).unwrap();
    fit.step().unwrap();
    for (a, b) in fit
        .surface()
        .control_points()
        .iter()
        .zip(s.control_points())
    {
        assert!((*a - *b).length() < 1e-10, "{a} vs {b}");
    }
    assert!(fit.stats().e_max < 1e-10);
}

#[test]
fn smoothing_lowers_the_energies_monotonically() {
    let s = reference_surface();
    let mut rng = Rng(11);
    let (mut points, uv) = samples(&s, 1500, &mut rng);
    for p in &mut points {
        p.z += 0.01 * (rng.next() - 0.5);
    }
    let fit_with = |b2: f64, b3: f64| {
        let opts = LsqSurfaceOptions::default()
            .with_betas(b2, b3)
            .with_fixed_knots(true)
            .with_solves_per_knots(1);
        let mut f =
            LsqSurfaceFitter::with_parameters(&points, given(uv.clone()), blank_like(&s), opts)
                .unwrap();
        f.step().unwrap();
        energies(f.surface())
    };
    let betas = [0.0, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3];
    let e2: Vec<f64> = betas.iter().map(|&b| fit_with(b, 0.0).0).collect();
    let e3: Vec<f64> = betas.iter().map(|&b| fit_with(0.0, b).1).collect();
    for w in e2.windows(2) {
        assert!(w[1] <= w[0] * (1.0 + 1e-9), "E2 {e2:?}");
    }
    for w in e3.windows(2) {
        assert!(w[1] <= w[0] * (1.0 + 1e-9), "E3 {e3:?}");
    }
    assert!(e2[5] < 0.5 * e2[0] && e3[5] < 0.5 * e3[0], "{e2:?} {e3:?}");
}

/// A dome, z = 0.3 (1 − x² − y²) over [−1, 1]², sampled on a jittered grid.
fn dome(n: usize, rng: &mut Rng) -> Vec<Point3> {
    (0..n * n)
        .map(|k| {
            let x = -1.0 + 2.0 * ((k / n) as f64 + rng.next()) / n as f64;
            let y = -1.0 + 2.0 * ((k % n) as f64 + rng.next()) / n as f64;
            Point3::new(
                x,
                y,
                0.3 * (1.0 - x * x - y * y) + 0.2 * (3.0 * x).sin() * y,
            )
        })
        .collect()
}

#[test]
fn parameter_correction_reduces_the_error() {
    let points = dome(40, &mut Rng(3));
    let opts = LsqSurfaceOptions::default()
        .with_control(7, 7)
        .with_fixed_knots(true)
        .with_solves_per_knots(4)
        .with_betas(1e-12, 0.0)
        .with_tolerance(1e-6, TolMode::Exact)
        .with_param(ParamOptions::default().with_view(Vec3::Z));
    let mut fit = LsqSurfaceFitter::try_new(&points, opts).unwrap();
    assert_eq!(fit.run().unwrap(), FitStatus::MaxIterations);
    let h = fit.history();
    assert_eq!(h.len(), 4);
    assert!(h[3].e_rms_pct < 0.9 * h[0].e_rms_pct, "{h:?}");
    for w in h.windows(2) {
        assert!(w[1].e_rms_pct < w[0].e_rms_pct, "{h:?}");
    }
}

#[test]
fn adaptive_splitting_meets_the_tolerance() {
    let points = dome(50, &mut Rng(5));
    for mode in [TolMode::Exact, TolMode::Noisy] {
        let opts = LsqSurfaceOptions::default()
            .with_control(4, 4)
            .with_tolerance(0.05, mode)
            .with_min_sample(4)
            .with_betas(1e-9, 1e-12);
        let mut fit = LsqSurfaceFitter::try_new(&points, opts).unwrap();
        assert_eq!(
            fit.run().unwrap(),
            FitStatus::Converged,
            "{:?}",
            fit.history()
        );
        let last = fit.history().last().unwrap();
        assert!(last.control_points > 16);
        if mode == TolMode::Exact {
            assert!(last.e_max_pct <= 0.05, "{last:?}");
        }
        assert!(fit.history().iter().any(|r| r.refined));
    }
}

#[test]
fn knots_far_from_the_tolerance_are_split_after_one_solve() {
    let points = dome(50, &mut Rng(5));
    // Which iterations refined, for a failing-share threshold of 0 (split as soon as any
    // patch fails) and 1 (always solve twice per knot vector).
    let refined = |share: f64| {
        let opts = LsqSurfaceOptions::default()
            .with_control(4, 4)
            .with_tolerance(0.01, TolMode::Exact)
            .with_max_iterations(6)
            .with_early_split_share(share)
            .with_param(ParamOptions::default().with_view(Vec3::Z));
        let mut fit = LsqSurfaceFitter::try_new(&points, opts).unwrap();
        fit.run().unwrap();
        fit.history().iter().map(|r| r.refined).collect::<Vec<_>>()
    };
    // Threshold 0: every iteration but the last refines.
    let early = refined(0.0);
    assert!(early.len() >= 4, "{early:?}");
    assert!(early[..early.len() - 1].iter().all(|&r| r), "{early:?}");
    // Threshold 1: two solves per knot vector, so refinements alternate.
    let late = refined(1.0);
    assert_eq!(late[..4], [false, true, false, true], "{late:?}");
    let bad = LsqSurfaceOptions::default().with_early_split_share(1.5);
    let err = LsqSurfaceFitter::try_new(&points, bad)
        .err()
        .expect("rejected");
    assert!(err.to_string().contains("early_split_share"), "{err}");
}

/// A sheet folded over itself along x: z = 0 for x in [0, 1], then back over x in [0.5, 1]
/// at z = 0.3.
fn folded_sheet() -> Vec<Point3> {
    let mut pts = Vec::new();
    for i in 0..60 {
        for j in 0..30 {
            let (x, y) = (i as f64 / 59.0, j as f64 / 29.0);
            pts.push(Point3::new(x, y, 0.0));
        }
    }
    for i in 0..15 {
        for j in 0..30 {
            pts.push(Point3::new(
                0.55 + 0.4 * i as f64 / 14.0,
                j as f64 / 29.0,
                0.3,
            ));
        }
    }
    pts
}

#[test]
fn fold_over_is_detected() {
    let pts = folded_sheet();
    let view = ParamOptions::default().with_view(Vec3::Z);
    let err = parameterize(&pts, &view.with_fold_policy(FoldPolicy::Fail)).unwrap_err();
    match err {
        FitError::FoldedProjection { count, total, .. } => {
            assert_eq!(total, pts.len());
            assert_eq!(count, 450, "the whole upper layer and nothing else");
        }
        other => panic!("unexpected {other}"),
    }
    let p = parameterize(&pts, &view).unwrap();
    assert_eq!(p.num_folded, 450);
    assert!(p.folded[..1800].iter().all(|f| !f));
    // Excluding folded points, the fit still runs and they stay measured.
    let opts = LsqSurfaceOptions::default()
        .with_control(5, 5)
        .with_fixed_knots(true)
        .with_param(view.with_fold_policy(FoldPolicy::Exclude));
    let mut fit = LsqSurfaceFitter::try_new(&pts, opts).unwrap();
    fit.run().unwrap();
    assert_eq!(fit.num_folded(), 450);
    assert_eq!(fit.point_errors().len(), pts.len());
    assert!(fit.point_errors()[..1800].iter().all(|d| d.abs() < 1e-6));
}

#[test]
fn steep_single_sheet_is_not_folded() {
    let mut pts = Vec::new();
    for i in 0..80 {
        for j in 0..30 {
            let x = i as f64 / 79.0;
            pts.push(Point3::new(
                x,
                j as f64 / 29.0,
                0.4 * (12.0 * (x - 0.5)).tanh(),
            ));
        }
    }
    let p = parameterize(&pts, &ParamOptions::default().with_view(Vec3::Z)).unwrap();
    assert_eq!(p.num_folded, 0);
}

#[test]
fn base_surface_parameterisation_recovers_parameters() {
    let s = reference_surface();
    let (points, uv) = samples(&s, 300, &mut Rng(19));
    let p = parameterize_on_surface(&points, &s, &ParamOptions::default()).unwrap();
    for (a, b) in p.uv.iter().zip(&uv) {
        assert!((a[0] - b[0]).abs() < 1e-8 && (a[1] - b[1]).abs() < 1e-8);
    }
    assert_eq!(p.num_folded, 0);
}

#[test]
fn bad_input_gives_typed_errors() {
    let opts = LsqSurfaceOptions::default();
    let few = vec![Point3::ZERO, Point3::X];
    assert!(matches!(
        LsqSurfaceFitter::try_new(&few, opts),
        Err(FitError::TooFewPoints { found: 2, .. })
    ));
    let mut pts = dome(10, &mut Rng(1));
    pts[17].x = f64::NAN;
    assert!(matches!(
        LsqSurfaceFitter::try_new(&pts, opts),
        Err(FitError::NonFinitePoint { index: 17 })
    ));
    // A vertical plane seen from above projects onto a segment.
    let wall: Vec<Point3> = (0..100)
        .map(|k| Point3::new(0.0, (k % 10) as f64, (k / 10) as f64))
        .collect();
    let top = opts.with_param(ParamOptions::default().with_view(Vec3::Z));
    assert!(matches!(
        LsqSurfaceFitter::try_new(&wall, top),
        Err(FitError::DegenerateProjection { .. })
    ));
    let line: Vec<Point3> = (0..100)
        .map(|k| Point3::new(k as f64, 2.0 * k as f64, 0.0))
        .collect();
    assert!(matches!(
        LsqSurfaceFitter::try_new(&line, opts),
        Err(FitError::DegenerateProjection { .. })
    ));
    let zero_view = opts.with_param(ParamOptions::default().with_view(Vec3::ZERO));
    assert!(matches!(
        LsqSurfaceFitter::try_new(&dome(10, &mut Rng(1)), zero_view),
        Err(FitError::InvalidOption { .. })
    ));
    assert!(matches!(
        LsqSurfaceFitter::try_new(&dome(10, &mut Rng(1)), opts.with_betas(-1.0, 0.0)),
        Err(FitError::InvalidOption { name: "beta2", .. })
    ));
    assert!(matches!(
        LsqSurfaceFitter::try_new(&dome(10, &mut Rng(1)), opts.with_control(3, 8)),
        Err(FitError::InvalidOption { name: "grid", .. })
    ));
    assert!(matches!(
        LsqSurfaceFitter::try_new(
            &dome(10, &mut Rng(1)),
            opts.with_tolerance(f64::NAN, TolMode::Exact)
        ),
        Err(FitError::InvalidOption { .. })
    ));
}
