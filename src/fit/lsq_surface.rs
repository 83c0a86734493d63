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

use super::parameterize::{parameterize, ParamOptions, Parameterization};
use super::patches::{
    correct_parameters, patch_errors, split_worst, Criterion, PatchError, PatchGrid, TolMode,
};
use super::{ErrorStats, FitError, FitStatus, Fitter, IterationRecord};
use crate::geom::{Aabb, Point3};
use crate::spline::{BSplineSurface, KnotVector, MAX_DEGREE};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Mat, Side};
use web_time::Instant;

/// Options of [`LsqSurfaceFitter`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct LsqSurfaceOptions {
    /// Degree in u and v. Default 3.
    pub degree: usize,
    /// Initial control points (u, v). Default (8, 8).
    pub control: (usize, usize),
    /// Keep the knots fixed (no patch splitting): the fit only re-solves with corrected
    /// parameters. Default false.
    pub fixed_knots: bool,
    /// Thin-plate weight β2 (scaled per patch by 1/ρ). Default 1e-12: enough to hold empty
    /// patches, small against the data term where there are points.
    pub beta2: f64,
    /// Curvature-variation weight β3 (scaled per patch by ρ). Default 1e-15.
    pub beta3: f64,
    /// Tolerance TOL, % of the bounding-box diagonal. Default 0.1.
    pub tol_pct: f64,
    /// How patches are judged against TOL. Default [`TolMode::Noisy`].
    pub tol_mode: TolMode,
    /// Cap on the control-point count when splitting. Default 40,000.
    pub max_control_points: usize,
    /// In [`TolMode::Noisy`], a patch with fewer points than this is judged on the points of
    /// its 3 × 3 patch neighbourhood (a 95 % share or a standard deviation of a handful of
    /// points says nothing about noise). Default 16.
    pub min_sample: usize,
    /// Solves (each followed by parameter correction) per knot vector. Default 2.
    pub solves_per_knots: usize,
    /// Iteration cap. Default 30.
    pub max_iterations: usize,
    /// Newton iterations per point in parameter correction (warm-started). Default 4.
    pub newton_iterations: usize,
    /// How the initial parameters are found.
    pub param: ParamOptions,
}

impl Default for LsqSurfaceOptions {
    fn default() -> Self {
        LsqSurfaceOptions {
            degree: 3,
            control: (8, 8),
            fixed_knots: false,
            beta2: 1e-12,
            beta3: 1e-15,
            tol_pct: 0.1,
            tol_mode: TolMode::Noisy,
            max_control_points: 40_000,
            min_sample: 16,
            solves_per_knots: 2,
            max_iterations: 30,
            newton_iterations: 4,
            param: ParamOptions::default(),
        }
    }
}

impl LsqSurfaceOptions {
    /// Sets the degree.
    pub fn with_degree(mut self, degree: usize) -> Self {
        self.degree = degree;
        self
    }
    /// Sets the initial control-point counts.
    pub fn with_control(mut self, nu: usize, nv: usize) -> Self {
        self.control = (nu, nv);
        self
    }
    /// Keeps the knots fixed.
    pub fn with_fixed_knots(mut self, fixed: bool) -> Self {
        self.fixed_knots = fixed;
        self
    }
    /// Sets β2 and β3.
    pub fn with_betas(mut self, beta2: f64, beta3: f64) -> Self {
        self.beta2 = beta2;
        self.beta3 = beta3;
        self
    }
    /// Sets the tolerance (%) and its mode.
    pub fn with_tolerance(mut self, tol_pct: f64, mode: TolMode) -> Self {
        self.tol_pct = tol_pct;
        self.tol_mode = mode;
        self
    }
    /// Sets the number of solves per knot vector.
    pub fn with_solves_per_knots(mut self, n: usize) -> Self {
        self.solves_per_knots = n;
        self
    }
    /// Sets the iteration cap.
    pub fn with_max_iterations(mut self, n: usize) -> Self {
        self.max_iterations = n;
        self
    }
    /// Sets the cap on control points.
    pub fn with_max_control_points(mut self, n: usize) -> Self {
        self.max_control_points = n;
        self
    }
    /// Sets the smallest sample (in points) of the noisy patch test.
    pub fn with_min_sample(mut self, n: usize) -> Self {
        self.min_sample = n;
        self
    }
    /// Sets the parameterisation options.
    pub fn with_param(mut self, param: ParamOptions) -> Self {
        self.param = param;
        self
    }

