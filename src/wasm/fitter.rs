//! The `Fitter` handle: a fit (subdivision surface, B-spline surface or curve) driven from
//! JavaScript (a Web Worker, typically) one iteration or one time budget at a time, with its
//! results as typed arrays and bytes; and the functions that tell the page every option's
//! default and where it applies, so no default is written twice.

use super::scan::LoadedScan;
use crate::export;
use crate::fem;
use crate::fit::{
    DeviationHistogram, DeviationStats, FitReport, FitSpec, FitStatus, Fitter as CoreFitter,
    IterationRecord, Method, Scheme, Shape, BACK_TOLERANCE_FACTOR,
};
use crate::geom::Point3;
use crate::io;
use crate::mesh::PolyMesh;
use crate::progress::{self, Phase};
use crate::render::buffers;
use serde::Serialize;
use wasm_bindgen::prelude::*;
use web_time::Instant;

/// Reads an options object (`undefined` or `null`: all defaults) into a [`FitSpec`]. Going
/// through a JSON value checks the object's own names: serde-wasm-bindgen alone reads only the
/// fields a struct declares, so a misspelt option would silently be a default.
pub(super) fn spec_from_js(options: JsValue) -> Result<FitSpec, JsError> {
    if options.is_undefined() || options.is_null() {
        return Ok(FitSpec::DEFAULT);
    }
    let bad = |e: &dyn std::fmt::Display| JsError::new(&format!("fit options: {e}"));
    let value: serde_json::Value = serde_wasm_bindgen::from_value(options).map_err(|e| bad(&e))?;
    serde_json::from_value(value).map_err(|e| bad(&e))
}

/// A value as a plain JavaScript object (`None` as `null`, maps as objects).
fn to_js(value: &impl Serialize) -> Result<JsValue, JsError> {
    let serializer = serde_wasm_bindgen::Serializer::json_compatible();
    Ok(value.serialize(&serializer)?)
}

/// The options object of `scheme` fitted by `method` (its default method when left out) with
/// every default written out, as the core uses it: `{scheme, method, tolAvg, tolMax, ...}`;
/// `null` where the data decides (`initial` and `maxControl` of subdivision surfaces, `closed`
/// of curves) or the scheme has no such option. Throws on an unknown name.
#[wasm_bindgen(js_name = defaultSpec, unchecked_return_type = "ResolvedFitSpec")]
pub fn default_spec(scheme: &str, method: Option<String>) -> Result<JsValue, JsError> {
    let (scheme, method) = scheme_and_method(scheme, method)?;
    to_js(&FitSpec::defaults_with(scheme, method))
}

/// `scheme` and `method` (the scheme's default when `None`) from their names.
fn scheme_and_method(scheme: &str, method: Option<String>) -> Result<(Scheme, Method), JsError> {
    let scheme: Scheme = scheme.parse().map_err(|e: String| JsError::new(&e))?;
    let method = match method {
        Some(m) => m.parse().map_err(|e: String| JsError::new(&e))?,
        None => scheme.default_method(),
    };
    Ok((scheme, method))
}

/// The names of the options that take part in a fit of `scheme` by `method` (the scheme's
/// default method when `method` is left out). Throws on an unknown name.
#[wasm_bindgen(js_name = optionsFor, unchecked_return_type = "(keyof FitSpec)[]")]
pub fn options_for(scheme: &str, method: Option<String>) -> Result<Vec<String>, JsError> {
    let (scheme, method) = scheme_and_method(scheme, method)?;
    Ok(FitSpec::options_for(scheme, method)
        .into_iter()
        .map(String::from)
        .collect())
}

/// The exports a fit of `scheme` offers: `cage`, `json` always; `obj`, `ply`, `stl` for
/// surfaces; `iges`, `step` for B-splines. Throws on an unknown scheme name.
#[wasm_bindgen(js_name = exportsFor, unchecked_return_type = "ExportName[]")]
pub fn exports_for(scheme: &str) -> Result<Vec<String>, JsError> {
    let scheme: Scheme = scheme.parse().map_err(|e: String| JsError::new(&e))?;
    Ok(export::exports_for(scheme)
        .iter()
        .map(|e| e.to_string())
        .collect())
}

