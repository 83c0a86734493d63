use crate::mesh::MeshError;
use thiserror::Error;

/// Why a mesh could not be simplified to the requested size.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum SimplifyError {
    /// The input has no faces (a bare point cloud): there is no surface to simplify.
    #[error("the mesh has no faces to simplify (a point cloud needs reconstruction first)")]
    NoFaces,
    /// The target is below the smallest mesh simplification keeps (a tetrahedron).
    #[error("target of {target} vertices is too small: at least {min} are needed")]
    TargetTooSmall {
        /// The requested vertex count.
        target: usize,
        /// The smallest target accepted.
        min: usize,
    },
    /// The target exceeds the number of vertices the faces use.
    #[error("target of {target} vertices exceeds the {available} vertices used by faces")]
    TargetTooLarge {
        /// The requested vertex count.
        target: usize,
        /// Vertices referenced by at least one non-degenerate face.
        available: usize,
    },
    /// Every remaining collapse would break the topology (or fold the surface), so the target
    /// cannot be reached: e.g. many small components, each already minimal.
    #[error("cannot go below {reached} vertices (target {target}) without breaking the surface")]
    TargetUnreachable {
        /// The requested vertex count.
        target: usize,
        /// The vertex count where no valid collapse was left.
        reached: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFiniteVertex {
        /// Index of the offending vertex.
        vertex: usize,
    },
    /// An option is out of its range.
    #[error("option `{name}` = {value} is out of range: {expected}")]
    InvalidOption {
        /// The option's name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The accepted range.
        expected: &'static str,
    },
    /// Building the output mesh failed (an internal invariant was broken).
    #[error("output mesh is invalid: {0}")]
    Mesh(#[from] MeshError),
}
