//! Skinning fit (SPEC §3 applied to surfaces, seed 004): a B-spline surface as a family of
//! section curves, for gridded data (a range scan's rows, a measuring machine's scan lines).
//!
//! 1. Every row is fitted by the knot-placement curve fitter ([`KnotPlacementFitter`]): a
//!    multiple knot where the row's shape is not C2 (a crease crossing the rows gets one in
//!    every row), then single knots at the largest deviations until the row meets the
//!    tolerance.
//! 2. The row curves are brought to one knot vector: the union of their knots, knots of
//!    different rows closer than half a data spacing merged into one (the highest multiplicity
//!    wins, and its value), and every row re-fitted by least squares on the merged knots.
//! 3. Each column of control points (one per row) is fitted across the rows the same way, and
//!    the column curves are brought to one knot vector too: their control points are the
//!    surface's. Column points are control points, so a column curve off by δ moves the
//!    surface by at most δ (the basis functions sum to 1); columns are fitted to half the
//!    tolerance and again to a quarter while the surface misses it.
//!
//! The first surface (built when the fitter is made) uses the multiple knots only — the
//! paper's "double knots only" figure; every [`Fitter::step`] is one stage (rows, common
//! knots, columns) so the page shows the progress. The standard deviation σ the paper reports
//! is that of the signed point-to-surface distances (foot points by Newton from the row and
//! column parameters), in model units and % of the bounding-box diagonal.

use super::patches::correct_parameters;
use crate::fit::{
    FitError, FitState, FitStatus, Fitter, KnotPlacementFitter, KnotPlacementOptions, Method,
    Scheme, Shape, Spline, Tolerances,
};
use crate::geom::Point3;
use crate::spline::{BSplineCurve, BSplineSurface};
use web_time::Instant;

/// Newton iterations of the foot points on the surface.
const FOOT_ITERATIONS: usize = 12;

