//! [`FitSpec`]: the one description of what to fit and how — scheme, method, tolerances,
//! budgets and every engine option — that the command line fills from its flags, JavaScript
//! passes as a plain object and the page's form is built from. Its defaults come from the
//! engines' own `DEFAULT` options, its validation names every bad field the same way
//! everywhere, and [`FitSpec::build`] makes the engine.
//!
//! ```
//! use geofit::fit::{FitData, FitSpec, Fitter, FitStatus, Scheme};
//! use geofit::geom::Point3;
//! use geofit::mesh::PolyMesh;
//!
//! // Points on a quarter circle, fitted by a cubic B-spline curve.
//! let points: Vec<Point3> = (0..40)
//!     .map(|i| {
//!         let t = i as f64 / 39.0 * std::f64::consts::FRAC_PI_2;
//!         Point3::new(t.cos(), t.sin(), 0.0)
//!     })
//!     .collect();
//! let mesh = PolyMesh::try_new(points, Vec::<[u32; 3]>::new())?;
//! let spec = FitSpec::new(Scheme::BsplineCurve).with_tol_max(Some(0.01));
//! let mut fit = spec.build(&FitData::points(&mesh))?;
//! assert_eq!(fit.run()?, FitStatus::Converged);
//! assert!(fit.stats().e_max_pct <= 0.01);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::curve::{CurveFitOptions, CurveFitter, KnotPlacementFitter, KnotPlacementOptions};
use super::strays::WithoutStrays;
use super::subdiv::{build_subdiv_fitter, find_creases, CreaseReport, SubdivFitOptions, Weighting};
use super::surface::{
    detect_rows, grid_rows, CreaseKnots, FoldPolicy, GeometricSurfaceFitter,
    GeometricSurfaceOptions, LsqSurfaceFitter, LsqSurfaceOptions, SectionsFitter, SectionsOptions,
    SurfaceGrid, TolMode,
};
use super::DataSurface;
use super::{Acceleration, FitError, Fitter, Tolerances};
use crate::cloud::{reconstruct, ReconstructOptions, SurfaceKind};
use crate::geom::{Point3, Vec3};
use crate::io::{LoadedFile, RangeGrid};
use crate::mesh::{FeatureLine, FeatureOptions, PolyMesh};
use crate::subdiv;
use serde::{Deserialize, Serialize};
use web_time::Instant;

/// What is fitted: a subdivision limit surface, one B-spline surface, or a curve.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Scheme {
    /// Loop subdivision surface (triangle control mesh).
    #[default]
    Loop,
    /// Catmull–Clark subdivision surface (quad control mesh).
    CatmullClark,
    /// Doo–Sabin subdivision surface (any polygons).
    DooSabin,
    /// One tensor-product B-spline surface (for open scans).
    BsplineSurface,
    /// A B-spline curve through ordered points (a section).
    BsplineCurve,
    /// Chaikin's corner-cutting curve: its limit is the quadratic B-spline, fitted as one (a
    /// degree-2 B-spline curve fit is reported as this scheme).
    ChaikinCurve,
}

named_enum!(Scheme, "scheme", {
    Loop => "loop",
    CatmullClark => "catmull-clark",
    DooSabin => "doo-sabin",
    BsplineSurface => "bspline-surface" | "bspline",
    BsplineCurve => "bspline-curve",
    ChaikinCurve => "chaikin-curve",
});

impl Scheme {
    /// The subdivision scheme, for the three subdivision surfaces.
    pub const fn subdivision(self) -> Option<subdiv::Scheme> {
        match self {
            Scheme::Loop => Some(subdiv::Scheme::Loop),
            Scheme::CatmullClark => Some(subdiv::Scheme::CatmullClark),
            Scheme::DooSabin => Some(subdiv::Scheme::DooSabin),
            _ => None,
        }
    }

    /// Whether the scheme fits a curve (to ordered points).
    pub const fn is_curve(self) -> bool {
        matches!(self, Scheme::BsplineCurve | Scheme::ChaikinCurve)
    }

    /// The methods the scheme can be fitted with; the first is its default.
    pub const fn methods(self) -> &'static [Method] {
        match self {
            Scheme::BsplineSurface => &[Method::LeastSquares, Method::Geometric, Method::Sections],
            Scheme::BsplineCurve | Scheme::ChaikinCurve => {
                &[Method::Geometric, Method::KnotPlacement]
            }
            _ => &[Method::Geometric],
        }
    }

    /// The method used when none is chosen.
    pub const fn default_method(self) -> Method {
        self.methods()[0]
    }
}

impl From<subdiv::Scheme> for Scheme {
    fn from(s: subdiv::Scheme) -> Scheme {
        match s {
            subdiv::Scheme::Loop => Scheme::Loop,
            subdiv::Scheme::CatmullClark => Scheme::CatmullClark,
            subdiv::Scheme::DooSabin => Scheme::DooSabin,
        }
    }
}

/// How control points are found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Move control points by weighted error vectors; no linear system (SPEC §1).
    Geometric,
    /// Smoothed least squares E1 + β2·E2 + β3·E3 with a sparse solver (SPEC §2).
    LeastSquares,
    /// Least squares with knots placed at features and deviations (SPEC §3).
    KnotPlacement,
    /// Skinning: gridded data's rows fitted by knot placement, then curves across them.
    Sections,
}

named_enum!(Method, "method", {
    Geometric => "geometric",
    LeastSquares => "least-squares",
    KnotPlacement => "knots",
    Sections => "sections",
});

