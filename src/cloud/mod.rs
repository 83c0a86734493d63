//! From bare points to a mesh: what a scan without connectivity needs before QEM simplification
//! and fitting (SPEC §1, steps 1–2).
//!
//! Two kinds of data, told apart automatically (or forced with
//! [`ReconstructOptions::with_kind`]):
//!
//! - **Open** single-view scans (height-field-like, e.g. one range image): triangulated by the
//!   scanner's range grid when the file has one, else by a 2D Delaunay triangulation of the
//!   points projected onto their best-fit plane; triangles that span holes or run outside the
//!   scanned outline (an edge longer than [`ReconstructOptions::long_edge_factor`] times the
//!   local point spacing) are cut away. The mesh's vertices are the input points themselves.
//! - **Closed** objects (points all around): normals by PCA over the k nearest neighbours,
//!   oriented consistently along a minimum spanning tree (Hoppe et al. 1992), then the zero set
//!   of an implicit moving-least-squares signed distance contoured by marching tetrahedra (its
//!   slivers collapsed): a watertight manifold wherever the sampling is closed and even
//!   enough. Its vertices are new points. Where the sampling is sparse or uneven (thin parts,
//!   a decimated mesh's vertices) the zero set also runs where no point is — sheets and blobs
//!   up to 10 % of the diagonal from the points — and those contour triangles are dropped
//!   (`closed::without_strays`), leaving holes that the fit may span.
//!
//! Either way the result is one manifold, consistently oriented piece; for fitting, keep the
//! input points as the data and use the mesh only to start from (e.g. through
//! [`crate::mesh::simplify`]).
//!
//! ```
//! use geofit::cloud::{reconstruct, ReconstructOptions, SurfaceKind};
//! use geofit::geom::Point3;
//!
//! // A 20×20 height field (a shallow bowl): an open scan.
//! let points: Vec<Point3> = (0..400)
//!     .map(|k| {
//!         let (x, y) = ((k % 20) as f64, (k / 20) as f64);
//!         Point3::new(x, y, 0.02 * ((x - 9.5).powi(2) + (y - 9.5).powi(2)))
//!     })
//!     .collect();
//! let out = reconstruct(&points, None, &ReconstructOptions::default())?;
//! assert_eq!(out.kind, SurfaceKind::Open);
//! assert_eq!(out.mesh.num_triangles(), 2 * 19 * 19);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod cleanup;
mod closed;
mod error;
mod neighbours;
mod normals;
mod open;

pub use error::ReconstructError;

use crate::geom::{median, Point3, Vec3};
use crate::io::RangeGrid;
use crate::mesh::PolyMesh;
use crate::mesh::{simplify_with, SimplifyOptions};
use crate::progress::{self, Part, Phase};
use neighbours::Neighbours;

/// The shares of the reconstruction's progress: the points' spacing, then normals (closed
/// surfaces and the open/closed test: neighbourhoods, principal axes, orientation), then the
/// meshing. Measured on the browser test's 500K-point sheet (natively, after the bulk-loaded
/// Delaunay): spacing 0.8 s, normals about 5 s, meshing about 2 s.
const SPACING_PART: Part = Part {
    phase: Phase::Reconstruction,
    from: 0.0,
    to: 0.1,
};
const NEIGHBOURS_PART: Part = Part {
    phase: Phase::Reconstruction,
    from: 0.1,
    to: 0.35,
};
const MESHING_PART: Part = Part {
    phase: Phase::Reconstruction,
    from: 0.7,
    to: 0.95,
};

/// Which kind of surface the points sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum SurfaceKind {
    /// A single-view, height-field-like scan with an outline.
    Open,
    /// An object sampled all around.
    Closed,
}

/// Settings of [`reconstruct`]. Build with `ReconstructOptions::default()` and the `with_*`
/// setters.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct ReconstructOptions {
    /// Force open or closed; `None` (default) decides from the data: a range grid means open;
    /// otherwise the points are open when at least 90 % of their oriented normals face the
    /// same side of the best-fit plane.
    pub kind: Option<SurfaceKind>,
    /// Neighbours per point for normals and spacing. Default 12.
    pub neighbours: usize,
    /// Open scans: triangles with an edge longer than this times the local spacing (mean
    /// distance of a point to its 6 nearest neighbours) are cut. Default 3.
    pub long_edge_factor: f64,
    /// Closed objects: contour grid cell size in units of the median point spacing. Default 2:
    /// finer costs time and gains nothing once QEM simplifies the result.
    pub cell_size: f64,
    /// Statistical outlier removal: drop points whose mean distance to their neighbours exceeds
    /// the mean over all points by this many standard deviations. Default `None` (off).
    pub outlier_std_ratio: Option<f64>,
}

