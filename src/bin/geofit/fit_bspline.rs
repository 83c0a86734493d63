//! `geofit fit FILE --scheme bspline [--degree 3] [--method geometric|least-squares]
//! [--beta2 X] [--beta3 X] [--tol-max PCT] [--tol-mode exact|noisy]
//! [--ctrl N | --ctrl-u N --ctrl-v N] [--json R.json] [--surface-json S.json] [--iges OUT.igs]
//! [--step OUT.stp]`: the `--scheme bspline` branch of `geofit fit`, fitting one
//! tensor-product B-spline surface to a scan. Its options are flattened into `geofit fit`'s.

use geofit::export::{iges::write_iges, step::write_step, ExportModel, SurfaceDesc};
use geofit::fit::{
    within_tolerance_pct, FitReport, FitStatus, Fitter, FoldPolicy, GeometricSurfaceFitter,
    GeometricSurfaceOptions, LsqSurfaceFitter, LsqSurfaceOptions, ParamOptions, TolMode,
};
use geofit::geom::Vec3;
use geofit::spline::BSplineSurface;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Least-squares solves on fixed knots by default: each parameter correction still lowers the
/// error markedly up to about the fourth (on bun000.ply at 400 control points E_max 2.05, 1.79,
/// 1.55, 1.44 %), and with fixed knots there is no splitting to continue from.
const FIXED_KNOT_SOLVES: usize = 4;

/// Fitting method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Method {
    /// Move control points by basis-weighted error vectors (no linear system).
    Geometric,
    /// Smoothed least squares E1 + β2·E2 + β3·E3 with a sparse solver (SPEC §2).
    LeastSquares,
}

/// Tolerance mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TolModeArg {
    /// Every patch's largest distance within the tolerance.
    Exact,
    /// Every patch has more than 95 % of its points within the tolerance, or mean + standard
    /// deviation of its distances within it (patches under 16 points: with their neighbours).
    Noisy,
}

/// What to do with points on a fold-over of the projection.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FoldArg {
    /// Stop with an error.
    Fail,
    /// Leave them out of the fit (still measured).
    Exclude,
    /// Fit them like all others.
    Keep,
}

/// Options of `geofit fit --scheme bspline` (flattened into `geofit fit`; all optional so that
/// giving one with another scheme is reported).
#[derive(clap::Args, Debug, Default)]
#[command(next_help_heading = "B-spline surface (--scheme bspline)")]
pub struct BsplineArgs {
    /// Degree in u and v [default: 3].
    #[arg(long)]
    degree: Option<usize>,
    /// Fitting method [default: least-squares].
    #[arg(long, value_enum)]
    method: Option<Method>,
    /// Thin-plate weight β2 (least squares) [default: 1e-12].
    #[arg(long)]
    beta2: Option<f64>,
    /// Curvature-variation weight β3 (least squares) [default: 1e-15].
    #[arg(long)]
    beta3: Option<f64>,
    /// How patches are judged against --tol-max [default: noisy].
    #[arg(long, value_enum)]
    tol_mode: Option<TolModeArg>,
    /// Fixed control-point count N (a √N × √N grid, knots kept fixed; the geometric method
    /// then starts from one least-squares solve).
    #[arg(long, conflicts_with_all = ["ctrl_u", "ctrl_v"])]
    ctrl: Option<usize>,
    /// Fixed control points along u (with --ctrl-v; knots kept fixed).
    #[arg(long, requires = "ctrl_v")]
    ctrl_u: Option<usize>,
    /// Fixed control points along v (with --ctrl-u).
    #[arg(long, requires = "ctrl_u")]
    ctrl_v: Option<usize>,
    /// Initial control points per direction when splitting adaptively [default: 8].
    #[arg(long)]
    initial_ctrl: Option<usize>,
    /// Least squares: solves (each followed by parameter correction) per knot vector
    /// [default: 2; with --ctrl/--ctrl-u, where the knots never change, 4].
    #[arg(long)]
    solves: Option<usize>,
    /// View direction "x,y,z" for the projection [default: least-variance axis].
    #[arg(long, value_parser = parse_vec3)]
    view: Option<Vec3>,
    /// Points on a fold-over of the projection [default: keep].
    #[arg(long, value_enum)]
    folded: Option<FoldArg>,
    /// Write the fitted surface (degree, knots, control grid) as JSON to this file.
    #[arg(long)]
    surface_json: Option<PathBuf>,
    /// Export the fitted surface as IGES (entity 128).
    #[arg(long)]
    iges: Option<PathBuf>,
    /// Export the fitted surface as STEP (AP214 B_SPLINE_SURFACE_WITH_KNOTS).
    #[arg(long)]
    step: Option<PathBuf>,
}