/// How bare points (no faces) are meshed before a subdivision fit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Cloud {
    /// Decide from the data (a range grid, or normals mostly facing one side, mean open).
    #[default]
    Auto,
    /// An open single-view scan: range grid or Delaunay on the best-fit plane.
    Open,
    /// A closed object: oriented normals and an implicit surface.
    Closed,
}

named_enum!(Cloud, "cloud", { Auto => "auto", Open => "open", Closed => "closed" });

/// The data a fit runs on: points with the faces a file gave (or none), the scanner's range
/// grid, polylines (ordered points for curves) and, optionally, a control mesh to start from.
#[derive(Clone, Copy, Debug)]
pub struct FitData<'a> {
    /// The points, and faces where the file has them.
    pub mesh: &'a PolyMesh,
    /// The scanner grid of a range scan (it meshes bare points without Delaunay).
    pub grid: Option<&'a RangeGrid>,
    /// Polylines as vertex indices into `mesh` (a curve fits the longest).
    pub polylines: &'a [Vec<u32>],
    /// A control mesh to start a subdivision fit from, instead of simplifying the data.
    pub control: Option<&'a PolyMesh>,
}

/// What a fit of a file runs on: its points and faces, range grid and polylines.
impl<'a> From<&'a LoadedFile> for FitData<'a> {
    fn from(file: &'a LoadedFile) -> FitData<'a> {
        FitData {
            mesh: &file.mesh,
            grid: file.range_grid.as_ref(),
            polylines: &file.polylines,
            control: None,
        }
    }
}

