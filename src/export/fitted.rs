//! What a fit exports, for every engine alike: its spline as IGES/STEP, its surface as a mesh,
//! its control net as OBJ. The command line and the JavaScript API both come here, so they
//! refuse the same exports with the same messages.

use super::{iges::write_iges, step::write_step, CurveDesc, ExportError, ExportModel, SurfaceDesc};
use crate::fit::{FitReport, Fitter, Scheme, Shape, Spline, SurfaceTrim};
use crate::geom::Point3;
use crate::io::{to_glb_bytes, GlbOptions};
use crate::mesh::PolyMesh;
use crate::spline::{BSplineSurface, TrimOptions};
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;

/// The exports a fit of `scheme` offers: `cage` and `json` always, `obj`/`ply`/`stl`/`glb` for
/// surfaces, `iges`/`step` for B-splines, `msh` (the FEM quad mesh, [`crate::fem`]) for
/// B-spline and Catmull–Clark surfaces, the cage's crease sidecar `creases` for subdivision
/// surfaces and the USD cage `usda` for Loop and Catmull–Clark ([`super::cage_usda`]).
pub fn exports_for(scheme: Scheme) -> &'static [&'static str] {
    match scheme {
        Scheme::Loop => &[
            "cage", "creases", "usda", "obj", "ply", "stl", "glb", "json",
        ],
        Scheme::DooSabin => &["cage", "creases", "obj", "ply", "stl", "glb", "json"],
        Scheme::CatmullClark => &[
            "cage", "creases", "usda", "obj", "ply", "stl", "glb", "msh", "json",
        ],
        Scheme::BsplineSurface => &[
            "cage", "obj", "ply", "stl", "glb", "iges", "step", "msh", "json",
        ],
        Scheme::BsplineCurve | Scheme::ChaikinCurve => &["cage", "iges", "step", "json"],
    }
}

/// Segments per patch edge of an exported surface mesh.
pub const EXPORT_RESOLUTION: usize = 4;

impl SurfaceDesc {
    /// The description of `surface`.
    pub fn from_surface(s: &BSplineSurface) -> SurfaceDesc {
        let (num_u, num_v) = s.num_control();
        SurfaceDesc {
            degree_u: s.knots_u().degree(),
            degree_v: s.knots_v().degree(),
            knots_u: s.knots_u().knots().to_vec(),
            knots_v: s.knots_v().knots().to_vec(),
            num_u,
            num_v,
            control_points: s.control_points().to_vec(),
            weights: s.weights().map(<[f64]>::to_vec),
            trim: None,
        }
    }
}

/// The fitted spline of `fit` as an export model; subdivision surfaces have none. A surface is
/// trimmed to its data ([`SurfaceTrim`]); where the data give no region (too few points, all
/// on a line) it stays the whole rectangle, and the fit report's `trim` says why.
pub fn cad_model(fit: &dyn Fitter) -> Result<ExportModel, ExportError> {
    let mut model = ExportModel::default();
    match fit.spline() {
        Some(Spline::Surface { surface, params }) => {
            let mut desc = SurfaceDesc::from_surface(surface);
            desc.trim = SurfaceTrim::of(surface, params, fit.data(), &TrimOptions::default())
                .ok()
                .map(|t| t.region);
            model.surfaces.push(desc)
        }
        Some(Spline::Curve { curve, .. }) => model.curves.push(CurveDesc::from_curve(curve)?),
        None => {
            return Err(ExportError::Unsupported {
                what: format!(
                    "scheme {}: IGES and STEP export a B-spline; choose a B-spline surface or \
                     curve scheme, or export the limit mesh",
                    fit.scheme()
                ),
            })
        }
    }
    Ok(model)
}

/// The fitted spline of `fit` as IGES 5.3 text named `name`.
pub fn iges_of(fit: &dyn Fitter, name: &str) -> Result<String, ExportError> {
    write_iges(&cad_model(fit)?, name)
}

/// The fitted spline of `fit` as STEP AP214 text named `name`.
pub fn step_of(fit: &dyn Fitter, name: &str) -> Result<String, ExportError> {
    write_step(&cad_model(fit)?, name)
}

/// The fitted surface tessellated with `resolution` segments per patch edge, a B-spline
/// surface cut to its trim (without the vertices of the quads left out): what the page draws
/// and every mesh export writes.
pub fn surface_shape(fit: &dyn Fitter, resolution: usize) -> Shape {
    let trimmed = fit
        .trimmed_limit_shape(resolution)
        .map(|shape| match shape {
            Shape::Mesh(mesh) => Shape::Mesh(mesh.without_unused_vertices().0),
            curve => curve,
        });
    trimmed.unwrap_or_else(|| fit.limit_shape(resolution))
}

