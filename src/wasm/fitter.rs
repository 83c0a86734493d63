//! The `Fitter` handle: a fit (subdivision surface, B-spline surface or curve) driven from
//! JavaScript (a Web Worker, typically) one iteration or one time budget at a time, with its
//! results as typed arrays and bytes.

use super::engine::{Engine, Fit, Shape};
use super::scan::LoadedScan;
use crate::cloud::{ReconstructOptions, SurfaceKind};
use crate::fit::{
    build_subdiv_fitter, Acceleration, CurveFitOptions, CurveFitter, FitStatus,
    GeometricSurfaceFitter, GeometricSurfaceOptions, IterationRecord, LsqSurfaceFitter,
    LsqSurfaceOptions, SubdivFitOptions, Tolerances, Weighting,
};
use crate::geom::Point3;
use crate::io;
use crate::mesh::PolyMesh;
use crate::render::buffers;
use crate::subdiv::Scheme;
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;
use web_time::Instant;

/// The options object of `new Fitter(scan, options)`; every field may be left out.
#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
struct JsFitOptions {
    /// 'loop' | 'catmull-clark' | 'doo-sabin' | 'bspline-surface' | 'bspline-curve' |
    /// 'chaikin-curve' [loop].
    scheme: Option<String>,
    /// B-spline surface: 'geometric' (error vectors) | 'least-squares' [geometric].
    method: Option<String>,
    /// Curves: fit a closed curve [true when the file's polyline ends where it starts].
    closed: Option<bool>,
    /// Tolerance on E_avg, % of the bounding-box diagonal.
    tol_avg: Option<f64>,
    /// Tolerance on E_max, %.
    tol_max: Option<f64>,
    /// Tolerance on E_rms, %.
    tol_rms: Option<f64>,
    /// Vertex count of the initial control mesh (QEM simplification of the data).
    initial: Option<usize>,
    /// Iteration cap [200].
    max_iter: Option<usize>,
    /// Split control faces where the tolerance is not met [true].
    refine: Option<bool>,
    /// Control-point budget for refinement.
    max_control: Option<usize>,
    /// 'patent' | 'basis' [basis].
    weights: Option<String>,
    /// 'none' | 'relax' | 'anderson' | 'cg' [cg with basis weights, none with patent weights].
    acceleration: Option<String>,
    /// Subdivision schemes, point files without faces: 'auto' | 'open' | 'closed' surface to
    /// reconstruct before simplifying [auto].
    cloud: Option<String>,
    /// Subdivision schemes, point files without faces: statistical outlier removal, standard
    /// deviations [off].
    outliers: Option<f64>,
}

/// What the `scheme` option names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum JsScheme {
    Subdiv(Scheme),
    BsplineSurface,
    BsplineCurve,
    ChaikinCurve,
}

impl JsScheme {
    /// The name reports use.
    fn name(self) -> &'static str {
        match self {
            JsScheme::Subdiv(Scheme::Loop) => "loop",
            JsScheme::Subdiv(Scheme::CatmullClark) => "catmull-clark",
            JsScheme::Subdiv(_) => "doo-sabin",
            JsScheme::BsplineSurface => "bspline-surface",
            JsScheme::BsplineCurve => "bspline-curve",
            JsScheme::ChaikinCurve => "chaikin-curve",
        }
    }
}

impl JsFitOptions {
    /// Reads the options object (`undefined` or `null`: all defaults). serde-wasm-bindgen reads
    /// only the fields a struct declares, so the object's own names are checked separately: a
    /// misspelt option is an error, not silently a default.
    fn from_js(options: JsValue) -> Result<JsFitOptions, JsError> {
        if options.is_undefined() || options.is_null() {
            return Ok(JsFitOptions::default());
        }
        let bad = |e: &dyn std::fmt::Display| JsError::new(&format!("fit options: {e}"));
        let names: std::collections::BTreeMap<String, serde::de::IgnoredAny> =
            serde_wasm_bindgen::from_value(options.clone()).map_err(|e| bad(&e))?;
        let nulls = names
            .into_keys()
            .map(|name| (name, serde_json::Value::Null))
            .collect();
        serde_json::from_value::<JsFitOptions>(serde_json::Value::Object(nulls))
            .map_err(|e| bad(&e))?;
        serde_wasm_bindgen::from_value(options).map_err(|e| bad(&e))
    }

