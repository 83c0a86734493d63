//! Gmsh MSH 4.1 ASCII: the mesh format finite-element tools read (Gmsh, meshio, FEniCS via
//! meshio, CalculiX converters). Written by hand: the format is a few counted blocks and no
//! maintained Rust crate writes it.
//!
//! The file holds one surface entity (tag 1, its bounding box, no physical groups) with every
//! node, then one element block per element type: 3-node triangles (type 2) and 4-node
//! quadrangles (type 3). Node tags are the vertex indices plus one, element tags count from 1.

use super::write::{Decimal, WriteError};
use crate::geom::Aabb;
use crate::mesh::PolyMesh;
use std::io::{BufWriter, Write};

/// Gmsh's element type numbers of the polygons the writer accepts.
const TRIANGLE: u32 = 2;
const QUADRANGLE: u32 = 3;

/// Writes the faces of `mesh` (triangles and quadrilaterals only) as Gmsh MSH 4.1 ASCII.
///
/// ```
/// use geofit::{geom::Point3, io::to_msh_bytes, mesh::PolyMesh};
/// let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
/// let points = square.iter().map(|p| Point3::new(p[0], p[1], 0.0)).collect();
/// let mesh = PolyMesh::try_new(points, [[0u32, 1, 2, 3]])?;
/// let text = String::from_utf8(to_msh_bytes(&mesh)?)?;
/// assert!(text.starts_with("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"));
/// assert!(text.contains("$Elements\n1 1 1 1\n2 1 3 1\n1 1 2 3 4\n$EndElements\n"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_msh(mesh: &PolyMesh, out: &mut impl Write) -> Result<(), WriteError> {
    let (mut tris, mut quads) = (Vec::new(), Vec::new());
    for (i, f) in mesh.faces().enumerate() {
        match f.len() {
            3 => tris.push(f),
            4 => quads.push(f),
            n => {
                return Err(WriteError::Invalid {
                    format: "MSH",
                    what: format!("face {i} has {n} corners; MSH takes triangles and quads"),
                })
            }
        }
    }
    let mut w = BufWriter::with_capacity(1 << 16, out);
    w.write_all(b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n")?;
    write_entities(mesh, &mut w)?;
    write_nodes(mesh, &mut w)?;
    let blocks: Vec<(u32, &[&[u32]])> = [(TRIANGLE, &tris[..]), (QUADRANGLE, &quads[..])]
        .into_iter()
        .filter(|(_, faces)| !faces.is_empty())
        .collect();
    let total = tris.len() + quads.len();
    writeln!(w, "$Elements\n{} {total} 1 {total}", blocks.len())?;
    let mut tag = 1usize;
    for (kind, faces) in blocks {
        writeln!(w, "2 1 {kind} {}", faces.len())?;
        for f in faces {
            write!(w, "{tag}")?;
            for &v in *f {
                write!(w, " {}", u64::from(v) + 1)?;
            }
            w.write_all(b"\n")?;
            tag += 1;
        }
    }
    w.write_all(b"$EndElements\n")?;
    w.flush()?;
    Ok(())
}

/// The one surface entity, bounded by the mesh's box.
fn write_entities(mesh: &PolyMesh, w: &mut impl Write) -> Result<(), WriteError> {
    let b = Aabb::from_points(mesh.positions());
    let (lo, hi) = b.map_or(([0.0; 3], [0.0; 3]), |b| {
        (b.min.to_array(), b.max.to_array())
    });
    w.write_all(b"$Entities\n0 0 1 0\n1")?;
    for x in lo.iter().chain(&hi) {
        write!(w, " {}", Decimal(*x))?;
    }
    w.write_all(b" 0 0\n$EndEntities\n")?;
    Ok(())
}

/// Every vertex in one block of surface 1: the tags, then the coordinates.
fn write_nodes(mesh: &PolyMesh, w: &mut impl Write) -> Result<(), WriteError> {
    let n = mesh.positions().len();
    if n == 0 {
        w.write_all(b"$Nodes\n0 0 0 0\n$EndNodes\n")?;
        return Ok(());
    }
    writeln!(w, "$Nodes\n1 {n} 1 {n}\n2 1 0 {n}")?;
    for tag in 1..=n {
        writeln!(w, "{tag}")?;
    }
    for p in mesh.positions() {
        writeln!(w, "{} {} {}", Decimal(p.x), Decimal(p.y), Decimal(p.z))?;
    }
    w.write_all(b"$EndNodes\n")?;
    Ok(())
}

/// [`write_msh`] into a new byte vector.
pub fn to_msh_bytes(mesh: &PolyMesh) -> Result<Vec<u8>, WriteError> {
    let mut out = Vec::new();
    write_msh(mesh, &mut out)?;
    Ok(out)
}
