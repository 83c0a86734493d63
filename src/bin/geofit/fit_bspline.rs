//! `geofit fit-bspline FILE [--degree 3] [--method geometric|least-squares] [--beta2 X]
//! [--beta3 X] [--tol-max PCT] [--tol-mode exact|noisy] [--ctrl N | --ctrl-u N --ctrl-v N]
//! [--json R.json] [--surface-json S.json] [--iges OUT.igs] [--step OUT.stp]`: fit one tensor-product B-spline surface to a scan
//! (the `--scheme bspline` branch of `geofit fit`, routed here by [`route`]).

use geofit::export::{iges::write_iges, step::write_step, ExportModel, SurfaceDesc};
use geofit::fit::{
    FitReport, FitStatus, Fitter, FoldPolicy, GeometricSurfaceFitter, GeometricSurfaceOptions,
    LsqSurfaceFitter, LsqSurfaceOptions, ParamOptions, TolMode,
};
use geofit::geom::Vec3;
use geofit::spline::BSplineSurface;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

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
    /// More than 95 % of every patch's points within the tolerance.
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

/// Arguments of the B-spline surface fit.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Point or mesh file (PLY, OBJ, STL, XYZ/CSV/PTS); only the points are used.
    file: PathBuf,
    /// Degree in u and v.
    #[arg(long, default_value_t = 3)]
    degree: usize,
    /// Fitting method.
    #[arg(long, value_enum, default_value_t = Method::LeastSquares)]
    method: Method,
    /// Thin-plate weight β2 (least squares).
    #[arg(long)]
    beta2: Option<f64>,
    /// Curvature-variation weight β3 (least squares).
    #[arg(long)]
    beta3: Option<f64>,
    /// Tolerance, % of the bounding-box diagonal.
    #[arg(long, default_value_t = 0.1)]
    tol_max: f64,
    /// How patches are judged against the tolerance.
    #[arg(long, value_enum, default_value_t = TolModeArg::Noisy)]
    tol_mode: TolModeArg,
    /// Fixed control-point count N (a √N × √N grid, knots kept fixed).
    #[arg(long, conflicts_with_all = ["ctrl_u", "ctrl_v"])]
    ctrl: Option<usize>,
    /// Fixed control points along u (with --ctrl-v; knots kept fixed).
    #[arg(long, requires = "ctrl_v")]
    ctrl_u: Option<usize>,
    /// Fixed control points along v (with --ctrl-u).
    #[arg(long, requires = "ctrl_u")]
    ctrl_v: Option<usize>,
    /// Initial control points per direction when splitting adaptively.
    #[arg(long, default_value_t = 8)]
    initial_ctrl: usize,
    /// Cap on control points when splitting.
    #[arg(long, default_value_t = 40_000)]
    max_ctrl: usize,
    /// Iteration cap.
    #[arg(long)]
    max_iter: Option<usize>,
    /// Least squares: solves (each followed by parameter correction) per knot vector.
    #[arg(long, default_value_t = 2)]
    solves: usize,
    /// View direction "x,y,z" for the projection (default: least-variance axis).
    #[arg(long, value_parser = parse_vec3)]
    view: Option<Vec3>,
    /// Points on a fold-over of the projection.
    #[arg(long, value_enum, default_value_t = FoldArg::Keep)]
    folded: FoldArg,
    /// Write the report as JSON to this file.
    #[arg(long)]
    json: Option<PathBuf>,
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

