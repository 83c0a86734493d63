//! Readers and writers for point and mesh files: PLY, OBJ, STL, XYZ/CSV/PTS point text, the
//! scanner formats E57, LAS/LAZ, PCD and PTX, and glTF/GLB meshes; writers for OBJ, PLY, STL
//! and GLB.
//!
//! Every reader returns a [`LoadedFile`] or a [`ReadError`] that says what went wrong and where
//! (line or byte offset); no input makes a reader panic or hang, and no header count makes a
//! reader reserve more memory than the bytes that follow could fill.
//!
//! The parsers are hand-written. The crates made for these formats were tried on the shared
//! scans and on mutated inputs (none panicked), but none fits: `ply-rs-bw` 4.0 parses
//! bun000.ply in about 0.5 s with its generic element maps (these readers: about 20 ms) and
//! locates binary errors by header line only; `tobj` 4.0 keeps only vertices that faces use
//! (34,834 of the bunny's 35,947), drops `l` polylines and reports errors without line
//! numbers; `stl_io` 0.11 reports errors without a location. Tristrips and range grids would
//! need code on top of any of them anyway.
//!
//! The scanner formats use a crate where the format is hard and the crate is careful, and are
//! hand-written where the format is simple or the crate breaks these rules:
//! - **E57**: the `e57` crate (cargo feature `e57`, on by default) (pure Rust, no unsafe, no panics by its lints; CRC-checked pages,
//!   bit-packed records and the XML tree are real work). Its header fields are checked against
//!   the file size first.
//! - **LAZ**: the `laz` crate (cargo feature `laz`, on by default; the only LASzip decoder in
//!   Rust), used sequentially; the chunk
//!   table and the layer sizes of LAS 1.4 chunks are checked against the bytes before it
//!   allocates by them. **LAS** itself is a fixed binary layout and is read by hand: the
//!   `las` crate 0.11 resizes an extended VLR to the 64-bit length the file states (a few
//!   hundred damaged bytes can ask for exabytes), needs an owned `'static` reader (a second copy
//!   of the file in the browser), reports errors without an offset and brings `chrono`.
//! - **PCD** by hand (a text header, then rows or LZF-compressed columns): `pcd-rs` 0.13
//!   allocates the compressed and decompressed sizes the file states and indexes the columns
//!   without checking them against the point count, and the `lzf` crate is deprecated.
//! - **PTX** by hand (text).
//! - **glTF/GLB** by hand over `serde_json` (already a dependency): the reader needs only
//!   buffers, accessors, meshes and nodes, and must check every offset and stride against the
//!   buffer anyway; the `gltf` crate deserialises and validates the whole schema.
//!
//! ```
//! let file = geofit::io::read_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", Some("tri.obj"))?;
//! assert_eq!(file.format, geofit::io::Format::Obj);
//! assert_eq!(file.mesh.num_triangles(), 1);
//! # Ok::<(), geofit::io::ReadError>(())
//! ```

mod detect;
#[cfg(feature = "e57")]
mod e57;
mod error;
mod glb;
mod gltf;
mod grid;
mod las;
mod msh;
mod obj;
mod pcd;
mod ply;
mod ptx;
mod stl;
mod text;
mod write;
mod xyz;

pub use error::{Location, ReadError};
pub use glb::{
    diverging_colour, to_glb_bytes, write_glb, ColourMap, GlbOptions, DIVERGING_NEGATIVE,
    DIVERGING_POSITIVE, DIVERGING_ZERO,
};
pub use grid::RangeGrid;
pub use msh::{to_msh_bytes, write_msh};
pub use write::{
    to_obj_bytes, to_ply_bytes, to_stl_bytes, write_obj, write_ply, write_stl, WriteError,
};

use crate::mesh::PolyMesh;
use serde::Serialize;
use std::fmt;
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
    /// ASTM E57 (terrestrial scanners): every scan, with its pose applied.
    E57,
    /// ASPRS LAS (airborne and mobile lidar), uncompressed.
    Las,
    /// LAZ: LAS compressed with LASzip.
    Laz,
    /// Point Cloud Library PCD (ascii, binary or binary_compressed).
    Pcd,
    /// Leica PTX: gridded scans with their poses.
    Ptx,
    /// glTF 2.0 JSON (`.gltf`) with embedded buffers.
    Gltf,
    /// Binary glTF 2.0 (`.glb`).
    Glb,
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Ply => "PLY",
            Format::Obj => "OBJ",
            Format::Stl => "STL",
            Format::Xyz => "XYZ",
            Format::E57 => "E57",
            Format::Las => "LAS",
            Format::Laz => "LAZ",
            Format::Pcd => "PCD",
            Format::Ptx => "PTX",
            Format::Gltf => "glTF",
            Format::Glb => "GLB",
        })
    }
}