impl BsplineArgs {
    /// The first B-spline-only option given, if any (they are an error with other schemes).
    pub fn first_given(&self) -> Option<&'static str> {
        let given = [
            ("--degree", self.degree.is_some()),
            ("--method", self.method.is_some()),
            ("--beta2", self.beta2.is_some()),
            ("--beta3", self.beta3.is_some()),
            ("--tol-mode", self.tol_mode.is_some()),
            ("--ctrl", self.ctrl.is_some()),
            ("--ctrl-u", self.ctrl_u.is_some()),
            ("--initial-ctrl", self.initial_ctrl.is_some()),
            ("--solves", self.solves.is_some()),
            ("--view", self.view.is_some()),
            ("--folded", self.folded.is_some()),
            ("--surface-json", self.surface_json.is_some()),
            ("--iges", self.iges.is_some()),
            ("--step", self.step.is_some()),
        ];
        given.iter().find(|g| g.1).map(|g| g.0)
    }
}

/// The options `geofit fit` shares with the other schemes.
pub struct Common<'a> {
    /// The data file.
    pub file: &'a Path,
    /// Tolerance, % of the bounding-box diagonal (default 0.1).
    pub tol_max: Option<f64>,
    /// Iteration cap.
    pub max_iter: usize,
    /// Control-point budget of the splitting (default 40,000).
    pub max_control: Option<usize>,
    /// Where to write the JSON report.
    pub json: Option<&'a Path>,
}

fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|e| format!("{x:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
        _ => Err(format!("expected x,y,z, got {s:?}")),
    }
}

/// The report of `geofit fit --scheme bspline`: the fields of every fit plus the control grid.
#[derive(Serialize)]
struct BsplineReport {
    #[serde(flatten)]
    base: FitReport,
    method: &'static str,
    control_points_u: usize,
    control_points_v: usize,
    folded_points: usize,
}

/// The fitted surface as plain data.
#[derive(Serialize)]
struct SurfaceJson<'a> {
    degree_u: usize,
    degree_v: usize,
    knots_u: &'a [f64],
    knots_v: &'a [f64],
    control_points_u: usize,
    control_points_v: usize,
    /// Row-major in u: index i · control_points_v + j.
    control_points: Vec<[f64; 3]>,
    /// The fit's foot-point parameters (u, v) of every data point, in data order (a
    /// benchmark's closest-point search can start from them).
    parameters: &'a [[f64; 2]],
}

