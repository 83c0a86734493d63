//! The fitting engines behind the JavaScript `Fitter`: subdivision surfaces, B-spline surfaces
//! (geometric or least-squares) and B-spline / Chaikin curves, seen through one interface —
//! iterate, read the figures, get drawable shapes (control net, limit, iso-parameter lines) and
//! export. Each engine is the core's own fitter; this module only adapts their accessors.

use crate::export::{iges::write_iges, step::write_step, CurveDesc, ExportModel, SurfaceDesc};
use crate::fit::{
    within_tolerance_pct, CurveFitter, FitReport, FitStatus, Fitter, GeometricSurfaceFitter,
    LsqSurfaceFitter, ReconstructionReport, SubdivFitter,
};
use crate::geom::{Aabb, Point3};
use crate::mesh::PolyMesh;
use crate::spline::{BSplineCurve, BSplineSurface, KnotVector};
use crate::subdiv::SubdivSurface;
use wasm_bindgen::JsError;

/// One of the core's fitters.
pub(super) enum Engine {
    /// Loop, Catmull–Clark or Doo–Sabin limit surface.
    Subdiv(Box<SubdivFitter<SubdivSurface>>),
    /// Tensor-product B-spline surface moved by error vectors.
    Geometric(Box<GeometricSurfaceFitter>),
    /// Tensor-product B-spline surface by smoothed least squares.
    LeastSquares(Box<LsqSurfaceFitter>),
    /// B-spline curve (degree 2 for the Chaikin scheme, whose limit it is).
    Curve(Box<CurveFitter>),
}

/// What is drawn for a control net or a limit shape: a polygon mesh, or a polyline (curves).
pub(super) enum Shape {
    /// Faces (drawn shaded; their edges drawn as lines).
    Mesh(PolyMesh),
    /// Points joined in order, back to the first when closed.
    Polyline {
        /// The vertices.
        points: Vec<Point3>,
        /// Whether the last joins the first.
        closed: bool,
    },
}

/// A running fit: the engine, its scheme name, and the data it fits (in error order).
pub(super) struct Fit {
    engine: Engine,
    scheme: &'static str,
    data: Vec<Point3>,
    diagonal: f64,
    /// The E_max tolerance in force (% of the diagonal), for `within_tolerance_pct`.
    tol_max_pct: Option<f64>,
    /// How bare points were made into a mesh, when they were.
    reconstruction: Option<ReconstructionReport>,
}

impl Fit {
    /// Wraps `engine`, fitting `data`, under the report name `scheme`.
    pub(super) fn new(engine: Engine, scheme: &'static str, data: Vec<Point3>) -> Fit {
        let diagonal = Aabb::from_points(&data).map_or(0.0, |b| b.diagonal());
        Fit {
            engine,
            scheme,
            data,
            diagonal,
            tol_max_pct: None,
            reconstruction: None,
        }
    }

    /// The fit with its E_max tolerance (% of the diagonal) known to the report.
    pub(super) fn with_tolerance(self, tol_max_pct: Option<f64>) -> Fit {
        Fit {
            tol_max_pct,
            ..self
        }
    }

    /// The fit with the reconstruction that made its control mesh, for the report.
    pub(super) fn with_reconstruction(self, reconstruction: Option<ReconstructionReport>) -> Fit {
        Fit {
            reconstruction,
            ..self
        }
    }