/// What a reader found in a file.
#[derive(Clone, Debug)]
pub struct LoadedFile {
    /// The format the file was parsed as.
    pub format: Format,
    /// Points, with faces when the file has them (PLY faces and triangle strips, OBJ faces, STL
    /// facets). A range scan's grid is kept apart in [`LoadedFile::range_grid`].
    pub mesh: PolyMesh,
    /// Polylines as vertex indices into `mesh` (OBJ `l` statements); curve fitting reads them.
    pub polylines: Vec<Vec<u32>>,
    /// The scanner grid of a raw range scan (PLY `range_grid` element), if the file has one.
    pub range_grid: Option<RangeGrid>,
    /// 2 when the file gives only x and y (a two-column point file or a PLY without `z`; z is
    /// then 0), otherwise 3.
    pub dimension: u8,
    /// How many scans (scanner set-ups) the points come from, for the formats that have them:
    /// E57 and PTX count their scans, a LAS/LAZ file is one scan; `None` for the others. A
    /// file of several scans keeps no [`LoadedFile::range_grid`]: each grid covers one view,
    /// and the grid triangulations of registered, overlapping views would stack their sheets;
    /// the merged points are reconstructed as one cloud instead.
    pub scans: Option<usize>,
    /// The length in metres of one unit of the coordinates, where the format defines it: 1 for
    /// E57 and glTF/GLB (both specify metres), `None` where the file does not say (LAS keeps
    /// units in its CRS text, PLY/OBJ/STL/XYZ/PCD/PTX have none).
    pub unit_to_metres: Option<f64>,
}

impl LoadedFile {
    /// A 3D file with just a mesh: the common case for the readers.
    fn from_mesh(format: Format, mesh: PolyMesh) -> LoadedFile {
        LoadedFile {
            format,
            mesh,
            polylines: Vec::new(),
            range_grid: None,
            dimension: 3,
            scans: None,
            unit_to_metres: None,
        }
    }
}

/// Reads a file from bytes. The format is taken from the content, with `name` (a file name
/// or extension) as a hint where the content is ambiguous.
pub fn read_bytes(bytes: &[u8], name: Option<&str>) -> Result<LoadedFile, ReadError> {
    if bytes.is_empty() {
        return Err(ReadError::Empty);
    }
    crate::progress::report(crate::progress::Phase::Reading, 0.0);
    let loaded = match detect::detect(bytes, name).ok_or(ReadError::UnknownFormat)? {
        Format::Ply => ply::read(bytes)?,
        Format::Obj => obj::read(bytes)?,
        Format::Stl => stl::read(bytes)?,
        Format::Xyz => xyz::read(bytes)?,
        #[cfg(feature = "e57")]
        Format::E57 => e57::read(bytes)?,
        #[cfg(not(feature = "e57"))]
        Format::E57 => return Err(not_built(Format::E57, "e57")),
        Format::Las | Format::Laz => las::read(bytes)?,
        Format::Pcd => pcd::read(bytes)?,
        Format::Ptx => ptx::read(bytes)?,
        Format::Gltf | Format::Glb => gltf::read(bytes)?,
    };
    if loaded.mesh.num_vertices() == 0 {
        return Err(ReadError::NoPoints {
            format: loaded.format,
        });
    }
    crate::progress::report(crate::progress::Phase::Reading, 1.0);
    Ok(loaded)
}

/// The mesh of a reader that collects faces flat: face k's corners are
/// `face_indices[face_starts[k]..face_starts[k + 1]]`.
fn mesh_from_flat_faces(
    positions: Vec<crate::geom::Point3>,
    face_starts: &[usize],
    face_indices: &[u32],
) -> Result<PolyMesh, ReadError> {
    let faces = face_starts.windows(2).map(|w| &face_indices[w[0]..w[1]]);
    Ok(PolyMesh::try_new(positions, faces)?)
}

/// The error for a format whose reader was left out of the build by its cargo feature.
#[cfg(any(not(feature = "e57"), not(feature = "laz")))]
fn not_built(format: Format, feature: &str) -> ReadError {
    ReadError::Unsupported {
        format,
        at: Location::Byte(0),
        message: format!("geofit was built without its '{feature}' feature"),
    }
}

/// Reads a file from disk; see [`read_bytes`].
pub fn read_path(path: &Path) -> Result<LoadedFile, ReadError> {
    let bytes = std::fs::read(path).map_err(|e| ReadError::Io(e.to_string()))?;
    read_bytes(&bytes, path.file_name().and_then(|n| n.to_str()))
}
