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
}
