//! Wavefront OBJ reader: `v`, `f` (all `v/vt/vn` forms, negative indices, polygons) and `l`
//! polylines. Every other statement (`vt`, `vn`, groups, materials, …) is ignored.

use super::text::{coordinate, lines, parse_i64, show, tokens};
use super::{mesh_from_flat_faces, Format, LoadedFile, Location, ReadError};
use crate::geom::Point3;

const OBJ: Format = Format::Obj;

/// Faces and polylines as flat index lists, with the largest index seen and where, so that
/// forward references can be checked once every vertex is known.
#[derive(Default)]
struct Parsed {
    positions: Vec<Point3>,
    face_starts: Vec<usize>,
    face_indices: Vec<u32>,
    polylines: Vec<Vec<u32>>,
    max_index: Option<(u32, usize)>,
}

pub fn read(bytes: &[u8]) -> Result<LoadedFile, ReadError> {
    let mut p = Parsed {
        face_starts: vec![0],
        ..Parsed::default()
    };
    for (line_no, line) in lines(bytes) {
        let mut toks = tokens(line);
        match toks.next() {
            Some(b"v") => p.positions.push(vertex(toks, line_no)?),
            Some(b"f") => {
                let start = p.face_indices.len();
                read_refs(&mut p, toks, line_no)?;
                let n = p.face_indices.len() - start;
                if n < 3 {
                    return Err(syntax(line_no, format!("face has {n} vertices, needs 3")));
                }
                p.face_starts.push(p.face_indices.len());
            }
            Some(b"l") => {
                let start = p.face_indices.len();
                read_refs(&mut p, toks, line_no)?;
                let line: Vec<u32> = p.face_indices.drain(start..).collect();
                if line.len() < 2 {
                    return Err(syntax(line_no, "line has fewer than 2 vertices".into()));
                }
                p.polylines.push(line);
            }
            _ => {}
        }
    }
    finish(p)
}

fn finish(p: Parsed) -> Result<LoadedFile, ReadError> {
    let count = p.positions.len();
    if let Some((index, line_no)) = p.max_index.filter(|&(i, _)| i as usize >= count) {
        return Err(ReadError::IndexOutOfRange {
            format: OBJ,
            at: Location::Line(line_no),
            index: i64::from(index) + 1,
            count,
        });
    }
    let mesh = mesh_from_flat_faces(p.positions, &p.face_starts, &p.face_indices)?;
    Ok(LoadedFile {
        polylines: p.polylines,
        ..LoadedFile::from_mesh(OBJ, mesh)
    })
}

fn syntax(line_no: usize, message: String) -> ReadError {
    ReadError::Syntax {
        format: OBJ,
        at: Location::Line(line_no),
        message,
    }
}

/// `v x y z [w] [r g b]`: the first three numbers; w and colours are ignored.
fn vertex<'a>(
    mut toks: impl Iterator<Item = &'a [u8]>,
    line_no: usize,
) -> Result<Point3, ReadError> {
    let at = Location::Line(line_no);
    let mut xyz = [0.0; 3];
    for c in &mut xyz {
        let t = toks
            .next()
            .ok_or_else(|| syntax(line_no, "vertex needs x, y and z".into()))?;
        *c = coordinate(t, OBJ, at)?;
    }
    Ok(Point3::from_array(xyz))
}

/// Appends the vertex references of an `f` or `l` statement (each `v`, `v/vt`, `v//vn` or
/// `v/vt/vn`) as 0-based indices. Negative indices count back from the last vertex read.
fn read_refs<'a>(
    p: &mut Parsed,
    toks: impl Iterator<Item = &'a [u8]>,
    line_no: usize,
) -> Result<(), ReadError> {
    for t in toks {
        let v = t.split(|&b| b == b'/').next().unwrap_or(t);
        let written = parse_i64(v).ok_or_else(|| {
            syntax(
                line_no,
                format!("expected a vertex index, found '{}'", show(t)),
            )
        })?;
        let count = p.positions.len() as i64;
        let resolved = match written {
            i if i > 0 => i - 1,
            i if i < 0 => count + i,
            _ => -1,
        };
        let index = u32::try_from(resolved).map_err(|_| ReadError::IndexOutOfRange {
            format: OBJ,
            at: Location::Line(line_no),
            index: written,
            count: p.positions.len(),
        })?;
        if p.max_index.is_none_or(|(m, _)| index > m) {
            p.max_index = Some((index, line_no));
        }
        p.face_indices.push(index);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_all_reference_forms_and_negative_indices() {
        let src = b"v 0 0 0\nv 1 0 0 1 0.5 0.5 0.5\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n\
            f 1/1 2//1 3/1/1 4\nf -1 -2 -3\nl 1 2 3\n";
        let f = read(src).unwrap();
        assert_eq!(f.mesh.num_vertices(), 4);
        assert_eq!(f.mesh.face(0), &[0, 1, 2, 3]);
        assert_eq!(f.mesh.face(1), &[3, 2, 1]);
        assert_eq!(f.polylines, vec![vec![0, 1, 2]]);
    }

    #[test]
    fn errors_name_the_line() {
        let e = read(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "OBJ line 4: vertex index 7 is out of range (the file has 3 vertices)"
        );
        let e = read(b"v 0 0 0\nf 1 -5 1\n").unwrap_err();
        assert!(
            e.to_string().starts_with("OBJ line 2: vertex index -5"),
            "{e}"
        );
        let e = read(b"v 0 0 0\nf 0 1 1\n").unwrap_err();
        assert!(
            e.to_string().starts_with("OBJ line 2: vertex index 0"),
            "{e}"
        );
        let e = read(b"v 0 0\n").unwrap_err();
        assert_eq!(e.to_string(), "OBJ line 1: vertex needs x, y and z");
        let e = read(b"v 0 0 nan\n").unwrap_err();
        assert!(matches!(
            e,
            ReadError::NonFinite {
                at: Location::Line(1),
                ..
            }
        ));
        let e = read(b"v 0 0 0\nf 1 1\n").unwrap_err();
        assert_eq!(e.to_string(), "OBJ line 2: face has 2 vertices, needs 3");
    }
}
