//! `geofit export-samples DIR`: writes a fixed set of curves and surfaces (open, closed,
//! rational, tensor-product) as IGES and STEP, plus `samples.json` with parameters and the
//! points geofit evaluates there, so a CAD kernel can be checked against them
//! (tests/interop/test_export_occ.py does this with Open CASCADE).

use crate::output::write_exports;
use geofit::export::{CurveDesc, ExportModel, SurfaceDesc};
use geofit::geom::Point3;
use geofit::spline::BSplineCurve;
use std::path::{Path, PathBuf};

/// Arguments of `geofit export-samples`.
#[derive(clap::Args)]
pub struct Args {
    /// Output directory (created if missing).
    dir: PathBuf,
}

fn wavy(n: usize, z: f64) -> Vec<Point3> {
    (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            Point3::new(
                30.0 * t.cos() + 3.0 * (3.0 * t).sin(),
                20.0 * t.sin(),
                z * (2.0 * t).cos(),
            )
        })
        .collect()
}

fn curves() -> Result<Vec<(&'static str, BSplineCurve)>, String> {
    let e = |e: geofit::spline::SplineError| e.to_string();
    let mut knots = vec![0.0; 4];
    knots.extend([0.15, 0.4, 0.4, 0.7]);
    knots.extend([1.0; 4]);
    let open = BSplineCurve::try_new(3, knots, wavy(8, 5.0)).map_err(e)?;
    let tau = [0.0, 0.1, 0.3, 0.45, 0.6, 0.8, 1.0];
    let closed = BSplineCurve::try_periodic(3, &tau, wavy(6, 4.0)).map_err(e)?;
    let w: Vec<f64> = (0..7).map(|i| 0.6 + 0.15 * i as f64).collect();
    let rational = BSplineCurve::try_periodic_uniform(2, wavy(7, 2.0))
        .and_then(|c| c.try_with_weights(w))
        .map_err(e)?;
    // The exact NURBS circle of radius 10: nine points, weights 1 and √½.
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let ring = [
        (1., 0.),
        (1., 1.),
        (0., 1.),
        (-1., 1.),
        (-1., 0.),
        (-1., -1.),
        (0., -1.),
        (1., -1.),
        (1., 0.),
    ];
    let ctrl: Vec<Point3> = ring
        .iter()
        .map(|&(x, y)| Point3::new(10.0 * x, 10.0 * y, 0.0))
        .collect();
    let cw: Vec<f64> = (0..9).map(|i| if i % 2 == 1 { s } else { 1.0 }).collect();
    let circle_knots = vec![0., 0., 0., 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1., 1., 1.];
    let circle = BSplineCurve::try_new(2, circle_knots, ctrl)
        .and_then(|c| c.try_with_weights(cw))
        .map_err(e)?;
    Ok(vec![
        ("open_cubic", open),
        ("closed_cubic", closed),
        ("closed_rational", rational),
        ("nurbs_circle", circle),
    ])
}

fn surfaces() -> Vec<(&'static str, SurfaceDesc)> {
    let grid = |nu: usize, nv: usize| -> Vec<Point3> {
        (0..nu * nv)
            .map(|k| {
                let (i, j) = ((k / nv) as f64, (k % nv) as f64);
                Point3::new(
                    10.0 * i,
                    8.0 * j + 0.5 * i * i,
                    3.0 * (0.9 * i).sin() * (0.7 * j).cos(),
                )
            })
            .collect()
    };
    let bspline = SurfaceDesc {
        degree_u: 3,
        degree_v: 3,
        knots_u: vec![0., 0., 0., 0., 0.4, 1., 1., 1., 1.],
        knots_v: vec![0., 0., 0., 0., 0.3, 0.6, 1., 1., 1., 1.],
        num_u: 5,
        num_v: 6,
        control_points: grid(5, 6),
        weights: None,
        trim: None,
    };
    let nurbs = SurfaceDesc {
        degree_u: 2,
        degree_v: 3,
        knots_u: vec![0., 0., 0., 0.5, 1., 1., 1.],
        knots_v: vec![0., 0., 0., 0., 1., 1., 1., 1.],
        num_u: 4,
        num_v: 4,
        control_points: grid(4, 4),
        weights: Some((0..16).map(|k| 0.5 + 0.1 * (k % 5) as f64).collect()),
        trim: None,
    };
    vec![("bspline_surface", bspline), ("nurbs_surface", nurbs)]
}

/// Writes `model` as `<name>.igs` and `<name>.stp` in `dir`; returns the two file names, as
/// samples.json lists them.
fn write_iges_and_step(
    dir: &Path,
    name: &str,
    model: &ExportModel,
) -> Result<(String, String), String> {
    let (iges, step) = (format!("{name}.igs"), format!("{name}.stp"));
    write_exports(model, Some(&dir.join(&iges)), Some(&dir.join(&step)))?;
    Ok((iges, step))
}

pub fn run(args: Args) -> Result<(), String> {
    std::fs::create_dir_all(&args.dir).map_err(|e| format!("{}: {e}", args.dir.display()))?;
    let mut curve_json = Vec::new();
    for (name, curve) in curves()? {
        let model = ExportModel {
            curves: vec![CurveDesc::from_curve(&curve).map_err(|e| e.to_string())?],
            surfaces: Vec::new(),
        };
        let (iges, step) = write_iges_and_step(&args.dir, name, &model)?;
        curve_json.push(serde_json::json!({
            "name": name, "iges": iges, "step": step, "closed": curve.is_closed(),
            "rational": curve.weights().is_some(),
            "domain": [curve.domain().0, curve.domain().1],
            "samples": curve.samples(41),
        }));
    }
    let mut surface_json = Vec::new();
    for (name, surface) in surfaces() {
        let mut samples = Vec::new();
        for i in 0..=8 {
            for j in 0..=8 {
                let (u, v) = (i as f64 / 8.0, j as f64 / 8.0);
                let p = surface.eval(u, v).map_err(|e| e.to_string())?;
                samples.push([u, v, p.x, p.y, p.z]);
            }
        }
        let model = ExportModel {
            curves: Vec::new(),
            surfaces: vec![surface],
        };
        let (iges, step) = write_iges_and_step(&args.dir, name, &model)?;
        surface_json.push(serde_json::json!({
            "name": name, "iges": iges, "step": step, "samples": samples,
        }));
    }
    let json = serde_json::json!({ "curves": curve_json, "surfaces": surface_json });
    let path = args.dir.join("samples.json");
    let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?;
    std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))
}
