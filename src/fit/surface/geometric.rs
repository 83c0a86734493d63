//! Geometric fitting of a tensor-product B-spline surface (SPEC §1, applied to B-splines):
//! no linear system. Each iteration finds the foot points by Newton, distributes every error
//! vector e_s = Q_s − S(u_s, v_s) to the (p + 1)(q + 1) control points of its patch weighted
//! by the basis values there, normalises per control point (d = Σ N e / Σ N), and moves the
//! control points, with Anderson acceleration and a damping guard that falls back to the plain
//! step when the error grows. Where the error stays above the tolerance, knots are inserted in
//! the worst patches (the surface is unchanged by insertion, so the fit continues from where it
//! was).

use super::parameterize::{check_points, parameterize, Parameterization};
use super::patches::{failing_share, split_worst};
use super::{
    check_early_split_share, plane_surface, LsqSurfaceFitter, LsqSurfaceOptions, SurfaceFit,
    SurfaceGrid,
};
use crate::fit::accel::Accelerator;
use crate::fit::{
    Acceleration, FitError, FitLog, FitState, FitStatus, Fitter, Method, Shape, Spline,
};
use crate::geom::{Point3, Vec3};
use crate::spline::BSplineSurface;
use web_time::Instant;

/// Options of [`GeometricSurfaceFitter`]. Defaults in brackets on each field.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct GeometricSurfaceOptions {
    /// The control grid, its splitting and the tolerance, shared with least squares.
    pub grid: SurfaceGrid,
    /// Acceleration of the control-point moves [[`Acceleration::ANDERSON`]].
    pub acceleration: Acceleration,
    /// Iterations on one knot vector before refining, unless the error stalls earlier
    /// (relative E_rms gain under 1 %) [12].
    pub iterations_per_knots: usize,
    /// Refine after this many iterations on a knot vector while more than `early_split_share`
    /// of the patches holding points miss TOL [4].
    ///
    /// Why: an iteration costs about the same on any knot vector (its work is per data point),
    /// so iterating a coarse surface that must be split anyway is the dearest way to lower the
    /// error. On bun000.ply at tol 0.1 % (noisy): 47 iterations and 11,067 control points
    /// instead of 64 and 10,440; at tol 0.05 % E_max 0.083 % instead of 0.123 % when both stop
    /// at the 40,000 cap.
    pub early_split_after: usize,
    /// See `early_split_after` [0.5].
    pub early_split_share: f64,
    /// Iteration cap [200].
    pub max_iterations: usize,
    /// Newton iterations per point and iteration (warm-started) [3].
    pub newton_iterations: usize,
    /// Start from one smoothed least-squares solve ([`LsqSurfaceFitter`] with its default
    /// weights, then a parameter correction) instead of the flat control net over the
    /// projection plane [false]. The error-vector iteration converges linearly from wherever
    /// it starts; from the flat net most of its iterations only lift the net onto the data,
    /// which one sparse solve does at the cost of about one iteration — worth it on fixed knots
    /// (bun000.ply, 400 control points: E_max 1.56 % after 3 iterations instead of 4.5 %).
    /// With adaptive splitting it is not: the warm fit's gains fall under the stall threshold
    /// sooner, so it splits earlier and ends with more control points (tol 0.1 %: 18,850
    /// instead of 10,350).
    pub warm_start: bool,
}

impl GeometricSurfaceOptions {
    /// The defaults, as each field documents them.
    pub const DEFAULT: GeometricSurfaceOptions = GeometricSurfaceOptions {
        grid: SurfaceGrid::DEFAULT,
        acceleration: Acceleration::ANDERSON,
        iterations_per_knots: 12,
        early_split_after: 4,
        early_split_share: 0.5,
        max_iterations: 200,
        newton_iterations: 3,
        warm_start: false,
    };

    pub(crate) fn grid_mut(&mut self) -> &mut SurfaceGrid {
        &mut self.grid
    }

    /// Checks every option's range.
    pub fn validate(&self) -> Result<(), FitError> {
        self.grid.validate()?;
        self.acceleration.validate()?;
        check_early_split_share(self.early_split_share)
    }
}

default_is_const!(GeometricSurfaceOptions);

setters!(GeometricSurfaceOptions {
    /// Sets when a knot vector is split early: after `iterations` while more than `share` of
    /// the patches fail.
    with_early_split(iterations: usize, share: f64) => |s| s.early_split_after, s.early_split_share;
    /// Sets the acceleration.
    with_acceleration(acceleration: Acceleration) => |s| s.acceleration;
    /// Starts from a least-squares solve (true) or from the flat control net (false).
    with_warm_start(warm_start: bool) => |s| s.warm_start;
});

/// Geometric (error-vector) B-spline surface fitter, driven through [`Fitter`].
pub struct GeometricSurfaceFitter {
    fit: SurfaceFit,
    opts: GeometricSurfaceOptions,
    accel: Accelerator,
    iters_at_knots: usize,
}

impl GeometricSurfaceFitter {
    /// Sets up a fit: checks points and options, parameterises the points by projection and
    /// starts from the flat control net over the projection plane.
    pub fn try_new(points: &[Point3], opts: GeometricSurfaceOptions) -> Result<Self, FitError> {
        let start = Instant::now();
        opts.validate()?;
        let g = opts.grid;
        check_points(points, g.degree + 1)?;
        let mut param = parameterize(points, &g.param)?;
        let mut surface = plane_surface(&param, g.degree, g.control)?;
        if opts.warm_start {
            (surface, param.uv) = least_squares_start(points, param.clone(), surface, &opts)?;
        }
        let mut fitter = GeometricSurfaceFitter {
            fit: SurfaceFit::new(Method::Geometric, &g, points, param, surface, start),
            opts,
            accel: Accelerator::new(opts.acceleration),
            iters_at_knots: 0,
        };
        fitter.fit.correct(opts.newton_iterations);
        *fitter.fit.state.log_mut() = FitLog::new(g.control.0 * g.control.1, start);
        Ok(fitter)
    }

