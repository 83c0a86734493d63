//! UV parameterisation of scattered points for tensor-product surface fitting (SPEC §2).
//!
//! Each data point needs parameters (u, v) on the surface before a fit can start. They come
//! from projecting the points along a view direction onto a plane (by default the plane of
//! the two largest principal axes, so the view is the least-variance axis), or from the
//! closest point on a user base surface. A projection is only usable where it is one-to-one:
//! where the scan folds over (points whose projections coincide while their depths differ by
//! more than the sampling allows) the parameters are wrong. Such points are detected and,
//! by [`FoldPolicy`], reported as an error, excluded from the fit, or kept.

use crate::fit::FitError;
use crate::geom::{symmetric_eigen, Point3, Vec3};
use crate::geom::{ClosestPoint, NewtonOptions};
use crate::spline::BSplineSurface;

/// What to do with points on a fold-over of the projection.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FoldPolicy {
    /// Fail with [`FitError::FoldedProjection`].
    Fail,
    /// Leave folded points out of the fit (they are still measured).
    Exclude,
    /// Fit folded points like all others (their parameters are corrected by closest points
    /// during the fit); they are only counted. The default.
    #[default]
    Keep,
}

named_enum!(FoldPolicy, "folded", { Fail => "fail", Exclude => "exclude", Keep => "keep" });

/// Options of [`parameterize`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct ParamOptions {
    /// View direction to project along; `None` (default) takes the least-variance principal
    /// axis of the points.
    pub view: Option<Vec3>,
    /// What folded points do. Default [`FoldPolicy::Keep`].
    pub fold_policy: FoldPolicy,
    /// Two points of one projection cell whose depths differ by more than this many cell
    /// sizes lie on different layers of a fold. Default 4.
    pub fold_gap_cells: f64,
    /// Rotate the parameter rectangle about the view to the least-area bounding rectangle
    /// of the projected points. Default true.
    pub min_area: bool,
}

default_is_const!(ParamOptions);

impl ParamOptions {
    /// The defaults, as each field documents them.
    pub const DEFAULT: ParamOptions = ParamOptions {
        view: None,
        fold_policy: FoldPolicy::Keep,
        fold_gap_cells: 4.0,
        min_area: true,
    };

    /// Sets the view direction.
    pub fn with_view(mut self, view: Vec3) -> Self {
        self.view = Some(view);
        self
    }

    /// Sets the fold policy.
    pub fn with_fold_policy(mut self, policy: FoldPolicy) -> Self {
        self.fold_policy = policy;
        self
    }
}

/// The plane points were projected onto: (u, v) ∈ [0, 1]² map to
/// `origin + u · size_u · axis_u + v · size_v · axis_v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProjectionFrame {
    /// The corner of the parameter rectangle, (u, v) = (0, 0).
    pub origin: Point3,
    /// Unit direction of growing u.
    pub axis_u: Vec3,
    /// Unit direction of growing v.
    pub axis_v: Vec3,
    /// Unit view direction (the plane normal).
    pub view: Vec3,
    /// Extent of the points along `axis_u`.
    pub size_u: f64,
    /// Extent of the points along `axis_v`.
    pub size_v: f64,
}

impl ProjectionFrame {
    /// The point of the plane at (u, v) ∈ [0, 1]².
    pub fn at(&self, u: f64, v: f64) -> Point3 {
        self.origin + self.axis_u * (u * self.size_u) + self.axis_v * (v * self.size_v)
    }
}

/// Parameters of every data point.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameterization {
    /// (u, v) of every point, in data order, in [0, 1]² for a plane or the base surface's
    /// domain.
    pub uv: Vec<[f64; 2]>,
    /// Whether each point lies on a fold-over (not the main layer of its projection cell).
    pub folded: Vec<bool>,
    /// Number of folded points.
    pub num_folded: usize,
    /// The projection plane, when the points were projected onto a plane.
    pub frame: Option<ProjectionFrame>,
}

