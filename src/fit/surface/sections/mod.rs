//! Skinning fit (SPEC §3 applied to surfaces, seed 004): a B-spline surface as a family of
//! section curves, for gridded data (a range scan's rows, a measuring machine's scan lines).
//!
//! 1. Every row's multiple knots are found where its shape is not C2 (the knot-placement
//!    curve fitter's test, [`KnotPlacementFitter`]). A crease crossing the rows shows in every
//!    row it crosses; scan noise makes such "features" too, but one row at a time. So a row's
//!    multiple knot is kept only when neighbouring rows have one nearby ([`supported_knots`]),
//!    and the kept ones of all rows are merged into one knot vector (knots closer than half a
//!    data spacing become one; the highest multiplicity wins).
//! 2. Single knots are placed on that common knot vector for all rows at once
//!    ([`place_common_knots`]): every row is fitted by least squares on it, every knot span is
//!    judged on the deviations of all rows' points in it (the surfaces' tolerance modes:
//!    [`TolMode::Exact`] on the largest, [`TolMode::Noisy`] on the 95 % share or mean +
//!    standard deviation), and each failing span is halved, until every span passes or is too
//!    short to hold data of every row on both sides. Fitting each row alone and taking the union
//!    of their knots instead puts every row's noise into the knot vector: on bun000's range
//!    grid that gave 519 control points per row of 160 points (the surface interpolated).
//! 3. The columns of control points (one per row) are fitted across the rows the same way, to
//!    half the tolerance and again to a quarter, an eighth while the surface misses it. Column
//!    points are control points, so a column curve off by δ moves the surface by at most δ (the
//!    basis functions sum to 1). Their control points are the surface's.
//!
//! The first surface (built when the fitter is made) uses the multiple knots only — the
//! paper's "double knots only" figure; every [`Fitter::step`] is one stage (rows, columns) so
//! the page shows the progress. The standard deviation σ the paper reports is that of the
//! signed point-to-surface distances (foot points by Newton from the row and column
//! parameters), in model units and % of the bounding-box diagonal.

mod creases;
mod knots;
mod rows;

pub use rows::{detect_rows, grid_rows, JUMP_FACTOR};

use super::patches::{correct_parameters, patch_errors, Criterion, PatchGrid, TolMode};
use crate::fit::{
    FitError, FitState, FitStatus, Fitter, KnotPlacementOptions, Method, Scheme, Shape, Spline,
    Tolerances,
};
use crate::geom::{Point3, Vec3};
use crate::spline::{BSplineCurve, BSplineSurface};
use creases::{grid_normals, GridFeatures};
use knots::{place_common_knots, span_errors, Family};
use web_time::Instant;

/// Newton iterations of the foot points on the surface.
const FOOT_ITERATIONS: usize = 12;

/// Options of the skinning fit. Defaults in brackets on each field.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SectionsOptions {
    /// Degree in u and v, 1..=5 [3].
    pub degree: usize,
    /// Tolerance TOL, % of the bounding-box diagonal of all the data [0.1].
    pub tol_pct: f64,
    /// How a knot span of the rows or columns, and a patch of the surface, is judged against
    /// TOL [[`TolMode::Noisy`]] (range scans are noisy; a measuring machine's clean sections
    /// are judged on their largest deviation with [`TolMode::Exact`]).
    pub tol_mode: TolMode,
    /// Points per row when the data do not say (an XYZ file in rows): `Some(n)` cuts the
    /// points into rows of n; `None` starts a row at every jump [none].
    pub rows: Option<usize>,
    /// Angle that makes a corner in a row or column, degrees [30].
    pub corner_angle_deg: f64,
    /// Second-derivative jump that makes a double knot, 1 / diagonal [1000].
    pub curvature_jump: f64,
}

impl SectionsOptions {
    /// The defaults, as each field documents them.
    pub const DEFAULT: SectionsOptions = SectionsOptions {
        degree: 3,
        tol_pct: 0.1,
        tol_mode: TolMode::Noisy,
        rows: None,
        corner_angle_deg: KnotPlacementOptions::DEFAULT.corner_angle_deg,
        curvature_jump: KnotPlacementOptions::DEFAULT.curvature_jump,
    };

    /// Range checks, by the curve fitter's own rules and names.
    pub fn validate(&self) -> Result<(), FitError> {
        if !(self.tol_pct.is_finite() && self.tol_pct > 0.0) {
            return Err(FitError::InvalidOption {
                name: "tolMax",
                reason: format!("{} must be a positive percentage", self.tol_pct),
            });
        }
        if let Some(n) = self.rows.filter(|&n| n < 2) {
            return Err(FitError::InvalidOption {
                name: "rows",
                reason: format!("{n} points per row: need at least 2"),
            });
        }
        self.curve_options().validate()
    }

