//! Subdivision surfaces (Loop, Catmull–Clark, Doo–Sabin) and exact evaluation of their limit
//! surfaces.
//!
//! The fitting engine talks to every scheme through [`LimitSurface`]: it moves control points
//! and needs, for a patch and local parameters, the limit point with derivatives, the control
//! points that influence it (the stencil), and a way to walk across patch edges.

use crate::geom::{Point3, Vec3};

/// A subdivision scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Scheme {
    /// Loop: triangle meshes, quartic box-spline limit.
    Loop,
    /// Catmull–Clark: quad meshes, bicubic B-spline limit.
    CatmullClark,
    /// Doo–Sabin: polygon meshes, biquadratic B-spline limit.
    DooSabin,
}

/// Parameter domain of every patch of a surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PatchDomain {
    /// The triangle `u >= 0, v >= 0, u + v <= 1`.
    Triangle,
    /// The unit square `[0, 1]²`.
    Square,
}

/// A location on the limit surface: a patch and its local parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceParam {
    /// Patch index.
    pub patch: u32,
    /// First local parameter.
    pub u: f64,
    /// Second local parameter.
    pub v: f64,
}

/// Limit-surface position with first and second derivatives at a [`SurfaceParam`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LimitEval {
    /// S(u, v).
    pub point: Point3,
    /// ∂S/∂u.
    pub du: Vec3,
    /// ∂S/∂v.
    pub dv: Vec3,
    /// ∂²S/∂u².
    pub duu: Vec3,
    /// ∂²S/∂u∂v.
    pub duv: Vec3,
    /// ∂²S/∂v².
    pub dvv: Vec3,
}

/// The contract between a subdivision scheme's limit surface and the fitting engine.
///
/// Moving control points with [`LimitSurface::set_control_points`] keeps the connectivity, so
/// implementations precompute everything topological once (stencils, eigen-structures) and
/// evaluation after a move costs only the weighted sums.
pub trait LimitSurface {
    /// Shape of every patch's parameter domain.
    fn domain(&self) -> PatchDomain;
    /// Number of patches.
    fn num_patches(&self) -> usize;
    /// Current control points.
    fn control_points(&self) -> &[Point3];
    /// Replaces the control points (same count, same connectivity).
    fn set_control_points(&mut self, points: &[Point3]);
    /// Limit position and derivatives at `at`.
    fn eval(&self, at: SurfaceParam) -> LimitEval;
    /// Appends `(control index, weight)` with `S(at) = Σ weight · P[index]` to `out`.
    fn stencil(&self, at: SurfaceParam, out: &mut Vec<(u32, f64)>);
    /// Appends the patent's local weights of `at` (SPEC §1.6) to `out`: barycentric (triangle)
    /// or bilinear (quad) coordinates with respect to the control vertices at the corners of the
    /// control face that contains `at`.
    fn corner_weights(&self, at: SurfaceParam, out: &mut Vec<(u32, f64)>);
    /// Maps parameters that left `patch`'s domain (after a Newton step) onto the patch that holds
    /// them, crossing edges as needed, and clamps onto the domain at open boundaries.
    fn relocate(&self, patch: u32, u: f64, v: f64) -> SurfaceParam;
}
