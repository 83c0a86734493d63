//! The `Fitter` handle: a subdivision-surface fit driven from JavaScript (a Web Worker, typically)
//! one iteration or one time budget at a time, with its results as typed arrays and bytes.

use super::scan::LoadedScan;
use crate::fit::{
    build_subdiv_fitter, Acceleration, FitReport, FitStatus, Fitter as _, IterationRecord,
    SubdivFitOptions, SubdivFitter, Tolerances, Weighting,
};
use crate::io;
use crate::mesh::PolyMesh;
use crate::render::buffers;
use crate::subdiv::{Scheme, SubdivSurface};
use serde::{Deserialize, Serialize};
use wasm_bindgen::prelude::*;
use web_time::Instant;

/// The options object of `new Fitter(scan, options)`; every field may be left out.
#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
struct JsFitOptions {
    /// 'loop' | 'catmull-clark' | 'doo-sabin' [loop].
    scheme: Option<String>,
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
}

impl JsFitOptions {
    fn scheme(&self) -> Result<Scheme, JsError> {
        match self.scheme.as_deref().unwrap_or("loop") {
            "loop" => Ok(Scheme::Loop),
            "catmull-clark" => Ok(Scheme::CatmullClark),
            "doo-sabin" => Ok(Scheme::DooSabin),
            other => Err(JsError::new(&format!(
                "option scheme: '{other}' is not one of 'loop', 'catmull-clark', 'doo-sabin'"
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
            "cg" => Ok(Acceleration::Cg { inner: 8 }),
            other => Err(JsError::new(&format!(
                "option acceleration: '{other}' is not one of 'none', 'relax', 'anderson', 'cg'"
            ))),
        }
    }

    /// The core options; ranges are checked by [`SubdivFitOptions::validate`].
    fn to_core(&self) -> Result<SubdivFitOptions, JsError> {
        let given = self.tol_avg.is_some() || self.tol_max.is_some() || self.tol_rms.is_some();
        let tolerances = if given {
            Tolerances {
                avg_pct: self.tol_avg,
                max_pct: self.tol_max,
                rms_pct: self.tol_rms,
            }
        } else {
            Tolerances::default()
        };
        let weighting = self.weighting()?;
        let defaults = SubdivFitOptions::default();
        let options = defaults
            .with_tolerances(tolerances)
            .with_max_iter(self.max_iter.unwrap_or(defaults.max_iter))
            .with_max_control(self.max_control)
            .with_refine(self.refine.unwrap_or(true))
            .with_weighting(weighting)
            .with_acceleration(self.acceleration(weighting)?);
        options.validate()?;
        Ok(options)
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

/// A triangle mesh for drawing: f32 positions and normals, u32 triangle indices, and the
/// polygon edges (index pairs) of the mesh before triangulation.
#[wasm_bindgen]
pub struct MeshArrays {
    positions: Vec<f32>,
    normals: Vec<f32>,
    indices: Vec<u32>,
    edges: Vec<u32>,
}

impl MeshArrays {
    fn of(mesh: &PolyMesh) -> MeshArrays {
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
    /// Smooth normal `x, y, z` per vertex.
    #[wasm_bindgen(getter)]
    pub fn normals(&self) -> Vec<f32> {
        self.normals.clone()
    }
    /// Three vertex indices per triangle.
    #[wasm_bindgen(getter)]
    pub fn indices(&self) -> Vec<u32> {
        self.indices.clone()
    }
    /// Two vertex indices per polygon edge (each edge once).
    #[wasm_bindgen(getter)]
    pub fn edges(&self) -> Vec<u32> {
        self.edges.clone()
    }
}

/// A subdivision-surface fit of a scan (SPEC §1), iterated on demand.
///
/// `new Fitter(scan, {scheme, tolAvg, tolMax, tolRms, initial, maxIter, refine, maxControl,
/// weights, acceleration})` builds the initial control mesh (QEM) and the first foot points;
/// then `step()` or `run(budgetMs)` iterate. Tolerances are % of the bounding-box diagonal.
#[wasm_bindgen]
pub struct Fitter {
    inner: SubdivFitter<SubdivSurface>,
    setup_s: f64,
    fit_s: f64,
}

#[wasm_bindgen]
impl Fitter {
    /// Builds a fitter of every point of `scan`. Throws on a bad option (naming it) or when the
    /// scan cannot be fitted (no faces to make a control mesh from, too few points, ...).
    #[wasm_bindgen(constructor)]
    pub fn new(scan: &LoadedScan, options: JsValue) -> Result<Fitter, JsError> {
        let start = Instant::now();
        let js: JsFitOptions = if options.is_undefined() || options.is_null() {
            JsFitOptions::default()
        } else {
            serde_wasm_bindgen::from_value(options)
                .map_err(|e| JsError::new(&format!("fit options: {e}")))?
        };
        let scheme = js.scheme()?;
        let core = js.to_core()?;
        let inner = build_subdiv_fitter(scan.mesh(), scheme, None, js.initial, core)?;
        Ok(Fitter {
            inner,
            setup_s: start.elapsed().as_secs_f64(),
            fit_s: 0.0,
        })
    }

    /// Runs one iteration (unless the fit has already stopped) and returns the statistics.
    pub fn step(&mut self) -> Result<JsValue, JsError> {
        if self.inner.status() == FitStatus::Running {
            let start = Instant::now();
            self.inner.step()?;
            self.fit_s += start.elapsed().as_secs_f64();
        }
        self.stats()
    }

    /// Iterates until the fit stops or `budget_ms` milliseconds are spent (at least one
    /// iteration while running); returns the statistics.
    pub fn run(&mut self, budget_ms: f64) -> Result<JsValue, JsError> {
        let start = Instant::now();
        while self.inner.status() == FitStatus::Running {
            self.step()?;
            if start.elapsed().as_secs_f64() * 1000.0 >= budget_ms {
                break;
            }
        }
        self.stats()
    }

    /// `{iter, controlPoints, eAvgPct, eMaxPct, eRmsPct, eAvg, eMax, eRms, diagonal, ms,
    /// totalMs, status, refined}`: the current errors (in % of the diagonal and model units),
    /// the last iteration's time and flags; status is 'running', 'converged' or 'max_iterations'.
    pub fn stats(&self) -> Result<JsValue, JsError> {
        let s = self.inner.stats();
        let last = self.inner.history().last();
        let stats = JsStats {
            iter: self.inner.history().len(),
            control_points: self.inner.num_control_points(),
            e_avg_pct: s.e_avg_pct,
            e_max_pct: s.e_max_pct,
            e_rms_pct: s.e_rms_pct,
            e_avg: s.e_avg,
            e_max: s.e_max,
            e_rms: s.e_rms,
            diagonal: self.inner.diagonal(),
            ms: last.map_or(0.0, |r| r.ms),
            total_ms: self.fit_s * 1000.0,
            status: self.inner.status(),
            refined: last.is_some_and(|r| r.refined),
        };
        Ok(serde_wasm_bindgen::to_value(&stats)?)
    }

    /// One `{iter, controlPoints, eAvgPct, eMaxPct, eRmsPct, ms, refined}` per iteration so far.
    pub fn history(&self) -> Result<JsValue, JsError> {
        let records: Vec<JsRecord> = self.inner.history().iter().map(JsRecord::from).collect();
        Ok(serde_wasm_bindgen::to_value(&records)?)
    }

    /// Signed distance of every data point to the surface (model units), in data order.
    #[wasm_bindgen(js_name = pointErrors)]
    pub fn point_errors(&self) -> Vec<f32> {
        self.inner
            .point_errors()
            .iter()
            .map(|&d| d as f32)
            .collect()
    }

    /// The data points, `x, y, z` each, in the order of `pointErrors()`.
    #[wasm_bindgen(js_name = dataPositions)]
    pub fn data_positions(&self) -> Vec<f32> {
        buffers::to_f32_xyz(self.inner.data())
    }

    /// The current control mesh (its polygons triangulated for drawing; `edges` are the polygon
    /// edges).
    #[wasm_bindgen(js_name = controlMesh)]
    pub fn control_mesh(&self) -> MeshArrays {
        MeshArrays::of(&self.inner.control_mesh())
    }

    /// The limit surface tessellated with `resolution` segments per patch edge (1..=64).
    #[wasm_bindgen(js_name = limitMesh)]
    pub fn limit_mesh(&self, resolution: usize) -> MeshArrays {
        MeshArrays::of(&self.inner.limit_mesh(resolution))
    }

    /// Error vectors as line segments: data point, then its foot point, `x, y, z` each.
    #[wasm_bindgen(js_name = errorVectors)]
    pub fn error_vectors(&self) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.inner.data().len() * 6);
        for (p, f) in self.inner.data().iter().zip(self.inner.foot_points()) {
            out.extend([p.x, p.y, p.z, f.point.x, f.point.y, f.point.z].map(|c| c as f32));
        }
        out
    }

    /// The limit surface (4 segments per patch edge) as OBJ bytes.
    #[wasm_bindgen(js_name = exportObj)]
    pub fn export_obj(&self) -> Result<Vec<u8>, JsError> {
        Ok(io::to_obj_bytes(&self.inner.limit_mesh(4))?)
    }

    /// The limit surface as binary little-endian PLY bytes.
    #[wasm_bindgen(js_name = exportPly)]
    pub fn export_ply(&self) -> Result<Vec<u8>, JsError> {
        Ok(io::to_ply_bytes(&self.inner.limit_mesh(4))?)
    }

    /// The limit surface as binary STL bytes.
    #[wasm_bindgen(js_name = exportStl)]
    pub fn export_stl(&self) -> Result<Vec<u8>, JsError> {
        Ok(io::to_stl_bytes(&self.inner.limit_mesh(4))?)
    }

    /// The control mesh (cage) as OBJ bytes: load it with the same scheme to get the surface.
    #[wasm_bindgen(js_name = exportCage)]
    pub fn export_cage(&self) -> Result<Vec<u8>, JsError> {
        Ok(io::to_obj_bytes(&self.inner.control_mesh())?)
    }

    /// The fit report (set-up, final errors, times, per-iteration history) as JSON text.
    #[wasm_bindgen(js_name = reportJson)]
    pub fn report_json(&self) -> Result<String, JsError> {
        let report = FitReport::of(
            &self.inner,
            self.setup_s - self.inner.precompute_seconds(),
            self.fit_s,
        );
        Ok(serde_json::to_string_pretty(&report)?)
    }
}