    /// How a patch is judged against `tol` model units: the options' mode, small patches
    /// pooled with their neighbours as the other surface fits do.
    fn criterion(&self, tol: f64) -> Criterion {
        Criterion {
            tol,
            mode: self.tol_mode,
            min_sample: super::SurfaceGrid::DEFAULT.min_sample,
        }
    }

    /// The knot-placement options whose feature test finds a section's multiple knots (its
    /// tolerances play no part: the knots between them are placed for all sections at once).
    fn curve_options(&self) -> KnotPlacementOptions {
        KnotPlacementOptions {
            degree: self.degree,
            corner_angle_deg: self.corner_angle_deg,
            curvature_jump: self.curvature_jump,
            ..KnotPlacementOptions::DEFAULT
        }
    }
}

default_is_const!(SectionsOptions);

setters!(SectionsOptions {
    /// Sets the degree.
    with_degree(degree: usize) => |s| s.degree;
    /// Sets the tolerance, %.
    with_tol_pct(tol_pct: f64) => |s| s.tol_pct;
    /// Sets how spans and patches are judged against the tolerance.
    with_tol_mode(tol_mode: TolMode) => |s| s.tol_mode;
    /// Sets the points per row.
    with_rows(rows: Option<usize>) => |s| s.rows;
    /// Sets the corner angle, degrees.
    with_corner_angle_deg(corner_angle_deg: f64) => |s| s.corner_angle_deg;
    /// Sets the double-knot threshold.
    with_curvature_jump(curvature_jump: f64) => |s| s.curvature_jump;
});

/// Where the skinning fit stands: the stage the next [`Fitter::step`] runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    Rows,
    Columns,
    Done,
}

/// The skinning fitter (module docs), driven through [`Fitter`].
#[derive(Clone, Debug)]
pub struct SectionsFitter {
    options: SectionsOptions,
    /// The data rows, as index ranges into the state's data.
    rows: Vec<std::ops::Range<usize>>,
    /// The crease lines across and along the rows.
    features: GridFeatures,
    /// The grid's unit normal at every data point ([`grid_normals`]), in data order.
    normals: Vec<Vec3>,
    /// The row curves of the current stage, on one knot vector.
    row_curves: Vec<BSplineCurve>,
    /// Single u knots the surface's failing patches asked for ([`SectionsFitter::split_u`]).
    u_splits: Vec<f64>,
    /// Parameter of every data point along its row (chord length, aligned on the creases
    /// crossing the rows), in data order.
    row_params: Vec<f64>,
    stage: Stage,
    /// σ of the first surface (multiple knots only), model units.
    sigma_features: f64,
    surface: BSplineSurface,
    uv: Vec<[f64; 2]>,
    state: FitState,
}

impl SectionsFitter {
    /// A skinning fit of `points` cut into `rows` (index ranges, in order, covering the
    /// points): checks the rows, fits them on their confirmed multiple knots only and skins
    /// that first surface.
    pub fn try_new(
        points: &[Point3],
        rows: Vec<std::ops::Range<usize>>,
        options: SectionsOptions,
    ) -> Result<SectionsFitter, FitError> {
        let start = Instant::now();
        options.validate()?;
        crate::geom::check_coordinates(points)?;
        check_rows(&rows, options.degree)?;
        let diagonal = crate::geom::Aabb::from_points(points).map_or(0.0, |b| b.diagonal());
        let tol = options.tol_pct / 100.0 * diagonal;
        let normals = grid_normals(rows.len(), rows[0].len(), |r, c| points[rows[r].start + c]);
        let (features, row_params) = GridFeatures::of(points, &rows, &normals, &options, tol)?;
        let u_knots = features.u_knots();
        let family = Family {
            points,
            sections: &rows,
            params: &row_params,
            normals: &normals,
        };
        let none = |_: &[BSplineCurve], _: &[f64]| Ok(Vec::new());
        let row_curves = place_common_knots(&family, u_knots, &options, f64::INFINITY, none)?;
        let (surface, v) = skin(&row_curves, &features, &options, &family, f64::INFINITY)?;
        let uv = initial_uv(&rows, &row_params, &v);
        let state = FitState::new(
            (Scheme::BsplineSurface, Method::Sections),
            Tolerances::max_only(options.tol_pct),
            points.to_vec(),
            surface.control_points().len(),
            start,
        );
        let mut fitter = SectionsFitter {
            options,
            rows,
            features,
            normals,
            u_splits: Vec::new(),
            row_curves,
            row_params,
            stage: Stage::Rows,
            sigma_features: 0.0,
            surface,
            uv,
            state,
        };
        fitter.measure();
        fitter.sigma_features = fitter.sigma();
        Ok(fitter)
    }

