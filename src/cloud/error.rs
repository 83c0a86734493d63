use thiserror::Error;

/// Why a point cloud could not be turned into a mesh.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ReconstructError {
    /// Too few points to span a surface.
    #[error("{count} points are too few to build a surface: at least {min} are needed")]
    TooFewPoints {
        /// Points given (after outlier removal, if asked for).
        count: usize,
        /// The minimum.
        min: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("point {index} has a non-finite coordinate")]
    NonFinitePoint {
        /// Index of the offending point.
        index: usize,
    },
    /// A coordinate is beyond ±[`COORDINATE_LIMIT`](crate::geom::COORDINATE_LIMIT).
    #[error("point {index} has coordinate {value:e}, beyond ±3.4e38 (the largest an f32 holds)")]
    CoordinateOutOfRange {
        /// Index of the offending point.
        index: usize,
        /// The coordinate.
        value: f64,
    },
    /// The points do not span a surface: they coincide or lie on one line.
    #[error("the points are {what}: they span no surface")]
    Degenerate {
        /// What the points do instead ("all at one place", "collinear").
        what: &'static str,
    },
    /// A range-grid cell refers to a point that does not exist.
    #[error("the range grid refers to point {index}, but there are {count} points")]
    GridMismatch {
        /// The out-of-range index.
        index: u32,
        /// Number of points.
        count: usize,
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
    /// Nothing usable was left: every triangle was removed as spanning a gap.
    #[error("no triangles were left after removing long edges and non-manifold pieces")]
    NoSurface,
}

impl From<crate::geom::BadCoordinate> for ReconstructError {
    fn from(bad: crate::geom::BadCoordinate) -> ReconstructError {
        match bad {
            crate::geom::BadCoordinate::NonFinite { index } => {
                ReconstructError::NonFinitePoint { index }
            }
            crate::geom::BadCoordinate::OutOfRange { index, value } => {
                ReconstructError::CoordinateOutOfRange { index, value }
            }
        }
    }
}