/// Reads the file, fits, prints the report (JSON) and writes the requested files.
pub fn run(common: Common, args: &BsplineArgs) -> Result<(), String> {
    let start = Instant::now();
    let file = common.file;
    let loaded = geofit::io::read_path(file).map_err(|e| format!("{}: {e}", file.display()))?;
    let points = loaded.mesh.positions().to_vec();
    let read_s = start.elapsed().as_secs_f64();
    let mut param =
        ParamOptions::default().with_fold_policy(match args.folded.unwrap_or(FoldArg::Keep) {
            FoldArg::Fail => FoldPolicy::Fail,
            FoldArg::Exclude => FoldPolicy::Exclude,
            FoldArg::Keep => FoldPolicy::Keep,
        });
    if let Some(v) = args.view {
        param = param.with_view(v);
    }
    let mode = match args.tol_mode.unwrap_or(TolModeArg::Noisy) {
        TolModeArg::Exact => TolMode::Exact,
        TolModeArg::Noisy => TolMode::Noisy,
    };
    let fixed = fixed_control(args)?;
    let initial = args.initial_ctrl.unwrap_or(8);
    let control = fixed.unwrap_or((initial, initial));
    let degree = args.degree.unwrap_or(3);
    let tol_max = common.tol_max.unwrap_or(0.1);
    let max_ctrl = common.max_control.unwrap_or(40_000);
    let (report, surface, parameters) = match args.method.unwrap_or(Method::LeastSquares) {
        Method::LeastSquares => {
            let d = LsqSurfaceOptions::default();
            let opts = d
                .with_degree(degree)
                .with_control(control.0, control.1)
                .with_fixed_knots(fixed.is_some())
                .with_tolerance(tol_max, mode)
                .with_max_control_points(max_ctrl)
                .with_solves_per_knots(args.solves.unwrap_or(if fixed.is_some() {
                    FIXED_KNOT_SOLVES
                } else {
                    d.solves_per_knots
                }))
                .with_param(param)
                .with_betas(args.beta2.unwrap_or(d.beta2), args.beta3.unwrap_or(d.beta3))
                .with_max_iterations(common.max_iter);
            let mut fitter = LsqSurfaceFitter::try_new(&points, opts).map_err(|e| e.to_string())?;
            let t = Instant::now();
            let status = fitter.run().map_err(|e| e.to_string())?;
            let fit_s = t.elapsed().as_secs_f64();
            let pre = read_s + fitter.precompute_seconds();
            let base = base_report(
                &fitter,
                status,
                points.len(),
                fitter.initial_control_points(),
                pre,
                fit_s,
                tol_max,
            );
            (
                report_of(base, "least-squares", fitter.surface(), fitter.num_folded()),
                fitter.surface().clone(),
                fitter.parameters().to_vec(),
            )
        }
        Method::Geometric => {
            let opts = GeometricSurfaceOptions::default()
                .with_degree(degree)
                .with_control(control.0, control.1)
                .with_fixed_knots(fixed.is_some())
                .with_warm_start(fixed.is_some())
                .with_tolerance(tol_max, mode)
                .with_max_control_points(max_ctrl)
                .with_param(param)
                .with_max_iterations(common.max_iter);
            let mut fitter =
                GeometricSurfaceFitter::try_new(&points, opts).map_err(|e| e.to_string())?;
            let t = Instant::now();
            let status = fitter.run().map_err(|e| e.to_string())?;
            let fit_s = t.elapsed().as_secs_f64();
            let pre = read_s + fitter.precompute_seconds();
            let base = base_report(
                &fitter,
                status,
                points.len(),
                fitter.initial_control_points(),
                pre,
                fit_s,
                tol_max,
            );
            (
                report_of(base, "geometric", fitter.surface(), fitter.num_folded()),
                fitter.surface().clone(),
                fitter.parameters().to_vec(),
            )
        }
    };
    let text = serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?;
    outln!("{text}");
    if let Some(path) = common.json {
        std::fs::write(path, &text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    let model = ExportModel {
        curves: Vec::new(),
        surfaces: vec![SurfaceDesc {
            degree_u: surface.knots_u().degree(),
            degree_v: surface.knots_v().degree(),
            knots_u: surface.knots_u().knots().to_vec(),
            knots_v: surface.knots_v().knots().to_vec(),
            num_u: surface.num_control().0,
            num_v: surface.num_control().1,
            control_points: surface.control_points().to_vec(),
            weights: surface.weights().map(<[f64]>::to_vec),
        }],
    };
    let name = file
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("geofit");
    if let Some(path) = &args.iges {
        let text = write_iges(&model, name).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    if let Some(path) = &args.step {
        let text = write_step(&model, name).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    if let Some(path) = &args.surface_json {
        let json = serde_json::to_string(&surface_json(&surface, &parameters))
            .map_err(|e| e.to_string())?;
        std::fs::write(path, json).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(())
}

fn fixed_control(args: &BsplineArgs) -> Result<Option<(usize, usize)>, String> {
    if let Some(n) = args.ctrl {
        let side = (n as f64).sqrt().round() as usize;
        if side * side != n {
            return Err(format!(
                "--ctrl {n} is not a square; use --ctrl-u and --ctrl-v"
            ));
        }
        return Ok(Some((side, side)));
    }
    Ok(args.ctrl_u.zip(args.ctrl_v))
}

fn base_report<F: Fitter>(
    fitter: &F,
    status: FitStatus,
    points: usize,
    initial: usize,
    precompute_s: f64,
    fit_s: f64,
    tol_pct: f64,
) -> FitReport {
    let stats = fitter.stats();
    // The fitter's own diagonal, from its E_max in model units and in %.
    let diagonal = if stats.e_max_pct > 0.0 {
        100.0 * stats.e_max / stats.e_max_pct
    } else {
        0.0
    };
    FitReport {
        scheme: "bspline".into(),
        points,
        initial_control_points: initial,
        final_control_points: fitter
            .history()
            .last()
            .map_or(initial, |r| r.control_points),
        iterations: fitter.history().len(),
        e_avg_pct: stats.e_avg_pct,
        e_max_pct: stats.e_max_pct,
        e_rms_pct: stats.e_rms_pct,
        converged: status == FitStatus::Converged,
        within_tolerance_pct: Some(within_tolerance_pct(
            fitter.point_errors(),
            diagonal,
            tol_pct,
        )),
        reconstruction: None,
        precompute_s,
        fit_s,
        total_s: precompute_s + fit_s,
        history: fitter.history().to_vec(),
    }
}

fn report_of(
    base: FitReport,
    method: &'static str,
    surface: &BSplineSurface,
    folded_points: usize,
) -> BsplineReport {
    let (nu, nv) = surface.num_control();
    BsplineReport {
        base,
        method,
        control_points_u: nu,
        control_points_v: nv,
        folded_points,
    }
}

fn surface_json<'a>(s: &'a BSplineSurface, parameters: &'a [[f64; 2]]) -> SurfaceJson<'a> {
    let (nu, nv) = s.num_control();
    SurfaceJson {
        degree_u: s.knots_u().degree(),
        degree_v: s.knots_v().degree(),
        knots_u: s.knots_u().knots(),
        knots_v: s.knots_v().knots(),
        control_points_u: nu,
        control_points_v: nv,
        control_points: s.control_points().iter().map(|p| p.to_array()).collect(),
        parameters,
    }
}
