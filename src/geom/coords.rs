//! The range of coordinates geofit takes, and the stray points it leaves out of a fit.
//!
//! Readers accept any finite number, but a coordinate such as −1e308 makes the bounding-box
//! diagonal overflow, and every tolerance (a percentage of it) with it. And scans carry stray
//! points — a reflection metres behind the object, a "no return" marker — that multiply the
//! diagonal and so loosen every tolerance by the same factor, while the fit reports success.

use super::{quantile, Point3};

/// The largest coordinate magnitude geofit takes: the largest an `f32` holds (3.4e38), since
/// the page renders, and GLB and STL store, positions as `f32`. Inside it the fit's maths stays
/// clear of `f64` overflow: QEM's quadrics and their determinants reach sixth powers of the
/// data's size; the bundled sample fits alike scaled by 1e-30 and by 1e30
/// (`tests/fit_strays.rs`).
pub const COORDINATE_LIMIT: f64 = f32::MAX as f64;

/// The first point geofit cannot take, and why.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BadCoordinate {
    /// Point `index` has a NaN or infinite coordinate.
    NonFinite {
        /// Index of the point.
        index: usize,
    },
    /// Point `index` has coordinate `value`, beyond ±[`COORDINATE_LIMIT`].
    OutOfRange {
        /// Index of the point.
        index: usize,
        /// The coordinate.
        value: f64,
    },
}

/// Checks that every coordinate of `points` is finite and within ±[`COORDINATE_LIMIT`].
pub fn check_coordinates(points: &[Point3]) -> Result<(), BadCoordinate> {
    for (index, p) in points.iter().enumerate() {
        for value in p.to_array() {
            if !value.is_finite() {
                return Err(BadCoordinate::NonFinite { index });
            }
            if value.abs() > COORDINATE_LIMIT {
                return Err(BadCoordinate::OutOfRange { index, value });
            }
        }
    }
    Ok(())
}

/// Fewer points than this have no bulk to stray from.
const MIN_POINTS: usize = 20;

/// The share of the points whose distance from the median defines the bulk's radius.
const BULK_SHARE: f64 = 0.99;

/// A point is a stray when an empty shell this many bulk radii thick separates it from the
/// bulk. On every mesh of the shared data and corpus the farthest point lies within 1.11 bulk
/// radii of the median with no gap at all; a stray a diagonal away leaves a gap of several.
const GAP_RADII: f64 = 1.0;

/// Stray points of `points` (finite coordinates within [`COORDINATE_LIMIT`]), in index order:
/// those beyond the first empty shell, at least one bulk radius thick, around the bulk.
///
/// The bulk is centred on the coordinate-wise median, and its radius is the distance from it
/// within which 99 % of the points lie, so up to 1 % of strays cannot move either. Sorting the
/// points beyond that radius by distance, the first gap wider than the radius ends the bulk:
/// a long, thin part of the object (a handle, an antenna) continues it without a gap and
/// stays, a point a diagonal away does not. Up to 1 % of the points can be found stray.
pub fn find_strays(points: &[Point3]) -> Vec<u32> {
    if points.len() < MIN_POINTS {
        return Vec::new();
    }
    let centre = median(points);
    let dist: Vec<f64> = points.iter().map(|p| p.distance(centre)).collect();
    let radius = quantile(&dist, BULK_SHARE);
    if !(radius > 0.0 && radius.is_finite()) {
        return Vec::new();
    }
    let mut beyond: Vec<f64> = dist.iter().copied().filter(|&d| d > radius).collect();
    beyond.sort_unstable_by(f64::total_cmp);
    let mut edge = radius;
    for &d in &beyond {
        if d - edge > GAP_RADII * radius {
            break;
        }
        edge = d;
    }
    (0..points.len() as u32)
        .filter(|&i| dist[i as usize] > edge)
        .collect()
}

/// The coordinate-wise median of `points` (non-empty).
fn median(points: &[Point3]) -> Point3 {
    let axis = |k: usize| quantile(&points.iter().map(|p| p[k]).collect::<Vec<_>>(), 0.5);
    Point3::new(axis(0), axis(1), axis(2))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points on a unit sphere, spread by the golden angle.
    fn sphere(n: usize) -> Vec<Point3> {
        (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let phi = i as f64 * 2.399_963_229_728_653;
                Point3::new(r * phi.cos(), r * phi.sin(), z)
            })
            .collect()
    }

    #[test]
    fn coordinates_beyond_the_limit_or_not_finite_are_named() {
        let mut p = sphere(4);
        assert_eq!(check_coordinates(&p), Ok(()));
        p[2].y = -1e308;
        assert_eq!(
            check_coordinates(&p),
            Err(BadCoordinate::OutOfRange {
                index: 2,
                value: -1e308
            })
        );
        p[1].z = f64::NAN;
        assert_eq!(
            check_coordinates(&p),
            Err(BadCoordinate::NonFinite { index: 1 })
        );
        p[1].z = COORDINATE_LIMIT;
        p[2].y = -COORDINATE_LIMIT;
        assert_eq!(check_coordinates(&p), Ok(()));
    }

    #[test]
    fn points_far_from_the_bulk_are_strays_and_the_bulk_is_not() {
        let mut p = sphere(500);
        assert!(find_strays(&p).is_empty());
        p[7] = Point3::new(50.0, 0.0, 0.0);
        p[300] = Point3::new(0.0, -f32::MAX as f64, 0.0);
        p[301] = Point3::new(0.0, 0.0, 4.0);
        assert_eq!(find_strays(&p), vec![7, 300, 301]);
    }

    #[test]
    fn a_long_thin_part_continues_the_bulk() {
        // A sphere with a rod of 30 points reaching to 6 radii: no gap, so no strays, though
        // the rod's end is far beyond the bulk radius.
        let mut p = sphere(3000);
        p.extend((1..=30).map(|k| Point3::new(1.0 + k as f64 / 6.0, 0.0, 0.0)));
        assert!(find_strays(&p).is_empty());
    }

    #[test]
    fn too_few_or_coincident_points_have_no_strays() {
        let mut p = sphere(10);
        p[0] = Point3::splat(1e6);
        assert!(find_strays(&p).is_empty());
        let mut same = vec![Point3::ONE; 100];
        same[0] = Point3::splat(9.0);
        assert!(find_strays(&same).is_empty());
    }
}
