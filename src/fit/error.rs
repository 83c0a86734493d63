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
    /// A data point repeats the one before it, so the polyline has a zero-length segment.
    #[error("data point {index} repeats the point before it")]
    DuplicatePoint {
        /// Index of the repeated point in the input.
        index: usize,
    },
    /// Bare points could not be turned into a mesh to start from.
    #[error("reconstructing a surface from the points: {0}")]
    Reconstruct(#[from] crate::cloud::ReconstructError),
    /// The spline could not be built (degree out of range, bad knots).
    #[error(transparent)]
    Spline(#[from] crate::spline::SplineError),
    /// A least-squares system has no unique solution: some control point has no data nearby.
    #[error("the least-squares system is singular at control point {index}")]
    Singular {
        /// The control point without support.
        index: usize,
    },
    /// The subdivision library rejected the control mesh.
    #[error(transparent)]
    Subdiv(#[from] crate::subdiv::SubdivError),
    /// Projecting the points to parameterise them gives no usable parameter domain.
    #[error("cannot parameterise the points: {reason}")]
    DegenerateProjection {
        /// What is degenerate, with the view direction.
        reason: String,
    },
    /// The projection used for the parameters is not one-to-one: some points lie on a
    /// fold-over (their projections coincide with other points' at a clearly different depth).
    #[error(
        "the projection is not one-to-one: {count} of {total} points lie on a fold-over \
         (first: point {first}); choose another view direction or a base surface, or exclude \
         or keep folded points"
    )]
    FoldedProjection {
        /// Folded points.
        count: usize,
        /// All points.
        total: usize,
        /// Index of the first folded point.
        first: usize,
    },
    /// The linear solver failed (the system is singular: raise the smoothing weights).
    #[error("the least-squares system cannot be solved: {reason}")]
    Solver {
        /// The solver's message.
        reason: String,
    },
}