    /// The scheme's name, as reports give it.
    pub(super) fn scheme(&self) -> &'static str {
        self.scheme
    }

    /// The engine as the shared fitting interface.
    pub(super) fn core(&self) -> &dyn Fitter {
        match &self.engine {
            Engine::Subdiv(f) => f.as_ref(),
            Engine::Geometric(f) => f.as_ref(),
            Engine::LeastSquares(f) => f.as_ref(),
            Engine::Curve(f) => f.as_ref(),
        }
    }

    /// The engine as the shared fitting interface, for iterating.
    pub(super) fn core_mut(&mut self) -> &mut dyn Fitter {
        match &mut self.engine {
            Engine::Subdiv(f) => f.as_mut(),
            Engine::Geometric(f) => f.as_mut(),
            Engine::LeastSquares(f) => f.as_mut(),
            Engine::Curve(f) => f.as_mut(),
        }
    }

    /// Whether the fit goes on, converged or ran out of iterations.
    pub(super) fn status(&self) -> FitStatus {
        match &self.engine {
            Engine::Subdiv(f) => f.status(),
            Engine::Geometric(f) => f.status(),
            Engine::LeastSquares(f) => f.status(),
            Engine::Curve(f) => f.status(),
        }
    }

    /// The data points, in the order of the point errors.
    pub(super) fn data(&self) -> &[Point3] {
        &self.data
    }

    /// Bounding-box diagonal of the data: what the `_pct` figures are relative to.
    pub(super) fn diagonal(&self) -> f64 {
        self.diagonal
    }

    /// Number of control points now.
    pub(super) fn num_control_points(&self) -> usize {
        match &self.engine {
            Engine::Subdiv(f) => f.num_control_points(),
            Engine::Geometric(f) => f.surface().control_points().len(),
            Engine::LeastSquares(f) => f.surface().control_points().len(),
            Engine::Curve(f) => f.curve().control_points().len(),
        }
    }

    /// The surface point (or curve point) each data point is measured to, in data order.
    pub(super) fn foot_points(&self) -> Vec<Point3> {
        match &self.engine {
            Engine::Subdiv(f) => f.foot_points().iter().map(|t| t.point).collect(),
            Engine::Geometric(f) => surface_feet(f.surface(), f.parameters()),
            Engine::LeastSquares(f) => surface_feet(f.surface(), f.parameters()),
            Engine::Curve(f) => f.params().iter().map(|&u| f.curve().eval(u)).collect(),
        }
    }

    fn spline_surface(&self) -> Option<&BSplineSurface> {
        match &self.engine {
            Engine::Geometric(f) => Some(f.surface()),
            Engine::LeastSquares(f) => Some(f.surface()),
            Engine::Subdiv(_) | Engine::Curve(_) => None,
        }
    }

    /// The control net: the control mesh, the B-spline control grid, or the control polygon.
    pub(super) fn control_shape(&self) -> Shape {
        match &self.engine {
            Engine::Subdiv(f) => Shape::Mesh(f.control_mesh()),
            Engine::Geometric(f) => control_grid(f.surface()),
            Engine::LeastSquares(f) => control_grid(f.surface()),
            Engine::Curve(f) => Shape::Polyline {
                points: f.curve().control_points().to_vec(),
                closed: f.curve().is_closed(),
            },
        }
    }

    /// The fitted shape: the surface tessellated with `resolution` segments per patch (knot
    /// span) edge, or the curve sampled with `resolution` × 4 segments per span.
    pub(super) fn limit_shape(&self, resolution: usize) -> Shape {
        let r = resolution.clamp(1, 64);
        match &self.engine {
            Engine::Subdiv(f) => Shape::Mesh(f.limit_mesh(r)),
            Engine::Geometric(f) => Shape::Mesh(surface_mesh(f.surface(), r)),
            Engine::LeastSquares(f) => Shape::Mesh(surface_mesh(f.surface(), r)),
            Engine::Curve(f) => Shape::Polyline {
                points: curve_samples(f.curve(), 4 * r),
                closed: false,
            },
        }
    }

    /// Iso-parameter lines of a B-spline surface at its knots, as segment end points (two per
    /// segment, `resolution` segments per knot span); none for other schemes.
    pub(super) fn iso_lines(&self, resolution: usize) -> Vec<Point3> {
        let Some(s) = self.spline_surface() else {
            return Vec::new();
        };
        let r = resolution.clamp(1, 64);
        let (us, vs) = (span_samples(s.knots_u(), r), span_samples(s.knots_v(), r));
        let (ku, kv) = (span_samples(s.knots_u(), 1), span_samples(s.knots_v(), 1));
        let mut out = Vec::new();
        for &u in &ku {
            out.extend(segments(vs.iter().map(|&v| s.eval(u, v))));
        }
        for &v in &kv {
            out.extend(segments(us.iter().map(|&u| s.eval(u, v))));
        }
        out
    }

    /// The fitted surface as a mesh for OBJ/PLY/STL (4 segments per patch edge); a curve has
    /// none.
    pub(super) fn export_mesh(&self) -> Result<PolyMesh, JsError> {
        match self.limit_shape(4) {
            Shape::Mesh(mesh) => Ok(mesh),
            Shape::Polyline { .. } => Err(JsError::new(&format!(
                "scheme {}: a curve has no surface to export as a mesh; export IGES or STEP",
                self.scheme
            ))),
        }
    }

    /// The fitted spline for IGES/STEP; subdivision surfaces have none.
    pub(super) fn cad_model(&self) -> Result<ExportModel, JsError> {
        let mut model = ExportModel::default();
        match &self.engine {
            Engine::Subdiv(_) => {
                return Err(JsError::new(&format!(
                    "scheme {}: IGES and STEP export a B-spline; choose a B-spline surface or \
                     curve scheme, or export the limit mesh",
                    self.scheme
                )))
            }
            Engine::Curve(f) => model.curves.push(CurveDesc::from_curve(f.curve())?),
            Engine::Geometric(f) => model.surfaces.push(surface_desc(f.surface())),
            Engine::LeastSquares(f) => model.surfaces.push(surface_desc(f.surface())),
        }
        Ok(model)
    }

    /// IGES 5.3 text of the fitted spline, named `name`.
    pub(super) fn iges(&self, name: &str) -> Result<String, JsError> {
        Ok(write_iges(&self.cad_model()?, name)?)
    }

    /// STEP AP214 text of the fitted spline, named `name`.
    pub(super) fn step(&self, name: &str) -> Result<String, JsError> {
        Ok(write_step(&self.cad_model()?, name)?)
    }

    /// The report of the fit now; `setup_s` is the whole set-up time, `fit_s` the iteration time.
    pub(super) fn report(&self, setup_s: f64, fit_s: f64) -> FitReport {
        if let Engine::Subdiv(f) = &self.engine {
            let mut report = FitReport::of(f, setup_s - f.precompute_seconds(), fit_s);
            report.reconstruction = self.reconstruction.clone();
            return report;
        }
        let core = self.core();
        let stats = core.stats();
        let initial = match &self.engine {
            Engine::Geometric(f) => f.initial_control_points(),
            Engine::LeastSquares(f) => f.initial_control_points(),
            Engine::Curve(f) => f.initial_control_points(),
            Engine::Subdiv(f) => f.initial_control_points(),
        };
        FitReport {
            scheme: self.scheme.to_string(),
            points: self.data.len(),
            initial_control_points: initial,
            final_control_points: self.num_control_points(),
            iterations: core.history().len(),
            e_avg_pct: stats.e_avg_pct,
            e_max_pct: stats.e_max_pct,
            e_rms_pct: stats.e_rms_pct,
            converged: self.status() == FitStatus::Converged,
            within_tolerance_pct: self
                .tol_max_pct
                .map(|tol| within_tolerance_pct(core.point_errors(), self.diagonal, tol)),
            reconstruction: None,
            precompute_s: setup_s,
            fit_s,
            total_s: setup_s + fit_s,
            history: core.history().to_vec(),
        }
    }
}

