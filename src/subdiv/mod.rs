//! Subdivision surfaces (Loop, Catmull–Clark, Doo–Sabin) and exact evaluation of their limit
//! surfaces.
//!
//! The fitting engine talks to every scheme through [`LimitSurface`]: it moves control points
//! and needs, for a patch and local parameters, the limit point with derivatives, the control
//! points that influence it (the stencil), and a way to walk across patch edges.

use crate::geom::{Point3, Vec3};
use crate::mesh::{ControlMesh, MeshError, PolyMesh, TopologyError};

pub mod adaptive;
mod basis;
mod doo_sabin;
mod nearest;
mod patch;
mod refine;
mod sites;
mod step;
mod surface;
mod tessellate;
mod topo;
mod walk;

pub use nearest::newton_foot;
pub use refine::{limit_positions, quadrangulate, refine, refine_levels};
pub use surface::{side_param, SubdivSurface};
pub use tessellate::{grid_params, tessellate, Tessellation};

/// Why a subdivision surface could not be built or refined.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum SubdivError {
    /// The polygon data is invalid.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The connectivity is not an oriented manifold (with boundary).
    #[error(transparent)]
    Topology(#[from] TopologyError),
    /// The mesh has no faces.
    #[error("the control mesh has no faces")]
    NoFaces,
    /// A face has the wrong number of corners for the scheme.
    #[error("face {face} has {len} corners; {scheme:?} needs {}", if *scheme == Scheme::Loop { "triangles" } else { "quads (convert with subdiv::quadrangulate)" })]
    WrongFaceSize {
        /// The offending face.
        face: usize,
        /// Its corner count.
        len: usize,
        /// The scheme asked for.
        scheme: Scheme,
    },
    /// A patch's neighbourhood has more control points than evaluation supports (very high
    /// valence).
    #[error("patch {patch} depends on {points} control points; at most {max} are supported (reduce vertex valence)")]
    NeighbourhoodTooLarge {
        /// The patch.
        patch: usize,
        /// Control points it depends on.
        points: usize,
        /// The limit.
        max: usize,
    },
    /// The scheme's rules could not be applied around a patch (internal consistency check).
    #[error(
        "patch {patch} cannot be evaluated: its neighbourhood does not determine the limit surface"
    )]
    Unevaluable {
        /// The patch.
        patch: usize,
    },
    /// A face-flag array of local refinement does not have one flag per face.
    #[error("{flags} face flags for {faces} faces")]
    FlagCount {
        /// Flags given.
        flags: usize,
        /// Faces of the mesh.
        faces: usize,
    },
    /// Refinement would number vertices beyond the `u32` range.
    #[error("{count} control points exceed the u32 index range")]
    TooManyPoints {
        /// The vertex count that did not fit.
        count: usize,
    },
    /// An internal consistency check failed (a bug, not bad input): the message says which.
    #[error("internal error: {what}")]
    Internal {
        /// The check that failed.
        what: String,
    },
    /// The operation is not available for this scheme.
    #[error("{what} is not implemented")]
    Unsupported {
        /// What was asked for.
        what: &'static str,
    },
}

/// A subdivision scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
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
    /// Limit position at `at`, where derivatives are not needed.
    fn point(&self, at: SurfaceParam) -> Point3 {
        self.eval(at).point
    }
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

/// The limit surface of `mesh` under `scheme`, ready for fitting. Loop needs a triangle mesh,
/// Doo–Sabin takes any polygons;
/// for Catmull–Clark a mesh that is not all quads is first converted by one Catmull–Clark step
/// ([`quadrangulate`]), so its control points are then those of the converted mesh (read them
/// with [`LimitSurface::control_points`]).
pub fn build(scheme: Scheme, mesh: &PolyMesh) -> Result<Box<dyn LimitSurface>, SubdivError> {
    let control = ControlMesh::try_new(mesh)?;
    let control = if scheme == Scheme::CatmullClark && !control.is_quad_mesh() {
        quadrangulate(&control)?
    } else {
        control
    };
    Ok(Box::new(SubdivSurface::try_new(scheme, control)?))
}

macro_rules! scheme_surface {
    ($(#[$doc:meta])* $name:ident, $scheme:expr) => {
        $(#[$doc])*
        pub struct $name(SubdivSurface);

        impl $name {
            /// Builds the surface from a polygon mesh, checking its topology.
            pub fn try_new(mesh: &PolyMesh) -> Result<$name, SubdivError> {
                $name::from_control_mesh(ControlMesh::try_new(mesh)?)
            }

            /// Builds the surface from a control mesh (keeps its crease tags).
            pub fn from_control_mesh(mesh: ControlMesh) -> Result<$name, SubdivError> {
                Ok($name(SubdivSurface::try_new($scheme, mesh)?))
            }
        }

        impl std::ops::Deref for $name {
            type Target = SubdivSurface;
            fn deref(&self) -> &SubdivSurface {
                &self.0
            }
        }

        impl LimitSurface for $name {
            fn domain(&self) -> PatchDomain {
                self.0.domain()
            }
            fn num_patches(&self) -> usize {
                self.0.num_patches()
            }
            fn control_points(&self) -> &[Point3] {
                self.0.control_points()
            }
            fn set_control_points(&mut self, points: &[Point3]) {
                self.0.set_control_points(points)
            }
            fn eval(&self, at: SurfaceParam) -> LimitEval {
                self.0.eval(at)
            }
            fn stencil(&self, at: SurfaceParam, out: &mut Vec<(u32, f64)>) {
                self.0.stencil(at, out)
            }
            fn corner_weights(&self, at: SurfaceParam, out: &mut Vec<(u32, f64)>) {
                self.0.corner_weights(at, out)
            }
            fn relocate(&self, patch: u32, u: f64, v: f64) -> SurfaceParam {
                self.0.relocate(patch, u, v)
            }
        }
    };
}

scheme_surface!(
    /// Loop limit surface of a triangle control mesh: a quartic box spline on regular patches,
    /// exact local subdivision near extraordinary vertices, boundaries and creases.
    LoopSurface,
    Scheme::Loop
);
scheme_surface!(
    /// Doo–Sabin limit surface of a polygon control mesh: one patch per face corner at an
    /// interior vertex, biquadratic B-spline where the refined vertex has four quads around it,
    /// exact local subdivision around non-quad faces (whose centroids the surface interpolates).
    DooSabinSurface,
    Scheme::DooSabin
);
scheme_surface!(
    /// Catmull–Clark limit surface of a quad control mesh: bicubic B-spline patches (with
    /// phantom points at straight boundaries and creases), exact local subdivision elsewhere.
    CatmullClarkSurface,
    Scheme::CatmullClark
);
