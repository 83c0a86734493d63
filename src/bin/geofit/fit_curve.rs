//! `geofit fit-curve FILE [--degree 3] [--closed] [--method geometric|knots] [--tol-max PCT]
//! [--json R.json] [--iges OUT.igs] [--step OUT.stp]`: fit a B-spline curve to an ordered point
//! file (point text, two or three columns, or an OBJ polyline) and export it.

use crate::output::read_input;
use geofit::export::{iges::write_iges, step::write_step, CurveDesc, ExportModel};
use geofit::fit::{
    CurveFitOptions, CurveFitter, FitStatus, Fitter, KnotPlacementFitter, KnotPlacementOptions,
    Tolerances,
};
use geofit::spline::BSplineCurve;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The fitting method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Method {
    /// Geometric iteration: control points moved by basis-weighted error vectors (SPEC §1.9).
    Geometric,
    /// Knot placement with least squares (SPEC §3): multiple knots at corners, single knots at
    /// the largest deviation.
    Knots,
}

/// Arguments of `geofit fit-curve`.
#[derive(clap::Args)]
pub struct Args {
    /// Ordered points: XYZ/CSV text (2 or 3 columns) or an OBJ with an `l` polyline.
    file: PathBuf,
    /// Curve degree, 1..=5.
    #[arg(long, default_value_t = 3)]
    degree: usize,
    /// Fit a closed (periodic) curve; implied by an OBJ polyline that ends where it starts.
    #[arg(long)]
    closed: bool,
    /// Fitting method.
    #[arg(long, value_enum, default_value_t = Method::Geometric)]
    method: Method,
    /// E_max tolerance, % of the bbox diagonal.
    #[arg(long)]
    tol_max: Option<f64>,
    /// E_avg tolerance, % of the bbox diagonal.
    #[arg(long)]
    tol_avg: Option<f64>,
    /// Iteration cap (geometric: iterations; knots: knot insertions).
    #[arg(long)]
    max_iter: Option<usize>,
    /// Knots method: corner angle in degrees.
    #[arg(long, default_value_t = 30.0)]
    corner_angle: f64,
    /// Knots method: second-derivative jump that makes a double knot, in 1 / bbox diagonal.
    #[arg(long, default_value_t = 1000.0)]
    curvature_jump: f64,
    /// Write the JSON report (with sample points of the curve) here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write the curve as IGES (entity 126) here.
    #[arg(long)]
    iges: Option<PathBuf>,
    /// Write the curve as STEP AP214 here.
    #[arg(long)]
    step: Option<PathBuf>,
}

/// Sample parameters and points of a curve, for the report and for interoperability checks.
pub fn curve_samples(curve: &BSplineCurve, count: usize) -> Vec<[f64; 4]> {
    let (a, b) = curve.domain();
    (0..count)
        .map(|i| {
            let u = a + (b - a) * i as f64 / (count - 1) as f64;
            let p = curve.eval(u);
            [u, p.x, p.y, p.z]
        })
        .collect()
}

pub fn run(args: Args) -> Result<(), String> {
    let (points, file_closed) = read_input(&args.file)?.curve_points();
    let closed = args.closed || file_closed;
    let tolerances = Tolerances {
        avg_pct: args.tol_avg,
        max_pct: args.tol_max,
        rms_pct: None,
    };
    let tolerances = if args.tol_avg.is_none() && args.tol_max.is_none() {
        Tolerances::default()
    } else {
        tolerances
    };
    let start = Instant::now();
    let (curve, stats, status, history, initial, extra) = match args.method {
        Method::Geometric => {
            let mut opts = CurveFitOptions::default()
                .with_degree(args.degree)
                .with_closed(closed)
                .with_tolerances(tolerances);
            if let Some(m) = args.max_iter {
                opts = opts.with_max_iter(m);
            }
            let mut fit = CurveFitter::try_new(&points, opts).map_err(|e| e.to_string())?;
            let status = fit.run().map_err(|e| e.to_string())?;
            let initial = fit.initial_control_points();
            let extra = serde_json::json!({});
            (
                fit.curve().clone(),
                fit.stats(),
                status,
                fit.history().to_vec(),
                initial,
                extra,
            )
        }
        Method::Knots => {
            let opts = KnotPlacementOptions::default()
                .with_degree(args.degree)
                .with_closed(closed)
                .with_tolerances(tolerances)
                .with_max_iter(args.max_iter)
                .with_corner_angle_deg(args.corner_angle)
                .with_curvature_jump(args.curvature_jump);
            let mut fit = KnotPlacementFitter::try_new(&points, opts).map_err(|e| e.to_string())?;
            let status = fit.run().map_err(|e| e.to_string())?;
            let corners = fit
                .features()
                .iter()
                .filter(|f| f.multiplicity == args.degree)
                .count();
            let extra = serde_json::json!({
                "features": fit.features().len(),
                "corners": corners,
                "std_pct": fit.std_pct(),
            });
            let initial = fit.initial_control_points();
            (
                fit.curve().clone(),
                fit.stats(),
                status,
                fit.history().to_vec(),
                initial,
                extra,
            )
        }
    };
    let fit_s = start.elapsed().as_secs_f64();
    let desc = CurveDesc::from_curve(&curve).map_err(|e| e.to_string())?;
    let clamped = serde_json::json!({
        "degree": desc.degree,
        "knots": desc.knots,
        "control_points": desc.control_points.iter().map(|p| p.to_array()).collect::<Vec<_>>(),
    });
    let model = ExportModel {
        curves: vec![desc],
        surfaces: Vec::new(),
    };
    write_exports(&model, args.iges.as_deref(), args.step.as_deref())?;
    let report = serde_json::json!({
        "scheme": "bspline-curve",
        "method": format!("{:?}", args.method).to_lowercase(),
        "degree": args.degree,
        "closed": closed,
        "points": points.len(),
        "initial_control_points": initial,
        "control_points": curve.control_points().len(),
        "final_control_points": curve.control_points().len(),
        "iterations": history.len(),
        "e_avg_pct": stats.e_avg_pct,
        "e_max_pct": stats.e_max_pct,
        "e_rms_pct": stats.e_rms_pct,
        "converged": status == FitStatus::Converged,
        "fit_s": fit_s,
        "total_s": fit_s,
        "details": extra,
        "history": history,
        "domain": [curve.domain().0, curve.domain().1],
        "samples": curve_samples(&curve, 101),
        "clamped": clamped,
    });
    let text = serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?;
    match &args.json {
        Some(path) => std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?,
        None => outln!(
            "{} control points, E_max {:.5} %, E_rms {:.5} %, {:?}, {:.1} ms",
            curve.control_points().len(),
            stats.e_max_pct,
            stats.e_rms_pct,
            status,
            fit_s * 1e3
        ),
    }
    Ok(())
}

/// Writes the IGES and STEP files that were asked for.
pub fn write_exports(
    model: &ExportModel,
    iges: Option<&Path>,
    step: Option<&Path>,
) -> Result<(), String> {
    let name = |p: &Path| {
        p.file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("geofit")
            .to_string()
    };
    if let Some(path) = iges {
        let text = write_iges(model, &name(path)).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    if let Some(path) = step {
        let text = write_step(model, &name(path)).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(())
}
