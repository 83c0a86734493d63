//! Open, single-view scans: triangulate by the scanner grid, or by a 2D Delaunay triangulation
//! of the points projected onto their best-fit plane, then cut the triangles that span holes
//! or run outside the scanned outline (edges long against the local point spacing).

use super::ReconstructError;
use crate::geom::Frame;
use crate::geom::Point3;
use crate::io::RangeGrid;
use crate::progress::{self, Part};
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

/// Triangles of the range grid, checked against the point count.
pub(super) fn grid_triangles(
    grid: &RangeGrid,
    count: usize,
    inlier: &[bool],
) -> Result<Vec<[u32; 3]>, ReconstructError> {
    let tris = grid.triangles();
    if let Some(&index) = tris.iter().flatten().find(|&&i| i as usize >= count) {
        return Err(ReconstructError::GridMismatch { index, count });
    }
    Ok(tris
        .into_iter()
        .filter(|t| t.iter().all(|&i| inlier[i as usize]))
        .collect())
}

/// A point of the cloud in the plane, with its index.
struct Site {
    at: Point2<f64>,
    index: u32,
}

impl HasPosition for Site {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.at
    }
}

/// Delaunay triangles of the inlier points projected onto the plane of `frame` (its two
/// major axes), wound counter-clockwise seen from the plane's normal (the minor axis).
/// Reports its progress as `part`.
pub(super) fn plane_triangles(
    points: &[Point3],
    inlier: &[bool],
    frame: &Frame,
    part: Part,
) -> Vec<[u32; 3]> {
    let (u, v) = (frame.axes[2], frame.axes[1]);
    // Orient (u, v, normal) right-handed so faces wind counter-clockwise about the normal.
    let v = if u.cross(v).dot(frame.axes[0]) < 0.0 {
        -v
    } else {
        v
    };
    // Bulk loading (spade orders the sites spatially first) took the Delaunay triangulation of
    // a 500K-point sheet from 6.3 s of point-by-point insertion to 0.3 s. The stable variant keeps the sites in input
    // order and, of duplicates, the first; sites spade cannot take (beyond its coordinate
    // range) are left out, as a failed insertion left them out.
    let mut sites = Vec::with_capacity(points.len());
    for (i, &p) in points.iter().enumerate() {
        if i % progress::BATCH == 0 {
            part.count(i, 4 * points.len());
        }
        let d = p - frame.centroid;
        let at = Point2::new(d.dot(u), d.dot(v));
        if inlier[i] && spade::validate_vertex(&at).is_ok() {
            sites.push(Site {
                at,
                index: i as u32,
            });
        }
    }
    let Ok(dt) = DelaunayTriangulation::<Site>::bulk_load_stable(sites) else {
        return Vec::new();
    };
    part.count(1, 1);
    dt.inner_faces()
        .map(|f| f.vertices().map(|h| h.data().index))
        .collect()
}

/// `tris` without triangles having an edge longer than `factor` times the local spacing of
/// its ends (the larger of the two).
pub(super) fn drop_long_edges(
    tris: Vec<[u32; 3]>,
    points: &[Point3],
    spacing: &[f64],
    factor: f64,
) -> Vec<[u32; 3]> {
    tris.into_iter()
        .filter(|t| {
            (0..3).all(|k| {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                points[a].distance(points[b]) <= factor * spacing[a].max(spacing[b])
            })
        })
        .collect()
}