    fn scheme(&self) -> Result<JsScheme, JsError> {
        match self.scheme.as_deref().unwrap_or("loop") {
            "loop" => Ok(JsScheme::Subdiv(Scheme::Loop)),
            "catmull-clark" => Ok(JsScheme::Subdiv(Scheme::CatmullClark)),
            "doo-sabin" => Ok(JsScheme::Subdiv(Scheme::DooSabin)),
            "bspline-surface" => Ok(JsScheme::BsplineSurface),
            "bspline-curve" => Ok(JsScheme::BsplineCurve),
            "chaikin-curve" => Ok(JsScheme::ChaikinCurve),
            other => Err(JsError::new(&format!(
                "option scheme: '{other}' is not one of 'loop', 'catmull-clark', 'doo-sabin', \
                 'bspline-surface', 'bspline-curve', 'chaikin-curve'"
            ))),
        }
    }

    fn weighting(&self) -> Result<Weighting, JsError> {
        match self.weights.as_deref().unwrap_or("basis") {
            "basis" => Ok(Weighting::Basis),
            "patent" => Ok(Weighting::Patent),
            other => Err(JsError::new(&format!(
                "option weights: '{other}' is not one of 'patent', 'basis'"
            ))),
        }
    }

    fn acceleration(&self, weighting: Weighting) -> Result<Acceleration, JsError> {
        let default = match weighting {
            Weighting::Basis => "cg",
            Weighting::Patent => "none",
        };
        match self.acceleration.as_deref().unwrap_or(default) {
            "none" => Ok(Acceleration::None),
            "relax" => Ok(Acceleration::Relax { omega: 1.5 }),
            "anderson" => Ok(Acceleration::Anderson { depth: 5 }),
            "cg" => Ok(Acceleration::cg()),
            other => Err(JsError::new(&format!(
                "option acceleration: '{other}' is not one of 'none', 'relax', 'anderson', 'cg'"
            ))),
        }
    }

    /// The tolerances given, or the core's defaults when none is.
    fn tolerances(&self) -> Tolerances {
        Tolerances::given_or_default(self.tol_avg, self.tol_max, self.tol_rms)
    }

    /// The subdivision options; ranges are checked by [`SubdivFitOptions::validate`].
    fn to_core(&self) -> Result<SubdivFitOptions, JsError> {
        let weighting = self.weighting()?;
        let defaults = SubdivFitOptions::default();
        let options = defaults
            .with_tolerances(self.tolerances())
            .with_max_iter(self.max_iter.unwrap_or(defaults.max_iter))
            .with_max_control(self.max_control)
            .with_refine(self.refine.unwrap_or(true))
            .with_weighting(weighting)
            .with_acceleration(self.acceleration(weighting)?);
        options.validate()?;
        Ok(options)
    }

    /// Control points per direction of a B-spline surface: the side of a square grid of about
    /// `initial` points [8 × 8].
    fn grid_side(&self) -> usize {
        self.initial
            .map_or(8, |n| (n as f64).sqrt().round() as usize)
            .max(4)
    }

    /// The B-spline surface engine: error-vector (geometric) or least-squares, on E_max; with
    /// the E_max tolerance in force.
    fn surface_engine(&self, points: &[Point3]) -> Result<(Engine, Option<f64>), JsError> {
        let side = self.grid_side();
        let fixed = !self.refine.unwrap_or(true);
        match self.method.as_deref().unwrap_or("geometric") {
            "geometric" => {
                let d = GeometricSurfaceOptions::default();
                let mut o = d
                    .with_control(side, side)
                    .with_fixed_knots(fixed)
                    .with_tolerance(self.tol_max.unwrap_or(d.tol_pct), d.tol_mode)
                    .with_max_iterations(self.max_iter.unwrap_or(d.max_iterations))
                    .with_max_control_points(self.max_control.unwrap_or(d.max_control_points));
                if self.acceleration.is_some() {
                    o = o.with_acceleration(self.acceleration(Weighting::Basis)?);
                }
                let tol = Some(o.tol_pct);
                let fitter = GeometricSurfaceFitter::try_new(points, o)?;
                Ok((Engine::Geometric(Box::new(fitter)), tol))
            }
            "least-squares" => {
                let d = LsqSurfaceOptions::default();
                let o = d
                    .with_control(side, side)
                    .with_fixed_knots(fixed)
                    .with_tolerance(self.tol_max.unwrap_or(d.tol_pct), d.tol_mode)
                    .with_max_iterations(self.max_iter.unwrap_or(d.max_iterations))
                    .with_max_control_points(self.max_control.unwrap_or(d.max_control_points));
                let tol = Some(o.tol_pct);
                let fitter = LsqSurfaceFitter::try_new(points, o)?;
                Ok((Engine::LeastSquares(Box::new(fitter)), tol))
            }
            other => Err(JsError::new(&format!(
                "option method: '{other}' is not one of 'geometric', 'least-squares'"
            ))),
        }
    }

