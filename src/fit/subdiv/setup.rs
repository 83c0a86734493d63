//! Building a subdivision fitter from loaded data: a mesh for bare points, the initial control
//! mesh by QEM simplification, scheme set-up, fitter. [`crate::fit::FitSpec::build`] calls it.

use super::{SubdivFitOptions, SubdivFitter};
use crate::cloud::{reconstruct, ReconstructOptions, SurfaceKind};
use crate::fit::surface::CreaseKnots;
use crate::fit::{DataSurface, FitError, Fitter};
use crate::geom::Point3;
use crate::io::RangeGrid;
use crate::mesh::{
    detect_features, simplify_with_creases, FeatureOptions, Features, PolyMesh, Simplified,
    SimplifyOptions, SimplifyReport,
};
use crate::progress::{self, Phase};
use crate::subdiv::{Scheme, SubdivSurface};
use serde::Serialize;
use web_time::Instant;

/// The initial control-mesh size for `n` data points when the user gives none: n/60 (at least
/// 200, at most 20,000, never more than the `used` vertices of the data mesh), a density at
/// which QEM keeps the shape of scans like the Stanford bunny (35,947 points -> 599). The floor
/// is for small meshes: 50 control points for the 2,930 of `spot.obj` lose its legs and ears,
/// and the fit pulls sheets towards them (E_back 2.4 % of the diagonal at the default
/// tolerances, 0.28 % from 200).
pub fn default_initial_count(n: usize, used: usize) -> usize {
    (n / 60).clamp(200, 20_000).min(used)
}

/// The data mesh repaired and simplified by QEM to `target` vertices (or
/// [`default_initial_count`]), with the report of both; with `features`, the data's creases
/// are detected first and kept by QEM as chains of edges ([`Simplified::creases`]), the
/// default count grows by the vertices the lines keep when they take much of it, and the
/// second value says what was found. A point cloud has no faces to simplify: reconstruct a
/// mesh first (as [`build_subdiv_fitter`] does).
pub fn initial_control(
    data: &PolyMesh,
    target: Option<usize>,
    features: Option<&FeatureOptions>,
    scheme: Scheme,
) -> Result<(Simplified, Option<CreaseReport>), FitError> {
    if data.is_point_cloud() {
        return Err(FitError::NoFaces);
    }
    let used = used_vertices(data);
    let given = target;
    let target = target.unwrap_or_else(|| default_initial_count(data.num_vertices(), used));
    let found = find_creases(data, features)?;
    let edges = found.as_ref().map_or(&[][..], |(_, f)| f.edges.as_slice());
    let options = SimplifyOptions::default();
    let mut simplified = simplify_with_creases(data, target, &options, edges)?;
    // The default count is for the smooth surface: where crease lines take much of it, their
    // vertices come on top. Out of fandisk's default 200, 164 sat on its lines, and the faces
    // between them had too few of their own to follow the part (its thin blade became a pillow
    // with sheets 1.7 % of the diagonal off the data). Where the lines take little (the
    // bunny's 127 of 599) the addition only costs control points. The quad schemes' cage is
    // one Catmull–Clark step of this mesh, six times the vertices, which follows the faces
    // with a quarter of the addition (see docs/features.md).
    let on_lines = crease_vertices(&simplified.creases);
    if given.is_none() && on_lines as f64 > LINE_SHARE * target as f64 {
        let extra = match scheme {
            Scheme::Loop => on_lines,
            Scheme::CatmullClark | Scheme::DooSabin => on_lines.div_ceil(4),
        };
        let more = (target + extra).min(used);
        simplified = simplify_with_creases(data, more, &options, edges)?;
    }
    let report = found.map(|(angle_deg, f)| {
        CreaseReport::of(
            angle_deg,
            &f,
            data.positions(),
            simplified.creases.len(),
            None,
        )
    });
    Ok((simplified, report))
}

/// The sharp features of `data` with the angle they were found at, when `features` asks for
/// them. Detection fails only on options FitSpec has validated already.
pub(crate) fn find_creases(
    data: &PolyMesh,
    features: Option<&FeatureOptions>,
) -> Result<Option<(f64, Features)>, FitError> {
    features
        .map(|f| detect_features(data, f).map(|found| (f.angle_deg, found)))
        .transpose()
        .map_err(|e| FitError::InvalidOption {
            name: "creaseAngle",
            reason: e.to_string(),
        })
}