/// Options of the skinning fit. Defaults in brackets on each field.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SectionsOptions {
    /// Degree in u and v, 1..=5 [3].
    pub degree: usize,
    /// Tolerance on E_max, % of the bounding-box diagonal of all the data [0.1].
    pub tol_pct: f64,
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
        self.curve_options(1.0, 1.0).validate()
    }

    /// The knot-placement options of a section whose own diagonal is `diagonal`, to an E_max
    /// of `tol` model units.
    fn curve_options(&self, tol: f64, diagonal: f64) -> KnotPlacementOptions {
        KnotPlacementOptions {
            degree: self.degree,
            tolerances: Tolerances::max_only(tol / diagonal * 100.0),
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
    /// Sets the E_max tolerance, %.
    with_tol_pct(tol_pct: f64) => |s| s.tol_pct;
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
    CommonKnots,
    Columns,
    Done,
}

/// The skinning fitter (module docs), driven through [`Fitter`].
#[derive(Clone, Debug)]
pub struct SectionsFitter {
    options: SectionsOptions,
    /// The data rows, as index ranges into the state's data.
    rows: Vec<std::ops::Range<usize>>,
    /// The row curves of the current stage.
    row_curves: Vec<BSplineCurve>,
    /// Chord-length parameter of every data point along its row, in data order.
    row_params: Vec<f64>,
    stage: Stage,
    /// The column tolerance, model units (halved while the surface misses the tolerance).
    column_tol: f64,
    /// σ of the first surface (multiple knots only), model units.
    sigma_features: f64,
    surface: BSplineSurface,
    uv: Vec<[f64; 2]>,
    state: FitState,
}

impl SectionsFitter {
    /// A skinning fit of `points` cut into `rows` (index ranges, in order, covering the
    /// points): checks the rows, fits them with their multiple knots only and skins that first
    /// surface.
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
        let fitters = row_fitters(points, &rows, &options, tol)?;
        let row_params: Vec<f64> = fitters.iter().flat_map(|f| f.params().to_vec()).collect();
        let curves: Vec<BSplineCurve> = fitters.iter().map(|f| f.curve().clone()).collect();
        let row_curves = on_common_knots(&curves, points, &rows, &row_params, options.degree)?;
        let (surface, v) = skin(&row_curves, &options, f64::INFINITY)?;
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
            row_curves,
            row_params,
            stage: Stage::Rows,
            column_tol: tol / 2.0,
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

    /// Foot points from the current parameters, the errors and their statistics.
    fn measure(&mut self) {
        let (points, errors) = self.state.data_and_errors_mut();
        correct_parameters(&self.surface, points, &mut self.uv, errors, FOOT_ITERATIONS);
        self.state.errors_changed();
    }

    /// Stage 1: every row fitted to the tolerance.
    fn fit_rows(&mut self) -> Result<(), FitError> {
        let tol = self.options.tol_pct / 100.0 * self.state.diagonal();
        let mut fitters = row_fitters(self.state.data(), &self.rows, &self.options, tol)?;
        for f in &mut fitters {
            f.run()?;
        }
        self.row_curves = fitters.iter().map(|f| f.curve().clone()).collect();
        Ok(())
    }

    /// Stage 2: the row curves re-fitted on their merged knots.
    fn common_knots(&mut self) -> Result<(), FitError> {
        self.row_curves = on_common_knots(
            &self.row_curves,
            self.state.data(),
            &self.rows,
            &self.row_params,
            self.options.degree,
        )?;
        Ok(())
    }

    /// Stage 3: the columns, and the surface they make.
    fn fit_columns(&mut self) -> Result<(), FitError> {
        let (surface, v) = skin(&self.row_curves, &self.options, self.column_tol)?;
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

/// The row `curves` re-fitted to the data `points` of their `rows` (at `params`, in data
/// order) on their merged knots: knots of different rows closer than half a data spacing
/// become one.
fn on_common_knots(
    curves: &[BSplineCurve],
    points: &[Point3],
    rows: &[std::ops::Range<usize>],
    params: &[f64],
    degree: usize,
) -> Result<Vec<BSplineCurve>, FitError> {
    let per_row = rows.iter().map(|r| r.len()).max().unwrap_or(1);
    let knots = merged_knots(curves, 0.5 / per_row as f64);
    rows.iter()
        .map(|r| refit(&knots, degree, &points[r.clone()], &params[r.clone()]))
        .collect()
}

/// A knot-placement fitter per row (multiple knots placed, first solve done), to an E_max of
/// `tol` model units.
fn row_fitters(
    points: &[Point3],
    rows: &[std::ops::Range<usize>],
    options: &SectionsOptions,
    tol: f64,
) -> Result<Vec<KnotPlacementFitter>, FitError> {
    rows.iter()
        .map(|r| {
            let row = &points[r.clone()];
            let diagonal = crate::geom::Aabb::from_points(row).map_or(1.0, |b| b.diagonal());
            KnotPlacementFitter::try_new(row, options.curve_options(tol, diagonal.max(tol)))
        })
        .collect()
}

/// The surface skinned across `rows` (curves on one knot vector): each column of control
/// points fitted by knot placement to `tol` (infinite: multiple knots only), the columns
/// brought to one knot vector and re-fitted at their common parameters. Returns the surface
/// and the v parameter of every row.
fn skin(
    rows: &[BSplineCurve],
    options: &SectionsOptions,
    tol: f64,
) -> Result<(BSplineSurface, Vec<f64>), FitError> {
    let nu = rows[0].control_points().len();
    let columns: Vec<Vec<Point3>> = (0..nu)
        .map(|j| rows.iter().map(|c| c.control_points()[j]).collect())
        .collect();
    let v = mean_chord(&columns);
    let mut curves = Vec::with_capacity(nu);
    for column in &columns {
        let diagonal = crate::geom::Aabb::from_points(column).map_or(1.0, |b| b.diagonal());
        let scale = diagonal.max(f64::MIN_POSITIVE);
        let tol_pct = if tol.is_finite() {
            (tol / scale * 100.0).max(1e-9)
        } else {
            1e9
        };
        let opts = KnotPlacementOptions {
            tolerances: Tolerances::max_only(tol_pct),
            ..options.curve_options(1.0, 1.0)
        };
        let mut fitter = KnotPlacementFitter::try_new(&distinct(column), opts)?;
        fitter.run()?;
        curves.push(fitter.curve().clone());
    }
    let knots = merged_knots(&curves, 0.5 / rows.len() as f64);
    let mut control = Vec::with_capacity(nu * rows.len());
    let mut kv = None;
    for column in &columns {
        let c = refit(&knots, options.degree, column, &v)?;
        control.extend_from_slice(c.control_points());
        kv = Some(c.knots().clone());
    }
    let kv = kv.ok_or(FitError::TooFewRows {
        found: 0,
        needed: 1,
    })?;
    let ku = rows[0].knots().clone();
    Ok((BSplineSurface::try_new(ku, kv, control)?, v))
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

/// The interior knots of all `curves` (open, on [0, 1]) as one list of (value, multiplicity):
/// knots closer than `gap` merged into one at the value of the highest multiplicity among
/// them, which it takes.
fn merged_knots(curves: &[BSplineCurve], gap: f64) -> Vec<(f64, usize)> {
    let mut all: Vec<(f64, usize)> = Vec::new();
    for c in curves {
        let k = c.knots().knots();
        let p = c.degree();
        let interior = &k[p + 1..k.len() - p - 1];
        let mut i = 0;
        while i < interior.len() {
            let m = interior[i..]
                .iter()
                .take_while(|&&x| x == interior[i])
                .count();
            all.push((interior[i], m));
            i += m;
        }
    }
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, usize)> = Vec::new();
    for (value, m) in all {
        match out.last_mut() {
            Some(last) if value - last.0 < gap => {
                if m > last.1 {
                    *last = (value, m);
                }
            }
            _ => out.push((value, m)),
        }
    }
    out
}

/// The least-squares curve of `degree` on the clamped knots `knots` (interior, with
/// multiplicities) through `points` at `params`.
fn refit(
    knots: &[(f64, usize)],
    degree: usize,
    points: &[Point3],
    params: &[f64],
) -> Result<BSplineCurve, FitError> {
    let mut all = vec![0.0; degree + 1];
    for &(value, m) in knots.iter().filter(|k| k.0 > 0.0 && k.0 < 1.0) {
        all.extend(std::iter::repeat_n(value, m.min(degree)));
    }
    all.extend(std::iter::repeat_n(1.0, degree + 1));
    let n = all.len() - degree - 1;
    let ctrl = (0..n).map(|i| points[i * points.len() / n]).collect();
    let template = BSplineCurve::try_new(degree, all, ctrl)?;
    crate::fit::least_squares_curve(&template, points, params)
}

/// Every data point's (u, v): its chord parameter along its row, and its row's v.
fn initial_uv(rows: &[std::ops::Range<usize>], row_params: &[f64], v: &[f64]) -> Vec<[f64; 2]> {
    rows.iter()
        .zip(v)
        .flat_map(|(r, &v)| row_params[r.clone()].iter().map(move |&u| [u, v]))
        .collect()
}

/// Rows of `points`: `Some(n)` points each, or else cut where the step to the next point is a
/// jump — longer than 4 times the median step, or going back against the scan direction (the
/// first step's).
pub fn detect_rows(points: &[Point3], per_row: Option<usize>) -> Vec<std::ops::Range<usize>> {
    if let Some(n) = per_row.filter(|&n| n > 0) {
        return (0..points.len())
            .step_by(n)
            .map(|s| s..(s + n).min(points.len()))
            .collect();
    }
    if points.len() < 2 {
        return std::iter::once(0..points.len()).collect();
    }
    let steps: Vec<_> = points.windows(2).map(|w| w[1] - w[0]).collect();
    let mut lengths: Vec<f64> = steps.iter().map(|s| s.length()).collect();
    lengths.sort_by(f64::total_cmp);
    let median = lengths[lengths.len() / 2];
    let dir = steps[0];
    let mut rows = Vec::new();
    let mut begin = 0;
    for (i, s) in steps.iter().enumerate() {
        if s.length() > 4.0 * median || s.dot(dir) < 0.0 {
            rows.push(begin..i + 1);
            begin = i + 1;
        }
    }
    rows.push(begin..points.len());
    rows
}

/// The rows of a range grid: the largest rectangle of columns × rows whose cells are all
/// measured (a skinned surface needs complete sections), as point indices row by row.
pub fn grid_rows(grid: &crate::io::RangeGrid) -> (Vec<u32>, Vec<std::ops::Range<usize>>) {
    let (cols, rows) = (grid.cols(), grid.rows());
    let mut height = vec![0usize; cols];
    let mut best = (0usize, 0, 0, 0, 0); // area, c0, c1, r0, r1 (inclusive-exclusive)
    for r in 0..rows {
        for (c, h) in height.iter_mut().enumerate() {
            *h = if grid.cell(c, r).is_some() { *h + 1 } else { 0 };
        }
        // Largest rectangle under the histogram `height`, ending at row r.
        let mut stack: Vec<usize> = Vec::new();
        for c in 0..=cols {
            let h = if c < cols { height[c] } else { 0 };
            while let Some(&top) = stack.last() {
                if height[top] < h {
                    break;
                }
                stack.pop();
                let left = stack.last().map_or(0, |&l| l + 1);
                let area = height[top] * (c - left);
                if area > best.0 {
                    best = (area, left, c, r + 1 - height[top], r + 1);
                }
            }
            stack.push(c);
        }
    }
    let (_, c0, c1, r0, r1) = best;
    let mut indices = Vec::with_capacity(best.0);
    let mut ranges = Vec::with_capacity(r1 - r0);
    for r in r0..r1 {
        let begin = indices.len();
        indices.extend((c0..c1).filter_map(|c| grid.cell(c, r)));
        ranges.push(begin..indices.len());
    }
    (indices, ranges)
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
                self.stage = Stage::CommonKnots;
                FitStatus::Running
            }
            Stage::CommonKnots => {
                self.common_knots()?;
                self.stage = Stage::Columns;
                FitStatus::Running
            }
            Stage::Columns | Stage::Done => {
                self.fit_columns()?;
                // Measured before judging: a surface that strays from the data has not
                // converged, whatever its data errors (SPEC §6).
                super::measure_back(&mut self.state, &self.surface, &self.uv);
                let tol = self.options.tol_pct / 100.0 * self.state.diagonal();
                if self.state.met() {
                    FitStatus::Converged
                } else if self.column_tol > tol / 8.0 {
                    self.column_tol /= 2.0;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_by_jump_and_by_count() {
        let pts: Vec<Point3> = (0..3)
            .flat_map(|r| (0..5).map(move |c| Point3::new(c as f64, r as f64, 0.0)))
            .collect();
        assert_eq!(detect_rows(&pts, None), vec![0..5, 5..10, 10..15]);
        assert_eq!(detect_rows(&pts, Some(5)), vec![0..5, 5..10, 10..15]);
        assert_eq!(detect_rows(&pts, Some(4)).len(), 4);
    }

    #[test]
    fn merged_knots_keep_highest_multiplicity() {
        let c = |k: Vec<f64>| {
            let n = k.len() - 4;
            BSplineCurve::try_new(3, k, vec![Point3::ZERO; n]).unwrap()
        };
        let a = c(vec![0., 0., 0., 0., 0.5, 0.5, 1., 1., 1., 1.]);
        let b = c(vec![0., 0., 0., 0., 0.51, 0.8, 1., 1., 1., 1.]);
        assert_eq!(merged_knots(&[a, b], 0.02), vec![(0.5, 2), (0.8, 1)]);
    }
}
