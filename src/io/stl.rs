//! STL reader, binary and ASCII. STL repeats each vertex in every facet that uses it; vertices
//! with identical coordinates (bit for bit, with -0 taken as +0) are merged so that the mesh
//! has shared vertices and its counts mean what they mean for the other formats.

use super::text::{coordinate, lines, show, tokens};
use super::{Format, LoadedFile, Location, ReadError};
use crate::geom::Point3;
use crate::mesh::PolyMesh;
use std::collections::HashMap;

const STL: Format = Format::Stl;
/// Binary STL: 80-byte header, then a little-endian u32 triangle count.
const HEADER: usize = 84;
/// Binary STL: normal, three vertices (12 f32) and a u16 attribute per triangle.
const TRIANGLE: usize = 50;

/// Whether the file's size is exactly what its binary triangle count says.
pub fn is_binary(bytes: &[u8]) -> bool {
    declared_triangles(bytes)
        .is_some_and(|n| (HEADER as u64) + (TRIANGLE as u64) * n == bytes.len() as u64)
}

/// Whether the file is binary STL, allowing for exporters that pad the end or start the
/// header with `solid`: exact size, or room for the declared triangles and a NUL or non-ASCII
/// byte in the first triangles, which ASCII STL never has.
pub fn looks_binary(bytes: &[u8]) -> bool {
    let fits = declared_triangles(bytes)
        .is_some_and(|n| (HEADER as u64) + (TRIANGLE as u64) * n <= bytes.len() as u64);
    let data = bytes.get(HEADER..).unwrap_or_default();
    is_binary(bytes) || (fits && data.iter().take(8 * TRIANGLE).any(|&b| b == 0 || b > 127))
}

fn declared_triangles(bytes: &[u8]) -> Option<u64> {
    let count: [u8; 4] = bytes.get(80..84)?.try_into().ok()?;
    Some(u64::from(u32::from_le_bytes(count)))
}

pub fn read(bytes: &[u8]) -> Result<LoadedFile, ReadError> {
    let starts_solid = tokens(bytes.get(..HEADER).unwrap_or(bytes)).next() == Some(b"solid");
    if starts_solid && !looks_binary(bytes) {
        read_ascii(bytes)
    } else {
        read_binary(bytes)
    }
}

/// Merges vertices by exact coordinates.
#[derive(Default)]
struct Welder {
    positions: Vec<Point3>,
    index: HashMap<[u64; 3], u32>,
    faces: Vec<[u32; 3]>,
}

impl Welder {
    fn vertex(&mut self, p: Point3) -> Result<u32, ReadError> {
        // Adding +0.0 turns -0.0 into +0.0, so the two zeros weld.
        let key = (p + 0.0).to_array().map(f64::to_bits);
        if let Some(&i) = self.index.get(&key) {
            return Ok(i);
        }
        let i = u32::try_from(self.positions.len()).map_err(|_| {
            ReadError::Mesh(crate::mesh::MeshError::TooLarge {
                what: "vertex count",
            })
        })?;
        self.positions.push(p);
        self.index.insert(key, i);
        Ok(i)
    }

    fn finish(self) -> Result<LoadedFile, ReadError> {
        let mesh = PolyMesh::try_new(self.positions, self.faces)?;
        Ok(LoadedFile::from_mesh(STL, mesh))
    }
}

fn read_binary(bytes: &[u8]) -> Result<LoadedFile, ReadError> {
    let count = declared_triangles(bytes).ok_or(ReadError::Truncated {
        format: STL,
        at: Location::Byte(bytes.len()),
        message: format!("a binary STL needs an {HEADER}-byte header"),
    })?;
    let needed = (HEADER as u64) + (TRIANGLE as u64) * count;
    if needed > bytes.len() as u64 {
        return Err(ReadError::Truncated {
            format: STL,
            at: Location::Byte(bytes.len()),
            message: format!(
                "the header (byte 80) declares {count} triangles, which need {needed} bytes, \
                 but the file has {}",
                bytes.len()
            ),
        });
    }
    let mut w = Welder::default();
    w.faces.reserve(count as usize);
    for t in bytes[HEADER..needed as usize].chunks_exact(TRIANGLE) {
        let offset = t.as_ptr() as usize - bytes.as_ptr() as usize;
        let mut face = [0; 3];
        for (k, v) in face.iter_mut().enumerate() {
            let start = 12 + 12 * k;
            *v = w.vertex(binary_vertex(&t[start..start + 12], offset + start)?)?;
        }
        w.faces.push(face);
    }
    w.finish()
}

