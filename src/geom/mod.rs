//! Geometric primitives in f64: points, vectors, axis-aligned boxes, and the closest-point
//! query every shape answers.

mod aabb;
mod eigen;
mod nearest;

pub use aabb::Aabb;
pub use eigen::symmetric_eigen;
pub use nearest::{ClosestPoint, Nearest, NewtonOptions};

/// A point in 3D space (f64). An alias of glam's `DVec3`, so points and vectors share maths.
pub type Point3 = glam::DVec3;
/// A vector in 3D space (f64).
pub type Vec3 = glam::DVec3;