/// The share of the default initial count above which the vertices QEM keeps on crease lines
/// are added to it (see [`initial_control`]): fandisk's lines take 82 % of it, rocker-arm's
/// 60 %, the bunny's 21 %, the teapot's 18 %.
const LINE_SHARE: f64 = 0.3;

/// Vertices of the crease edges `creases`.
fn crease_vertices(creases: &[[u32; 2]]) -> usize {
    let mut ends: Vec<u32> = creases.iter().flatten().copied().collect();
    ends.sort_unstable();
    ends.dedup();
    ends.len()
}

/// The sharp features found on the data and kept on the initial control mesh: goes into the
/// fit report as `creases`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CreaseReport {
    /// The crease angle used, degrees.
    pub angle_deg: f64,
    /// One line for people ([`crate::mesh::Features::summary`]).
    pub summary: String,
    /// Crease edges of the data mesh.
    pub edges: usize,
    /// Crease lines they form.
    pub lines: usize,
    /// Corners (three or more crease edges).
    pub corners: usize,
    /// Dart ends (a line ending inside the surface).
    pub darts: usize,
    /// Total length of the crease edges, model units.
    pub length: f64,
    /// Crease edges tagged sharp on the initial control mesh (0 for a B-spline surface).
    pub control_edges: usize,
    /// A B-spline surface's crease knot lines: which crease lines it could represent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub knot_lines: Option<CreaseKnots>,
    /// The crease edges of the data as line segments (both ends of each), for drawing; not
    /// written to JSON.
    #[serde(skip)]
    pub segments: Vec<Point3>,
}

impl CreaseReport {
    /// The report of `features` found at `angle_deg` on the points `positions`, with what the
    /// fit made of them: crease edges of the control mesh, or a B-spline surface's knot lines.
    pub(crate) fn of(
        angle_deg: f64,
        features: &Features,
        positions: &[Point3],
        control_edges: usize,
        knot_lines: Option<CreaseKnots>,
    ) -> CreaseReport {
        CreaseReport {
            segments: features
                .edges
                .iter()
                .flat_map(|e| e.map(|v| positions[v as usize]))
                .collect(),
            angle_deg,
            summary: features.summary(),
            edges: features.edges.len(),
            lines: features.lines.len(),
            corners: features.corners.len(),
            darts: features.darts.len(),
            length: features.total_length,
            control_edges,
            knot_lines,
        }
    }
}

/// What [`build_subdiv_fitter`] made of bare points before simplifying: goes into the fit
/// report as `reconstruction`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReconstructionReport {
    /// `open` or `closed`.
    pub kind: &'static str,
    /// `range-grid`, `delaunay` (open scans) or `implicit` (closed objects).
    pub method: &'static str,
    /// Points removed as outliers (they are not fitted either).
    pub outliers: usize,
    /// Vertices of the reconstructed mesh.
    pub vertices: usize,
    /// Triangles of the reconstructed mesh.
    pub triangles: usize,
    /// Closed objects: triangles of the implicit surface dropped because they strayed from
    /// the points (the mesh has holes there; see [`crate::cloud`]).
    pub stray_triangles: usize,
    /// Points taken for an open scan that a triangulation in projection left in no triangle
    /// (too many: they are no height field), so they were reconstructed as a closed object;
    /// absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub open_uncovered: Option<usize>,
    /// Seconds the reconstruction took (included in the report's `precompute_s`).
    pub seconds: f64,
}