impl Default for ReconstructOptions {
    fn default() -> ReconstructOptions {
        ReconstructOptions {
            kind: None,
            neighbours: 12,
            long_edge_factor: 3.0,
            cell_size: 2.0,
            outlier_std_ratio: None,
        }
    }
}

setters!(ReconstructOptions {
    /// Sets [`ReconstructOptions::kind`].
    with_kind(kind: Option<SurfaceKind>) => |s| s.kind;
    /// Sets [`ReconstructOptions::neighbours`].
    with_neighbours(k: usize) => |s| s.neighbours;
    /// Sets [`ReconstructOptions::long_edge_factor`].
    with_long_edge_factor(factor: f64) => |s| s.long_edge_factor;
    /// Sets [`ReconstructOptions::cell_size`].
    with_cell_size(spacings: f64) => |s| s.cell_size;
    /// Sets [`ReconstructOptions::outlier_std_ratio`].
    with_outlier_std_ratio(ratio: Option<f64>) => |s| s.outlier_std_ratio;
});

impl ReconstructOptions {
    fn validate(&self) -> Result<(), ReconstructError> {
        let bad = |name, value: f64, expected| {
            Err(ReconstructError::InvalidOption {
                name,
                value,
                expected,
            })
        };
        if !(3..=64).contains(&self.neighbours) {
            return bad("neighbours", self.neighbours as f64, "3 to 64");
        }
        let f = self.long_edge_factor;
        if !(f.is_finite() && f > 0.0) {
            return bad("long_edge_factor", f, "finite and > 0");
        }
        let c = self.cell_size;
        if !(c.is_finite() && (0.25..=64.0).contains(&c)) {
            return bad("cell_size", c, "0.25 to 64");
        }
        match self.outlier_std_ratio {
            Some(r) if !(r.is_finite() && r > 0.0) => bad("outlier_std_ratio", r, "finite and > 0"),
            _ => Ok(()),
        }
    }
}

/// A mesh built from points.
#[derive(Clone, Debug)]
pub struct Reconstruction {
    /// The surface: for open scans over the input points (same indices; points cut away or
    /// removed as outliers are in no face), for closed objects over new contour vertices.
    pub mesh: PolyMesh,
    /// Which kind the points were taken for.
    pub kind: SurfaceKind,
    /// Points removed as outliers.
    pub outliers: usize,
    /// Per input point: whether it survived outlier removal (all `true` without it).
    pub inlier: Vec<bool>,
    /// Closed objects: contour triangles dropped because they strayed from the points (see
    /// the module docs); the mesh has holes there. 0 for open scans.
    pub stray_triangles: usize,
    /// Points detected as an open scan whose triangulation in projection left this many of
    /// them in no triangle (more than 1 in [`MAX_UNCOVERED_SHARE`]), so they were
    /// reconstructed as a closed object instead; `None` when that did not happen.
    pub open_uncovered: Option<usize>,
}

/// Neighbours for spacing estimates and the outlier test.
const SPACING_NEIGHBOURS: usize = 6;
/// Fewest points that span a surface.
const MIN_POINTS: usize = 4;
/// Fraction of normals on one side of the best-fit plane above which points are an open scan.
const OPEN_FRACTION: f64 = 0.9;
/// Points taken for an open scan (automatically, without a range grid) go to the closed
/// method when their triangulation in projection leaves more than one in this many in no
/// triangle. Judged against the meshes the corpus's points were taken from (the fitted surface's
/// distance to that mesh, away from its holes): beetle-alt's car body, whose sides fold under
/// its roof, left 18 % of its points out, and its fits came 0.5–0.95 % from its mesh through the
/// closed method against 1.3–1.7 % through the projection; the sparser Beetle (8.6 % left out)
/// and bun000's points without their grid (2.9 %) fit closer through the projection (bun000
/// 0.76 % against 3.4 %), so a few points left out are not enough to switch.
pub const MAX_UNCOVERED_SHARE: usize = 10;
/// Closed contour: cells within this many cells of a point are evaluated.
const BAND_CELLS: i32 = 2;
/// Closed contour: sliver removal keeps one vertex in this many.
const SLIVER_REDUCTION: usize = 2;