    /// The current surface.
    pub fn surface(&self) -> &BSplineSurface {
        &self.surface
    }

    /// The number of rows.
    pub fn num_rows(&self) -> usize {
        self.rows.len()
    }

    /// The standard deviation of the signed point-to-surface distances, model units.
    pub fn sigma(&self) -> f64 {
        let e = self.state.errors();
        let n = e.len().max(1) as f64;
        let mean = e.iter().sum::<f64>() / n;
        (e.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt()
    }

    /// σ of the first surface, fitted with the multiple knots only, model units.
    pub fn sigma_features(&self) -> f64 {
        self.sigma_features
    }

    /// The data as a family of sections: the rows, their parameters and normals.
    fn data(&self) -> Family<'_> {
        Family {
            points: self.state.data(),
            sections: &self.rows,
            params: &self.row_params,
            normals: &self.normals,
        }
    }

    /// Foot points from the current parameters, the errors and their statistics.
    fn measure(&mut self) {
        let (points, errors) = self.state.data_and_errors_mut();
        correct_parameters(&self.surface, points, &mut self.uv, errors, FOOT_ITERATIONS);
        self.state.errors_changed();
    }

    /// Stage 1: single knots placed for all rows at once, to the tolerance.
    fn fit_rows(&mut self) -> Result<(), FitError> {
        let tol = self.options.tol_pct / 100.0 * self.state.diagonal();
        let family = self.data();
        let mut knots = self.features.u_knots();
        knots.extend(self.u_splits.iter().map(|&u| (u, 1)));
        let mode = self.options.tol_mode;
        let failing = |curves: &[BSplineCurve], bounds: &[f64]| {
            let spans = span_errors(&family, curves, bounds, tol);
            Ok(spans
                .iter()
                .map(|a| a.count > 0 && !a.judge(tol, mode).0)
                .collect())
        };
        self.row_curves = place_common_knots(&family, knots, &self.options, tol, failing)?;
        Ok(())
    }

    /// Whether every patch of the surface meets the tolerance in the options' mode.
    fn patches_pass(&self) -> bool {
        let crit = self
            .options
            .criterion(self.options.tol_pct / 100.0 * self.state.diagonal());
        let grid = PatchGrid::of(&self.surface);
        let all = vec![true; self.uv.len()];
        let errors = self.state.errors();
        patch_errors(&self.surface, &grid, &self.uv, errors, &all, crit)
            .iter()
            .all(|e| e.pass)
    }

    /// Where the surface's patches miss the tolerance although each row met it (the columns
    /// smooth the rows' control points): the u spans of those patches halved for the next
    /// round of rows, where every row keeps data on both sides ([`Family::splits`]). Returns
    /// whether any was.
    fn split_u(&mut self) -> bool {
        let tol = self.options.tol_pct / 100.0 * self.state.diagonal();
        let data = self.data();
        let v: Vec<f64> = self.rows.iter().map(|r| self.uv[r.start][1]).collect();
        let mut halves: Vec<f64> = failing_patches(&self.surface, &data, &v, &self.options, tol)
            .into_iter()
            .map(|((a, b), _)| (a, 0.5 * (a + b), b))
            .filter(|&(a, m, b)| data.splits(a, m, b))
            .map(|(_, m, _)| m)
            .collect();
        halves.sort_by(f64::total_cmp);
        halves.dedup();
        self.u_splits.extend_from_slice(&halves);
        !halves.is_empty()
    }

    /// Stage 2: the columns, and the surface they make.
    fn fit_columns(&mut self) -> Result<(), FitError> {
        let tol = self.options.tol_pct / 100.0 * self.state.diagonal();
        let data = self.data();
        let (surface, v) = skin(&self.row_curves, &self.features, &self.options, &data, tol)?;
        self.surface = surface;
        self.uv = initial_uv(&self.rows, &self.row_params, &v);
        self.measure();
        Ok(())
    }
}