    /// The curve engine: degree 3, or degree 2 for Chaikin (the limit of corner cutting is the
    /// quadratic B-spline); with the E_max tolerance in force.
    fn curve_engine(
        &self,
        scan: &LoadedScan,
        degree: usize,
    ) -> Result<(Engine, Option<f64>), JsError> {
        let (points, file_closed) = scan.curve_points();
        let d = CurveFitOptions::default();
        let mut o = d
            .with_degree(degree)
            .with_closed(self.closed.unwrap_or(file_closed))
            .with_tolerances(self.tolerances())
            .with_max_iter(self.max_iter.unwrap_or(d.max_iter))
            .with_max_control(self.max_control);
        if self.acceleration.is_some() {
            o = o.with_acceleration(self.acceleration(Weighting::Basis)?);
        }
        let tol = o.tolerances.max_pct;
        Ok((
            Engine::Curve(Box::new(CurveFitter::try_new(&points, o)?)),
            tol,
        ))
    }

    /// How bare points become a mesh for the subdivision schemes; ranges are checked by the
    /// reconstruction.
    fn cloud(&self) -> Result<ReconstructOptions, JsError> {
        let kind = match self.cloud.as_deref().unwrap_or("auto") {
            "auto" => None,
            "open" => Some(SurfaceKind::Open),
            "closed" => Some(SurfaceKind::Closed),
            other => {
                return Err(JsError::new(&format!(
                    "option cloud: '{other}' is not one of 'auto', 'open', 'closed'"
                )))
            }
        };
        Ok(ReconstructOptions::default()
            .with_kind(kind)
            .with_outlier_std_ratio(self.outliers))
    }

    /// The engine of the chosen scheme, fitting `scan`.
    fn build(&self, scan: &LoadedScan) -> Result<Fit, JsError> {
        let scheme = self.scheme()?;
        let mut reconstruction = None;
        let (engine, tol_max_pct) = match scheme {
            JsScheme::Subdiv(s) => {
                let setup = build_subdiv_fitter(
                    scan.mesh(),
                    scan.range_grid(),
                    &self.cloud()?,
                    s,
                    None,
                    self.initial,
                    self.to_core()?,
                )?;
                reconstruction = setup.reconstruction;
                let tol = setup.fitter.options().tolerances.max_pct;
                (Engine::Subdiv(Box::new(setup.fitter)), tol)
            }
            JsScheme::BsplineSurface => self.surface_engine(scan.mesh().positions())?,
            JsScheme::BsplineCurve => self.curve_engine(scan, 3)?,
            JsScheme::ChaikinCurve => self.curve_engine(scan, 2)?,
        };
        let data = match &engine {
            Engine::Subdiv(f) => f.data().to_vec(),
            Engine::Curve(f) => f.data().to_vec(),
            Engine::Geometric(_) | Engine::LeastSquares(_) => scan.mesh().positions().to_vec(),
        };
        Ok(Fit::new(engine, scheme.name(), data)
            .with_tolerance(tol_max_pct)
            .with_reconstruction(reconstruction))
    }
}

