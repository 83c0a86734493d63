use thiserror::Error;

/// Why a file could not be read.
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
}