impl Parameterization {
    /// Whether point `i` takes part in the fit under `policy`.
    pub fn is_active(&self, i: usize, policy: FoldPolicy) -> bool {
        policy != FoldPolicy::Exclude || !self.folded[i]
    }
}

/// Checks that there are at least `needed` points and that all coordinates are finite and in
/// range.
pub fn check_points(points: &[Point3], needed: usize) -> Result<(), FitError> {
    if points.len() < needed {
        return Err(FitError::TooFewPoints {
            found: points.len(),
            needed,
        });
    }
    Ok(crate::geom::check_coordinates(points)?)
}

/// Parameters by projection onto a plane along `opts.view` (default: least-variance axis).
/// Fails on fewer than 3 or non-finite points, on a zero or non-finite view direction, on
/// points whose projection is degenerate (collinear, or a plane seen edge-on), and, under
/// [`FoldPolicy::Fail`], on folded points.
pub fn parameterize(points: &[Point3], opts: &ParamOptions) -> Result<Parameterization, FitError> {
    check_points(points, 3)?;
    let center = points.iter().copied().sum::<Point3>() / points.len() as f64;
    let (values, axes) = principal_axes(points, center);
    let scale = values[0].max(f64::MIN_POSITIVE).sqrt();
    if let Some(v) = opts.view {
        let len = v.length();
        if !(len.is_finite() && len > 0.0) {
            return Err(FitError::InvalidOption {
                name: "view",
                reason: format!("the view direction {v} must be finite and non-zero"),
            });
        }
        let (param, _) = project_along(points, center, axes, v / len, scale, opts)?;
        return finish(param, opts.fold_policy);
    }
    // No view given: the least-variance axis, or the direction tilted from it (15° and 30°,
    // eight azimuths) under which the fewest points fold — a range scan's own view direction
    // is rarely the least-variance axis of the shape it sees.
    let quick = ParamOptions {
        min_area: false,
        ..*opts
    };
    let mut best: Option<(Vec3, usize)> = None;
    for view in candidate_views(axes) {
        let Ok((_, folds)) = project_along(points, center, axes, view, scale, &quick) else {
            continue;
        };
        if best.is_none_or(|b| folds < b.1) {
            best = Some((view, folds));
        }
    }
    let view = best.map_or(axes[2], |b| b.0);
    let (param, _) = project_along(points, center, axes, view, scale, opts)?;
    finish(param, opts.fold_policy)
}

/// The least-variance axis first, then tilts of 15° and 30° towards eight azimuths.
fn candidate_views(axes: [Vec3; 3]) -> Vec<Vec3> {
    let mut views = vec![axes[2]];
    for tilt in [15.0f64, 30.0] {
        for k in 0..8 {
            let az = (k as f64 * 45.0).to_radians();
            let side = axes[0] * libm::cos(az) + axes[1] * libm::sin(az);
            let t = tilt.to_radians();
            views.push((axes[2] * libm::cos(t) + side * libm::sin(t)).normalize());
        }
    }
    views
}