/// Rejects fewer than degree + 1 rows, rows of fewer than 2·degree + 2 points and rows of
/// unequal length (a skinned surface needs one control-point column per row and the same
/// sections everywhere).
fn check_rows(rows: &[std::ops::Range<usize>], degree: usize) -> Result<(), FitError> {
    let needed_rows = (2 * degree + 2).max(8);
    if rows.len() < needed_rows {
        return Err(FitError::TooFewRows {
            found: rows.len(),
            needed: needed_rows,
        });
    }
    let expected = rows[0].len();
    let needed = (2 * degree + 2).max(8);
    if expected < needed {
        return Err(FitError::TooFewPoints {
            found: expected,
            needed,
        });
    }
    if let Some((row, r)) = rows.iter().enumerate().find(|(_, r)| r.len() != expected) {
        return Err(FitError::RaggedRows {
            row,
            found: r.len(),
            expected,
        });
    }
    Ok(())
}

/// The surface skinned across `rows` (curves on one knot vector): the columns of their control
/// points, at the rows' mean chord parameters, fitted on one knot vector
/// ([`place_common_knots`]) from the data columns' creases, with single knots where the
/// surface misses the `data` (the rows' points, parameters and normals) by more than `tol`
/// (infinite: the creases alone). Returns the surface and the v parameter of every row.
///
/// The spans are judged on the data, not on the columns' own control points: those carry
/// the rows' noise (bun000's depths are quantised to 0.095 % of the diagonal), and columns
/// fitted to them within half the tolerance chased it (every span of bun000's columns failed).
fn skin(
    rows: &[BSplineCurve],
    features: &GridFeatures,
    options: &SectionsOptions,
    data: &Family<'_>,
    tol: f64,
) -> Result<(BSplineSurface, Vec<f64>), FitError> {
    let (nu, nr) = (rows[0].control_points().len(), rows.len());
    let columns: Vec<Vec<Point3>> = (0..nu)
        .map(|j| rows.iter().map(|c| c.control_points()[j]).collect())
        .collect();
    let v = mean_chord(&columns);
    let points: Vec<Point3> = columns.concat();
    let sections: Vec<std::ops::Range<usize>> = (0..nu).map(|j| j * nr..(j + 1) * nr).collect();
    let params: Vec<f64> = (0..nu).flat_map(|_| v.iter().copied()).collect();
    let family = Family {
        points: &points,
        sections: &sections,
        params: &params,
        normals: &[],
    };
    let ku = rows[0].knots();
    let failing = |curves: &[BSplineCurve], bounds: &[f64]| {
        let surface = surface_of(ku, curves)?;
        let patches = failing_patches(&surface, data, &v, options, tol);
        let mut spans = vec![false; bounds.len() - 1];
        for &(_, pv) in &patches {
            spans[pv] = true;
        }
        Ok(spans)
    };
    let curves = place_common_knots(
        &family,
        features.v_knots(&v, options.degree),
        options,
        tol,
        failing,
    )?;
    Ok((surface_of(ku, &curves)?, v))
}

/// The surface whose columns of control points are `columns` (curves on one knot vector), on
/// the u knots `ku`.
fn surface_of(
    ku: &crate::spline::KnotVector,
    columns: &[BSplineCurve],
) -> Result<BSplineSurface, FitError> {
    let control = columns
        .iter()
        .flat_map(|c| c.control_points().to_vec())
        .collect();
    let kv = columns[0].knots().clone();
    Ok(BSplineSurface::try_new(ku.clone(), kv, control)?)
}

/// The patches (u span's bounds, v cell) of `surface` whose `data` (the rows' points at their own u and
/// their row's `v`) miss `tol` in the options' tolerance mode, measured along the data's
/// normals at those parameters — the judgement the fit converges by, without foot points.
fn failing_patches(
    surface: &BSplineSurface,
    data: &Family<'_>,
    v: &[f64],
    options: &SectionsOptions,
    tol: f64,
) -> Vec<((f64, f64), usize)> {
    let mut uv = Vec::with_capacity(data.points.len());
    let mut dist = Vec::with_capacity(data.points.len());
    for (r, &v) in data.sections.iter().zip(v) {
        for i in r.clone() {
            let e = data.points[i] - surface.eval(data.params[i], v);
            let n = data.normals[i];
            uv.push([data.params[i], v]);
            dist.push(if n == Vec3::ZERO {
                e.length()
            } else {
                e.dot(n)
            });
        }
    }
    let grid = PatchGrid::of(surface);
    let all = vec![true; uv.len()];
    let crit = options.criterion(tol);
    let nv = grid.v.len();
    let errors = patch_errors(surface, &grid, &uv, &dist, &all, crit);
    let failing = errors.iter().enumerate().filter(|(_, e)| !e.pass);
    let knots = surface.knots_u().knots();
    let u_span = |cell: usize| {
        let k = grid.u.knot_index(cell);
        (knots[k], knots[k + 1])
    };
    failing.map(|(k, _)| (u_span(k / nv), k % nv)).collect()
}