    /// Checks the ranges shared by both surface fitters.
    pub(crate) fn check(&self) -> Result<(), FitError> {
        check_common(self.degree, self.control, self.tol_pct)?;
        for (name, b) in [("beta2", self.beta2), ("beta3", self.beta3)] {
            if !(b.is_finite() && b >= 0.0) {
                return Err(FitError::InvalidOption {
                    name,
                    reason: format!("{b} must be a finite number ≥ 0"),
                });
            }
        }
        if self.solves_per_knots == 0 {
            return Err(FitError::InvalidOption {
                name: "solves_per_knots",
                reason: "must be at least 1".into(),
            });
        }
        Ok(())
    }
}

/// Range checks of degree, control counts and tolerance shared by the surface fitters.
pub(crate) fn check_common(
    degree: usize,
    control: (usize, usize),
    tol_pct: f64,
) -> Result<(), FitError> {
    if degree == 0 || degree > MAX_DEGREE {
        return Err(FitError::InvalidOption {
            name: "degree",
            reason: format!("{degree} is outside 1..={MAX_DEGREE}"),
        });
    }
    let (nu, nv) = control;
    if nu <= degree || nv <= degree {
        return Err(FitError::InvalidOption {
            name: "ctrl",
            reason: format!("{nu} × {nv} control points cannot carry degree {degree}"),
        });
    }
    if !(tol_pct.is_finite() && tol_pct > 0.0) {
        return Err(FitError::InvalidOption {
            name: "tol-max",
            reason: format!("{tol_pct} must be a positive percentage"),
        });
    }
    Ok(())
}

/// The initial clamped uniform surface over the projection plane, control points at the
/// Greville abscissae.
pub(crate) fn plane_surface(
    param: &Parameterization,
    degree: usize,
    (nu, nv): (usize, usize),
) -> Result<BSplineSurface, FitError> {
    let spline = |e: crate::spline::SplineError| FitError::InvalidOption {
        name: "ctrl",
        reason: e.to_string(),
    };
    let ku = KnotVector::clamped_uniform(degree, nu).map_err(spline)?;
    let kv = KnotVector::clamped_uniform(degree, nv).map_err(spline)?;
    let greville = |kv: &KnotVector, i: usize| {
        let k = kv.knots();
        k[i + 1..=i + degree].iter().sum::<f64>() / degree as f64
    };
    let control = (0..nu * nv)
        .map(|idx| {
            let (u, v) = (greville(&ku, idx / nv), greville(&kv, idx % nv));
            param.frame.map_or(Point3::new(u, v, 0.0), |f| f.at(u, v))
        })
        .collect();
    BSplineSurface::try_new(ku, kv, control).map_err(spline)
}

/// Smoothed least-squares B-spline surface fitter (SPEC §2), driven through [`Fitter`].
pub struct LsqSurfaceFitter {
    points: Vec<Point3>,
    active: Vec<bool>,
    uv: Vec<[f64; 2]>,
    dist: Vec<f64>,
    num_folded: usize,
    surface: BSplineSurface,
    opts: LsqSurfaceOptions,
    diagonal: f64,
    history: Vec<IterationRecord>,
    system: Option<NormalSystem>,
    solves_at_knots: usize,
    initial_control: usize,
    /// Parameter area of an initial patch over the domain's: the reference of the per-patch
    /// weight scaling (see [`patch_weights`]).
    ref_cell_area: f64,
    precompute_s: f64,
    status: FitStatus,
}

impl LsqSurfaceFitter {
    /// Sets up a fit of `points`: checks them and the options, and parameterises the points.
    pub fn try_new(points: &[Point3], opts: LsqSurfaceOptions) -> Result<Self, FitError> {
        let start = Instant::now();
        opts.check()?;
        let (nu, nv) = opts.control;
        super::parameterize::check_points(points, nu.min(nv).max(opts.degree + 1))?;
        let param = parameterize(points, &opts.param)?;
        let surface = plane_surface(&param, opts.degree, opts.control)?;
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
        opts.check()?;
        super::parameterize::check_points(points, opts.degree + 1)?;
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
        let active: Vec<bool> = (0..points.len())
            .map(|i| param.is_active(i, opts.param.fold_policy))
            .collect();
        let diagonal = Aabb::from_points(points).map_or(0.0, |b| b.diagonal());
        let (nu, nv) = surface.num_control();
        Ok(LsqSurfaceFitter {
            points: points.to_vec(),
            active,
            dist: vec![0.0; points.len()],
            num_folded: param.num_folded,
            uv: param.uv,
            initial_control: nu * nv,
            ref_cell_area: 1.0 / PatchGrid::of(&surface).len().max(1) as f64,
            surface,
            opts,
            diagonal,
            history: Vec::new(),
            system: None,
            solves_at_knots: 0,
            precompute_s: start.elapsed().as_secs_f64(),
            status: FitStatus::Running,
        })
    }

