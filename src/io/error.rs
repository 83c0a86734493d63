use super::Format;
use crate::mesh::MeshError;
use std::fmt;
use thiserror::Error;

/// Where in a file something went wrong: a 1-based line for text, a byte offset for binary data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Location {
    /// 1-based line number in a text file or text header.
    Line(usize),
    /// 0-based byte offset from the start of the file.
    Byte(usize),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(n) => write!(f, "line {n}"),
            Location::Byte(n) => write!(f, "byte {n}"),
        }
    }
}

/// Why a file could not be read. Every variant that concerns file content names the format and
/// the line or byte offset.
///
/// ```
/// use geofit::io::{read_bytes, ReadError};
/// let err = read_bytes(b"v 1 2 zz\n", Some("a.obj")).unwrap_err();
/// assert!(matches!(err, ReadError::Syntax { .. }));
/// assert_eq!(err.to_string(), "OBJ line 1: expected a number, found 'zz'");
/// ```
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ReadError {
    /// The input has no bytes.
    #[error("the file is empty")]
    Empty,
    /// The content matches no supported format.
    #[error("unknown file format: expected PLY, OBJ, STL or XYZ/CSV/PTS point text")]
    UnknownFormat,
    /// The operating system refused to read the file.
    #[error("cannot read the file: {0}")]
    Io(String),
    /// The content breaks the format's grammar (bad keyword, text in a numeric field, …).
    #[error("{format} {at}: {message}")]
    Syntax {
        /// The format being parsed.
        format: Format,
        /// Where the problem is.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// The file ends before the data its header or structure promises.
    #[error("{format} {at}: file ends early: {message}")]
    Truncated {
        /// The format being parsed.
        format: Format,
        /// Where the data ran out (or where the promise was made).
        at: Location,
        /// What was still expected.
        message: String,
    },
    /// A coordinate is NaN or infinite.
    #[error("{format} {at}: coordinate is not a finite number")]
    NonFinite {
        /// The format being parsed.
        format: Format,
        /// Where the coordinate is.
        at: Location,
    },
    /// A face, strip, grid cell or line refers to a vertex that does not exist.
    #[error("{format} {at}: vertex index {index} is out of range (the file has {count} vertices)")]
    IndexOutOfRange {
        /// The format being parsed.
        format: Format,
        /// Where the index is.
        at: Location,
        /// The index as written in the file (OBJ: 1-based or negative).
        index: i64,
        /// Number of vertices available.
        count: usize,
    },
    /// The file parses but holds no points.
    #[error("{format}: the file has no points")]
    NoPoints {
        /// The format being parsed.
        format: Format,
    },
    /// The parsed data does not form a valid mesh.
    #[error("invalid mesh: {0}")]
    Mesh(#[from] MeshError),
}