impl<'a> FitData<'a> {
    /// Just points (and faces, if `mesh` has them).
    pub fn points(mesh: &'a PolyMesh) -> FitData<'a> {
        FitData {
            mesh,
            grid: None,
            polylines: &[],
            control: None,
        }
    }

    /// The points of a curve in order, and whether the data closes them: the longest
    /// polyline (closed when it returns to its first vertex, which is then given once), or
    /// else all points in file order, open.
    pub fn curve_points(&self) -> (Vec<Point3>, bool) {
        let pos = self.mesh.positions();
        let Some(line) = self.polylines.iter().max_by_key(|l| l.len()) else {
            return (pos.to_vec(), false);
        };
        let closed = line.len() > 2 && line.first() == line.last();
        let take = if closed { line.len() - 1 } else { line.len() };
        let points = line[..take]
            .iter()
            .filter_map(|&i| pos.get(i as usize).copied())
            .collect();
        (points, closed)
    }
}

/// What to fit and how. Every field may be left at its default: `None` means "the scheme's
/// default" (see [`FitSpec::defaults`]), which for `initial` and `maxControl` of subdivision
/// surfaces is computed from the data. Serialised in camelCase (the JavaScript API's options
/// object); unknown fields are rejected.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields, default)]
#[non_exhaustive]
pub struct FitSpec {
    /// What is fitted [loop].
    pub scheme: Scheme,
    /// How [the scheme's first method: least squares for B-spline surfaces, geometric
    /// otherwise].
    pub method: Option<Method>,
    /// Tolerance on E_avg, % of the bounding-box diagonal. Giving any tolerance means only the
    /// given ones count.
    pub tol_avg: Option<f64>,
    /// Tolerance on E_max, %.
    pub tol_max: Option<f64>,
    /// Tolerance on E_rms, %.
    pub tol_rms: Option<f64>,
    /// Initial control points: the vertex count of the QEM-simplified control mesh
    /// (subdivision; automatic: [`crate::fit::default_initial_count`]), or about that many as a
    /// square grid (B-spline surface).
    pub initial: Option<usize>,
    /// B-spline surface: control points along u and v, instead of a square grid of `initial`.
    pub grid: Option<[usize; 2]>,
    /// Iteration cap (knot insertions for the knots method).
    pub max_iter: Option<usize>,
    /// Split faces / insert knots where the tolerance is missed; off keeps the control net's
    /// structure (fixed knots) [true].
    pub refine: bool,
    /// Control-point budget of refinement [half the points for subdivision, 40,000 for
    /// surfaces, the number of points for curves].
    pub max_control: Option<usize>,
    /// Subdivision: error-vector weighting [basis].
    pub weights: Weighting,
    /// Acceleration of the geometric iteration [cg with basis weights, none with patent
    /// weights; anderson for B-spline surfaces; none for curves].
    pub acceleration: Option<Acceleration>,
    /// Subdivision with CG: weight of the tangential error against the normal one, in (0, 1].
    pub tangent_weight: Option<f64>,
    /// Subdivision: one refinement adds at most this fraction of the control points.
    pub refine_growth: Option<f64>,
    /// Subdivision (Loop): edge flips after a refinement [true].
    pub remesh: bool,
    /// Subdivision, bare points: how they are meshed [auto].
    pub cloud: Cloud,
    /// Subdivision, bare points: statistical outlier removal, standard deviations [off].
    pub outliers: Option<f64>,
    /// Subdivision, bare points: mesh a range scan along its scanner grid [true].
    pub use_grid: bool,
    /// Curves: closed (periodic) [when the data's polyline ends where it starts].
    pub closed: Option<bool>,
    /// Degree (B-spline surface, B-spline curve; Chaikin is 2).
    pub degree: Option<usize>,
    /// B-spline surface: how patches are judged against the tolerance [noisy].
    pub tol_mode: TolMode,
    /// B-spline surface, least squares: thin-plate weight β2.
    pub beta2: Option<f64>,
    /// B-spline surface, least squares: curvature-variation weight β3.
    pub beta3: Option<f64>,
    /// B-spline surface, least squares: solves per knot vector.
    pub solves: Option<usize>,
    /// B-spline surface: view direction of the projection [least-variance axis].
    pub view: Option<[f64; 3]>,
    /// B-spline surface: points on a fold-over of the projection [keep].
    pub folded: FoldPolicy,
    /// Curves, knots method: angle that makes a corner, degrees.
    pub corner_angle: Option<f64>,
    /// Curves, knots method: second-derivative jump that makes a double knot (1 / diagonal).
    pub curvature_jump: Option<f64>,
    /// B-spline surface, sections method: points per row of data without a range grid [rows
    /// start at every jump].
    pub rows: Option<usize>,
    /// Subdivision and B-spline surfaces (geometric, least squares): find the data's sharp
    /// creases and keep them sharp (subdivision: QEM keeps them as edge chains, the control
    /// mesh tags them, refinement carries them; B-spline surface: the lines that run along a
    /// parameter line become C0 knot lines) [off: see docs/features.md for why it is not yet
    /// the default].
    pub creases: bool,
    /// Subdivision and B-spline surfaces: dihedral angle above which a data edge is a crease,
    /// degrees [40].
    pub crease_angle: Option<f64>,
}

/// One field of [`FitSpec`]: its name (camelCase, as JavaScript and the errors spell it), its
/// command-line flag, what it means, and which schemes and methods use it.
#[derive(Clone, Copy, Debug)]
pub struct OptionInfo {
    /// The field name.
    pub name: &'static str,
    /// The `geofit fit` flag (without `--`).
    pub flag: &'static str,
    /// One line of help.
    pub help: &'static str,
    schemes: &'static [Scheme],
    methods: &'static [Method],
}

impl OptionInfo {
    /// Whether the option takes part in a fit of `scheme` by `method`.
    pub fn applies(&self, scheme: Scheme, method: Method) -> bool {
        self.schemes.contains(&scheme)
            && (self.methods.is_empty() || self.methods.contains(&method))
    }
}

use Method::{Geometric as GEO, KnotPlacement as KNOTS, LeastSquares as LSQ, Sections as SECTIONS};
use Scheme::{
    BsplineCurve as BC, BsplineSurface as BS, CatmullClark as CC, ChaikinCurve as CH,
    DooSabin as DS, Loop as LP,
};
const ALL: &[Scheme] = &[LP, CC, DS, BS, BC, CH];
const SUBDIV: &[Scheme] = &[LP, CC, DS];
const CURVES: &[Scheme] = &[BC, CH];
const NOT_SURFACE: &[Scheme] = &[LP, CC, DS, BC, CH];

macro_rules! info {
    ($name:literal, $flag:literal, $schemes:expr, $methods:expr, $help:literal) => {
        OptionInfo {
            name: $name,
            flag: $flag,
            help: $help,
            schemes: $schemes,
            methods: $methods,
        }
    };
}

/// Every field of [`FitSpec`] with where it applies: the one table of option applicability.
pub const OPTION_TABLE: &[OptionInfo] = &[
    info!("scheme", "scheme", ALL, &[], "what is fitted"),
    info!(
        "method",
        "method",
        &[BS, BC, CH],
        &[],
        "how control points are found"
    ),
    info!(
        "tolAvg",
        "tol-avg",
        NOT_SURFACE,
        &[],
        "tolerance on E_avg, % of the diagonal"
    ),
    info!(
        "tolMax",
        "tol-max",
        ALL,
        &[],
        "tolerance on E_max, % of the diagonal"
    ),
    info!(
        "tolRms",
        "tol-rms",
        NOT_SURFACE,
        &[],
        "tolerance on E_rms, % of the diagonal"
    ),
    info!(
        "initial",
        "initial",
        &[LP, CC, DS, BS],
        &[GEO, LSQ],
        "initial control points"
    ),
    info!(
        "grid",
        "ctrl-u",
        &[BS],
        &[GEO, LSQ],
        "control points along u and v"
    ),
    info!(
        "maxIter",
        "max-iter",
        ALL,
        &[GEO, LSQ, KNOTS],
        "iteration cap"
    ),
    info!(
        "refine",
        "no-refine",
        ALL,
        &[GEO, LSQ],
        "refine where the tolerance is missed"
    ),
    info!(
        "maxControl",
        "max-control",
        ALL,
        &[GEO, LSQ],
        "control-point budget of refinement"
    ),
    info!("weights", "weights", SUBDIV, &[], "error-vector weighting"),
    info!(
        "acceleration",
        "accel",
        ALL,
        &[GEO],
        "acceleration of the iteration"
    ),
    info!(
        "tangentWeight",
        "tangent-weight",
        SUBDIV,
        &[],
        "CG: tangential error weight"
    ),
    info!(
        "refineGrowth",
        "refine-growth",
        SUBDIV,
        &[],
        "largest growth of one refinement"
    ),
    info!(
        "remesh",
        "no-remesh",
        SUBDIV,
        &[],
        "edge flips after a refinement (Loop)"
    ),
    info!("cloud", "cloud", SUBDIV, &[], "how bare points are meshed"),
    info!(
        "outliers",
        "outliers",
        SUBDIV,
        &[],
        "outlier removal, standard deviations"
    ),
    info!(
        "useGrid",
        "no-grid",
        SUBDIV,
        &[],
        "mesh a range scan along its grid"
    ),
    info!("closed", "closed", CURVES, &[], "fit a closed curve"),
    info!("degree", "degree", &[BS, BC], &[], "degree"),
    info!(
        "tolMode",
        "tol-mode",
        &[BS],
        &[GEO, LSQ, SECTIONS],
        "how patches are judged"
    ),
    info!("beta2", "beta2", &[BS], &[LSQ], "thin-plate weight β2"),
    info!(
        "beta3",
        "beta3",
        &[BS],
        &[LSQ],
        "curvature-variation weight β3"
    ),
    info!("solves", "solves", &[BS], &[LSQ], "solves per knot vector"),
    info!(
        "view",
        "view",
        &[BS],
        &[GEO, LSQ],
        "view direction of the projection"
    ),
    info!(
        "folded",
        "folded",
        &[BS],
        &[GEO, LSQ],
        "points on a fold-over"
    ),
    info!(
        "cornerAngle",
        "corner-angle",
        &[BS, BC, CH],
        &[KNOTS, SECTIONS],
        "angle that makes a corner, degrees"
    ),
    info!(
        "curvatureJump",
        "curvature-jump",
        &[BS, BC, CH],
        &[KNOTS, SECTIONS],
        "jump that makes a double knot"
    ),
    info!(
        "rows",
        "rows",
        &[BS],
        &[SECTIONS],
        "points per row of gridded data"
    ),
    info!(
        "creases",
        "creases",
        &[LP, CC, DS, BS],
        &[GEO, LSQ],
        "keep the data's sharp creases sharp"
    ),
    info!(
        "creaseAngle",
        "crease-angle",
        &[LP, CC, DS, BS],
        &[GEO, LSQ],
        "dihedral angle that makes a crease, degrees"
    ),
];

/// Calls `$m!` with every field of [`FitSpec`] but the scheme, each with its name: the one list
/// that checking what was given and clearing what does not apply both walk.
macro_rules! spec_fields {
    ($m:ident) => {
        $m!(method: "method", tol_avg: "tolAvg", tol_max: "tolMax", tol_rms: "tolRms",
            initial: "initial", grid: "grid", max_iter: "maxIter", refine: "refine",
            max_control: "maxControl", weights: "weights", acceleration: "acceleration",
            tangent_weight: "tangentWeight", refine_growth: "refineGrowth", remesh: "remesh",
            cloud: "cloud", outliers: "outliers", use_grid: "useGrid", closed: "closed",
            degree: "degree", tol_mode: "tolMode", beta2: "beta2", beta3: "beta3",
            solves: "solves", view: "view", folded: "folded", corner_angle: "cornerAngle",
            curvature_jump: "curvatureJump", rows: "rows", creases: "creases",
            crease_angle: "creaseAngle")
    };
}

default_is_const!(FitSpec);

impl FitSpec {
    /// Every field at its default: a Loop fit with the scheme's defaults.
    pub const DEFAULT: FitSpec = FitSpec {
        scheme: Scheme::Loop,
        method: None,
        tol_avg: None,
        tol_max: None,
        tol_rms: None,
        initial: None,
        grid: None,
        max_iter: None,
        refine: true,
        max_control: None,
        weights: Weighting::Basis,
        acceleration: None,
        tangent_weight: None,
        refine_growth: None,
        remesh: true,
        cloud: Cloud::Auto,
        outliers: None,
        use_grid: true,
        closed: None,
        degree: None,
        tol_mode: TolMode::Noisy,
        beta2: None,
        beta3: None,
        solves: None,
        view: None,
        folded: FoldPolicy::Keep,
        corner_angle: None,
        curvature_jump: None,
        rows: None,
        creases: false,
        crease_angle: None,
    };

