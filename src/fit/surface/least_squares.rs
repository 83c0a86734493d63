//! Smoothed least-squares fitting of one tensor-product B-spline surface to a noisy scan
//! (SPEC §2).
//!
//! The control points minimise E1 + β2·E2 + β3·E3: E1 = Σ |S(u_s, v_s) − Q_s|² over the data,
//! E2 the thin-plate energy ∬ |S_uu|² + 2|S_uv|² + |S_vv|², E3 the curvature-variation energy
//! ∬ |S_uuu|² + 3|S_uuv|² + 3|S_uvv|² + |S_vvv|². E1 is divided by the number of points so
//! that β is independent of the sampling. The weights vary per patch with the relative point
//! density ρ: β2/ρ and β3·ρ, so sparse or empty patches are held flat and dense noisy ones are
//! held smooth in curvature.
//!
//! The normal equations are assembled directly in sparse form — each point couples the
//! (p + 1)(q + 1) basis functions it touches, each energy cell a (p + 1)(q + 1) block, the
//! 1D energy integrals exact by Gauss–Legendre quadrature over the knot spans — and solved by a
//! sparse Cholesky factorisation whose symbolic part is reused for every solve with the same
//! knots. Each iteration solves, then corrects the parameters (Newton foot points), then
//! splits the patches that miss the tolerance, worst first.

use super::folds::Stiffness;
use super::normal_system::{for_cell_pairs, span_gram, NormalSystem};
use super::parameterize::{check_points, parameterize, Parameterization};
use super::patches::{failing_share, split_worst, PatchGrid};
use super::{check_early_split_share, plane_surface, SurfaceFit, SurfaceGrid};
use crate::fit::{FitError, FitState, FitStatus, Fitter, Method, Shape, Spline};
use crate::geom::Point3;
use crate::spline::BSplineSurface;
use faer::Mat;
use web_time::Instant;

/// Options of [`LsqSurfaceFitter`]. Defaults in brackets on each field.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct LsqSurfaceOptions {
    /// The control grid, its splitting and the tolerance, shared with the geometric method.
    /// With fixed knots the fit only re-solves with corrected parameters.
    pub grid: SurfaceGrid,
    /// Thin-plate weight β2, scaled per patch by 1/ρ [1e-12: enough to hold empty patches,
    /// small against the data term where there are points].
    pub beta2: f64,
    /// Curvature-variation weight β3, scaled per patch by ρ [1e-15].
    pub beta3: f64,
    /// Solves (each followed by parameter correction) per knot vector [2; with fixed knots
    /// [`LsqSurfaceOptions::FIXED_KNOT_SOLVES`]].
    pub solves_per_knots: usize,
    /// Share of the non-empty patches above which the fit splits right after the first solve
    /// on a knot vector, without the further solves of `solves_per_knots` (not with fixed
    /// knots, which never split) [0.25].
    ///
    /// Why: while most patches miss TOL (the coarse start of an adaptive fit) the split is
    /// certain, and a second solve would only refine parameters that the finer surface corrects
    /// anyway; near the end a second solve with corrected parameters keeps a patch from being
    /// split on an error that parameter correction alone removes. On bun000.ply at tol 0.05
    /// (noisy) this takes 10 instead of 14 iterations for 29,241 instead of 28,362 control points.
    pub early_split_share: f64,
    /// Iteration cap [30].
    pub max_iterations: usize,
    /// Newton iterations per point in parameter correction (warm-started) [4].
    pub newton_iterations: usize,
}

impl LsqSurfaceOptions {
    /// The defaults, as each field documents them.
    pub const DEFAULT: LsqSurfaceOptions = LsqSurfaceOptions {
        grid: SurfaceGrid::DEFAULT,
        beta2: 1e-12,
        beta3: 1e-15,
        solves_per_knots: 2,
        early_split_share: 0.25,
        max_iterations: 30,
        newton_iterations: 4,
    };

    /// Solves per knot vector when the knots are fixed: each parameter correction still lowers
    /// the error markedly up to about the fourth (on bun000.ply at 400 control points E_max
    /// 2.05, 1.79, 1.55, 1.44 %), and with fixed knots there is no splitting to continue from.
    pub const FIXED_KNOT_SOLVES: usize = 4;

    pub(crate) fn grid_mut(&mut self) -> &mut SurfaceGrid {
        &mut self.grid
    }