/// Projects along the unit `view` onto the plane through `center`, in the least-area
/// rectangle, and counts the folded points.
fn project_along(
    points: &[Point3],
    center: Point3,
    axes: [Vec3; 3],
    view: Vec3,
    scale: f64,
    opts: &ParamOptions,
) -> Result<(Parameterization, usize), FitError> {
    // In-plane axes: the principal axes with the view component removed.
    let axis_u = (axes[0] - view * axes[0].dot(view)).try_normalize();
    let axis_u = axis_u
        .or_else(|| (axes[1] - view * axes[1].dot(view)).try_normalize())
        .unwrap_or(Vec3::X);
    let axis_v = view.cross(axis_u).normalize_or_zero();
    let (axis_u, axis_v) = if opts.min_area {
        min_area_axes(points, center, axis_u, axis_v)
    } else {
        (axis_u, axis_v)
    };
    let proj: Vec<[f64; 3]> = points
        .iter()
        .map(|p| {
            let d = *p - center;
            [d.dot(axis_u), d.dot(axis_v), d.dot(view)]
        })
        .collect();
    let (min_u, max_u) = extent(proj.iter().map(|q| q[0]));
    let (min_v, max_v) = extent(proj.iter().map(|q| q[1]));
    let (size_u, size_v) = (max_u - min_u, max_v - min_v);
    let thin = 1e-9 * scale;
    if !(size_u > thin && size_v > thin) {
        return Err(FitError::DegenerateProjection {
            reason: format!(
                "the points project onto a segment ({size_u:.3e} × {size_v:.3e}) along view \
                 {view}: they are collinear or seen edge-on"
            ),
        });
    }
    let uv: Vec<[f64; 2]> = proj
        .iter()
        .map(|q| [(q[0] - min_u) / size_u, (q[1] - min_v) / size_v])
        .collect();
    let depth: Vec<f64> = proj.iter().map(|q| q[2]).collect();
    let folded = detect_folds(&uv, &depth, size_u, size_v, opts.fold_gap_cells);
    let num_folded = folded.iter().filter(|&&f| f).count();
    let frame = ProjectionFrame {
        origin: center + axis_u * min_u + axis_v * min_v,
        axis_u,
        axis_v,
        view,
        size_u,
        size_v,
    };
    let param = Parameterization {
        uv,
        folded,
        num_folded,
        frame: Some(frame),
    };
    Ok((param, num_folded))
}

/// Parameters from the closest points on a user base surface S_B, seeded from a grid of
/// samples; folds are detected on (u, v, signed distance along the normal).
pub fn parameterize_on_surface(
    points: &[Point3],
    base: &BSplineSurface,
    opts: &ParamOptions,
) -> Result<Parameterization, FitError> {
    check_points(points, 3)?;
    let ((u0, u1), (v0, v1)) = base.domain();
    const SAMPLES: usize = 33;
    let seeds: Vec<(f64, f64, Point3)> = (0..SAMPLES * SAMPLES)
        .map(|k| {
            let u = u0 + (u1 - u0) * (k / SAMPLES) as f64 / (SAMPLES - 1) as f64;
            let v = v0 + (v1 - v0) * (k % SAMPLES) as f64 / (SAMPLES - 1) as f64;
            (u, v, base.eval(u, v))
        })
        .collect();
    // Physical size of the parameter rectangle (mid-line lengths), for the fold cell size.
    let mid = SAMPLES / 2;
    let at = |a: usize, b: usize| seeds[a * SAMPLES + b].2;
    let size_u: f64 = (1..SAMPLES)
        .map(|a| (at(a, mid) - at(a - 1, mid)).length())
        .sum();
    let size_v: f64 = (1..SAMPLES)
        .map(|b| (at(mid, b) - at(mid, b - 1)).length())
        .sum();
    let mut uv = Vec::with_capacity(points.len());
    let mut depth = Vec::with_capacity(points.len());
    for p in points {
        let seed = seeds
            .iter()
            .min_by(|a, b| {
                (a.2 - *p)
                    .length_squared()
                    .total_cmp(&(b.2 - *p).length_squared())
            })
            .map_or((u0, v0), |s| (s.0, s.1));
        let near = base.closest_point_from(*p, [seed.0, seed.1], &NewtonOptions::DEFAULT);
        let [u, v] = near.param;
        uv.push([(u - u0) / (u1 - u0), (v - v0) / (v1 - v0)]);
        depth.push((*p - near.point).dot(near.direction));
    }
    let folded = detect_folds(
        &uv,
        &depth,
        size_u.max(f64::MIN_POSITIVE),
        size_v.max(f64::MIN_POSITIVE),
        opts.fold_gap_cells,
    );
    let uv = uv
        .into_iter()
        .map(|[u, v]| [u0 + u * (u1 - u0), v0 + v * (v1 - v0)])
        .collect();
    let num_folded = folded.iter().filter(|&&f| f).count();
    let param = Parameterization {
        uv,
        folded,
        num_folded,
        frame: None,
    };
    finish(param, opts.fold_policy)
}