/// The column points with exact repeats nudged apart (a column of equal control points — a
/// flat stretch — is a valid section, but the curve fitter rejects repeated points).
fn distinct(points: &[Point3]) -> Vec<Point3> {
    let scale = crate::geom::Aabb::from_points(points).map_or(1.0, |b| b.diagonal().max(1.0));
    let mut out: Vec<Point3> = Vec::with_capacity(points.len());
    for (i, &p) in points.iter().enumerate() {
        let mut q = p;
        if out.last() == Some(&q) {
            q.z += 1e-9 * scale * i as f64;
        }
        out.push(q);
    }
    out
}

/// Chord-length parameters of the points of every column, averaged over the columns.
fn mean_chord(columns: &[Vec<Point3>]) -> Vec<f64> {
    let n = columns[0].len();
    let mut v = vec![0.0; n];
    for column in columns {
        let mut acc = vec![0.0; n];
        for i in 1..n {
            acc[i] = acc[i - 1] + (column[i] - column[i - 1]).length();
        }
        let total = acc[n - 1];
        for i in 0..n {
            v[i] += if total > 0.0 {
                acc[i] / total
            } else {
                i as f64 / (n - 1) as f64
            };
        }
    }
    v.iter_mut().for_each(|x| *x /= columns.len() as f64);
    v
}

/// Every data point's (u, v): its chord parameter along its row, and its row's v.
fn initial_uv(rows: &[std::ops::Range<usize>], row_params: &[f64], v: &[f64]) -> Vec<[f64; 2]> {
    rows.iter()
        .zip(v)
        .flat_map(|(r, &v)| row_params[r.clone()].iter().map(move |&u| [u, v]))
        .collect()
}

impl Fitter for SectionsFitter {
    fn step(&mut self) -> Result<FitStatus, FitError> {
        if self.status() != FitStatus::Running {
            return Ok(self.status());
        }
        let start = Instant::now();
        let status = match self.stage {
            Stage::Rows => {
                self.fit_rows()?;
                self.stage = Stage::Columns;
                FitStatus::Running
            }
            Stage::Columns | Stage::Done => {
                self.fit_columns()?;
                // Measured before judging: a surface that strays from the data has not
                // converged, whatever its data errors (SPEC §6).
                super::measure_back(&mut self.state, &self.surface, &self.uv);
                let pass = self.patches_pass();
                if pass && self.state.back_met() {
                    FitStatus::Converged
                } else if !pass && self.split_u() {
                    self.stage = Stage::Rows;
                    FitStatus::Running
                } else {
                    FitStatus::Stalled
                }
            }
        };
        if status != FitStatus::Running {
            self.stage = Stage::Done;
        }
        let n = self.surface.control_points().len();
        Ok(self.state.record(start, n, true, status))
    }

    fn state(&self) -> &FitState {
        &self.state
    }

    fn state_mut(&mut self) -> &mut FitState {
        &mut self.state
    }

    fn foot_points(&self) -> Vec<Point3> {
        super::surface_feet(&self.surface, &self.uv)
    }

    fn num_control_points(&self) -> usize {
        self.surface.control_points().len()
    }

    fn control_shape(&self) -> Shape {
        super::control_grid(&self.surface)
    }

    fn limit_shape(&self, resolution: usize) -> Shape {
        super::surface_mesh(&self.surface, resolution)
    }

    fn trimmed_limit_shape(&self, resolution: usize) -> Option<Shape> {
        super::trimmed_surface_mesh(&self.surface, &self.uv, resolution)
    }

    fn iso_lines(&self, resolution: usize) -> Vec<Point3> {
        super::iso_lines(&self.surface, resolution)
    }

    fn spline(&self) -> Option<Spline<'_>> {
        Some(Spline::Surface {
            surface: &self.surface,
            params: &self.uv,
        })
    }

    fn details(&self) -> serde_json::Map<String, serde_json::Value> {
        let mut m = super::details(&self.surface, &self.uv, self.state.data(), 0);
        let d = self.state.diagonal();
        m.insert("rows".into(), self.rows.len().into());
        m.insert("sigma".into(), self.sigma().into());
        m.insert("sigma_pct".into(), (self.sigma() / d * 100.0).into());
        m.insert("sigma_features".into(), self.sigma_features.into());
        m.insert(
            "sigma_features_pct".into(),
            (self.sigma_features / d * 100.0).into(),
        );
        m
    }
}