/// A fitter of the data points by the limit surface of `scheme`, starting from `control` when
/// given, else from a QEM simplification to `initial` vertices of the data mesh.
///
/// Data with faces is simplified as it is. Bare points (no faces) are first reconstructed
/// into a mesh by [`crate::cloud::reconstruct`] with `cloud` (open or closed, outlier
/// removal), using the scanner's `grid` when there is one; the fit then runs on the original
/// points (less those removed as outliers), not on the reconstructed vertices.
/// The reconstruction, when there was one, is in the fitter's log.
/// With `features`, the data's creases are found and kept sharp ([`initial_control`]); a
/// given control mesh is taken as it is.
#[allow(clippy::too_many_arguments)] // the set-up's inputs, all from one FitSpec
pub(crate) fn build_subdiv_fitter(
    data: &PolyMesh,
    grid: Option<&RangeGrid>,
    cloud: &ReconstructOptions,
    scheme: Scheme,
    control: Option<&PolyMesh>,
    initial: Option<usize>,
    features: Option<&FeatureOptions>,
    options: SubdivFitOptions,
) -> Result<SubdivFitter<SubdivSurface>, FitError> {
    options.validate()?;
    let (points, mesh, reconstruction) = if data.is_point_cloud() {
        let (points, mesh, report) = reconstruct_cloud(data.positions(), grid, cloud)?;
        (
            std::borrow::Cow::Owned(points),
            std::borrow::Cow::Owned(mesh),
            Some(report),
        )
    } else {
        let points = std::borrow::Cow::Borrowed(data.positions());
        (points, std::borrow::Cow::Borrowed(data), None)
    };
    let start = control_mesh(&mesh, control, initial, features, scheme)?;
    progress::report(Phase::Setup, 0.0);
    let reference = match reconstruction {
        None => DataSurface::of_mesh(&mesh),
        Some(_) => DataSurface::of_points(&points, &mesh),
    };
    let mut fitter =
        SubdivFitter::with_creases(&points, start.mesh, &start.creases, scheme, options)?
            .with_reference(reference);
    fitter.log_mut().set_reconstruction(reconstruction);
    fitter.log_mut().set_simplification(start.simplified);
    fitter.log_mut().set_creases(start.crease_report);
    Ok(fitter)
}

/// The initial control mesh of a fit and how it was made.
struct Start {
    mesh: PolyMesh,
    creases: Vec<[u32; 2]>,
    simplified: Option<SimplifyReport>,
    crease_report: Option<CreaseReport>,
}

/// The user's control mesh, or the simplification of `mesh` with its creases and reports.
fn control_mesh(
    mesh: &PolyMesh,
    given: Option<&PolyMesh>,
    initial: Option<usize>,
    features: Option<&FeatureOptions>,
    scheme: Scheme,
) -> Result<Start, FitError> {
    if let Some(control) = given {
        return Ok(Start {
            mesh: control.clone(),
            creases: Vec::new(),
            simplified: None,
            crease_report: None,
        });
    }
    let (simplified, crease_report) = initial_control(mesh, initial, features, scheme)?;
    Ok(Start {
        mesh: simplified.mesh,
        creases: simplified.creases,
        simplified: Some(simplified.report),
        crease_report,
    })
}

/// The points to fit (outliers dropped), the mesh reconstructed from them and its report.
fn reconstruct_cloud(
    points: &[Point3],
    grid: Option<&RangeGrid>,
    options: &ReconstructOptions,
) -> Result<(Vec<Point3>, PolyMesh, ReconstructionReport), FitError> {
    let start = Instant::now();
    let rec = reconstruct(points, grid, options)?;
    let kept: Vec<Point3> = points
        .iter()
        .zip(&rec.inlier)
        .filter_map(|(p, &k)| k.then_some(*p))
        .collect();
    let (kind, method) = match (rec.kind, grid) {
        (SurfaceKind::Closed, _) => ("closed", "implicit"),
        (_, Some(_)) => ("open", "range-grid"),
        (_, None) => ("open", "delaunay"),
    };
    let report = ReconstructionReport {
        kind,
        method,
        outliers: rec.outliers,
        vertices: used_vertices(&rec.mesh),
        triangles: rec.mesh.num_triangles(),
        stray_triangles: rec.stray_triangles,
        open_uncovered: rec.open_uncovered,
        seconds: start.elapsed().as_secs_f64(),
    };
    Ok((kept, rec.mesh, report))
}

/// How many vertices of `mesh` some face uses.
fn used_vertices(mesh: &PolyMesh) -> usize {
    let mut used = vec![false; mesh.num_vertices()];
    for f in mesh.faces() {
        for &v in f {
            used[v as usize] = true;
        }
    }
    used.iter().filter(|&&u| u).count()
}