/// One iteration's figures as JavaScript sees them (camelCase plain object).
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct JsStats {
    iter: usize,
    control_points: usize,
    e_avg_pct: f64,
    e_max_pct: f64,
    e_rms_pct: f64,
    e_avg: f64,
    e_max: f64,
    e_rms: f64,
    diagonal: f64,
    ms: f64,
    total_ms: f64,
    status: FitStatus,
    refined: bool,
    scheme: &'static str,
}

/// One history entry (camelCase plain object).
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct JsRecord {
    iter: usize,
    control_points: usize,
    e_avg_pct: f64,
    e_max_pct: f64,
    e_rms_pct: f64,
    ms: f64,
    refined: bool,
}

impl From<&IterationRecord> for JsRecord {
    fn from(r: &IterationRecord) -> Self {
        JsRecord {
            iter: r.iter,
            control_points: r.control_points,
            e_avg_pct: r.e_avg_pct,
            e_max_pct: r.e_max_pct,
            e_rms_pct: r.e_rms_pct,
            ms: r.ms,
            refined: r.refined,
        }
    }
}

/// A shape for drawing: f32 positions (and smooth normals), u32 triangle indices, and the
/// polygon edges (index pairs) of the mesh before triangulation, or the segments of a polyline
/// (then there are no triangles).
#[wasm_bindgen]
pub struct MeshArrays {
    positions: Vec<f32>,
    normals: Vec<f32>,
    indices: Vec<u32>,
    edges: Vec<u32>,
}

impl MeshArrays {
    fn of(shape: &Shape) -> MeshArrays {
        match shape {
            Shape::Mesh(mesh) => MeshArrays::of_mesh(mesh),
            Shape::Polyline { points, closed } => {
                let n = points.len() as u32;
                let segments = if *closed { n } else { n.saturating_sub(1) };
                MeshArrays {
                    positions: buffers::to_f32_xyz(points),
                    normals: Vec::new(),
                    indices: Vec::new(),
                    edges: (0..segments).flat_map(|i| [i, (i + 1) % n]).collect(),
                }
            }
        }
    }

    fn of_mesh(mesh: &PolyMesh) -> MeshArrays {
        let triangles = mesh.triangles();
        let mut seen = std::collections::HashSet::new();
        let mut edges = Vec::new();
        for face in mesh.faces() {
            for (k, &a) in face.iter().enumerate() {
                let b = face[(k + 1) % face.len()];
                if seen.insert((a.min(b), a.max(b))) {
                    edges.extend([a, b]);
                }
            }
        }
        MeshArrays {
            positions: buffers::to_f32_xyz(mesh.positions()),
            normals: buffers::vertex_normals(mesh.positions(), &triangles),
            indices: triangles.into_iter().flatten().collect(),
            edges,
        }
    }
}

#[wasm_bindgen]
impl MeshArrays {
    /// `x, y, z` per vertex.
    #[wasm_bindgen(getter)]
    pub fn positions(&self) -> Vec<f32> {
        self.positions.clone()
    }
    /// Smooth normal `x, y, z` per vertex (empty for a polyline).
    #[wasm_bindgen(getter)]
    pub fn normals(&self) -> Vec<f32> {
        self.normals.clone()
    }
    /// Three vertex indices per triangle (empty for a polyline).
    #[wasm_bindgen(getter)]
    pub fn indices(&self) -> Vec<u32> {
        self.indices.clone()
    }
    /// Two vertex indices per polygon edge or polyline segment (each edge once).
    #[wasm_bindgen(getter)]
    pub fn edges(&self) -> Vec<u32> {
        self.edges.clone()
    }
}

/// A fit of a scan, iterated on demand: a subdivision surface (SPEC §1), a B-spline surface or
/// a B-spline / Chaikin curve (for ordered section data).
///
/// `new Fitter(scan, {scheme, method, closed, tolAvg, tolMax, tolRms, initial, maxIter, refine,
/// maxControl, weights, acceleration, cloud, outliers})` builds the initial control net (bare
/// points are first reconstructed into a mesh for the subdivision schemes) and the first foot
/// points;
/// then `step()` or `run(budgetMs)` iterate. Tolerances are % of the bounding-box diagonal.
#[wasm_bindgen]
pub struct Fitter {
    fit: Fit,
    initial: MeshArrays,
    setup_s: f64,
    fit_s: f64,
}

