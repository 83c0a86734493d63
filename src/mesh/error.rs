use thiserror::Error;

/// Why a mesh was rejected.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum MeshError {
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFiniteVertex {
        /// Index of the offending vertex.
        vertex: usize,
    },
    /// A vertex coordinate is finite but beyond ±[`COORDINATE_LIMIT`](crate::geom::COORDINATE_LIMIT).
    #[error(
        "vertex {vertex} has coordinate {value:e}, beyond ±3.4e38 (the largest an f32 holds; \
         geofit renders and stores positions as f32)"
    )]
    CoordinateOutOfRange {
        /// Index of the offending vertex.
        vertex: usize,
        /// The coordinate.
        value: f64,
    },
    /// A face refers to a vertex that does not exist.
    #[error("face {face} refers to vertex {index}, but the mesh has {vertex_count} vertices")]
    IndexOutOfRange {
        /// Index of the offending face.
        face: usize,
        /// The out-of-range vertex index.
        index: u64,
        /// Number of vertices in the mesh.
        vertex_count: usize,
    },
    /// A face has fewer than three vertices.
    #[error("face {face} has {len} vertices; a face needs at least 3")]
    FaceTooSmall {
        /// Index of the offending face.
        face: usize,
        /// Its vertex count.
        len: usize,
    },
    /// The mesh has more vertices or face corners than a `u32` index can address.
    #[error("mesh too large: {what} exceeds u32 indexing")]
    TooLarge {
        /// What overflowed.
        what: &'static str,
    },
    /// An option of a mesh operation is out of its range.
    #[error("option {name}: {reason}")]
    InvalidOption {
        /// The option.
        name: &'static str,
        /// Why it is rejected.
        reason: String,
    },
}

impl From<crate::geom::BadCoordinate> for MeshError {
    fn from(bad: crate::geom::BadCoordinate) -> MeshError {
        match bad {
            crate::geom::BadCoordinate::NonFinite { index } => {
                MeshError::NonFiniteVertex { vertex: index }
            }
            crate::geom::BadCoordinate::OutOfRange { index, value } => {
                MeshError::CoordinateOutOfRange {
                    vertex: index,
                    value,
                }
            }
        }
    }
}