    /// Checks every option's range.
    pub fn validate(&self) -> Result<(), FitError> {
        self.grid.validate()?;
        for (name, b) in [("beta2", self.beta2), ("beta3", self.beta3)] {
            if !(b.is_finite() && b >= 0.0) {
                return Err(FitError::InvalidOption {
                    name,
                    reason: format!("{b} must be a finite number ≥ 0"),
                });
            }
        }
        check_early_split_share(self.early_split_share)?;
        if self.solves_per_knots == 0 {
            return Err(FitError::InvalidOption {
                name: "solves",
                reason: "must be at least 1".into(),
            });
        }
        Ok(())
    }
}

default_is_const!(LsqSurfaceOptions);

setters!(LsqSurfaceOptions {
    /// Sets β2 and β3.
    with_betas(beta2: f64, beta3: f64) => |s| s.beta2, s.beta3;
    /// Sets the number of solves per knot vector.
    with_solves_per_knots(solves_per_knots: usize) => |s| s.solves_per_knots;
    /// Sets the failing share of patches above which a knot vector is split after one solve.
    with_early_split_share(early_split_share: f64) => |s| s.early_split_share;
});

/// Smoothed least-squares B-spline surface fitter (SPEC §2), driven through [`Fitter`].
pub struct LsqSurfaceFitter {
    fit: SurfaceFit,
    opts: LsqSurfaceOptions,
    system: Option<NormalSystem>,
    solves_at_knots: usize,
    /// Parameter area of an initial patch over the domain's: the reference of the per-patch
    /// weight scaling (see [`patch_weights`]).
    ref_cell_area: f64,
    /// Extra weight of the patches that folded (see [`super::folds`]).
    stiffness: Stiffness,
    /// What the last full solve assembled, for [`LsqSurfaceFitter::resolve_stiffened`].
    last: Option<LastSolve>,
    /// E_back (%) when the patches last all passed and the surface strayed: the next time,
    /// it must have fallen for the fit to go on (see [`LsqSurfaceFitter::back_gate`]).
    strayed_pct: f64,
}

/// The right-hand side of the last full solve and its per-patch energy weights (β2 and β3
/// included, before the stiffness factors), with the patch grid and the points per patch they
/// were made for (the fold check's too).
struct LastSolve {
    rhs: Mat<f64>,
    energy: Vec<[f64; 2]>,
    grid: PatchGrid,
    held: Vec<usize>,
}

/// Control points beyond a stiffened patch's own that its window frees, per side: two patch
/// supports, so the held points lie where the change has died out.
const WINDOW_PAD: usize = 8;

/// A re-solve by windows is used while the windows hold less than 1/`WINDOW_SHARE` of the
/// control points.
const WINDOW_SHARE: usize = 4;

/// The control-point rectangles (rows, columns) freed for the re-solve after stiffening the
/// patches `changed` of `grid`: each patch's (p + 1) × (q + 1) control points padded by
/// [`WINDOW_PAD`], merged while two come within the coupling reach (p rows, q columns) of
/// each other, so that no two windows share an equation.
fn stiffened_windows(
    grid: &PatchGrid,
    changed: &[usize],
    (nu, nv): (usize, usize),
    (p, q): (usize, usize),
) -> Vec<(std::ops::Range<usize>, std::ops::Range<usize>)> {
    let span = |first: usize, order: usize, n: usize| {
        first.saturating_sub(WINDOW_PAD)..(first + order + WINDOW_PAD).min(n)
    };
    let mut windows: Vec<_> = changed
        .iter()
        .map(|&i| {
            let (cu, cv) = (i / grid.v.len(), i % grid.v.len());
            (
                span(grid.u.knot_index(cu) - p, p + 1, nu),
                span(grid.v.knot_index(cv) - q, q + 1, nv),
            )
        })
        .collect();
    let near = |a: &std::ops::Range<usize>, b: &std::ops::Range<usize>, reach: usize| {
        a.start < b.end + reach && b.start < a.end + reach
    };
    let mut merged = true;
    while merged {
        merged = false;
        let mut out: Vec<(std::ops::Range<usize>, std::ops::Range<usize>)> = Vec::new();
        for w in windows {
            match out
                .iter_mut()
                .find(|o| near(&o.0, &w.0, p) && near(&o.1, &w.1, q))
            {
                Some(o) => {
                    o.0 = o.0.start.min(w.0.start)..o.0.end.max(w.0.end);
                    o.1 = o.1.start.min(w.1.start)..o.1.end.max(w.1.end);
                    merged = true;
                }
                None => out.push(w),
            }
        }
        windows = out;
    }
    windows
}