    surface_accessors!();

    /// The normalised basis-weighted error vector of every control point (zero where no
    /// point's patch reaches it).
    fn moves(&self) -> Vec<Vec3> {
        let s = &self.fit.surface;
        let (nu, nv) = s.num_control();
        let (p, q) = (s.knots_u().degree(), s.knots_v().degree());
        let mut num = vec![Vec3::ZERO; nu * nv];
        let mut den = vec![0.0; nu * nv];
        for (pt, t) in self.fit.samples() {
            // One basis evaluation gives both the foot point and the weights.
            let b = s.basis(t[0], t[1]);
            let ctrl = s.control_points();
            let mut foot = Vec3::ZERO;
            for r in 0..=p {
                for k in 0..=q {
                    foot += b.bu[r] * b.bv[k] * ctrl[(b.first_u + r) * nv + b.first_v + k];
                }
            }
            let e = *pt - foot;
            for r in 0..=p {
                for k in 0..=q {
                    let c = (b.first_u + r) * nv + b.first_v + k;
                    let w = b.bu[r] * b.bv[k];
                    num[c] += e * w;
                    den[c] += w;
                }
            }
        }
        num.iter()
            .zip(&den)
            .map(|(n, &d)| if d > 1e-12 { *n / d } else { Vec3::ZERO })
            .collect()
    }

    /// Moves the control points (accelerated), keeping the plain step when the accelerated one
    /// raises the RMS error.
    fn move_control_points(&mut self) -> Result<(), FitError> {
        let before = self.fit.state.stats();
        let x = self.fit.surface.control_points().to_vec();
        let d = self.moves();
        let proposed = self.accel.propose(&x, &d);
        self.fit.surface.set_control_points(&proposed)?;
        let uv_saved = self.fit.uv.clone();
        let errors_saved = self.fit.state.errors().to_vec();
        let newton = self.opts.newton_iterations;
        self.fit.correct(newton);
        if self.fit.state.stats().e_rms > before.e_rms && proposed != plain_step(&x, &d) {
            // Damping: the accelerated step overshot; take the plain one and forget history.
            self.accel.reset();
            self.fit.surface.set_control_points(&plain_step(&x, &d))?;
            self.fit.uv = uv_saved;
            self.fit.state.restore(errors_saved, before);
            self.fit.correct(newton);
        }
        Ok(())
    }
}

/// One smoothed least-squares solve on the knots of `surface` with the parameters `param`,
/// followed by a parameter correction: the warm start (surface, corrected parameters).
fn least_squares_start(
    points: &[Point3],
    param: Parameterization,
    surface: BSplineSurface,
    opts: &GeometricSurfaceOptions,
) -> Result<(BSplineSurface, Vec<[f64; 2]>), FitError> {
    let lsq = LsqSurfaceOptions {
        grid: opts.grid.with_fixed_knots(true),
        solves_per_knots: 1,
        ..LsqSurfaceOptions::DEFAULT
    };
    let mut fitter = LsqSurfaceFitter::with_parameters(points, param, surface, lsq)?;
    fitter.step()?;
    Ok((fitter.surface().clone(), fitter.parameters().to_vec()))
}

fn plain_step(x: &[Point3], d: &[Vec3]) -> Vec<Point3> {
    x.iter().zip(d).map(|(a, b)| *a + *b).collect()
}

impl Fitter for GeometricSurfaceFitter {
    fn step(&mut self) -> Result<FitStatus, FitError> {
        if self.status() != FitStatus::Running {
            return Ok(self.status());
        }
        let start = Instant::now();
        let rms_before = self.fit.state.stats().e_rms;
        self.move_control_points()?;
        self.iters_at_knots += 1;
        let (grid, errors) = self.fit.judge(&self.opts.grid);
        let stalled = self.fit.state.stats().e_rms > 0.99 * rms_before;
        let split_early = self.iters_at_knots >= self.opts.early_split_after
            && failing_share(&errors) > self.opts.early_split_share;
        let due = stalled || split_early || self.iters_at_knots >= self.opts.iterations_per_knots;
        let mut refined = false;
        let all_pass = errors.iter().all(|e| e.pass);
        let status = if all_pass {
            // Nothing in the error-vector moves holds a patch that strays from the data
            // (the least-squares fit stiffens it): such a fit has stalled.
            if self.fit.measure_strays().is_empty() {
                FitStatus::Converged
            } else {
                FitStatus::Stalled
            }
        } else if self.log().iterations() + 1 >= self.opts.max_iterations {
            FitStatus::MaxIterations
        } else if !due {
            FitStatus::Running
        } else if self.opts.grid.fixed_knots {
            if stalled {
                FitStatus::MaxIterations
            } else {
                FitStatus::Running
            }
        } else {
            let inserted = split_worst(
                &mut self.fit.surface,
                &grid,
                &errors,
                self.opts.grid.max_control_points,
                f64::INFINITY,
            );
            refined = inserted > 0;
            self.iters_at_knots = 0;
            self.accel.reset();
            if refined || !stalled {
                FitStatus::Running
            } else {
                FitStatus::MaxIterations
            }
        };
        if !all_pass {
            self.fit.measure_back(status);
        }
        let n = self.fit.surface.control_points().len();
        Ok(self.fit.state.record(start, n, refined, status))
    }

    surface_fitter_methods!();
}