    /// A fit of `scheme` with every other field at its default.
    pub fn new(scheme: Scheme) -> FitSpec {
        FitSpec {
            scheme,
            ..FitSpec::DEFAULT
        }
    }

    /// The method in force.
    pub fn method(&self) -> Method {
        self.method.unwrap_or(self.scheme.default_method())
    }

    /// The options that take part in a fit of `scheme` by `method` (their names).
    pub fn options_for(scheme: Scheme, method: Method) -> Vec<&'static str> {
        OPTION_TABLE
            .iter()
            .filter(|o| o.applies(scheme, method))
            .map(|o| o.name)
            .collect()
    }

    /// The spec with every applicable default written out, as a form shows it: the values the
    /// engines use when the field is left out. Left `None`: what the data decides
    /// (`initial` and `maxControl` of subdivision, `closed` of curves), and options the scheme
    /// does not use.
    pub fn defaults(scheme: Scheme) -> FitSpec {
        FitSpec::defaults_with(scheme, scheme.default_method())
    }

    /// [`FitSpec::defaults`] for `method` (one of the scheme's methods; another gives the
    /// defaults of the scheme's own method).
    pub fn defaults_with(scheme: Scheme, method: Method) -> FitSpec {
        let method = if scheme.methods().contains(&method) {
            method
        } else {
            scheme.default_method()
        };
        let spec = FitSpec {
            method: Some(method),
            ..FitSpec::new(scheme)
        };
        let tol = spec.tolerances();
        let mut d = FitSpec {
            method: Some(method),
            tol_avg: tol.avg_pct,
            tol_max: tol.max_pct,
            tol_rms: tol.rms_pct,
            max_iter: spec.default_max_iter(),
            acceleration: (method == Method::Geometric).then(|| spec.acceleration_in_force()),
            ..spec.clone()
        };
        d.crease_angle = Some(FeatureOptions::DEFAULT_ANGLE_DEG);
        match scheme {
            Scheme::Loop | Scheme::CatmullClark | Scheme::DooSabin => {
                let o = SubdivFitOptions::DEFAULT;
                d.tangent_weight = Some(o.tangent_weight);
                d.refine_growth = Some(o.refine_growth);
            }
            Scheme::BsplineSurface => {
                let g = SurfaceGrid::DEFAULT;
                let l = LsqSurfaceOptions::DEFAULT;
                d.initial = Some(g.control.0 * g.control.1);
                d.max_control = Some(g.max_control_points);
                d.degree = Some(g.degree);
                (d.beta2, d.beta3, d.solves) =
                    (Some(l.beta2), Some(l.beta3), Some(l.solves_per_knots));
                let s = SectionsOptions::DEFAULT;
                (d.corner_angle, d.curvature_jump) =
                    (Some(s.corner_angle_deg), Some(s.curvature_jump));
            }
            Scheme::BsplineCurve | Scheme::ChaikinCurve => {
                let k = KnotPlacementOptions::DEFAULT;
                d.degree =
                    (scheme == Scheme::BsplineCurve).then_some(CurveFitOptions::DEFAULT.degree);
                d.corner_angle = Some(k.corner_angle_deg);
                d.curvature_jump = Some(k.curvature_jump);
            }
        }
        d.clear_inapplicable();
        d
    }