/// Builds a manifold triangle mesh from `points`, using the scanner `grid` (indices into
/// `points`) when there is one. See the [module docs](self).
pub fn reconstruct(
    points: &[Point3],
    grid: Option<&RangeGrid>,
    options: &ReconstructOptions,
) -> Result<Reconstruction, ReconstructError> {
    options.validate()?;
    crate::geom::check_coordinates(points)?;
    if points.len() < MIN_POINTS {
        return Err(ReconstructError::TooFewPoints {
            count: points.len(),
            min: MIN_POINTS,
        });
    }
    progress::report(Phase::Reconstruction, 0.0);
    let tree = Neighbours::new(points);
    let spacing = tree.mean_distances(points, SPACING_NEIGHBOURS, SPACING_PART);
    let inlier = inliers(&spacing, options.outlier_std_ratio);
    let outliers = inlier.iter().filter(|&&k| !k).count();
    let kept: Vec<Point3> = points
        .iter()
        .zip(&inlier)
        .filter_map(|(p, &k)| k.then_some(*p))
        .collect();
    if kept.len() < MIN_POINTS {
        return Err(ReconstructError::TooFewPoints {
            count: kept.len(),
            min: MIN_POINTS,
        });
    }
    let frame = crate::geom::principal_frame(kept.iter().copied());
    let extent = frame.values[2].max(0.0).sqrt();
    if extent == 0.0 {
        return Err(ReconstructError::Degenerate {
            what: "all at one place",
        });
    }
    // The eigenvalues carry rounding of about 1e-16 of the largest, so a line off the axes
    // shows a width of about 1e-8 of its length: anything thinner than 1e-6 is a line.
    if frame.values[1].max(0.0).sqrt() <= 1e-6 * extent {
        return Err(ReconstructError::Degenerate { what: "collinear" });
    }
    // Oriented normals of the kept points: needed to tell the kinds apart (a range grid means
    // open) and for closed surfaces.
    let oriented = match options.kind {
        Some(SurfaceKind::Open) => false,
        Some(_) => true,
        None => grid.is_none(),
    }
    .then(|| oriented_normals(&kept, &frame, options.neighbours));
    progress::report(Phase::Reconstruction, MESHING_PART.from);
    let kind = match (options.kind, &oriented) {
        (Some(kind), _) => kind,
        (None, Some((_, normals))) => detect_kind(normals, &frame),
        (None, None) => SurfaceKind::Open,
    };
    let mut open_uncovered = None;
    if kind == SurfaceKind::Open {
        let mesh = open_mesh(points, grid, &inlier, &spacing, &frame, options)?;
        let uncovered = uncovered_points(&mesh, &inlier);
        // Detected as open but not a height field over its plane (a car body's sides fold
        // onto its roof in projection): the projection left its folds out; the implicit
        // surface takes any shape and leaves the open parts as holes.
        let auto = options.kind.is_none() && grid.is_none();
        if !(auto && uncovered * MAX_UNCOVERED_SHARE > kept.len()) || oriented.is_none() {
            progress::report(Phase::Reconstruction, 1.0);
            return Ok(Reconstruction {
                mesh,
                kind,
                outliers,
                inlier,
                stray_triangles: 0,
                open_uncovered: None,
            });
        }
        open_uncovered = Some(uncovered);
    }
    // Closed (detected, forced, or open in projection only) always comes with normals.
    let Some((tree, normals)) = oriented else {
        return Err(ReconstructError::NoSurface);
    };
    let (mesh, stray_triangles) = closed_mesh(&kept, &normals, &tree, &spacing, &inlier, options)?;
    progress::report(Phase::Reconstruction, 1.0);
    Ok(Reconstruction {
        mesh,
        kind: SurfaceKind::Closed,
        outliers,
        inlier,
        stray_triangles,
        open_uncovered,
    })
}

/// Inlier points of an open mesh (whose vertices are the points) that are in no triangle,
/// other than repeats of a point that is in one (a triangulation keeps one of equal points).
fn uncovered_points(mesh: &PolyMesh, inlier: &[bool]) -> usize {
    let mut used = vec![false; inlier.len()];
    for &v in mesh.raw_faces().1 {
        used[v as usize] = true;
    }
    let key = |p: &Point3| [p.x, p.y, p.z].map(f64::to_bits);
    let positions = mesh.positions();
    let covered: std::collections::HashSet<[u64; 3]> = positions
        .iter()
        .zip(&used)
        .filter(|&(_, &u)| u)
        .map(|(p, _)| key(p))
        .collect();
    (0..inlier.len())
        .filter(|&i| inlier[i] && !used[i] && !covered.contains(&key(&positions[i])))
        .count()
}

/// Which points survive statistical outlier removal (all when `ratio` is `None`).
fn inliers(spacing: &[f64], ratio: Option<f64>) -> Vec<bool> {
    let Some(ratio) = ratio else {
        return vec![true; spacing.len()];
    };
    let n = spacing.len() as f64;
    let mean = spacing.iter().sum::<f64>() / n;
    let var = spacing.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / n;
    let limit = mean + ratio * var.sqrt();
    spacing.iter().map(|&s| s <= limit).collect()
}

