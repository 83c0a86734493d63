use thiserror::Error;

/// Why a spline could not be built or evaluated.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum SplineError {
    /// The degree is outside the supported range.
    #[error("degree {degree} is not supported (1..={max})")]
    BadDegree {
        /// Requested degree.
        degree: usize,
        /// Largest supported degree.
        max: usize,
    },
    /// The knot vector is too short for its degree.
    #[error("{found} knots cannot carry degree {degree}: need at least {needed}")]
    TooFewKnots {
        /// Knots given.
        found: usize,
        /// Knots needed, 2 · (degree + 1).
        needed: usize,
        /// The degree.
        degree: usize,
    },
    /// A knot is NaN or infinite.
    #[error("knot {index} is not finite")]
    NonFiniteKnot {
        /// Index of the knot.
        index: usize,
    },
    /// The knots decrease somewhere.
    #[error("knots decrease at index {index}: {prev} > {next}")]
    DecreasingKnots {
        /// Index of the smaller, later knot.
        index: usize,
        /// The earlier knot.
        prev: f64,
        /// The later knot.
        next: f64,
    },
    /// The parameter domain has zero length.
    #[error("the knot vector has an empty domain [{start}, {end}]")]
    EmptyDomain {
        /// Domain start, knot `degree`.
        start: f64,
        /// Domain end, knot `len - degree - 1`.
        end: f64,
    },
    /// A knot is repeated more often than continuity allows.
    #[error(
        "knot {value} at index {index} has multiplicity {multiplicity}, more than the {limit} allowed"
    )]
    KnotMultiplicity {
        /// Index of the first copy.
        index: usize,
        /// The knot value.
        value: f64,
        /// How often it occurs.
        multiplicity: usize,
        /// The largest multiplicity allowed: degree + 1 (degree for a closed curve).
        limit: usize,
    },
    /// The number of control points (or weights) does not fit the knots and degree.
    #[error("{found} control points given where {expected} are needed")]
    ControlPointCount {
        /// Control points (or weights) given.
        found: usize,
        /// Control points needed.
        expected: usize,
    },
    /// A control point has a NaN or infinite coordinate.
    #[error("control point {index} is not finite")]
    NonFiniteControlPoint {
        /// Index of the control point.
        index: usize,
    },
    /// A NURBS weight is not a positive finite number.
    #[error("weight {index} is {value}: weights must be positive and finite")]
    BadWeight {
        /// Index of the weight.
        index: usize,
        /// The weight.
        value: f64,
    },
    /// A knot cannot be inserted: outside the domain, not finite, or already of full
    /// multiplicity.
    #[error("cannot insert knot {value}: outside the domain or already of multiplicity p")]
    BadKnotInsertion {
        /// The knot value.
        value: f64,
    },
}