/// The fitted surface tessellated for OBJ/PLY/STL/GLB ([`EXPORT_RESOLUTION`] segments per
/// patch edge), a B-spline surface cut to its trim as the page draws it and STEP and IGES
/// write it (the rectangle beyond the data curls away from it); a curve has none.
pub fn surface_mesh(fit: &dyn Fitter) -> Result<PolyMesh, ExportError> {
    match surface_shape(fit, EXPORT_RESOLUTION) {
        Shape::Mesh(mesh) => Ok(mesh),
        Shape::Polyline { .. } => Err(ExportError::Unsupported {
            what: format!(
                "scheme {}: a curve has no surface to export as a mesh; export IGES or STEP",
                fit.scheme()
            ),
        }),
    }
}

/// The fitted surface as GLB (binary glTF 2.0): [`surface_mesh`] with normals, the signed
/// deviation of every vertex as `COLOR_0` (diverging scale, white within the E_max tolerance
/// band fading to red above and blue below) and as the `_DEVIATION` attribute, and the fit's
/// figures (the report without its history) in the scene's `extras`. A vertex's deviation is
/// that of the data point whose foot point is nearest to it, so the colours show the data's
/// errors where they are on the surface. `unit_to_metres` (from the input file, when its
/// format says) scales the node so viewers show metres.
pub fn glb_of(fit: &dyn Fitter, unit_to_metres: Option<f64>) -> Result<Vec<u8>, ExportError> {
    let mesh = surface_mesh(fit)?;
    let deviation = vertex_deviation(&mesh, &fit.foot_points(), fit.point_errors());
    let mut figures =
        serde_json::to_value(FitReport::of(fit)).map_err(|e| ExportError::Invalid {
            what: "fit report".into(),
            reason: e.to_string(),
        })?;
    if let Some(map) = figures.as_object_mut() {
        map.remove("history");
    }
    let mut options = GlbOptions::default()
        .with_deviation(&deviation)
        .with_extras(&figures);
    if let Some(tol) = fit.tolerances().max_pct {
        options = options.with_tolerance(tol / 100.0 * fit.diagonal());
    }
    if let Some(unit) = unit_to_metres {
        options = options.with_unit_to_metres(unit);
    }
    to_glb_bytes(&mesh, &options).map_err(|e| ExportError::Unsupported {
        what: e.to_string(),
    })
}

/// The signed error of the data point whose foot point is nearest to each vertex of `mesh`
/// (0 everywhere without data).
fn vertex_deviation(mesh: &PolyMesh, feet: &[Point3], errors: &[f64]) -> Vec<f64> {
    let n = mesh.num_vertices();
    if feet.is_empty() || feet.len() != errors.len() {
        return vec![0.0; n];
    }
    let f32s = |p: &Point3| [p.x as f32, p.y as f32, p.z as f32];
    let at: Vec<[f32; 3]> = feet.iter().map(f32s).collect();
    let tree: ImmutableKdTree<f32, u32, 3, 32> = ImmutableKdTree::new_from_slice(&at);
    mesh.positions()
        .iter()
        .map(|p| {
            let near = tree.nearest_one::<SquaredEuclidean>(&f32s(p));
            errors.get(near.item as usize).copied().unwrap_or(0.0)
        })
        .collect()
}

/// The control net as OBJ text: the cage of a subdivision surface (load it with the same
/// scheme to get the surface), the control grid of a B-spline surface, or a curve's control
/// polygon as an OBJ polyline (`l`).
pub fn cage_obj(fit: &dyn Fitter) -> Result<Vec<u8>, ExportError> {
    match fit.control_shape() {
        Shape::Mesh(mesh) => crate::io::to_obj_bytes(&mesh).map_err(|e| ExportError::Unsupported {
            what: e.to_string(),
        }),
        Shape::Polyline { points, closed } => Ok(polyline_obj(&points, closed).into_bytes()),
    }
}

/// A polyline as OBJ text: its vertices and one `l` statement (back to the first when closed).
fn polyline_obj(points: &[Point3], closed: bool) -> String {
    let mut text = String::from("# geofit control polygon\n");
    for p in points {
        text.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    let mut indices: Vec<usize> = (1..=points.len()).collect();
    if closed && !points.is_empty() {
        indices.push(1);
    }
    text.push('l');
    for i in indices {
        text.push_str(&format!(" {i}"));
    }
    text.push('\n');
    text
}