fn finish(param: Parameterization, policy: FoldPolicy) -> Result<Parameterization, FitError> {
    if policy == FoldPolicy::Fail && param.num_folded > 0 {
        let first = param.folded.iter().position(|&f| f).unwrap_or(0);
        return Err(FitError::FoldedProjection {
            count: param.num_folded,
            total: param.uv.len(),
            first,
        });
    }
    Ok(param)
}

/// Marks points that are not on the main layer of their projection cell. Cells are about twice
/// the mean projected point spacing; within a cell the depths are sorted and split into layers
/// wherever consecutive depths jump by more than `gap_cells` cell sizes (a single sheet, even a
/// steep one, has depth steps no larger than its sampling). The largest layer is the main one
/// (ties: the nearest to the viewer).
fn detect_folds(
    uv: &[[f64; 2]],
    depth: &[f64],
    size_u: f64,
    size_v: f64,
    gap_cells: f64,
) -> Vec<bool> {
    let n = uv.len();
    let cell = 2.0 * (size_u * size_v / n as f64).sqrt();
    let gap = gap_cells * cell;
    let cols = ((size_u / cell).ceil() as usize).clamp(1, 1 << 15);
    let rows = ((size_v / cell).ceil() as usize).clamp(1, 1 << 15);
    // Points grouped by cell with a counting sort (one pass, no comparisons: the view search
    // runs this for 17 directions), then each cell's few members sorted by depth.
    let key: Vec<usize> = uv
        .iter()
        .map(|[u, v]| {
            let cu = ((u * cols as f64) as usize).min(cols - 1);
            let cv = ((v * rows as f64) as usize).min(rows - 1);
            cu * rows + cv
        })
        .collect();
    let mut start = vec![0usize; cols * rows + 1];
    for &k in &key {
        start[k + 1] += 1;
    }
    for c in 0..cols * rows {
        start[c + 1] += start[c];
    }
    let mut order = vec![0usize; n];
    let mut next = start.clone();
    for (i, &k) in key.iter().enumerate() {
        order[next[k]] = i;
        next[k] += 1;
    }
    let mut folded = vec![false; n];
    for c in 0..cols * rows {
        let members = &mut order[start[c]..start[c + 1]];
        if members.len() > 1 {
            // Stable: equal depths keep index order.
            members.sort_by(|&a, &b| depth[a].total_cmp(&depth[b]));
            mark_minor_layers(members, depth, gap, &mut folded);
        }
    }
    folded
}

/// Splits depth-sorted `members` into layers at gaps above `gap` and flags all but the largest.
fn mark_minor_layers(members: &[usize], depth: &[f64], gap: f64, folded: &mut [bool]) {
    let mut layers: Vec<(usize, usize)> = Vec::new();
    let mut start = 0;
    for k in 1..=members.len() {
        if k == members.len() || depth[members[k]] - depth[members[k - 1]] > gap {
            layers.push((start, k));
            start = k;
        }
    }
    if layers.len() < 2 {
        return;
    }
    let main = layers
        .iter()
        .enumerate()
        .max_by(|a, b| {
            (a.1 .1 - a.1 .0)
                .cmp(&(b.1 .1 - b.1 .0))
                .then(b.0.cmp(&a.0))
        })
        .map_or(0, |(i, _)| i);
    for (li, &(s, e)) in layers.iter().enumerate() {
        if li != main {
            for &m in &members[s..e] {
                folded[m] = true;
            }
        }
    }
}

