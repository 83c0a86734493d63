use crate::mesh::{SimplifyError, TopologyError};
use thiserror::Error;

/// Why a fit could not be set up or continued. Variants about the input or the options carry
/// the offending index or option name; [`FitError::Internal`] marks a failed consistency check
/// (a bug, not bad input).
///
/// ```
/// use geofit::fit::{FitError, FitSpec, Scheme};
///
/// let spec = FitSpec::new(Scheme::Loop).with_tol_max(Some(-1.0));
/// match spec.validate() {
///     Err(FitError::InvalidOption { name, .. }) => assert_eq!(name, "tolMax"),
///     other => panic!("{other:?}"),
/// }
/// ```
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum FitError {
    /// There are too few data points for the requested surface or curve.
    ///
    /// ```
    /// use geofit::fit::{CurveFitOptions, CurveFitter, FitError};
    /// use geofit::geom::Point3;
    /// let two = [Point3::ZERO, Point3::X];
    /// let err = CurveFitter::try_new(&two, CurveFitOptions::default()).err();
    /// assert!(matches!(err, Some(FitError::TooFewPoints { found: 2, .. })));
    /// ```
    #[error("too few data points: {found}, need at least {needed}")]
    TooFewPoints {
        /// Points given.
        found: usize,
        /// Points needed.
        needed: usize,
    },
    /// Gridded data with fewer rows than a skinned surface needs.
    #[error("too few rows: {found}, need at least {needed}")]
    TooFewRows {
        /// Rows found.
        found: usize,
        /// Rows needed.
        needed: usize,
    },
    /// Gridded data whose rows differ in length: a skinned surface needs one point per
    /// column in every row.
    #[error("row {row} has {found} points, the first row {expected}")]
    RaggedRows {
        /// Index of the first row of another length.
        row: usize,
        /// Its points.
        found: usize,
        /// Points of the first row.
        expected: usize,
    },
    /// An option is out of its valid range.
    ///
    /// ```
    /// use geofit::fit::{FitError, SubdivFitOptions};
    /// let err = SubdivFitOptions::default().with_max_iter(0).validate();
    /// assert!(matches!(err, Err(FitError::InvalidOption { name: "maxIter", .. })));
    /// ```
    #[error("option {name}: {reason}")]
    InvalidOption {
        /// The option, as [`crate::fit::FitSpec`] names it (camelCase).
        name: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// An option was given that the chosen scheme (and method) does not use.
    ///
    /// ```
    /// use geofit::fit::{FitError, FitSpec, Scheme};
    /// let err = FitSpec::new(Scheme::Loop).with_degree(Some(3)).validate();
    /// assert!(matches!(err, Err(FitError::NotApplicable { name: "degree", .. })));
    /// ```
    #[error("option {name} does not apply to scheme {scheme}{}", method.map_or(String::new(), |m| format!(" with method {m}")))]
    NotApplicable {
        /// The option.
        name: &'static str,
        /// The scheme chosen.
        scheme: crate::fit::Scheme,
        /// The method chosen, when the option depends on it.
        method: Option<crate::fit::Method>,
    },
    /// The data has no faces to start a subdivision fit from, and no control mesh was given.
    ///
    /// ```
    /// use geofit::fit::{initial_control, FitError};
    /// use geofit::geom::Point3;
    /// use geofit::mesh::PolyMesh;
    /// let cloud = PolyMesh::try_new(vec![Point3::ZERO; 3], Vec::<[u32; 3]>::new()).unwrap();
    /// let loop_scheme = geofit::subdiv::Scheme::Loop;
    /// assert_eq!(initial_control(&cloud, None, None, loop_scheme), Err(FitError::NoFaces));
    /// ```
    #[error("invalid control mesh: the data has no faces; reconstruct a mesh from the points or give a control mesh")]
    NoFaces,
    /// The control mesh (given, or made by simplification) has no faces.
    ///
    /// ```
    /// use geofit::fit::FitError;
    /// assert_eq!(
    ///     FitError::EmptyControlMesh.to_string(),
    ///     "invalid control mesh: the control mesh has no faces"
    /// );
    /// ```
    #[error("invalid control mesh: the control mesh has no faces")]
    EmptyControlMesh,
    /// The control mesh is not a valid oriented manifold for subdivision.
    ///
    /// ```
    /// use geofit::fit::{surface_of, FitError};
    /// use geofit::geom::Point3;
    /// use geofit::mesh::PolyMesh;
    /// use geofit::subdiv::Scheme;
    /// // Two triangles that run their shared edge the same way.
    /// let p = vec![Point3::ZERO, Point3::X, Point3::Y, Point3::ONE];
    /// let mesh = PolyMesh::try_new(p, vec![[0, 1, 2], [0, 1, 3]]).unwrap();
    /// let err = surface_of(Scheme::Loop, &mesh, &[]).err();
    /// assert!(matches!(err, Some(FitError::ControlMesh(_))), "{err:?}");
    /// ```
    #[error("invalid control mesh: {0}")]
    ControlMesh(#[from] TopologyError),
    /// QEM simplification could not make the initial control mesh.
    ///
    /// ```
    /// use geofit::fit::FitError;
    /// use geofit::mesh::SimplifyError;
    /// let e: FitError = SimplifyError::NoFaces.into();
    /// assert!(e.to_string().starts_with("invalid control mesh: simplification: "));
    /// ```
    #[error("invalid control mesh: simplification: {0}")]
    Simplify(#[from] SimplifyError),
    /// The limit surface has no finite point near a data point (a degenerate control mesh).
    ///
    /// ```
    /// use geofit::fit::FitError;
    /// let e = FitError::NoSurfaceNear { point: 7 };
    /// assert_eq!(e.to_string(), "the limit surface has no finite point near data point 7");
    /// ```
    #[error("the limit surface has no finite point near data point {point}")]
    NoSurfaceNear {
        /// The data point.
        point: usize,
    },
    /// A data point has a NaN or infinite coordinate.
    ///
    /// ```
    /// use geofit::fit::{CurveFitOptions, CurveFitter, FitError};
    /// use geofit::geom::Point3;
    /// let pts = [Point3::ZERO, Point3::X, Point3::NAN, Point3::Y, Point3::Z];
    /// let err = CurveFitter::try_new(&pts, CurveFitOptions::default()).err();
    /// assert_eq!(err, Some(FitError::NonFinitePoint { index: 2 }));
    /// ```
    #[error("data point {index} has a non-finite coordinate")]
    NonFinitePoint {
        /// Index of the point in the data.
        index: usize,
    },
    /// A data point has a coordinate beyond ±[`COORDINATE_LIMIT`](crate::geom::COORDINATE_LIMIT).
    ///
    /// ```
    /// use geofit::fit::{CurveFitOptions, CurveFitter, FitError};
    /// use geofit::geom::Point3;
    /// let pts = [Point3::ZERO, Point3::X, Point3::new(0.0, 1e300, 0.0), Point3::Y];
    /// let err = CurveFitter::try_new(&pts, CurveFitOptions::default()).err();
    /// assert_eq!(err, Some(FitError::CoordinateOutOfRange { index: 2, value: 1e300 }));
    /// ```
    #[error(
        "data point {index} has coordinate {value:e}, beyond ±3.4e38 (the largest an f32 holds)"
    )]
    CoordinateOutOfRange {
        /// Index of the point in the data.
        index: usize,
        /// The coordinate.
        value: f64,
    },
    /// A data point repeats the one before it, so the polyline has a zero-length segment.
    ///
    /// ```
    /// use geofit::fit::{CurveFitOptions, CurveFitter, FitError};
    /// use geofit::geom::Point3;
    /// let pts = [Point3::ZERO, Point3::X, Point3::X, Point3::Y, Point3::Z];
    /// let err = CurveFitter::try_new(&pts, CurveFitOptions::default()).err();
    /// assert_eq!(err, Some(FitError::DuplicatePoint { index: 2 }));
    /// ```
    #[error("data point {index} repeats the point before it")]
    DuplicatePoint {
        /// Index of the repeated point in the input.
        index: usize,
    },
    /// Bare points could not be turned into a mesh to start from.
    ///
    /// ```
    /// use geofit::fit::{FitData, FitError, FitSpec, Scheme};
    /// use geofit::geom::Point3;
    /// use geofit::mesh::PolyMesh;
    /// let two = PolyMesh::from_points(vec![Point3::ZERO, Point3::X]).unwrap();
    /// let err = FitSpec::new(Scheme::Loop).build(&FitData::points(&two)).err();
    /// assert!(matches!(err, Some(FitError::Reconstruct(_))));
    /// ```
    #[error("reconstructing a surface from the points: {0}")]
    Reconstruct(#[from] crate::cloud::ReconstructError),
    /// The spline could not be built (degree out of range, bad knots).
    ///
    /// ```
    /// use geofit::fit::{least_squares_curve, FitError};
    /// use geofit::geom::Point3;
    /// use geofit::spline::BSplineCurve;
    /// let c = BSplineCurve::try_new(1, vec![0.0, 0.0, 1.0, 1.0], vec![Point3::ZERO, Point3::X]);
    /// let line = c.unwrap();
    /// let err = least_squares_curve(&line, &[Point3::ZERO], &[0.0, 1.0]).err();
    /// assert!(matches!(err, Some(FitError::InvalidOption { name: "params", .. })));
    /// let e: FitError = geofit::spline::SplineError::NonFiniteKnot { index: 0 }.into();
    /// assert!(matches!(e, FitError::Spline(_)));
    /// ```
    #[error(transparent)]
    Spline(#[from] crate::spline::SplineError),
    /// A least-squares system has no unique solution: some control point has no data nearby.
    ///
    /// ```
    /// use geofit::fit::FitError;
    /// let e = FitError::Singular { index: 4 };
    /// assert_eq!(e.to_string(), "the least-squares system is singular at control point 4");
    /// ```
    #[error("the least-squares system is singular at control point {index}")]
    Singular {
        /// The control point without support.
        index: usize,
    },
    /// The subdivision library rejected the control mesh or a refinement of it.
    ///
    /// ```
    /// use geofit::fit::{surface_of, FitError};
    /// use geofit::geom::Point3;
    /// use geofit::mesh::PolyMesh;
    /// use geofit::subdiv::Scheme;
    /// let quad = PolyMesh::try_new(
    ///     vec![Point3::ZERO, Point3::X, Point3::ONE, Point3::Y],
    ///     vec![vec![0u32, 1, 2, 3]],
    /// )
    /// .unwrap();
    /// let err = surface_of(Scheme::Loop, &quad, &[]).err();
    /// assert!(matches!(err, Some(FitError::Subdiv(_))), "{err:?}");
    /// ```
    #[error(transparent)]
    Subdiv(#[from] crate::subdiv::SubdivError),
    /// Projecting the points to parameterise them gives no usable parameter domain.
    ///
    /// ```
    /// use geofit::fit::{FitError, LsqSurfaceFitter, LsqSurfaceOptions};
    /// use geofit::geom::Point3;
    /// let line: Vec<Point3> = (0..50).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
    /// let err = LsqSurfaceFitter::try_new(&line, LsqSurfaceOptions::default()).err();
    /// assert!(matches!(err, Some(FitError::DegenerateProjection { .. })), "{err:?}");
    /// ```
    #[error("cannot parameterise the points: {reason}")]
    DegenerateProjection {
        /// What is degenerate, with the view direction.
        reason: String,
    },
    /// The projection used for the parameters is not one-to-one: some points lie on a
    /// fold-over (their projections coincide with other points' at a clearly different depth).
    ///
    /// ```
    /// use geofit::fit::FitError;
    /// let e = FitError::FoldedProjection { count: 3, total: 100, first: 17 };
    /// assert!(e.to_string().starts_with("the projection is not one-to-one: 3 of 100 points"));
    /// ```
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
    ///
    /// ```
    /// use geofit::fit::FitError;
    /// let e = FitError::Solver { reason: "not positive definite".into() };
    /// assert!(e.to_string().ends_with("not positive definite"));
    /// ```
    #[error("the least-squares system cannot be solved: {reason}")]
    Solver {
        /// The solver's message.
        reason: String,
    },
    /// An internal consistency check failed: a bug, not a problem of the input.
    ///
    /// ```
    /// use geofit::fit::FitError;
    /// let e = FitError::Internal { what: "a check".into() };
    /// assert_eq!(e.to_string(), "internal error: a check");
    /// ```
    #[error("internal error: {what}")]
    Internal {
        /// The check that failed.
        what: String,
    },
}

impl From<crate::geom::BadCoordinate> for FitError {
    fn from(bad: crate::geom::BadCoordinate) -> FitError {
        match bad {
            crate::geom::BadCoordinate::NonFinite { index } => FitError::NonFinitePoint { index },
            crate::geom::BadCoordinate::OutOfRange { index, value } => {
                FitError::CoordinateOutOfRange { index, value }
            }
        }
    }
}