    /// The current surface.
    pub fn surface(&self) -> &BSplineSurface {
        &self.surface
    }

    /// Current (u, v) of every point.
    pub fn parameters(&self) -> &[[f64; 2]] {
        &self.uv
    }

    /// Points found on a fold-over of the initial projection.
    pub fn num_folded(&self) -> usize {
        self.num_folded
    }

    /// Control points at the start.
    pub fn initial_control_points(&self) -> usize {
        self.initial_control
    }

    /// Seconds spent in set-up (checks, parameterisation).
    pub fn precompute_seconds(&self) -> f64 {
        self.precompute_s
    }

    /// The status after the last step.
    pub fn status(&self) -> FitStatus {
        self.status
    }

    /// The energies (E2, E3) of the current surface over its whole domain, unweighted.
    pub fn energies(&self) -> (f64, f64) {
        energies(&self.surface)
    }

    /// Solves the normal equations for the current knots and parameters.
    fn solve(&mut self) -> Result<(), FitError> {
        let (nu, nv) = self.surface.num_control();
        let (p, q) = (
            self.surface.knots_u().degree(),
            self.surface.knots_v().degree(),
        );
        if self
            .system
            .as_ref()
            .is_none_or(|s| s.shape != (nu, nv, p, q))
        {
            self.system = Some(NormalSystem::new(nu, nv, p, q)?);
        }
        let Some(system) = self.system.as_mut() else {
            return Ok(());
        };
        system.clear();
        let mut rhs = Mat::<f64>::zeros(nu * nv, 3);
        let samples = self
            .points
            .iter()
            .zip(&self.uv)
            .zip(&self.active)
            .filter(|x| *x.1)
            .map(|x| x.0);
        let count = system.add_points(&self.surface, samples, &mut rhs);
        let grid = PatchGrid::of(&self.surface);
        let weights = patch_weights(
            &self.surface,
            &grid,
            &self.uv,
            &self.active,
            count,
            self.ref_cell_area,
        );
        let scale = count.max(1) as f64;
        system.add_energies(
            &self.surface,
            &grid,
            &weights,
            self.opts.beta2 * scale,
            self.opts.beta3 * scale,
        );
        let control = system.solve(rhs)?;
        self.surface
            .set_control_points(&control)
            .map_err(|e| FitError::Solver {
                reason: e.to_string(),
            })
    }
}

impl Fitter for LsqSurfaceFitter {
    fn step(&mut self) -> Result<FitStatus, FitError> {
        if self.status != FitStatus::Running {
            return Ok(self.status);
        }
        let start = Instant::now();
        self.solve()?;
        self.solves_at_knots += 1;
        correct_parameters(
            &self.surface,
            &self.points,
            &mut self.uv,
            &mut self.dist,
            self.opts.newton_iterations,
        );
        let grid = PatchGrid::of(&self.surface);
        let tol = self.opts.tol_pct / 100.0 * self.diagonal;
        let errors: Vec<PatchError> = patch_errors(
            &self.surface,
            &grid,
            &self.uv,
            &self.dist,
            &self.active,
            Criterion {
                tol,
                mode: self.opts.tol_mode,
                min_sample: self.opts.min_sample,
            },
        );
        let all_pass = errors.iter().all(|e| e.pass);
        let mut refined = false;
        self.status = if all_pass {
            FitStatus::Converged
        } else if self.history.len() + 1 >= self.opts.max_iterations {
            FitStatus::MaxIterations
        } else if self.solves_at_knots < self.opts.solves_per_knots {
            FitStatus::Running
        } else if self.opts.fixed_knots {
            FitStatus::MaxIterations
        } else {
            let inserted = split_worst(
                &mut self.surface,
                &grid,
                &errors,
                self.opts.max_control_points,
            );
            refined = inserted > 0;
            self.solves_at_knots = 0;
            if refined {
                FitStatus::Running
            } else {
                FitStatus::MaxIterations
            }
        };
        let stats = self.stats();
        let (nu, nv) = self.surface.num_control();
        self.history.push(IterationRecord {
            iter: self.history.len() + 1,
            control_points: nu * nv,
            e_avg_pct: stats.e_avg_pct,
            e_max_pct: stats.e_max_pct,
            e_rms_pct: stats.e_rms_pct,
            ms: start.elapsed().as_secs_f64() * 1e3,
            refined,
        });
        Ok(self.status)
    }

