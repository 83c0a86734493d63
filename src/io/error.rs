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
    /// A numbered part of a structured file: `("accessor", 3)` in glTF, `("scan", 1)` in E57
    /// or PTX. Used where a byte offset would not help the user find the problem (JSON
    /// objects, a library-decoded section) but the part's index does.
    Item(&'static str, usize),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(n) => write!(f, "line {n}"),
            Location::Byte(n) => write!(f, "byte {n}"),
            Location::Item(kind, n) => write!(f, "{kind} {n}"),
        }
    }
}

/// Why a file could not be read. Every variant that concerns file content names the format and
/// the line or byte offset.
///
/// ```
/// use geofit::io::{read_bytes, read_path, ReadError};
/// let msg = |bytes: &[u8]| read_bytes(bytes, None).unwrap_err().to_string();
/// assert_eq!(msg(b""), "the file is empty");
/// assert!(msg(b"\x00\x01").starts_with("unknown file format"));
/// assert_eq!(msg(b"v 1 2 zz\n"), "OBJ line 1: expected a number, found 'zz'");
/// assert_eq!(msg(b"v 1 2 3\nf 1 2 4\n"), "OBJ line 2: vertex index 4 is out of range (the file has 1 vertices)");
/// assert_eq!(msg(b"1 2 3\n4 nan 6\n"), "XYZ line 2: coordinate is not a finite number");
/// assert_eq!(
///     msg(b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n\0\0\0\0\0\0\0"),
///     "PLY byte 102: file ends early: while reading property 'y' of vertex 0 (of 1)"
/// );
/// assert_eq!(read_bytes(b"# only a comment\n", Some("a.obj")).unwrap_err().to_string(), "OBJ: the file has no points");
/// assert!(matches!(read_path("/no/such/file.ply".as_ref()), Err(ReadError::Io(_))));
/// let gltf = br#"{"asset":{"version":"2.0"},"extensionsRequired":["KHR_draco_mesh_compression"]}"#;
/// assert_eq!(msg(gltf), "glTF extensionsRequired 0: not supported: the mesh data is compressed with KHR_draco_mesh_compression");
/// let external = br#"{"asset":{"version":"2.0"},"buffers":[{"uri":"a.bin","byteLength":12}],
///     "bufferViews":[{"buffer":0,"byteLength":12}],
///     "accessors":[{"bufferView":0,"componentType":5126,"count":1,"type":"VEC3"}],
///     "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}"#;
/// assert!(msg(external).starts_with("glTF buffer 0: the data is in the external file 'a.bin'"));
/// ```
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ReadError {
    /// The input has no bytes.
    #[error("the file is empty")]
    Empty,
    /// The content matches no supported format.
    #[error(
        "unknown file format: expected PLY, OBJ, STL, XYZ/CSV/PTS point text, E57, LAS/LAZ, PCD, \
         PTX or glTF/GLB"
    )]
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
    /// The file uses a feature of its format that geofit does not decode (a glTF compression
    /// extension, an E57 scan with only spherical coordinates in a mode not supported, …).
    #[error("{format} {at}: not supported: {message}")]
    Unsupported {
        /// The format being parsed.
        format: Format,
        /// Where the feature is used.
        at: Location,
        /// What is not supported.
        message: String,
    },
    /// The file's data lives in another file (a glTF buffer with a relative `uri`), which
    /// cannot be opened from the bytes of this one. Re-export as GLB or with embedded buffers.
    #[error("{format} {at}: the data is in the external file '{uri}'; open a .glb or a .gltf with embedded (data:) buffers instead")]
    ExternalData {
        /// The format being parsed.
        format: Format,
        /// The buffer that refers to the file.
        at: Location,
        /// The file name or URI as written.
        uri: String,
    },
    /// The parsed data does not form a valid mesh.
    #[error("invalid mesh: {0}")]
    Mesh(#[from] MeshError),
}