/// Lets `geofit fit FILE --scheme bspline ...` reach this command: rewrites the arguments to
/// `geofit fit-bspline FILE ...` when the `fit` subcommand asks for the bspline scheme.
pub fn route(args: Vec<std::ffi::OsString>) -> Vec<std::ffi::OsString> {
    let is = |a: &std::ffi::OsString, s: &str| a.to_str() == Some(s);
    if args.len() < 2 || !is(&args[1], "fit") {
        return args;
    }
    let pos = args.iter().position(|a| is(a, "--scheme"));
    let bspline = match pos {
        Some(i) => args.get(i + 1).is_some_and(|a| is(a, "bspline")),
        None => args.iter().any(|a| is(a, "--scheme=bspline")),
    };
    if !bspline {
        return args;
    }
    let mut out = vec![args[0].clone(), "fit-bspline".into()];
    let mut skip = false;
    for (i, a) in args.iter().enumerate().skip(2) {
        if skip {
            skip = false;
            continue;
        }
        if Some(i) == pos {
            skip = true;
            continue;
        }
        if !is(a, "--scheme=bspline") {
            out.push(a.clone());
        }
    }
    out
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
}

/// Reads the file, fits, prints the report and writes the requested files.
pub fn run(args: Args) -> Result<(), String> {
    let start = Instant::now();
    let loaded =
        geofit::io::read_path(&args.file).map_err(|e| format!("{}: {e}", args.file.display()))?;
    let points = loaded.mesh.positions().to_vec();
    let read_s = start.elapsed().as_secs_f64();
    let mut param = ParamOptions::default().with_fold_policy(match args.folded {
        FoldArg::Fail => FoldPolicy::Fail,
        FoldArg::Exclude => FoldPolicy::Exclude,
        FoldArg::Keep => FoldPolicy::Keep,
    });
    if let Some(v) = args.view {
        param = param.with_view(v);
    }
    let mode = match args.tol_mode {
        TolModeArg::Exact => TolMode::Exact,
        TolModeArg::Noisy => TolMode::Noisy,
    };
    let fixed = fixed_control(&args)?;
    let control = fixed.unwrap_or((args.initial_ctrl, args.initial_ctrl));
    let (report, surface) = match args.method {
        Method::LeastSquares => {
            let mut opts = LsqSurfaceOptions::default()
                .with_degree(args.degree)
                .with_control(control.0, control.1)
                .with_fixed_knots(fixed.is_some())
                .with_tolerance(args.tol_max, mode)
                .with_max_control_points(args.max_ctrl)
                .with_solves_per_knots(args.solves)
                .with_param(param);
            let d = LsqSurfaceOptions::default();
            opts = opts.with_betas(args.beta2.unwrap_or(d.beta2), args.beta3.unwrap_or(d.beta3));
            if let Some(n) = args.max_iter {
                opts = opts.with_max_iterations(n);
            }
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
            );
            (
                report_of(base, "least-squares", fitter.surface(), fitter.num_folded()),
                fitter.surface().clone(),
            )
        }
        Method::Geometric => {
            let mut opts = GeometricSurfaceOptions::default()
                .with_degree(args.degree)
                .with_control(control.0, control.1)
                .with_fixed_knots(fixed.is_some())
                .with_tolerance(args.tol_max, mode)
                .with_max_control_points(args.max_ctrl)
                .with_param(param);
            if let Some(n) = args.max_iter {
                opts = opts.with_max_iterations(n);
            }
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
            );
            (
                report_of(base, "geometric", fitter.surface(), fitter.num_folded()),
                fitter.surface().clone(),
            )
        }
    };
    let text = serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?;
    println!("{text}");
    if let Some(path) = &args.json {
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
    let name = args
        .file
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
        let json = serde_json::to_string(&surface_json(&surface)).map_err(|e| e.to_string())?;
        std::fs::write(path, json).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(())
}

fn fixed_control(args: &Args) -> Result<Option<(usize, usize)>, String> {
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
) -> FitReport {
    let stats = fitter.stats();
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

fn surface_json(s: &BSplineSurface) -> SurfaceJson<'_> {
    let (nu, nv) = s.num_control();
    SurfaceJson {
        degree_u: s.knots_u().degree(),
        degree_v: s.knots_v().degree(),
        knots_u: s.knots_u().knots(),
        knots_v: s.knots_v().knots(),
        control_points_u: nu,
        control_points_v: nv,
        control_points: s.control_points().iter().map(|p| p.to_array()).collect(),
    }
}
