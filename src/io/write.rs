//! Writers: OBJ (text, exact decimal round trip), binary little-endian PLY (f64 coordinates)
//! and binary STL (f32, triangulated, as the format requires); GLB is in `glb.rs`.

use crate::mesh::PolyMesh;
use std::io::{BufWriter, Write};
use thiserror::Error;

/// Why a mesh could not be written.
///
/// ```
/// use geofit::{io::to_obj_bytes, mesh::PolyMesh, geom::Point3};
/// let mesh = PolyMesh::from_points(vec![Point3::ZERO])?;
/// assert_eq!(to_obj_bytes(&mesh)?, b"# written by geofit\nv 0 0 0\n");
/// let options = geofit::io::GlbOptions::default().with_deviation(&[f64::NAN]);
/// let err = geofit::io::to_glb_bytes(&mesh, &options).unwrap_err();
/// assert_eq!(err.to_string(), "cannot write GLB: the deviation of vertex 0 is not finite");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum WriteError {
    /// The output refused the bytes.
    #[error("cannot write: {0}")]
    Io(#[from] std::io::Error),
    /// The mesh exceeds what the format can count (binary STL: 2³² − 1 triangles).
    #[error("the mesh is too large for {format}: {what}")]
    TooLarge {
        /// The format.
        format: &'static str,
        /// What overflowed.
        what: String,
    },
    /// The data given with the mesh does not fit it (GLB: a deviation or normal list of the
    /// wrong length, a non-finite deviation, a non-positive unit scale).
    #[error("cannot write {format}: {what}")]
    Invalid {
        /// The format.
        format: &'static str,
        /// What is wrong.
        what: String,
    },
}

/// Writes `mesh` as Wavefront OBJ: `v` lines with shortest round-trip decimals, then 1-based
/// `f` lines (polygons kept as they are).
pub fn write_obj(mesh: &PolyMesh, out: &mut impl Write) -> Result<(), WriteError> {
    let mut w = BufWriter::new(out);
    w.write_all(b"# written by geofit\n")?;
    for p in mesh.positions() {
        writeln!(w, "v {} {} {}", Decimal(p.x), Decimal(p.y), Decimal(p.z))?;
    }
    for f in mesh.faces() {
        w.write_all(b"f")?;
        for &i in f {
            write!(w, " {}", u64::from(i) + 1)?;
        }
        w.write_all(b"\n")?;
    }
    w.flush()?;
    Ok(())
}

/// Writes `mesh` as binary little-endian PLY with `double` coordinates (lossless) and a
/// `face` list whose count type is `uchar` unless a polygon has more than 255 corners.
pub fn write_ply(mesh: &PolyMesh, out: &mut impl Write) -> Result<(), WriteError> {
    let mut w = BufWriter::new(out);
    let wide = mesh.faces().any(|f| f.len() > usize::from(u8::MAX));
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment written by geofit\n\
         element vertex {}\nproperty double x\nproperty double y\nproperty double z\n",
        mesh.num_vertices()
    )?;
    if !mesh.is_point_cloud() {
        let count = if wide { "uint" } else { "uchar" };
        write!(
            w,
            "element face {}\nproperty list {count} uint vertex_indices\n",
            mesh.num_faces()
        )?;
    }
    w.write_all(b"end_header\n")?;
    for p in mesh.positions() {
        for c in p.to_array() {
            w.write_all(&c.to_le_bytes())?;
        }
    }
    for f in mesh.faces() {
        // A face has at most u32::MAX corners (PolyMesh indexes corners with u32).
        let n = u32::try_from(f.len()).unwrap_or(u32::MAX);
        if wide {
            w.write_all(&n.to_le_bytes())?;
        } else {
            w.write_all(&[n as u8])?;
        }
        for &i in f {
            w.write_all(&i.to_le_bytes())?;
        }
    }
    w.flush()?;
    Ok(())
}

/// Writes `mesh` as binary STL: polygons fan-triangulated, a unit normal per triangle (zero
/// for a degenerate one), coordinates rounded to f32 (beyond f32's range is an error). Points without faces are not written,
/// since STL has only triangles.
pub fn write_stl(mesh: &PolyMesh, out: &mut impl Write) -> Result<(), WriteError> {
    let triangles = mesh.triangles();
    let count = u32::try_from(triangles.len()).map_err(|_| WriteError::TooLarge {
        format: "STL",
        what: format!("{} triangles", triangles.len()),
    })?;
    let mut w = BufWriter::new(out);
    let mut header = [b' '; 80];
    header[..24].copy_from_slice(b"binary STL by geofit    ");
    w.write_all(&header)?;
    w.write_all(&count.to_le_bytes())?;
    let p = mesh.positions();
    for t in triangles {
        let [a, b, c] = t.map(|i| p[i as usize]);
        let normal = (b - a).cross(c - a).normalize_or_zero();
        for v in [normal, a, b, c] {
            for x in v.to_array() {
                w.write_all(&to_f32(x)?.to_le_bytes())?;
            }
        }
        w.write_all(&[0, 0])?;
    }
    w.flush()?;
    Ok(())
}

/// The shortest decimal that reads back as the same f64: plain for moderate magnitudes,
/// scientific (`1e300`, `2.5e-7`) otherwise, where plain notation would run to hundreds of
/// digits. Shared by the text writers (OBJ, Gmsh).
pub(super) struct Decimal(pub(super) f64);

impl std::fmt::Display for Decimal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || (1e-5..1e16).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

fn to_f32(x: f64) -> Result<f32, WriteError> {
    checked_f32(x, "STL", "coordinate")
}

/// `x` rounded to f32, or an error where it overflows to infinity; the message calls `x` a
/// `what` of `format` (the writers that store f32 share it).
pub(super) fn checked_f32(x: f64, format: &'static str, what: &str) -> Result<f32, WriteError> {
    let y = x as f32;
    if y.is_finite() {
        Ok(y)
    } else {
        Err(WriteError::TooLarge {
            format,
            what: format!("{what} {x:e} exceeds the f32 range"),
        })
    }
}

/// [`write_obj`] into a new byte vector.
pub fn to_obj_bytes(mesh: &PolyMesh) -> Result<Vec<u8>, WriteError> {
    let mut out = Vec::new();
    write_obj(mesh, &mut out)?;
    Ok(out)
}

/// [`write_ply`] into a new byte vector.
pub fn to_ply_bytes(mesh: &PolyMesh) -> Result<Vec<u8>, WriteError> {
    let mut out = Vec::new();
    write_ply(mesh, &mut out)?;
    Ok(out)
}

/// [`write_stl`] into a new byte vector.
pub fn to_stl_bytes(mesh: &PolyMesh) -> Result<Vec<u8>, WriteError> {
    let mut out = Vec::new();
    write_stl(mesh, &mut out)?;
    Ok(out)
}