/// The methods of `scheme`, its default first.
#[wasm_bindgen(js_name = methodsFor, unchecked_return_type = "Method[]")]
pub fn methods_for(scheme: &str) -> Result<Vec<String>, JsError> {
    let scheme: Scheme = scheme.parse().map_err(|e: String| JsError::new(&e))?;
    Ok(scheme
        .methods()
        .iter()
        .map(|m: &Method| m.name().to_string())
        .collect())
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
    method: &'static str,
    tol_avg_pct: Option<f64>,
    tol_max_pct: Option<f64>,
    tol_rms_pct: Option<f64>,
    /// Surface → data: the largest and 99th-percentile distance of the limit surface to the
    /// data, % of the diagonal (`null` where not measured).
    e_back_max_pct: Option<f64>,
    e_back_p99_pct: Option<f64>,
    /// The E_back a converged fit stays within: [`BACK_TOLERANCE_FACTOR`] E_max tolerances,
    /// % (`null` without an E_max tolerance).
    tol_back_pct: Option<f64>,
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

/// The deviation figures as JavaScript sees them (camelCase plain object).
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct JsDeviations {
    points: usize,
    mean: f64,
    sigma: f64,
    p50: f64,
    p90: f64,
    p95: f64,
    p99: f64,
    max: f64,
    tolerance: Option<f64>,
    within_tolerance_pct: Option<f64>,
    half_width: f64,
    counts: Vec<u32>,
    below: u32,
    above: u32,
}

impl JsDeviations {
    fn of(s: DeviationStats, h: DeviationHistogram) -> JsDeviations {
        JsDeviations {
            points: s.points,
            mean: s.mean,
            sigma: s.sigma,
            p50: s.p50,
            p90: s.p90,
            p95: s.p95,
            p99: s.p99,
            max: s.max,
            tolerance: s.tolerance,
            within_tolerance_pct: s.within_tolerance_pct,
            half_width: h.half_width,
            counts: h.counts,
            below: h.below,
            above: h.above,
        }
    }
}

/// A shape for drawing: f32 positions (and smooth normals), u32 triangle indices, and the
/// polygon edges (index pairs) of the mesh before triangulation, or the segments of a polyline
/// (then there are no triangles).
///
/// Holds WebAssembly memory until `free()` is called, or the scope of a `using` declaration
/// ends (`[Symbol.dispose]()` is `free()`); the garbage collector does not free it in time.
#[wasm_bindgen]
#[derive(Clone)]
pub struct MeshArrays {
    positions: Vec<f32>,
    normals: Vec<f32>,
    indices: Vec<u32>,
    edges: Vec<u32>,
    creases: Vec<u32>,
}

impl MeshArrays {
    pub(super) fn of(shape: &Shape) -> MeshArrays {
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
                    creases: Vec::new(),
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
            creases: Vec::new(),
        }
    }

    /// The control net of `fit` ([`MeshArrays::of`] its control shape) with the crease edges
    /// of a subdivision cage.
    fn control_of(fit: &dyn crate::fit::Fitter) -> MeshArrays {
        let mut arrays = MeshArrays::of(&fit.control_shape());
        if let Some(surface) = fit.subdiv_surface() {
            arrays.creases = surface.control_mesh().creases().concat();
        }
        arrays
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
    /// Two vertex indices per crease edge of a subdivision cage (tagged sharp; empty for other
    /// shapes and for fits without creases).
    #[wasm_bindgen(getter)]
    pub fn creases(&self) -> Vec<u32> {
        self.creases.clone()
    }
}

/// A fit of a scan, iterated on demand: a subdivision surface (SPEC §1), a B-spline surface or
/// a B-spline / Chaikin curve (for ordered section data).
///
/// `new Fitter(scan, options)` takes the options object of the core's `FitSpec` (see
/// `defaultSpec(scheme)` for every field and its default, `optionsFor(scheme)` for those that
/// apply), builds the initial control net (bare points are first reconstructed into a mesh
/// for the subdivision schemes) and the first foot points; then `step()` or `run(budgetMs)`
/// iterate. Tolerances are % of the bounding-box diagonal.
///
/// Holds WebAssembly memory until `free()` is called, or the scope of a `using` declaration
/// ends (`[Symbol.dispose]()` is `free()`); the garbage collector does not free it in time.
#[wasm_bindgen]
pub struct Fitter {
    fit: Box<dyn CoreFitter>,
    initial: MeshArrays,
    /// Metres per unit of the scan, when its format says (for the GLB export).
    unit_to_metres: Option<f64>,
}

impl Fitter {
    /// One iteration, its start and end reported as progress (the engines report their own
    /// steps in between).
    fn iterate(&mut self) -> Result<(), JsError> {
        progress::report(Phase::Iteration, 0.0);
        self.fit.step()?;
        progress::report(Phase::Iteration, 1.0);
        Ok(())
    }
}

#[wasm_bindgen]
impl Fitter {
    /// Builds a fitter of `scan`. Throws on a bad option (naming it) or when the scan cannot be
    /// fitted by the scheme (no faces to make a control mesh from, too few points, ...).
    /// `onProgress(phase, done)`, when given, hears the set-up's phases (`repair`,
    /// `reconstruction`, `simplification`, `setup`), each from 0 to 1.
    #[wasm_bindgen(constructor)]
    pub fn new(
        scan: &LoadedScan,
        #[wasm_bindgen(unchecked_param_type = "FitSpec | null | undefined")] options: JsValue,
        #[wasm_bindgen(js_name = onProgress, unchecked_optional_param_type = "ProgressCallback | null")]
        on_progress: Option<js_sys::Function>,
    ) -> Result<Fitter, JsError> {
        let spec = spec_from_js(options)?;
        let fit = super::with_progress(on_progress, || spec.build(&scan.fit_data()))?;
        let initial = MeshArrays::control_of(fit.as_ref());
        Ok(Fitter {
            fit,
            initial,
            unit_to_metres: scan.unit_to_metres(),
        })
    }

    /// Runs one iteration (unless the fit has already stopped) and returns the statistics.
    /// `onProgress(phase, done)`, when given, hears how far the iteration is (phase
    /// `iteration`).
    #[wasm_bindgen(unchecked_return_type = "FitStats")]
    pub fn step(
        &mut self,
        #[wasm_bindgen(js_name = onProgress, unchecked_optional_param_type = "ProgressCallback | null")]
        on_progress: Option<js_sys::Function>,
    ) -> Result<JsValue, JsError> {
        super::with_progress(on_progress, || self.iterate())?;
        self.stats()
    }

    /// Iterates until the fit stops or `budget_ms` milliseconds are spent (at least one
    /// iteration while running); returns the statistics. `onProgress` as for `step`, once
    /// per iteration.
    #[wasm_bindgen(unchecked_return_type = "FitStats")]
    pub fn run(
        &mut self,
        budget_ms: f64,
        #[wasm_bindgen(js_name = onProgress, unchecked_optional_param_type = "ProgressCallback | null")]
        on_progress: Option<js_sys::Function>,
    ) -> Result<JsValue, JsError> {
        let start = Instant::now();
        super::with_progress(on_progress, || {
            while self.fit.status() == FitStatus::Running {
                self.iterate()?;
                if start.elapsed().as_secs_f64() * 1000.0 >= budget_ms {
                    break;
                }
            }
            Ok::<_, JsError>(())
        })?;
        self.stats()
    }

    /// `{iter, controlPoints, eAvgPct, eMaxPct, eRmsPct, eAvg, eMax, eRms, diagonal, ms,
    /// totalMs, status, refined, scheme, method, tolAvgPct, tolMaxPct, tolRmsPct}`: the
    /// current errors (in % of the diagonal and model units), the last iteration's time and
    /// flags, and the tolerances in force (`null` where none); status is 'running',
    /// 'converged', 'max_iterations' or 'stalled'.
    #[wasm_bindgen(unchecked_return_type = "FitStats")]
    pub fn stats(&self) -> Result<JsValue, JsError> {
        let f = self.fit.as_ref();
        let s = f.stats();
        let last = f.history().last();
        let stats = JsStats {
            iter: f.history().len(),
            control_points: f.num_control_points(),
            e_avg_pct: s.e_avg_pct,
            e_max_pct: s.e_max_pct,
            e_rms_pct: s.e_rms_pct,
            e_avg: s.e_avg,
            e_max: s.e_max,
            e_rms: s.e_rms,
            diagonal: f.diagonal(),
            ms: last.map_or(0.0, |r| r.ms),
            total_ms: f.log().fit_seconds() * 1000.0,
            status: f.status(),
            refined: last.is_some_and(|r| r.refined),
            scheme: f.scheme().name(),
            method: f.method().name(),
            tol_avg_pct: f.tolerances().avg_pct,
            tol_max_pct: f.tolerances().max_pct,
            tol_rms_pct: f.tolerances().rms_pct,
            e_back_max_pct: f.back_stats().map(|b| b.max_pct),
            e_back_p99_pct: f.back_stats().map(|b| b.p99_pct),
            tol_back_pct: f.tolerances().max_pct.map(|t| BACK_TOLERANCE_FACTOR * t),
        };
        to_js(&stats)
    }

    /// One `{iter, controlPoints, eAvgPct, eMaxPct, eRmsPct, ms, refined}` per iteration so far.
    #[wasm_bindgen(unchecked_return_type = "HistoryEntry[]")]
    pub fn history(&self) -> Result<JsValue, JsError> {
        let records: Vec<JsRecord> = self.fit.history().iter().map(JsRecord::from).collect();
        to_js(&records)
    }

    /// Signed distance of every data point to the surface or curve (model units), in the order
    /// of `dataPositions()`.
    #[wasm_bindgen(js_name = pointErrors)]
    pub fn point_errors(&self) -> Vec<f32> {
        self.fit.point_errors().iter().map(|&d| d as f32).collect()
    }

    /// The distribution of `pointErrors()` (model units): `{points, mean, sigma, p50, p90,
    /// p95, p99, max, tolerance, withinTolerancePct}` (percentiles of |d|; `tolerance` the
    /// E_max tolerance in units, `null` without one) and a histogram of `bins` (1..=1024) equal
    /// bins over `-halfWidth..halfWidth`: `counts`, lowest first, the end bins holding the
    /// `below` / `above` points beyond the range. The same figures as the report's `deviation`.
    #[wasm_bindgen(unchecked_return_type = "Deviation")]
    pub fn deviations(&self, bins: usize) -> Result<JsValue, JsError> {
        if !(1..=1024).contains(&bins) {
            return Err(JsError::new(&format!(
                "deviations: bins {bins} is not in 1..=1024"
            )));
        }
        let f = self.fit.as_ref();
        let errors = f.point_errors();
        let stats = DeviationStats::of(errors, f.diagonal(), f.tolerances().max_pct);
        let histogram = DeviationHistogram::of(errors, &stats, bins);
        to_js(&JsDeviations::of(stats, histogram))
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
        MeshArrays::control_of(self.fit.as_ref())
    }

    /// The control net the fit started from, as `controlMesh()` gives it.
    #[wasm_bindgen(js_name = initialMesh)]
    pub fn initial_mesh(&self) -> MeshArrays {
        self.initial.clone()
    }

    /// The fitted shape: the surface tessellated with `resolution` segments per patch edge
    /// (1..=64), or the curve as a polyline (`edges` only). A B-spline surface is cut to the
    /// outline of the data, the face the STEP and IGES exports write, unless `untrimmed` is
    /// `true` (both on the same points, so their `positions` agree).
    #[wasm_bindgen(js_name = limitMesh)]
    pub fn limit_mesh(&self, resolution: usize, untrimmed: Option<bool>) -> MeshArrays {
        let trimmed = match untrimmed {
            Some(true) => None,
            _ => self.fit.trimmed_limit_shape(resolution),
        };
        MeshArrays::of(&trimmed.unwrap_or_else(|| self.fit.limit_shape(resolution)))
    }

    /// Iso-parameter lines of a B-spline surface at its knots, as line segments (`x, y, z` of
    /// both ends, `resolution` segments per knot span); empty for other schemes.
    #[wasm_bindgen(js_name = isoLines)]
    pub fn iso_lines(&self, resolution: usize) -> Vec<f32> {
        buffers::to_f32_xyz(&self.fit.iso_lines(resolution))
    }

    /// The limit curves of the cage's crease edges as line segments (`x, y, z` of both ends,
    /// `resolution` segments per crease edge); empty without creases, and for Doo–Sabin.
    #[wasm_bindgen(js_name = creaseCurves)]
    pub fn crease_curves(&self, resolution: usize) -> Vec<f32> {
        let curves = self
            .fit
            .subdiv_surface()
            .map(|s| s.crease_curves(resolution.clamp(1, 64)))
            .unwrap_or_default();
        buffers::to_f32_xyz(&curves)
    }

    /// The crease edges found on the data (`creases` on) as line segments, `x, y, z` of both
    /// ends; empty when crease detection was off or found none.
    #[wasm_bindgen(js_name = dataCreases)]
    pub fn data_creases(&self) -> Vec<f32> {
        let log = self.fit.state().log();
        buffers::to_f32_xyz(log.creases().map_or(&[][..], |c| &c.segments))
    }

    /// The distance to the data of every point `x, y, z` in `positions` (the `positions` of
    /// [`Fitter::limit_mesh`], to colour the surface by how far it strays), model units; −1
    /// for a point over a hole of the data or beyond its outline (the points E_back leaves
    /// out). Empty when the fit measures no surface → data distance (curves).
    #[wasm_bindgen(js_name = surfaceDistances)]
    pub fn surface_distances(&self, positions: &[f32]) -> Vec<f32> {
        let points: Vec<Point3> = positions
            .chunks_exact(3)
            .map(|p| Point3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
            .collect();
        self.fit
            .distances_to_data(&points)
            .map_or_else(Vec::new, |d| {
                d.into_iter()
                    .map(|d| d.map_or(-1.0, |d| d as f32))
                    .collect()
            })
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
        Ok(io::to_obj_bytes(&self.export_mesh()?)?)
    }

    /// The fitted surface as binary little-endian PLY bytes; throws for curves.
    #[wasm_bindgen(js_name = exportPly)]
    pub fn export_ply(&self) -> Result<Vec<u8>, JsError> {
        Ok(io::to_ply_bytes(&self.export_mesh()?)?)
    }

    /// The fitted surface as binary STL bytes; throws for curves.
    #[wasm_bindgen(js_name = exportStl)]
    pub fn export_stl(&self) -> Result<Vec<u8>, JsError> {
        Ok(io::to_stl_bytes(&self.export_mesh()?)?)
    }

    /// The control net as OBJ bytes: the cage of a subdivision surface (load it with the same
    /// scheme to get the surface), the control grid of a B-spline surface, or a curve's control
    /// polygon as an OBJ polyline (`l`).
    #[wasm_bindgen(js_name = exportCage)]
    pub fn export_cage(&self) -> Result<Vec<u8>, JsError> {
        Ok(export::cage_obj(self.fit.as_ref())?)
    }

    /// The surface as GLB (binary glTF): triangles, normals, the signed deviation as vertex
    /// colours and as `_DEVIATION`, the fit's figures in `extras`, in metres when the file's
    /// unit is known; throws for curves.
    #[wasm_bindgen(js_name = exportGlb)]
    pub fn export_glb(&self) -> Result<Vec<u8>, JsError> {
        Ok(export::glb_of(self.fit.as_ref(), self.unit_to_metres)?)
    }

    /// The fitted B-spline surface or curve as IGES 5.3 bytes (entity 128 or 126); throws for
    /// subdivision schemes.
    #[wasm_bindgen(js_name = exportIges)]
    pub fn export_iges(&self) -> Result<Vec<u8>, JsError> {
        Ok(export::iges_of(self.fit.as_ref(), "geofit")?.into_bytes())
    }

    /// The fitted B-spline surface or curve as STEP AP214 bytes; throws for subdivision schemes.
    #[wasm_bindgen(js_name = exportStep)]
    pub fn export_step(&self) -> Result<Vec<u8>, JsError> {
        Ok(export::step_of(self.fit.as_ref(), "geofit")?.into_bytes())
    }

    /// The export named `what` (one of `exportsFor(scheme)`: `cage`, `creases` (the cage's
    /// crease sidecar, JSON), `usda` (the cage as USD, with its creases), `obj`, `ply`, `stl`,
    /// `glb`, `iges`, `step`, `json`, `msh`: the FEM quad mesh with the default options) as
    /// bytes, as the `export*` method of that name gives it; the
    /// workers export by name through this one table. Throws on another name, or when the
    /// scheme has no such export.
    #[wasm_bindgen(js_name = exportAs)]
    pub fn export_as(
        &self,
        #[wasm_bindgen(unchecked_param_type = "ExportName")] what: &str,
    ) -> Result<Vec<u8>, JsError> {
        match what {
            "cage" => self.export_cage(),
            "obj" => self.export_obj(),
            "ply" => self.export_ply(),
            "stl" => self.export_stl(),
            "glb" => self.export_glb(),
            "iges" => self.export_iges(),
            "step" => self.export_step(),
            "json" => Ok(self.report_json()?.into_bytes()),
            "msh" => Ok(self.fem_export(&FemJsOptions::default())?.0),
            "creases" => Ok(export::cage_creases_json(self.fit.as_ref())?.into_bytes()),
            "usda" => Ok(export::cage_usda(self.fit.as_ref())?.into_bytes()),
            _ => Err(JsError::new(&format!(
                "unknown export '{what}': one of cage, creases, usda, obj, ply, stl, glb, iges, \
                 step, json, msh"
            ))),
        }
    }

    /// The FEM quad mesh of the fitted B-spline or Catmull–Clark surface ([`crate::fem`]):
    /// `options` is `{size?, count?, grading?, format?}` (`size` the target edge length in model
    /// units or `count` the number of elements, default 10,000; `grading` default 4; `format`
    /// `"msh"` (Gmsh 4.1 ASCII, default) or `"obj"`). Returns `{bytes, quality}`, `quality`
    /// holding `elements`, `nodes`, `aspectMin/Mean/Max`, `skewMaxDeg`, `skewMeanDeg`,
    /// `jacobianMin`, `inverted`, `onFolds`, `invertedOffFolds`. Throws on bad options and for
    /// other schemes.
    #[wasm_bindgen(js_name = exportFem, unchecked_return_type = "FemExport")]
    pub fn export_fem(
        &self,
        #[wasm_bindgen(unchecked_param_type = "FemExportOptions | null | undefined")]
        options: JsValue,
    ) -> Result<JsValue, JsError> {
        let o: FemJsOptions = if options.is_undefined() || options.is_null() {
            FemJsOptions::default()
        } else {
            let value: serde_json::Value = serde_wasm_bindgen::from_value(options)?;
            serde_json::from_value(value).map_err(|e| JsError::new(&format!("FEM options: {e}")))?
        };
        let (bytes, mesh) = self.fem_export(&o)?;
        let out = js_sys::Object::new();
        let bytes = js_sys::Uint8Array::from(bytes.as_slice());
        js_sys::Reflect::set(&out, &"bytes".into(), &bytes)
            .map_err(|_| JsError::new("exportFem"))?;
        js_sys::Reflect::set(&out, &"quality".into(), &to_js(mesh.quality())?)
            .map_err(|_| JsError::new("exportFem"))?;
        Ok(out.into())
    }

    /// What happened to the data before the first iteration, one line each ("repaired: 3
    /// non-manifold vertices split", "reconstructed open surface (delaunay): ...").
    #[wasm_bindgen(js_name = intakeNotes)]
    pub fn intake_notes(&self) -> Vec<String> {
        self.fit.log().intake_notes()
    }

    /// The fit report (set-up, final errors, times, per-iteration history) as JSON text.
    #[wasm_bindgen(js_name = reportJson)]
    pub fn report_json(&self) -> Result<String, JsError> {
        Ok(serde_json::to_string_pretty(&FitReport::of(
            self.fit.as_ref(),
        ))?)
    }
}

/// The options object of [`Fitter::export_fem`]; unknown names are errors.
#[derive(Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct FemJsOptions {
    size: Option<f64>,
    count: Option<usize>,
    grading: Option<f64>,
    format: Option<String>,
    untrimmed: Option<bool>,
}

impl Fitter {
    fn export_mesh(&self) -> Result<PolyMesh, JsError> {
        Ok(export::surface_mesh(self.fit.as_ref())?)
    }
}

impl Fitter {
    /// The FEM quad mesh `o` asks for, and its file (Gmsh `.msh` or OBJ quads).
    fn fem_export(&self, o: &FemJsOptions) -> Result<(Vec<u8>, fem::FemMesh), JsError> {
        if o.size.is_some() && o.count.is_some() {
            return Err(JsError::new("FEM options: give size or count, not both"));
        }
        let mut fem_options = fem::FemOptions::default().with_trim(!o.untrimmed.unwrap_or(false));
        if let Some(l) = o.size {
            fem_options = fem_options.with_edge(l);
        }
        if let Some(n) = o.count {
            fem_options = fem_options.with_count(n);
        }
        if let Some(g) = o.grading {
            fem_options = fem_options.with_grading(g);
        }
        let mesh = fem::mesh_fit(self.fit.as_ref(), &fem_options)?;
        let bytes = match o.format.as_deref() {
            None | Some("msh") => io::to_msh_bytes(mesh.mesh())?,
            Some("obj") => io::to_obj_bytes(mesh.mesh())?,
            Some(f) => return Err(JsError::new(&format!("FEM format '{f}': use msh or obj"))),
        };
        Ok((bytes, mesh))
    }
}