    fn history(&self) -> &[IterationRecord] {
        &self.history
    }

    fn point_errors(&self) -> &[f64] {
        &self.dist
    }

    fn stats(&self) -> ErrorStats {
        ErrorStats::from_distances(&self.dist, self.diagonal)
    }
}

/// The factors of β2 and β3 of every patch: 1/ρ and ρ (SPEC §2), with ρ the relative point
/// density (points per parameter area over points per domain area, kept within [1/64, 64] so
/// empty patches get a finite weight), times s² and s³ for s = the patch's parameter area over
/// `ref_area` (at most 1).
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
    uv: &[[f64; 2]],
    active: &[bool],
    count: usize,
    ref_area: f64,
) -> Vec<[f64; 2]> {
    let mut counts = vec![0usize; grid.len()];
    for (t, _) in uv.iter().zip(active).filter(|x| *x.1) {
        counts[grid.patch(surface, t[0], t[1])] += 1;
    }
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

/// ∫ N_r^(k) N_s^(k) over one knot span, for k = 0..=3 and the p + 1 functions of the span.
struct SpanGram {
    degree: usize,
    g: [[[f64; MAX_DEGREE + 1]; MAX_DEGREE + 1]; 4],
}

fn span_gram(kv: &KnotVector, span: usize) -> SpanGram {
    let p = kv.degree();
    let k = kv.knots();
    let (a, b) = (k[span], k[span + 1]);
    let mut g = [[[0.0; MAX_DEGREE + 1]; MAX_DEGREE + 1]; 4];
    let (nodes, weights) = gauss_legendre(p + 1);
    let mut ders = [[0.0; MAX_DEGREE + 1]; 4];
    for (x, w) in nodes.iter().zip(&weights) {
        let t = 0.5 * (a + b) + 0.5 * (b - a) * x;
        let wt = 0.5 * (b - a) * w;
        kv.basis_ders(span, t, 3, &mut ders);
        for (order, gk) in g.iter_mut().enumerate() {
            for r in 0..=p {
                for s in 0..=p {
                    gk[r][s] += wt * ders[order][r] * ders[order][s];
                }
            }
        }
    }
    SpanGram { degree: p, g }
}

/// Calls `f(a, b, c, d, w2, w3)` for every pair of local basis products (a, b), (c, d) of one
/// cell, with the E2 and E3 weights of that pair.
fn for_cell_pairs<F: FnMut(usize, usize, usize, usize, f64, f64)>(
    gu: &SpanGram,
    gv: &SpanGram,
    mut f: F,
) {
    let (u, v) = (&gu.g, &gv.g);
    for a in 0..=gu.degree {
        for b in 0..=gv.degree {
            for c in 0..=gu.degree {
                for d in 0..=gv.degree {
                    let w2 = u[2][a][c] * v[0][b][d]
                        + 2.0 * u[1][a][c] * v[1][b][d]
                        + u[0][a][c] * v[2][b][d];
                    let w3 = u[3][a][c] * v[0][b][d]
                        + 3.0 * u[2][a][c] * v[1][b][d]
                        + 3.0 * u[1][a][c] * v[2][b][d]
                        + u[0][a][c] * v[3][b][d];
                    f(a, b, c, d, w2, w3);
                }
            }
        }
    }
}

/// Gauss–Legendre nodes and weights on [−1, 1] with `n` points (exact for polynomials of
/// degree 2n − 1), by Newton's method on the Legendre polynomial.
fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = Vec::with_capacity(n);
    let mut weights = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (p, d) = legendre(n, x);
            dp = d;
            let dx = p / d;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let (_, d) = legendre(n, x);
        dp = if d != 0.0 { d } else { dp };
        nodes.push(x);
        weights.push(2.0 / ((1.0 - x * x) * dp * dp));
    }
    (nodes, weights)
}

