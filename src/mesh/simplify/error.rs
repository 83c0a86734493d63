use crate::mesh::MeshError;
use thiserror::Error;

/// Why a mesh could not be simplified.
///
/// ```
/// use geofit::mesh::{simplify, PolyMesh, SimplifyError};
///
/// let cloud = PolyMesh::from_points(vec![geofit::geom::Point3::ZERO; 5])?;
/// assert_eq!(simplify(&cloud, 4), Err(SimplifyError::NoFaces));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum SimplifyError {
    /// The input has no faces (a bare point cloud), or none that repair could keep: there is
    /// no surface to simplify.
    #[error("the mesh has no faces to simplify (a point cloud needs reconstruction first)")]
    NoFaces,
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
    /// Repairing or rebuilding the mesh failed (it outgrew `u32` indexing).
    #[error("mesh is invalid: {0}")]
    Mesh(#[from] MeshError),
}