/// A kd-tree over `points` and their PCA normals, oriented consistently.
fn oriented_normals(
    points: &[Point3],
    frame: &crate::geom::Frame,
    k: usize,
) -> (Neighbours, Vec<Vec3>) {
    let tree = Neighbours::new(points);
    let near = normals::neighbourhoods(points, &tree, k, NEIGHBOURS_PART);
    let mut n = normals::pca_normals(points, &near, k, frame.axes[0]);
    progress::report(
        Phase::Reconstruction,
        (NEIGHBOURS_PART.to + MESHING_PART.from) / 2.0,
    );
    normals::orient(points, &mut n, &near);
    (tree, n)
}

/// Open or closed, from how the oriented normals sit against the best-fit plane.
fn detect_kind(normals: &[Vec3], frame: &crate::geom::Frame) -> SurfaceKind {
    let axis = frame.axes[0];
    let up = normals.iter().filter(|v| v.dot(axis) > 0.0).count() as f64 / normals.len() as f64;
    if up.max(1.0 - up) >= OPEN_FRACTION {
        SurfaceKind::Open
    } else {
        SurfaceKind::Closed
    }
}

fn open_mesh(
    points: &[Point3],
    grid: Option<&RangeGrid>,
    inlier: &[bool],
    spacing: &[f64],
    frame: &crate::geom::Frame,
    options: &ReconstructOptions,
) -> Result<PolyMesh, ReconstructError> {
    let tris = match grid {
        Some(g) => open::grid_triangles(g, points.len(), inlier)?,
        None => open::plane_triangles(points, inlier, frame, MESHING_PART),
    };
    let tris = open::drop_long_edges(tris, points, spacing, options.long_edge_factor);
    let tris = cleanup::manifold_part(tris, points.len(), cleanup::Pieces::Substantial);
    if tris.is_empty() {
        return Err(ReconstructError::NoSurface);
    }
    PolyMesh::try_new(points.to_vec(), tris).map_err(|_| ReconstructError::NoSurface)
}

fn closed_mesh(
    kept: &[Point3],
    normals: &[Vec3],
    tree: &Neighbours,
    spacing: &[f64],
    inlier: &[bool],
    options: &ReconstructOptions,
) -> Result<(PolyMesh, usize), ReconstructError> {
    let kept_spacing: Vec<f64> = spacing
        .iter()
        .zip(inlier)
        .filter_map(|(s, &k)| k.then_some(*s))
        .collect();
    let mut cell = options.cell_size * median(&kept_spacing);
    if cell <= 0.0 {
        // Mostly duplicated points: fall back to a hundredth of the spread.
        cell = crate::geom::principal_frame(kept.iter().copied()).values[2].sqrt() * 1e-2;
    }
    let (positions, tris) = closed::contour(kept, normals, tree, cell, BAND_CELLS, MESHING_PART);
    let (tris, strays) = closed::without_strays(&positions, tris, tree, &kept_spacing);
    let tris = cleanup::manifold_part(tris, positions.len(), cleanup::Pieces::Largest);
    if tris.is_empty() {
        return Err(ReconstructError::NoSurface);
    }
    let (positions, tris) = compact(positions, tris);
    let mesh = PolyMesh::try_new(positions, tris).map_err(|_| ReconstructError::NoSurface)?;
    Ok((without_slivers(mesh), strays))
}

/// `mesh` with the slivers marching tetrahedra leaves (contour vertices a hair apart where the
/// surface passes near a grid corner) collapsed: a QEM simplification to half the vertices
/// with no triangle-quality limit, whose cheapest collapses are exactly those short edges. A
/// later QEM to a control mesh with its quality limit is then no longer hemmed in by them (on
/// the bunny's vertices → 612: the points' rms distance to the control mesh drops from 0.75 %
/// to 0.47 % of the diagonal, as from the original mesh). Kept as is if that fails (tiny
/// meshes).
fn without_slivers(mesh: PolyMesh) -> PolyMesh {
    let options = SimplifyOptions::default().with_min_triangle_quality(0.0);
    simplify_with(&mesh, mesh.num_vertices() / SLIVER_REDUCTION, &options).unwrap_or(mesh)
}

/// Drops vertices in no triangle, renumbering the rest in order.
fn compact(positions: Vec<Point3>, tris: Vec<[u32; 3]>) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let mut remap = vec![u32::MAX; positions.len()];
    let mut out = Vec::new();
    for t in &tris {
        for &v in t {
            if remap[v as usize] == u32::MAX {
                remap[v as usize] = 0;
            }
        }
    }
    for (v, p) in positions.into_iter().enumerate() {
        if remap[v] != u32::MAX {
            remap[v] = out.len() as u32;
            out.push(p);
        }
    }
    let tris = tris
        .into_iter()
        .map(|t| t.map(|v| remap[v as usize]))
        .collect();
    (out, tris)
}