fn surface_feet(s: &BSplineSurface, uv: &[[f64; 2]]) -> Vec<Point3> {
    uv.iter().map(|t| s.eval(t[0], t[1])).collect()
}

/// The distinct knots inside the domain, with `per_span - 1` parameters between neighbours.
fn span_samples(knots: &KnotVector, per_span: usize) -> Vec<f64> {
    let (a, b) = knots.domain();
    let mut distinct: Vec<f64> = knots
        .knots()
        .iter()
        .copied()
        .filter(|&k| k >= a && k <= b)
        .collect();
    distinct.dedup();
    let mut out = Vec::with_capacity(distinct.len() * per_span);
    for w in distinct.windows(2) {
        for k in 0..per_span {
            out.push(w[0] + (w[1] - w[0]) * k as f64 / per_span as f64);
        }
    }
    out.extend(distinct.last());
    out
}

/// Consecutive points as segment end points: a, b, b, c, ...
fn segments(points: impl Iterator<Item = Point3>) -> Vec<Point3> {
    let pts: Vec<Point3> = points.collect();
    pts.windows(2).flat_map(|w| [w[0], w[1]]).collect()
}

/// Quads between grid vertices `(i, j)` at `i * nv + j`.
fn grid_quads(nu: usize, nv: usize) -> Vec<[u32; 4]> {
    let at = |i: usize, j: usize| (i * nv + j) as u32;
    let mut quads = Vec::with_capacity(nu.saturating_sub(1) * nv.saturating_sub(1));
    for i in 1..nu {
        for j in 1..nv {
            quads.push([at(i - 1, j - 1), at(i, j - 1), at(i, j), at(i - 1, j)]);
        }
    }
    quads
}

/// A mesh over `points` laid out as an `nu × nv` grid; empty when a point is not finite (the
/// fitters keep control points and surface points finite).
fn grid_mesh(points: Vec<Point3>, nu: usize, nv: usize) -> PolyMesh {
    PolyMesh::try_new(points, grid_quads(nu, nv)).unwrap_or_default()
}

fn control_grid(s: &BSplineSurface) -> Shape {
    let (nu, nv) = s.num_control();
    Shape::Mesh(grid_mesh(s.control_points().to_vec(), nu, nv))
}

/// The surface sampled `r` times per knot span in each direction, as a quad mesh.
fn surface_mesh(s: &BSplineSurface, r: usize) -> PolyMesh {
    let (us, vs) = (span_samples(s.knots_u(), r), span_samples(s.knots_v(), r));
    let points = us
        .iter()
        .flat_map(|&u| vs.iter().map(move |&v| s.eval(u, v)))
        .collect();
    grid_mesh(points, us.len(), vs.len())
}

fn surface_desc(s: &BSplineSurface) -> SurfaceDesc {
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
    }
}

/// The curve at `per_span` parameters per control point over its domain, ends included.
fn curve_samples(c: &BSplineCurve, per_span: usize) -> Vec<Point3> {
    let (a, b) = c.domain();
    let n = (c.control_points().len() * per_span).max(2);
    (0..=n)
        .map(|i| c.eval(a + (b - a) * i as f64 / n as f64))
        .collect()
}
