//! Geometric primitives in f64: points, vectors, axis-aligned boxes, and the closest-point
//! query every shape answers.

mod aabb;
mod coords;
mod eigen;
mod nearest;
mod order;
mod prefetch;

pub use aabb::Aabb;
pub use coords::{check_coordinates, find_strays, BadCoordinate, COORDINATE_LIMIT};
pub use eigen::{principal_frame, symmetric_eigen, Frame};
pub use nearest::{ClosestPoint, Nearest, NewtonOptions};
pub(crate) use order::{median, quantile};
pub(crate) use prefetch::{prefetch, prefetch_slice};

/// A point in 3D space (f64). An alias of glam's `DVec3`, so points and vectors share maths.
pub type Point3 = glam::DVec3;
/// A vector in 3D space (f64).
pub type Vec3 = glam::DVec3;

/// Per vertex, the sum of the (unnormalised) normals of its triangles: each weighs by twice its
/// area. Callers normalise as their format needs (a vertex on no triangle sums to zero).
pub(crate) fn area_weighted_normal_sums(positions: &[Point3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sums = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &v in t {
            sums[v as usize] += n;
        }
    }
    sums
}