impl LsqSurfaceFitter {
    /// Sets up a fit of `points`: checks them and the options, and parameterises the points.
    pub fn try_new(points: &[Point3], opts: LsqSurfaceOptions) -> Result<Self, FitError> {
        let start = Instant::now();
        opts.validate()?;
        let g = opts.grid;
        let (nu, nv) = g.control;
        check_points(points, nu.min(nv).max(g.degree + 1))?;
        let param = parameterize(points, &g.param)?;
        let surface = plane_surface(&param, g.degree, g.control)?;
        Self::from_parts(points, param, surface, opts, start)
    }

    /// Sets up a fit from given parameters and an initial surface whose knots are used (its
    /// control points are replaced by the first solve).
    pub fn with_parameters(
        points: &[Point3],
        param: Parameterization,
        surface: BSplineSurface,
        opts: LsqSurfaceOptions,
    ) -> Result<Self, FitError> {
        let start = Instant::now();
        opts.validate()?;
        check_points(points, opts.grid.degree + 1)?;
        if param.uv.len() != points.len() {
            return Err(FitError::InvalidOption {
                name: "parameters",
                reason: format!("{} parameters for {} points", param.uv.len(), points.len()),
            });
        }
        Self::from_parts(points, param, surface, opts, start)
    }

    fn from_parts(
        points: &[Point3],
        param: Parameterization,
        surface: BSplineSurface,
        opts: LsqSurfaceOptions,
        start: Instant,
    ) -> Result<Self, FitError> {
        Ok(LsqSurfaceFitter {
            ref_cell_area: 1.0 / PatchGrid::of(&surface).len().max(1) as f64,
            fit: SurfaceFit::new(
                Method::LeastSquares,
                &opts.grid,
                points,
                param,
                surface,
                start,
            ),
            opts,
            system: None,
            solves_at_knots: 0,
            stiffness: Stiffness::default(),
            last: None,
            strayed_pct: f64::INFINITY,
        })
    }

    surface_accessors!();

    /// The energies (E2, E3) of the current surface over its whole domain, unweighted.
    pub fn energies(&self) -> (f64, f64) {
        energies(&self.fit.surface)
    }

    /// Solves the normal equations for the current knots and parameters.
    fn solve(&mut self) -> Result<(), FitError> {
        let surface = &self.fit.surface;
        let (nu, nv) = surface.num_control();
        let (p, q) = (surface.knots_u().degree(), surface.knots_v().degree());
        if self
            .system
            .as_ref()
            .is_none_or(|s| s.shape() != (nu, nv, p, q))
        {
            self.system = Some(NormalSystem::new(nu, nv, p, q)?);
        }
        let Some(system) = self.system.as_mut() else {
            return Ok(());
        };
        system.clear();
        let mut rhs = Mat::<f64>::zeros(nu * nv, 3);
        let count = system.add_points(surface, self.fit.samples(), &mut rhs);
        let grid = PatchGrid::of(surface);
        let held = patch_counts(surface, &grid, &self.fit.uv, &self.fit.active);
        let mut weights = patch_weights(surface, &grid, &held, count, self.ref_cell_area);
        let scale = count.max(1) as f64;
        let (b2, b3) = (self.opts.beta2 * scale, self.opts.beta3 * scale);
        for w in weights.iter_mut() {
            *w = [w[0] * b2, w[1] * b3];
        }
        let mut stiffened = weights.clone();
        for (w, f) in stiffened
            .iter_mut()
            .zip(self.stiffness.factors(surface, &grid))
        {
            *w = w.map(|x| x * f);
        }
        system.add_energies(surface, &grid, &stiffened, 1.0, 1.0);
        self.last = Some(LastSolve {
            rhs: rhs.clone(),
            energy: weights,
            grid,
            held,
        });
        let control = system.solve(rhs)?;
        self.set_control(&control)
    }

    fn set_control(&mut self, control: &[Point3]) -> Result<(), FitError> {
        self.fit
            .surface
            .set_control_points(control)
            .map_err(|e| FitError::Solver {
                reason: e.to_string(),
            })
    }