/// P_n(x) and P_n'(x) by the three-term recurrence.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

/// The sparse normal matrix of one knot configuration: its upper triangle in compressed
/// columns, the numeric values, and the symbolic Cholesky factorisation reused by every solve.
struct NormalSystem {
    shape: (usize, usize, usize, usize),
    col_ptr: Vec<usize>,
    symbolic: SymbolicSparseColMat<usize>,
    llt: SymbolicLlt<usize>,
    values: Vec<f64>,
}

impl NormalSystem {
    /// The pattern: control point (i, j) couples with (i', j') when |i − i'| ≤ p and
    /// |j − j'| ≤ q; column c = i·nv + j keeps the rows r ≤ c, ordered by (i', j').
    fn new(nu: usize, nv: usize, p: usize, q: usize) -> Result<NormalSystem, FitError> {
        let n = nu * nv;
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for c in 0..n {
            let (i, j) = (c / nv, c % nv);
            for ii in i.saturating_sub(p)..=i {
                let j_end = if ii == i { j } else { (j + q).min(nv - 1) };
                for jj in j.saturating_sub(q)..=j_end {
                    row_idx.push(ii * nv + jj);
                }
            }
            col_ptr.push(row_idx.len());
        }
        let nnz = row_idx.len();
        let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr.clone(), None, row_idx);
        let llt =
            SymbolicLlt::try_new(symbolic.as_ref(), Side::Upper).map_err(|e| FitError::Solver {
                reason: format!("symbolic factorisation: {e:?}"),
            })?;
        Ok(NormalSystem {
            shape: (nu, nv, p, q),
            col_ptr,
            symbolic,
            llt,
            values: vec![0.0; nnz],
        })
    }

    fn clear(&mut self) {
        self.values.fill(0.0);
    }

    /// Position of entry (row r, column c), r ≤ c, both inside the band.
    fn position(&self, r: usize, c: usize) -> usize {
        let (_, nv, p, q) = self.shape;
        let (i, j) = (c / nv, c % nv);
        let (ii, jj) = (r / nv, r % nv);
        let (i0, j0) = (i.saturating_sub(p), j.saturating_sub(q));
        let width = (j + q).min(nv - 1) - j0 + 1;
        self.col_ptr[c] + (ii - i0) * width + (jj - j0)
    }

    /// Adds the data points (point, (u, v)): their basis products to the matrix and their
    /// weighted coordinates to the right-hand side; returns how many there were.
    ///
    /// Points of one knot-span cell touch the same (p + 1)(q + 1) control points, so their
    /// products are summed in a small dense block per cell first and scattered into the sparse
    /// matrix once per cell: the per-point work is then plain multiply-adds on a contiguous
    /// block, without locating each entry in the sparse pattern.
    fn add_points<'a, I>(&mut self, s: &BSplineSurface, samples: I, rhs: &mut Mat<f64>) -> usize
    where
        I: Iterator<Item = (&'a Point3, &'a [f64; 2])>,
    {
        const MAX_M: usize = (MAX_DEGREE + 1) * (MAX_DEGREE + 1);
        let (nu, nv, p, q) = self.shape;
        let m = (p + 1) * (q + 1);
        let tri = m * (m + 1) / 2;
        let cells_v = nv - q;
        let mut block_of = vec![usize::MAX; (nu - p) * cells_v];
        let mut blocks: Vec<f64> = Vec::new();
        let mut firsts: Vec<(usize, usize)> = Vec::new();
        let mut count = 0;
        for (pt, t) in samples {
            count += 1;
            let b = s.basis(t[0], t[1]);
            let cell = b.first_u * cells_v + b.first_v;
            if block_of[cell] == usize::MAX {
                block_of[cell] = firsts.len();
                firsts.push((b.first_u, b.first_v));
                blocks.resize(blocks.len() + tri, 0.0);
            }
            let slot = block_of[cell];
            let mut w = [0.0; MAX_M];
            for r in 0..=p {
                for c in 0..=q {
                    w[r * (q + 1) + c] = b.bu[r] * b.bv[c];
                }
            }
            let block = &mut blocks[slot * tri..(slot + 1) * tri];
            let mut pos = 0;
            for k in 0..m {
                let wk = w[k];
                for (dst, wl) in block[pos..=pos + k].iter_mut().zip(&w[..=k]) {
                    *dst += wk * wl;
                }
                pos += k + 1;
                let c = (b.first_u + k / (q + 1)) * nv + b.first_v + k % (q + 1);
                rhs[(c, 0)] += wk * pt.x;
                rhs[(c, 1)] += wk * pt.y;
                rhs[(c, 2)] += wk * pt.z;
            }
        }
        let mut idx = [0usize; MAX_M];
        for (slot, &(fu, fv)) in firsts.iter().enumerate() {
            for (k, x) in idx.iter_mut().enumerate().take(m) {
                *x = (fu + k / (q + 1)) * nv + fv + k % (q + 1);
            }
            let block = &blocks[slot * tri..(slot + 1) * tri];
            let mut pos = 0;
            for k in 0..m {
                for l in 0..=k {
                    // idx is increasing, so idx[l] ≤ idx[k].
                    let at = self.position(idx[l], idx[k]);
                    self.values[at] += block[pos];
                    pos += 1;
                }
            }
        }
        count
    }

    /// Adds the per-patch weighted E2 and E3 Gram blocks (β2/ρ and β3·ρ per patch).
    fn add_energies(
        &mut self,
        s: &BSplineSurface,
        grid: &PatchGrid,
        weights: &[[f64; 2]],
        beta2: f64,
        beta3: f64,
    ) {
        if beta2 == 0.0 && beta3 == 0.0 {
            return;
        }
        let nv = self.shape.1;
        let grams_v: Vec<SpanGram> = (0..grid.v.len())
            .map(|c| span_gram(s.knots_v(), grid.v.knot_index(c)))
            .collect();
        for cu in 0..grid.u.len() {
            let gu = span_gram(s.knots_u(), grid.u.knot_index(cu));
            let fu = grid.u.knot_index(cu) - gu.degree;
            for (cv, gv) in grams_v.iter().enumerate() {
                let fv = grid.v.knot_index(cv) - gv.degree;
                let [w2, w3] = weights[cu * grid.v.len() + cv];
                let (b2, b3) = (beta2 * w2, beta3 * w3);
                for_cell_pairs(&gu, gv, |a, b, c, d, w2, w3| {
                    let (col, row) = ((fu + a) * nv + fv + b, (fu + c) * nv + fv + d);
                    if row <= col {
                        let pos = self.position(row, col);
                        self.values[pos] += b2 * w2 + b3 * w3;
                    }
                });
            }
        }
    }

    /// Factorises numerically (reusing the symbolic factorisation) and solves for the three
    /// coordinate columns.
    fn solve(&self, mut rhs: Mat<f64>) -> Result<Vec<Point3>, FitError> {
        let mat = SparseColMatRef::new(self.symbolic.as_ref(), &self.values);
        let llt = Llt::try_new_with_symbolic(self.llt.clone(), mat, Side::Upper).map_err(|e| {
            FitError::Solver {
                reason: format!(
                    "the normal matrix is not positive definite ({e:?}); too few points for \
                     the control points, or raise beta2"
                ),
            }
        })?;
        llt.solve_in_place(rhs.as_mut());
        let out: Vec<Point3> = (0..rhs.nrows())
            .map(|i| Point3::new(rhs[(i, 0)], rhs[(i, 1)], rhs[(i, 2)]))
            .collect();
        if out.iter().any(|p| !p.is_finite()) {
            return Err(FitError::Solver {
                reason: "the solution is not finite; raise beta2".into(),
            });
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        for n in 1..=8 {
            let (x, w) = gauss_legendre(n);
            for deg in 0..2 * n {
                let integral: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                let exact = if deg % 2 == 1 {
                    0.0
                } else {
                    2.0 / (deg as f64 + 1.0)
                };
                assert!((integral - exact).abs() < 1e-13, "n {n} degree {deg}");
            }
        }
    }

    #[test]
    fn pattern_positions_are_consistent() {
        let sys = NormalSystem::new(5, 6, 2, 3).expect("pattern");
        let (_, rows) = (sys.symbolic.col_ptr(), sys.symbolic.row_idx());
        for c in 0..30 {
            for (k, &r) in rows[sys.col_ptr[c]..sys.col_ptr[c + 1]].iter().enumerate() {
                assert_eq!(sys.position(r, c), sys.col_ptr[c] + k);
            }
        }
    }
}