    /// Sets every option the scheme and method do not use back to its default.
    fn clear_inapplicable(&mut self) {
        let (scheme, method) = (self.scheme, self.method());
        let keep = |name: &str| {
            OPTION_TABLE
                .iter()
                .any(|o| o.name == name && o.applies(scheme, method))
        };
        let d = FitSpec::DEFAULT;
        macro_rules! clear {
            ($($field:ident: $name:literal),*) => {
                $(if !keep($name) { self.$field = d.$field.clone(); })*
            };
        }
        spec_fields!(clear);
    }

    /// The names of the fields set away from [`FitSpec::DEFAULT`].
    pub fn given(&self) -> Vec<&'static str> {
        let d = FitSpec::DEFAULT;
        let mut out = Vec::new();
        macro_rules! given {
            ($($field:ident: $name:literal),*) => {
                $(if self.$field != d.$field { out.push($name); })*
            };
        }
        spec_fields!(given);
        out
    }

    /// Checks the spec: the method fits the scheme, every option given applies to the scheme
    /// and method, and every value is in range (by the engines' own checks, which name the
    /// same fields). Data-dependent checks (too few points, no faces) come with
    /// [`FitSpec::build`].
    pub fn validate(&self) -> Result<(), FitError> {
        let (scheme, method) = (self.scheme, self.method());
        for name in self.given() {
            let info = OPTION_TABLE.iter().find(|o| o.name == name);
            if info.is_some_and(|o| !o.applies(scheme, method)) {
                let by_method = OPTION_TABLE
                    .iter()
                    .any(|o| o.name == name && o.schemes.contains(&scheme));
                return Err(FitError::NotApplicable {
                    name,
                    scheme,
                    method: by_method.then_some(method),
                });
            }
        }
        if !scheme.methods().contains(&method) {
            let names: Vec<String> = scheme.methods().iter().map(|m| format!("'{m}'")).collect();
            return Err(FitError::InvalidOption {
                name: "method",
                reason: format!(
                    "'{method}' is not one of {} (scheme {scheme})",
                    names.join(", ")
                ),
            });
        }
        self.check_ranges()
    }

    /// Range checks of the spec's own fields and of the engine options it makes.
    fn check_ranges(&self) -> Result<(), FitError> {
        let bad = |name, reason: String| Err(FitError::InvalidOption { name, reason });
        if self.initial == Some(0) {
            return bad("initial", "must be at least 1".into());
        }
        if self.max_iter == Some(0) {
            return bad("maxIter", "must be at least 1".into());
        }
        if let Some(r) = self.outliers.filter(|r| !(r.is_finite() && *r > 0.0)) {
            return bad(
                "outliers",
                format!("{r} is not a positive number of deviations"),
            );
        }
        if let Some(v) = self
            .view
            .filter(|v| !Vec3::from(*v).is_finite() || Vec3::from(*v).length() == 0.0)
        {
            return bad("view", format!("{v:?} is not a direction"));
        }
        if let Some(f) = self.feature_options() {
            f.validate().map_err(|e| FitError::InvalidOption {
                name: "creaseAngle",
                reason: e.to_string(),
            })?;
        }
        match self.scheme {
            Scheme::Loop | Scheme::CatmullClark | Scheme::DooSabin => {
                self.subdiv_options().validate()
            }
            Scheme::BsplineSurface => match self.method() {
                Method::LeastSquares => self.lsq_options().validate(),
                Method::Sections => self.sections_options().validate(),
                _ => self.geometric_surface_options().validate(),
            },
            Scheme::BsplineCurve | Scheme::ChaikinCurve => match self.method() {
                Method::KnotPlacement => self.knot_options(false).validate(),
                _ => self.curve_options(false).validate(),
            },
        }
    }

    /// Builds the engine for `data`: validates, leaves out stray points far from the rest
    /// ([`crate::geom::find_strays`]; the log's [`FitLog::strays`](super::FitLog::strays)
    /// lists them), makes the initial control net (QEM
    /// simplification, with meshing of bare points first, for subdivision; the projection
    /// grid for surfaces; Douglas–Peucker for curves) and the first foot points. The log's
    /// set-up time covers all of it.
    pub fn build(&self, data: &FitData) -> Result<Box<dyn Fitter>, FitError> {
        let start = Instant::now();
        self.validate()?;
        let without_strays = WithoutStrays::of(data);
        let data = &without_strays.as_ref().map_or(*data, |w| w.data(data));
        let points = data.mesh.positions();
        let mut fitter: Box<dyn Fitter> = match (self.scheme, self.method()) {
            (scheme, _) if scheme.subdivision().is_some() => {
                let grid = data.grid.filter(|_| self.use_grid);
                Box::new(build_subdiv_fitter(
                    data.mesh,
                    grid,
                    &self.cloud_options(),
                    scheme.subdivision().unwrap_or(subdiv::Scheme::Loop),
                    data.control,
                    self.initial,
                    self.feature_options().as_ref(),
                    self.subdiv_options(),
                )?)
            }
            (Scheme::BsplineSurface, Method::Geometric) => {
                let mut fitter =
                    GeometricSurfaceFitter::try_new(points, self.geometric_surface_options())?;
                let report = self.surface_creases(data.mesh, |l| fitter.keep_creases(l))?;
                fitter.log_mut().set_creases(report);
                Box::new(fitter)
            }
            (Scheme::BsplineSurface, Method::Sections) => {
                let (points, rows) = match data.grid {
                    Some(grid) => {
                        let (indices, rows) = grid_rows(grid, points);
                        let pick = indices.iter().filter_map(|&i| points.get(i as usize));
                        (pick.copied().collect(), rows)
                    }
                    None => (points.to_vec(), detect_rows(points, self.rows)),
                };
                Box::new(SectionsFitter::try_new(
                    &points,
                    rows,
                    self.sections_options(),
                )?)
            }
            (Scheme::BsplineSurface, _) => {
                let mut fitter = LsqSurfaceFitter::try_new(points, self.lsq_options())?;
                let report = self.surface_creases(data.mesh, |l| fitter.keep_creases(l))?;
                fitter.log_mut().set_creases(report);
                Box::new(fitter)
            }
            (_, method) => {
                let (points, file_closed) = data.curve_points();
                let closed = self.closed.unwrap_or(file_closed);
                match method {
                    Method::KnotPlacement => Box::new(KnotPlacementFitter::try_new(
                        &points,
                        self.knot_options(closed),
                    )?),
                    _ => Box::new(CurveFitter::try_new(&points, self.curve_options(closed))?),
                }
            }
        };
        if self.scheme == Scheme::BsplineSurface {
            let reference = self.back_reference(data);
            fitter.state_mut().set_reference(reference);
        }
        let own = fitter.log().precompute_seconds();
        let outside = start.elapsed().as_secs_f64() - own;
        fitter.log_mut().add_precompute(outside);
        fitter
            .log_mut()
            .set_strays(without_strays.map(|w| w.strays));
        crate::progress::report(crate::progress::Phase::Setup, 1.0);
        Ok(fitter)
    }

    /// The tolerances in force: those given, else the scheme's defaults.
    pub fn tolerances(&self) -> Tolerances {
        let default = match self.scheme {
            Scheme::BsplineSurface => Tolerances::max_only(SurfaceGrid::DEFAULT.tol_pct),
            Scheme::BsplineCurve | Scheme::ChaikinCurve => CurveFitOptions::DEFAULT.tolerances,
            _ => SubdivFitOptions::DEFAULT.tolerances,
        };
        Tolerances::given_or(self.tol_avg, self.tol_max, self.tol_rms, default)
    }

    /// The engine's own iteration cap when none is given (`None` for knot placement, whose
    /// cap is the number of points).
    fn default_max_iter(&self) -> Option<usize> {
        Some(match (self.scheme, self.method()) {
            (_, Method::Sections) => return None,
            (Scheme::BsplineSurface, Method::LeastSquares) => {
                LsqSurfaceOptions::DEFAULT.max_iterations
            }
            (Scheme::BsplineSurface, _) => GeometricSurfaceOptions::DEFAULT.max_iterations,
            (_, Method::KnotPlacement) => return None,
            (s, _) if s.is_curve() => CurveFitOptions::DEFAULT.max_iter,
            _ => SubdivFitOptions::DEFAULT.max_iter,
        })
    }

    /// The acceleration of the geometric iteration: the one chosen, else the engine's.
    fn acceleration_in_force(&self) -> Acceleration {
        self.acceleration.unwrap_or(match self.scheme {
            Scheme::BsplineSurface => GeometricSurfaceOptions::DEFAULT.acceleration,
            s if s.is_curve() => CurveFitOptions::DEFAULT.acceleration,
            _ => SubdivFitOptions::default_acceleration(self.weights),
        })
    }

    pub(crate) fn subdiv_options(&self) -> SubdivFitOptions {
        let d = SubdivFitOptions::DEFAULT;
        SubdivFitOptions {
            tolerances: self.tolerances(),
            max_iter: self.max_iter.unwrap_or(d.max_iter),
            max_control: self.max_control,
            refine: self.refine,
            remesh: self.remesh,
            weighting: self.weights,
            acceleration: self.acceleration_in_force(),
            tangent_weight: self.tangent_weight.unwrap_or(d.tangent_weight),
            refine_growth: self.refine_growth.unwrap_or(d.refine_growth),
            ..d
        }
    }

    /// With [`FitSpec::creases`], the creases of `mesh` (the data) found and handed to `keep`,
    /// a B-spline surface fitter's `keep_creases`, and the report of both.
    fn surface_creases(
        &self,
        mesh: &PolyMesh,
        keep: impl FnOnce(&[FeatureLine]) -> CreaseKnots,
    ) -> Result<Option<CreaseReport>, FitError> {
        let Some((angle, found)) = find_creases(mesh, self.feature_options().as_ref())? else {
            return Ok(None);
        };
        let knots = keep(&found.lines);
        Ok(Some(CreaseReport::of(
            angle,
            &found,
            mesh.positions(),
            0,
            Some(knots),
        )))
    }

    /// How the data's creases are found, or `None` when [`FitSpec::creases`] is off.
    pub fn feature_options(&self) -> Option<FeatureOptions> {
        self.creases.then(|| FeatureOptions {
            angle_deg: self
                .crease_angle
                .unwrap_or(FeatureOptions::DEFAULT_ANGLE_DEG),
            ..FeatureOptions::default()
        })
    }

    /// The data's surface a B-spline surface fit's E_back is measured against: the data's
    /// faces, else the points' discs with the holes of the mesh that a subdivision fit starts
    /// from (the range grid's triangles for a range scan), as a subdivision fit measures it.
    /// `None` when no mesh can be made of the points: the fit then reports no E_back, and
    /// fits on.
    fn back_reference(&self, data: &FitData) -> Option<DataSurface> {
        if !data.mesh.is_point_cloud() {
            return DataSurface::of_mesh(data.mesh);
        }
        let grid = data.grid.filter(|_| self.use_grid);
        let made = reconstruct(data.mesh.positions(), grid, &self.cloud_options()).ok()?;
        let inliers: Vec<Point3> = data
            .mesh
            .positions()
            .iter()
            .zip(&made.inlier)
            .filter_map(|(&p, &keep)| keep.then_some(p))
            .collect();
        DataSurface::of_points(&inliers, &made.mesh)
    }

    fn cloud_options(&self) -> ReconstructOptions {
        let kind = match self.cloud {
            Cloud::Auto => None,
            Cloud::Open => Some(SurfaceKind::Open),
            Cloud::Closed => Some(SurfaceKind::Closed),
        };
        ReconstructOptions::default()
            .with_kind(kind)
            .with_outlier_std_ratio(self.outliers)
    }

    /// The grid shared by both surface methods: `grid`, or a square of about `initial` control
    /// points (at least degree + 1 a side).
    fn surface_grid(&self) -> SurfaceGrid {
        let d = SurfaceGrid::DEFAULT;
        let degree = self.degree.unwrap_or(d.degree);
        let control = match (self.grid, self.initial) {
            (Some([nu, nv]), _) => (nu, nv),
            (None, Some(n)) => {
                let side = ((n as f64).sqrt().round() as usize).max(degree + 1);
                (side, side)
            }
            (None, None) => d.control,
        };
        let mut param = d.param.with_fold_policy(self.folded);
        if let Some(v) = self.view {
            param = param.with_view(Vec3::from(v));
        }
        SurfaceGrid {
            degree,
            control,
            fixed_knots: !self.refine,
            tol_pct: self.tolerances().max_pct.unwrap_or(d.tol_pct),
            tol_mode: self.tol_mode,
            max_control_points: self.max_control.unwrap_or(d.max_control_points),
            param,
            ..d
        }
    }

    fn lsq_options(&self) -> LsqSurfaceOptions {
        let d = LsqSurfaceOptions::DEFAULT;
        let solves = if self.refine {
            d.solves_per_knots
        } else {
            LsqSurfaceOptions::FIXED_KNOT_SOLVES
        };
        LsqSurfaceOptions {
            grid: self.surface_grid(),
            beta2: self.beta2.unwrap_or(d.beta2),
            beta3: self.beta3.unwrap_or(d.beta3),
            solves_per_knots: self.solves.unwrap_or(solves),
            max_iterations: self.max_iter.unwrap_or(d.max_iterations),
            ..d
        }
    }

    /// On fixed knots the geometric method starts from one least-squares solve (see
    /// [`GeometricSurfaceOptions::warm_start`]).
    fn geometric_surface_options(&self) -> GeometricSurfaceOptions {
        let d = GeometricSurfaceOptions::DEFAULT;
        GeometricSurfaceOptions {
            grid: self.surface_grid(),
            acceleration: self.acceleration_in_force(),
            max_iterations: self.max_iter.unwrap_or(d.max_iterations),
            warm_start: !self.refine,
            ..d
        }
    }

    fn curve_degree(&self) -> usize {
        match self.scheme {
            Scheme::ChaikinCurve => 2,
            _ => self.degree.unwrap_or(CurveFitOptions::DEFAULT.degree),
        }
    }

    fn curve_options(&self, closed: bool) -> CurveFitOptions {
        let d = CurveFitOptions::DEFAULT;
        CurveFitOptions {
            degree: self.curve_degree(),
            closed,
            tolerances: self.tolerances(),
            max_iter: self.max_iter.unwrap_or(d.max_iter),
            refine: self.refine,
            max_control: self.max_control,
            acceleration: self.acceleration_in_force(),
            ..d
        }
    }

    fn sections_options(&self) -> SectionsOptions {
        let d = SectionsOptions::DEFAULT;
        SectionsOptions {
            degree: self.degree.unwrap_or(d.degree),
            tol_pct: self.tolerances().max_pct.unwrap_or(d.tol_pct),
            tol_mode: self.tol_mode,
            rows: self.rows,
            corner_angle_deg: self.corner_angle.unwrap_or(d.corner_angle_deg),
            curvature_jump: self.curvature_jump.unwrap_or(d.curvature_jump),
        }
    }

    fn knot_options(&self, closed: bool) -> KnotPlacementOptions {
        let d = KnotPlacementOptions::DEFAULT;
        KnotPlacementOptions {
            degree: self.curve_degree(),
            closed,
            tolerances: self.tolerances(),
            max_iter: self.max_iter,
            corner_angle_deg: self.corner_angle.unwrap_or(d.corner_angle_deg),
            curvature_jump: self.curvature_jump.unwrap_or(d.curvature_jump),
            ..d
        }
    }
}