    /// Re-solves after the patches `changed` were stiffened from `before` to `after` (their
    /// factors): adds the energy the stiffening adds to the assembled system, then solves for
    /// the control points near those patches alone, the others held, window by window (a block
    /// Gauss–Seidel step on the new system). When the windows would cover much of the grid it
    /// solves the whole updated system instead (a new factorisation, but no new assembly of
    /// the points: that was a third of a solve's time at 10,000 control points).
    ///
    /// Why: the stiffening changes the solution only where it acts (the data pin the rest), and
    /// a window's factorisation costs a fraction of the whole grid's, which dominated the fit's
    /// time when every step solved twice.
    fn resolve_stiffened(
        &mut self,
        grid: &PatchGrid,
        before: &[f64],
        after: &[f64],
    ) -> Result<(), FitError> {
        let surface = &self.fit.surface;
        let (nu, nv) = surface.num_control();
        let (p, q) = (surface.knots_u().degree(), surface.knots_v().degree());
        let (Some(system), Some(last)) = (self.system.as_mut(), self.last.as_ref()) else {
            return self.solve();
        };
        let changed: Vec<usize> = (0..after.len())
            .filter(|&i| after[i] != before[i])
            .collect();
        let delta: Vec<[f64; 2]> = last
            .energy
            .iter()
            .zip(before.iter().zip(after))
            .map(|(w, (b, a))| w.map(|x| x * (a - b)))
            .collect();
        system.add_energies(surface, grid, &delta, 1.0, 1.0);
        let windows = stiffened_windows(grid, &changed, (nu, nv), (p, q));
        let area: usize = windows.iter().map(|(r, c)| r.len() * c.len()).sum();
        if area * WINDOW_SHARE > nu * nv {
            let control = system.solve(last.rhs.clone())?;
            return self.set_control(&control);
        }
        let mut x = surface.control_points().to_vec();
        for (rows, cols) in windows {
            let mut sub = system.window(rows.clone(), cols.clone())?;
            let wv = cols.len();
            let index = |k: usize| (rows.start + k / wv) * nv + cols.start + k % wv;
            let mut r = Mat::<f64>::zeros(rows.len() * wv, 3);
            for k in 0..rows.len() * wv {
                let g = index(k);
                let ax = system.row_times(g, &x);
                for d in 0..3 {
                    r[(k, d)] = last.rhs[(g, d)] - ax[d];
                }
            }
            for (k, dx) in sub.solve(r)?.into_iter().enumerate() {
                x[index(k)] += dx;
            }
        }
        self.set_control(&x)
    }

    /// Relaxes the stiffness of earlier steps, solves; where the solution folds beside the
    /// data, stiffens the patches and solves once more (see [`super::folds`]). Without
    /// smoothing (β2 = β3 = 0) there is nothing to stiffen.
    fn solve_without_folds(&mut self) -> Result<(), FitError> {
        self.stiffness.relax();
        self.solve()?;
        if self.opts.beta2 == 0.0 && self.opts.beta3 == 0.0 {
            return Ok(());
        }
        let Some(last) = self.last.as_mut() else {
            return Ok(());
        };
        let (grid, held) = (last.grid.clone(), std::mem::take(&mut last.held));
        let before = self.stiffness.factors(&self.fit.surface, &grid);
        if self
            .stiffness
            .stiffen_folds(&self.fit.surface, &grid, &held, &self.fit.c0)
            == 0
        {
            return Ok(());
        }
        let after = self.stiffness.factors(&self.fit.surface, &grid);
        self.resolve_stiffened(&grid, &before, &after)
    }
}

impl LsqSurfaceFitter {
    /// The status of a step whose patches all pass the tolerance: converged when the surface
    /// also stays within the surface → data bound (SPEC §6: a sheet or spike away from the
    /// data is not a fit). Where it strays beyond, the patches are held stiff for the rest of
    /// the fit ([`Stiffness::hold_strays`]) and the fit goes on; stalled when they are held
    /// already, there is no smoothing to stiffen, or E_back did not fall since the last hold.
    ///
    /// Why the last rule: a closed object fitted as one sheet strays next to its data too
    /// (where the sheet folds over at its silhouette), and holding those patches only spends
    /// iterations and control points: without the rule the cow took 8.7 s instead of 1.0 s
    /// and 30 iterations to stall at E_back 4.4 %.
    fn back_gate(&mut self, grid: &PatchGrid) -> FitStatus {
        let strays = self.fit.measure_strays();
        let back = self.fit.state.back().map_or(0.0, |b| b.max_pct);
        let falling = back < std::mem::replace(&mut self.strayed_pct, back);
        if strays.is_empty() {
            FitStatus::Converged
        } else if falling && (self.opts.beta2 > 0.0 || self.opts.beta3 > 0.0) && {
            let f = &self.fit;
            let held = patch_counts(&f.surface, grid, &f.uv, &f.active);
            self.stiffness.hold_strays(&f.surface, grid, &held, &strays) > 0
        } {
            FitStatus::Running
        } else {
            FitStatus::Stalled
        }
    }
}