#[wasm_bindgen]
impl Fitter {
    /// Builds a fitter of `scan`. Throws on a bad option (naming it) or when the scan cannot be
    /// fitted by the scheme (no faces to make a control mesh from, too few points, ...).
    #[wasm_bindgen(constructor)]
    pub fn new(scan: &LoadedScan, options: JsValue) -> Result<Fitter, JsError> {
        let start = Instant::now();
        let js = JsFitOptions::from_js(options)?;
        let fit = js.build(scan)?;
        let initial = MeshArrays::of(&fit.control_shape());
        Ok(Fitter {
            fit,
            initial,
            setup_s: start.elapsed().as_secs_f64(),
            fit_s: 0.0,
        })
    }

    /// Runs one iteration (unless the fit has already stopped) and returns the statistics.
    pub fn step(&mut self) -> Result<JsValue, JsError> {
        if self.fit.status() == FitStatus::Running {
            let start = Instant::now();
            self.fit.core_mut().step()?;
            self.fit_s += start.elapsed().as_secs_f64();
        }
        self.stats()
    }

    /// Iterates until the fit stops or `budget_ms` milliseconds are spent (at least one
    /// iteration while running); returns the statistics.
    pub fn run(&mut self, budget_ms: f64) -> Result<JsValue, JsError> {
        let start = Instant::now();
        while self.fit.status() == FitStatus::Running {
            self.step()?;
            if start.elapsed().as_secs_f64() * 1000.0 >= budget_ms {
                break;
            }
        }
        self.stats()
    }

    /// `{iter, controlPoints, eAvgPct, eMaxPct, eRmsPct, eAvg, eMax, eRms, diagonal, ms,
    /// totalMs, status, refined, scheme}`: the current errors (in % of the diagonal and model
    /// units), the last iteration's time and flags; status is 'running', 'converged' or
    /// 'max_iterations'.
    pub fn stats(&self) -> Result<JsValue, JsError> {
        let core = self.fit.core();
        let s = core.stats();
        let last = core.history().last();
        let stats = JsStats {
            iter: core.history().len(),
            control_points: self.fit.num_control_points(),
            e_avg_pct: s.e_avg_pct,
            e_max_pct: s.e_max_pct,
            e_rms_pct: s.e_rms_pct,
            e_avg: s.e_avg,
            e_max: s.e_max,
            e_rms: s.e_rms,
            diagonal: self.fit.diagonal(),
            ms: last.map_or(0.0, |r| r.ms),
            total_ms: self.fit_s * 1000.0,
            status: self.fit.status(),
            refined: last.is_some_and(|r| r.refined),
            scheme: self.fit.scheme(),
        };
        Ok(serde_wasm_bindgen::to_value(&stats)?)
    }

    /// One `{iter, controlPoints, eAvgPct, eMaxPct, eRmsPct, ms, refined}` per iteration so far.
    pub fn history(&self) -> Result<JsValue, JsError> {
        let records: Vec<JsRecord> = self
            .fit
            .core()
            .history()
            .iter()
            .map(JsRecord::from)
            .collect();
        Ok(serde_wasm_bindgen::to_value(&records)?)
    }

    /// Signed distance of every data point to the surface or curve (model units), in the order
    /// of `dataPositions()`.
    #[wasm_bindgen(js_name = pointErrors)]
    pub fn point_errors(&self) -> Vec<f32> {
        self.fit
            .core()
            .point_errors()
            .iter()
            .map(|&d| d as f32)
            .collect()
    }

    /// The data points, `x, y, z` each, in the order of `pointErrors()` (for curves: the ordered
    /// points of the file's longest polyline, or all points in file order).
    #[wasm_bindgen(js_name = dataPositions)]
    pub fn data_positions(&self) -> Vec<f32> {
        buffers::to_f32_xyz(self.fit.data())
    }

    /// The current control net: the control mesh (polygons triangulated for drawing, `edges`
    /// the polygon edges), the B-spline control grid, or a curve's control polygon (`edges`
    /// only).
    #[wasm_bindgen(js_name = controlMesh)]
    pub fn control_mesh(&self) -> MeshArrays {
        MeshArrays::of(&self.fit.control_shape())
    }