fn binary_vertex(b: &[u8], offset: usize) -> Result<Point3, ReadError> {
    let mut xyz = [0.0; 3];
    for (c, chunk) in xyz.iter_mut().zip(b.chunks_exact(4)) {
        let raw: [u8; 4] = chunk.try_into().unwrap_or_default();
        *c = f64::from(f32::from_le_bytes(raw));
    }
    let p = Point3::from_array(xyz);
    if p.is_finite() {
        Ok(p)
    } else {
        Err(ReadError::NonFinite {
            format: STL,
            at: Location::Byte(offset),
        })
    }
}

fn syntax(line_no: usize, message: String) -> ReadError {
    ReadError::Syntax {
        format: STL,
        at: Location::Line(line_no),
        message,
    }
}

/// ASCII STL: `facet … outer loop / vertex x y z … / endloop / endfacet`, any number of solids.
fn read_ascii(bytes: &[u8]) -> Result<LoadedFile, ReadError> {
    let mut w = Welder::default();
    let mut facet: Option<Vec<u32>> = None;
    let mut last_line = 1;
    for (line_no, line) in lines(bytes) {
        last_line = line_no;
        let mut toks = tokens(line);
        match (toks.next(), facet.as_mut()) {
            (Some(b"facet"), None) => facet = Some(Vec::with_capacity(3)),
            (Some(b"vertex"), Some(f)) => {
                let mut xyz = [0.0; 3];
                for c in &mut xyz {
                    let t = toks
                        .next()
                        .ok_or_else(|| syntax(line_no, "vertex needs x, y and z".into()))?;
                    *c = coordinate(t, STL, Location::Line(line_no))?;
                }
                f.push(w.vertex(Point3::from_array(xyz))?);
            }
            (Some(b"endfacet"), Some(f)) => {
                let [a, b, c] = f[..] else {
                    return Err(syntax(
                        line_no,
                        format!("facet has {} vertices, needs 3", f.len()),
                    ));
                };
                w.faces.push([a, b, c]);
                facet = None;
            }
            (Some(b"outer" | b"endloop"), Some(_))
            | (Some(b"solid" | b"endsolid") | None, None) => {}
            (Some(t), _) => {
                return Err(syntax(line_no, format!("unexpected '{}'", show(t))));
            }
            (None, Some(_)) => {}
        }
    }
    if facet.is_some() {
        return Err(ReadError::Truncated {
            format: STL,
            at: Location::Line(last_line),
            message: "the last facet has no endfacet".into(),
        });
    }
    w.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &[u8] =
        b"solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n\
        \x20 vertex 0 1 0\n endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\n\
        vertex 1 1 0\nvertex 0 1 -0\nendloop\nendfacet\nendsolid t\n";

    #[test]
    fn ascii_welds_shared_vertices() {
        let f = read(ASCII).unwrap();
        assert_eq!(f.mesh.num_vertices(), 4);
        assert_eq!(f.mesh.triangles(), vec![[0, 1, 2], [1, 3, 2]]);
    }

    #[test]
    fn ascii_errors_name_the_line() {
        let bad = String::from_utf8_lossy(ASCII).replace("vertex 1 1 0", "vertex 1 q 0");
        let e = read(bad.as_bytes()).unwrap_err();
        assert_eq!(e.to_string(), "STL line 12: expected a number, found 'q'");
        let e = read(&ASCII[..56]).unwrap_err();
        assert!(matches!(e, ReadError::Truncated { .. }), "{e}");
    }

    #[test]
    fn padded_binary_with_solid_header() {
        let mut b = b"solid exported".to_vec();
        b.resize(80, b' ');
        b.extend(1u32.to_le_bytes());
        for v in [
            0.0f32, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0,
        ] {
            b.extend(v.to_le_bytes());
        }
        b.extend([0; 2 + 7]); // attribute, then 7 bytes of padding
        let f = read(&b).unwrap();
        assert_eq!(f.mesh.num_vertices(), 3);
        assert_eq!(super::super::read_bytes(&b, None).unwrap().format, STL);
    }

    #[test]
    fn binary_truncation_reports_sizes() {
        let mut b = vec![0u8; HEADER + TRIANGLE];
        b[80] = 2;
        let e = read(&b).unwrap_err();
        assert_eq!(
            e.to_string(),
            "STL byte 134: file ends early: the header (byte 80) declares 2 triangles, which \
             need 184 bytes, but the file has 134"
        );
    }
}