impl Fitter for LsqSurfaceFitter {
    fn step(&mut self) -> Result<FitStatus, FitError> {
        if self.status() != FitStatus::Running {
            return Ok(self.status());
        }
        let start = Instant::now();
        self.solve_without_folds()?;
        self.solves_at_knots += 1;
        self.fit.correct(self.opts.newton_iterations);
        let (grid, errors) = self.fit.judge(&self.opts.grid);
        let all_pass = errors.iter().all(|e| e.pass);
        let mut refined = false;
        let fixed = self.opts.grid.fixed_knots;
        let last = self.log().iterations() + 1 >= self.opts.max_iterations;
        let status = if all_pass {
            match self.back_gate(&grid) {
                FitStatus::Running if last => FitStatus::MaxIterations,
                gate => gate,
            }
        } else if self.log().iterations() + 1 >= self.opts.max_iterations {
            FitStatus::MaxIterations
        } else if self.solves_at_knots < self.opts.solves_per_knots
            && (fixed || failing_share(&errors) <= self.opts.early_split_share)
        {
            FitStatus::Running
        } else if fixed {
            FitStatus::MaxIterations
        } else {
            // Halving a span divides the error by about 2^(p + 1) (see split_worst).
            let s = &self.fit.surface;
            let p = s.knots_u().degree().min(s.knots_v().degree());
            let tol = self.opts.grid.criterion(self.fit.state.diagonal()).tol;
            let quarter_above = tol * 2f64.powi(p as i32 + 1);
            let inserted = split_worst(
                &mut self.fit.surface,
                &grid,
                &errors,
                self.opts.grid.max_control_points,
                quarter_above,
            );
            refined = inserted > 0;
            self.solves_at_knots = 0;
            if refined {
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

/// The factors of β2 and β3 of every patch: 1/ρ and ρ (SPEC §2), with ρ the relative point
/// density (points per parameter area over points per domain area, kept within [1/64, 64] so
/// empty patches get a finite weight), times s² and s³ for s = the patch's parameter area over
/// `ref_area` (at most 1); `counts` are the points of the fit per patch.
///
/// Why s: a feature that a patch of width h must follow has S_uu ~ 1/h² and S_uuu ~ 1/h³, so
/// against the data term of the patch's points the thin-plate energy grows like 1/h⁴ and the
/// curvature-variation energy like 1/h⁶ as patches are split. Without s, splitting would make
/// the fit stiffer exactly where it must follow the data more closely, and the adaptive fit
/// could not reach a fine tolerance; with s, a split patch is smoothed as much, relative to its
/// own size, as the initial patches.
fn patch_weights(
    surface: &BSplineSurface,
    grid: &PatchGrid,
    counts: &[usize],
    count: usize,
    ref_area: f64,
) -> Vec<[f64; 2]> {
    let ((u0, u1), (v0, v1)) = surface.domain();
    let area = (u1 - u0) * (v1 - v0);
    let (ku, kv) = (surface.knots_u().knots(), surface.knots_v().knots());
    counts
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            let (su, sv) = (
                grid.u.knot_index(i / grid.v.len()),
                grid.v.knot_index(i % grid.v.len()),
            );
            let cell_area = (ku[su + 1] - ku[su]) * (kv[sv + 1] - kv[sv]) / area;
            let rho = (c as f64 / (cell_area * count.max(1) as f64)).clamp(1.0 / 64.0, 64.0);
            let s = (cell_area / ref_area).min(1.0);
            [s * s / rho, s * s * s * rho]
        })
        .collect()
}

/// The number of points taking part in the fit in every patch.
fn patch_counts(
    surface: &BSplineSurface,
    grid: &PatchGrid,
    uv: &[[f64; 2]],
    active: &[bool],
) -> Vec<usize> {
    let mut counts = vec![0usize; grid.len()];
    for (t, _) in uv.iter().zip(active).filter(|x| *x.1) {
        counts[grid.patch(surface, t[0], t[1])] += 1;
    }
    counts
}

/// E2 and E3 of `surface`, unweighted, from the same exact quadrature as the fit.
pub fn energies(surface: &BSplineSurface) -> (f64, f64) {
    let grid = PatchGrid::of(surface);
    let nv = surface.num_control().1;
    let ctrl = surface.control_points();
    let (mut e2, mut e3) = (0.0, 0.0);
    for cu in 0..grid.u.len() {
        let gu = span_gram(surface.knots_u(), grid.u.knot_index(cu));
        for cv in 0..grid.v.len() {
            let gv = span_gram(surface.knots_v(), grid.v.knot_index(cv));
            let (fu, fv) = (
                grid.u.knot_index(cu) - gu.degree,
                grid.v.knot_index(cv) - gv.degree,
            );
            for_cell_pairs(&gu, &gv, |a, b, c, d, w2, w3| {
                let dot = ctrl[(fu + a) * nv + fv + b].dot(ctrl[(fu + c) * nv + fv + d]);
                e2 += w2 * dot;
                e3 += w3 * dot;
            });
        }
    }
    (e2, e3)
}