    /// The control net the fit started from, as `controlMesh()` gives it.
    #[wasm_bindgen(js_name = initialMesh)]
    pub fn initial_mesh(&self) -> MeshArrays {
        MeshArrays {
            positions: self.initial.positions.clone(),
            normals: self.initial.normals.clone(),
            indices: self.initial.indices.clone(),
            edges: self.initial.edges.clone(),
        }
    }

    /// The fitted shape: the surface tessellated with `resolution` segments per patch edge
    /// (1..=64), or the curve as a polyline (`edges` only).
    #[wasm_bindgen(js_name = limitMesh)]
    pub fn limit_mesh(&self, resolution: usize) -> MeshArrays {
        MeshArrays::of(&self.fit.limit_shape(resolution))
    }

    /// Iso-parameter lines of a B-spline surface at its knots, as line segments (`x, y, z` of
    /// both ends, `resolution` segments per knot span); empty for other schemes.
    #[wasm_bindgen(js_name = isoLines)]
    pub fn iso_lines(&self, resolution: usize) -> Vec<f32> {
        buffers::to_f32_xyz(&self.fit.iso_lines(resolution))
    }

    /// Error vectors as line segments: data point, then its foot point, `x, y, z` each.
    #[wasm_bindgen(js_name = errorVectors)]
    pub fn error_vectors(&self) -> Vec<f32> {
        let feet = self.fit.foot_points();
        let pairs: Vec<Point3> = self
            .fit
            .data()
            .iter()
            .zip(&feet)
            .flat_map(|(p, f)| [*p, *f])
            .collect();
        buffers::to_f32_xyz(&pairs)
    }

    /// The fitted surface (4 segments per patch edge) as OBJ bytes; throws for curves.
    #[wasm_bindgen(js_name = exportObj)]
    pub fn export_obj(&self) -> Result<Vec<u8>, JsError> {
        Ok(io::to_obj_bytes(&self.fit.export_mesh()?)?)
    }

    /// The fitted surface as binary little-endian PLY bytes; throws for curves.
    #[wasm_bindgen(js_name = exportPly)]
    pub fn export_ply(&self) -> Result<Vec<u8>, JsError> {
        Ok(io::to_ply_bytes(&self.fit.export_mesh()?)?)
    }

    /// The fitted surface as binary STL bytes; throws for curves.
    #[wasm_bindgen(js_name = exportStl)]
    pub fn export_stl(&self) -> Result<Vec<u8>, JsError> {
        Ok(io::to_stl_bytes(&self.fit.export_mesh()?)?)
    }

    /// The control net as OBJ bytes: the cage of a subdivision surface (load it with the same
    /// scheme to get the surface), the control grid of a B-spline surface, or a curve's control
    /// polygon as an OBJ polyline (`l`).
    #[wasm_bindgen(js_name = exportCage)]
    pub fn export_cage(&self) -> Result<Vec<u8>, JsError> {
        match self.fit.control_shape() {
            Shape::Mesh(mesh) => Ok(io::to_obj_bytes(&mesh)?),
            Shape::Polyline { points, closed } => Ok(polyline_obj(&points, closed).into_bytes()),
        }
    }

    /// The fitted B-spline surface or curve as IGES 5.3 bytes (entity 128 or 126); throws for
    /// subdivision schemes.
    #[wasm_bindgen(js_name = exportIges)]
    pub fn export_iges(&self) -> Result<Vec<u8>, JsError> {
        Ok(self.fit.iges("geofit")?.into_bytes())
    }

    /// The fitted B-spline surface or curve as STEP AP214 bytes; throws for subdivision schemes.
    #[wasm_bindgen(js_name = exportStep)]
    pub fn export_step(&self) -> Result<Vec<u8>, JsError> {
        Ok(self.fit.step("geofit")?.into_bytes())
    }

    /// The fit report (set-up, final errors, times, per-iteration history) as JSON text.
    #[wasm_bindgen(js_name = reportJson)]
    pub fn report_json(&self) -> Result<String, JsError> {
        let report = self.fit.report(self.setup_s, self.fit_s);
        Ok(serde_json::to_string_pretty(&report)?)
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