/// The in-plane axes, rotated about the view, whose bounding rectangle of the projected points
/// has the least area (1° steps over a quarter turn): the parameter rectangle then wastes as
/// little of its domain on empty patches as the data's outline allows.
fn min_area_axes(points: &[Point3], center: Point3, a: Vec3, b: Vec3) -> (Vec3, Vec3) {
    let flat: Vec<(f64, f64)> = points
        .iter()
        .map(|p| ((*p - center).dot(a), (*p - center).dot(b)))
        .collect();
    let area = |deg: usize| {
        let (s, c) = libm::sincos((deg as f64).to_radians());
        let (lo_u, hi_u) = extent(flat.iter().map(|&(x, y)| c * x + s * y));
        let (lo_v, hi_v) = extent(flat.iter().map(|&(x, y)| -s * x + c * y));
        (hi_u - lo_u) * (hi_v - lo_v)
    };
    // Every 6°, then every 1° around the best.
    let coarse = (0..15)
        .map(|k| k * 6)
        .min_by(|&i, &j| area(i).total_cmp(&area(j)))
        .unwrap_or(0);
    let best = (coarse + 90 - 5..=coarse + 90 + 5)
        .map(|d| d % 90)
        .min_by(|&i, &j| area(i).total_cmp(&area(j)))
        .unwrap_or(coarse);
    let (s, c) = libm::sincos((best as f64).to_radians());
    (a * c + b * s, b * c - a * s)
}

fn extent<I: Iterator<Item = f64>>(values: I) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    })
}

/// Eigenvalues (descending) and unit eigenvectors of the points' covariance matrix.
fn principal_axes(points: &[Point3], center: Point3) -> ([f64; 3], [Vec3; 3]) {
    let mut c = [[0.0; 3]; 3];
    for p in points {
        let d = (*p - center).to_array();
        for (r, row) in c.iter_mut().enumerate() {
            for (s, x) in row.iter_mut().enumerate() {
                *x += d[r] * d[s];
            }
        }
    }
    let n = points.len() as f64;
    for row in c.iter_mut() {
        for x in row.iter_mut() {
            *x /= n;
        }
    }
    let (values, vectors) = symmetric_eigen(c);
    (
        [values[2], values[1], values[0]],
        [vectors[2], vectors[1], vectors[0]],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 60 × 60 sheet at z = 0 and, inside its right quarter, a sparse 6 × 12 flap at
    /// z = 0.5: seen along z, exactly the flap's points lie on a second (smaller) layer.
    fn sheet_with_flap() -> Vec<Point3> {
        let mut pts: Vec<Point3> = (0..3600)
            .map(|k| Point3::new((k / 60) as f64 / 59.0, (k % 60) as f64 / 59.0, 0.0))
            .collect();
        pts.extend((0..72).map(|k| {
            let (x, y) = ((k / 12) as f64 / 5.0, (k % 12) as f64 / 11.0);
            Point3::new(0.75 + 0.24 * x, 0.01 + 0.98 * y, 0.5)
        }));
        pts
    }

    #[test]
    fn the_flap_of_a_fold_is_detected() {
        let pts = sheet_with_flap();
        let opts = ParamOptions::default().with_view(Vec3::Z);
        let param = parameterize(&pts, &opts).expect("parameterised");
        assert_eq!(param.num_folded, 72);
        assert!(param.folded[3600..].iter().all(|&f| f));
        let fail = opts.with_fold_policy(FoldPolicy::Fail);
        assert!(matches!(
            parameterize(&pts, &fail),
            Err(FitError::FoldedProjection { count: 72, .. })
        ));
        // The flat sheet alone has no folds.
        assert_eq!(
            parameterize(&pts[..3600], &opts).expect("flat").num_folded,
            0
        );
    }

    #[test]
    fn layers_split_at_gaps() {
        let depth = [0.0, 0.1, 0.2, 5.0, 5.1];
        let mut folded = vec![false; 5];
        mark_minor_layers(&[0, 1, 2, 3, 4], &depth, 1.0, &mut folded);
        assert_eq!(folded, vec![false, false, false, true, true]);
    }
}
