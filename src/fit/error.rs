use thiserror::Error;

/// Why a fit could not be set up or continued.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum FitError {
    /// There are too few data points for the requested surface or curve.
    #[error("too few data points: {found}, need at least {needed}")]
    TooFewPoints {
        /// Points given.
        found: usize,
        /// Points needed.
        needed: usize,
    },
    /// An option is out of its valid range.
    #[error("invalid option {name}: {reason}")]
    InvalidOption {
        /// Option name as the user spells it.
        name: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// The control mesh cannot be used by the scheme or the refinement (wrong face arity,
    /// non-manifold or inconsistently oriented edges, ...).
    #[error("invalid control mesh: {reason}")]
    ControlMesh {
        /// What is wrong, with the offending face or vertex.
        reason: String,
    },
    /// A data point has a NaN or infinite coordinate.
    #[error("data point {index} has a non-finite coordinate")]
    NonFinitePoint {
        /// Index of the point in the data.
        index: usize,
    },
}