setters!(FitSpec {
    /// Sets the method.
    with_method(method: Option<Method>) => |s| s.method;
    /// Sets the E_avg tolerance, %.
    with_tol_avg(tol_avg: Option<f64>) => |s| s.tol_avg;
    /// Sets the E_max tolerance, %.
    with_tol_max(tol_max: Option<f64>) => |s| s.tol_max;
    /// Sets the E_rms tolerance, %.
    with_tol_rms(tol_rms: Option<f64>) => |s| s.tol_rms;
    /// Sets the initial control-point count.
    with_initial(initial: Option<usize>) => |s| s.initial;
    /// Sets the iteration cap.
    with_max_iter(max_iter: Option<usize>) => |s| s.max_iter;
    /// Turns refinement on or off.
    with_refine(refine: bool) => |s| s.refine;
    /// Sets the control-point budget.
    with_max_control(max_control: Option<usize>) => |s| s.max_control;
    /// Sets the degree.
    with_degree(degree: Option<usize>) => |s| s.degree;
    /// Sets whether a curve is closed.
    with_closed(closed: Option<bool>) => |s| s.closed;
    /// Sets whether the data's creases are found and kept sharp.
    with_creases(creases: bool) => |s| s.creases;
    /// Sets the crease angle, degrees.
    with_crease_angle(crease_angle: Option<f64>) => |s| s.crease_angle;
});

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_has_one_row_in_the_table() {
        let json = serde_json::to_value(FitSpec::DEFAULT).expect("serialises");
        let fields: Vec<&String> = json.as_object().expect("object").keys().collect();
        assert_eq!(fields.len(), OPTION_TABLE.len());
        for f in fields {
            assert!(OPTION_TABLE.iter().any(|o| o.name == f), "{f} has no row");
        }
    }

    #[test]
    fn scheme_names_round_trip() {
        for &s in Scheme::ALL {
            assert_eq!(s.name().parse::<Scheme>(), Ok(s));
        }
        assert_eq!("bspline".parse::<Scheme>(), Ok(Scheme::BsplineSurface));
        let err = "nurbs".parse::<Scheme>().unwrap_err();
        assert!(
            err.starts_with("option scheme: 'nurbs' is not one of 'loop'"),
            "{err}"
        );
    }

    #[test]
    fn defaults_are_the_engines_and_valid() {
        for &s in Scheme::ALL {
            let d = FitSpec::defaults(s);
            d.validate().unwrap_or_else(|e| panic!("{s}: {e}"));
        }
        let loop_ = FitSpec::defaults(Scheme::Loop);
        assert_eq!(loop_.tol_avg, SubdivFitOptions::DEFAULT.tolerances.avg_pct);
        assert_eq!(loop_.max_iter, Some(SubdivFitOptions::DEFAULT.max_iter));
        assert_eq!(loop_.initial, None);
        let surface = FitSpec::defaults(Scheme::BsplineSurface);
        assert_eq!(surface.method, Some(Method::LeastSquares));
        assert_eq!(
            surface.max_iter,
            Some(LsqSurfaceOptions::DEFAULT.max_iterations)
        );
        assert_eq!(surface.tol_avg, None);
    }

    #[test]
    fn options_of_other_schemes_are_rejected() {
        let err = FitSpec::new(Scheme::BsplineSurface)
            .with_tol_avg(Some(0.1))
            .validate();
        assert!(matches!(
            err,
            Err(FitError::NotApplicable { name: "tolAvg", .. })
        ));
        let mut spec = FitSpec::new(Scheme::BsplineSurface);
        spec.beta2 = Some(1e-9);
        spec.method = Some(Method::Geometric);
        let err = spec.validate().unwrap_err().to_string();
        assert_eq!(
            err,
            "option beta2 does not apply to scheme bspline-surface with method geometric"
        );
        let err = FitSpec::new(Scheme::Loop)
            .with_method(Some(Method::LeastSquares))
            .validate();
        assert!(matches!(
            err,
            Err(FitError::NotApplicable { name: "method", .. })
        ));
    }

    #[test]
    fn js_names_and_unknown_fields() {
        let spec: FitSpec =
            serde_json::from_str(r#"{"scheme":"bspline-surface","tolMax":0.2,"grid":[10,12]}"#)
                .expect("parses");
        assert_eq!(spec.scheme, Scheme::BsplineSurface);
        assert_eq!(spec.surface_grid().control, (10, 12));
        let err = serde_json::from_str::<FitSpec>(r#"{"tolerance":1}"#).unwrap_err();
        assert!(
            err.to_string().contains("unknown field `tolerance`"),
            "{err}"
        );
        let err = serde_json::from_str::<FitSpec>(r#"{"cloud":"sideways"}"#).unwrap_err();
        assert!(
            err.to_string()
                .contains("option cloud: 'sideways' is not one of"),
            "{err}"
        );
    }
}
