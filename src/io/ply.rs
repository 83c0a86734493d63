//! Stanford PLY reader: ASCII, binary little- and big-endian, any element and property layout.
//!
//! Known elements: `vertex` (x, y, z), `face` (a `vertex_indices` or `vertex_index` list),
//! `tristrips` (strips with -1 restart markers) and `range_grid` (Cyberware raw scans, with
//! `num_cols`/`num_rows` in `obj_info` header lines). Every other element and property, list or
//! scalar, is skipped by its declared type.

mod body;
mod header;

use super::{mesh_from_flat_faces, Format, LoadedFile, Location, RangeGrid, ReadError};
use crate::geom::Point3;
use body::{Ascii, Binary, Body, Fault};
use header::{Element, Encoding, Header, PropKind};

const PLY: Format = Format::Ply;

pub fn read(bytes: &[u8]) -> Result<LoadedFile, ReadError> {
    let header = header::parse(bytes)?;
    let rest = &bytes[header.body_offset..];
    match header.encoding {
        Encoding::Ascii => read_body(Ascii::new(rest, header.body_line), &header),
        Encoding::BinaryLittleEndian => {
            read_body(Binary::<false>::new(bytes, header.body_offset), &header)
        }
        Encoding::BinaryBigEndian => {
            read_body(Binary::<true>::new(bytes, header.body_offset), &header)
        }
    }
}

/// What each property of an element feeds.
#[derive(Clone, Copy, PartialEq)]
enum Slot {
    Coord(usize),
    Indices,
    Skip,
}

/// The body's content as it is read, before it becomes a mesh.
struct Parsed {
    vertex_count: usize,
    positions: Vec<Point3>,
    face_starts: Vec<usize>,
    face_indices: Vec<u32>,
    grid_cells: Vec<Option<u32>>,
}

fn read_body<B: Body>(mut body: B, header: &Header) -> Result<LoadedFile, ReadError> {
    let vertex_count = header.element("vertex").map_or(0, |e| e.count);
    let mut p = Parsed {
        vertex_count,
        positions: Vec::new(),
        face_starts: vec![0],
        face_indices: Vec::new(),
        grid_cells: Vec::new(),
    };
    let mut has_z = true;
    let mut first_vertex = true;
    for el in &header.elements {
        check_room(&mut body, el)?;
        match el.name.as_str() {
            "vertex" if first_vertex => {
                first_vertex = false;
                has_z = read_vertices(&mut body, el, &mut p)?;
            }
            "face" => read_lists(&mut body, el, &mut p, push_face)?,
            "tristrips" => read_lists(&mut body, el, &mut p, push_strip)?,
            "range_grid" => read_lists(&mut body, el, &mut p, push_grid_cell)?,
            _ => read_elements(&mut body, el, &[], |_, _| Ok(()))?,
        }
    }
    finish(p, header, has_z)
}

fn finish(mut p: Parsed, header: &Header, has_z: bool) -> Result<LoadedFile, ReadError> {
    let range_grid = grid(std::mem::take(&mut p.grid_cells), header)?;
    let mesh = mesh_from_flat_faces(p.positions, &p.face_starts, &p.face_indices)?;
    Ok(LoadedFile {
        range_grid,
        dimension: if has_z { 3 } else { 2 },
        ..LoadedFile::from_mesh(PLY, mesh)
    })
}

/// The range grid, when the file has a `range_grid` element and `obj_info` gives its size.
fn grid(cells: Vec<Option<u32>>, header: &Header) -> Result<Option<RangeGrid>, ReadError> {
    let Some(el) = header.element("range_grid") else {
        return Ok(None);
    };
    let (Some(cols), Some(rows)) = (header.num_cols, header.num_rows) else {
        return Ok(None);
    };
    RangeGrid::try_new(cols, rows, cells)
        .map(Some)
        .ok_or_else(|| ReadError::Syntax {
            format: PLY,
            at: Location::Line(el.line),
            message: format!(
                "range_grid has {} cells but obj_info gives {cols} columns × {rows} rows",
                el.count
            ),
        })
}

/// Refuses an element count that the remaining bytes cannot hold, before anything is reserved:
/// a ten-byte file that declares four billion vertices fails here at once. One byte of slack
/// lets an ASCII file end without a final separator; a binary body one byte short still
/// fails, at the exact offset, when the last value is read.
fn check_room<B: Body>(body: &mut B, el: &Element) -> Result<(), ReadError> {
    let needed = el.count.saturating_mul(body.min_item_size(el));
    let remaining = body.remaining();
    if needed.saturating_sub(1) <= remaining {
        return Ok(());
    }
    Err(ReadError::Truncated {
        format: PLY,
        at: body.at(),
        message: format!(
            "the header (line {}) declares {} '{}' elements, which need at least {needed} bytes, \
             but only {remaining} remain",
            el.line, el.count, el.name
        ),
    })
}

/// Reads every item of `el`, filling `slots` (x/y/z coordinates and one index list) and
/// handing them to `take` with the item's location. Properties without a slot are
/// skipped by type.
fn read_elements<B: Body>(
    body: &mut B,
    el: &Element,
    slots: &[Slot],
    mut take: impl FnMut(&Item, Location) -> Result<(), ReadError>,
) -> Result<(), ReadError> {
    if el.props.is_empty() {
        return Ok(());
    }
    let mut item = Item::default();
    for i in 0..el.count {
        let at = body.at();
        read_item(body, el, slots, &mut item).map_err(|(prop, fault)| {
            fault_error(fault, body.fault_at(), el, i, &el.props[prop].name)
        })?;
        take(&item, at)?;
    }
    Ok(())
}

/// The slotted values of one element item.
#[derive(Default)]
struct Item {
    xyz: [f64; 3],
    list: Vec<i64>,
}

fn read_item<B: Body>(
    body: &mut B,
    el: &Element,
    slots: &[Slot],
    item: &mut Item,
) -> Result<(), (usize, Fault)> {
    for (k, prop) in el.props.iter().enumerate() {
        let slot = slots.get(k).copied().unwrap_or(Slot::Skip);
        let r = match (prop.kind, slot) {
            (PropKind::Scalar(t), Slot::Coord(c)) => body.value(t).map(|v| item.xyz[c] = v),
            (PropKind::Scalar(t), _) => body.skip(t, 1),
            (PropKind::List { count, item: t }, Slot::Indices) => {
                read_index_list(body, count, t, &mut item.list)
            }
            (PropKind::List { count, item: t }, _) => {
                body.length(count).and_then(|n| body.skip(t, n))
            }
        };
        r.map_err(|f| (k, f))?;
    }
    Ok(())
}

fn read_index_list<B: Body>(
    body: &mut B,
    count: header::Scalar,
    item: header::Scalar,
    list: &mut Vec<i64>,
) -> Result<(), Fault> {
    let n = body.length(count)?;
    list.clear();
    for _ in 0..n {
        list.push(body.integer(item)?);
    }
    Ok(())
}

fn fault_error(fault: Fault, at: Location, el: &Element, i: usize, prop: &str) -> ReadError {
    let what = format!("property '{prop}' of {} {i} (of {})", el.name, el.count);
    let message = match fault {
        Fault::End => {
            return ReadError::Truncated {
                format: PLY,
                at,
                message: format!("while reading {what}"),
            }
        }
        Fault::NotNumber(token) => format!("expected a number for {what}, found '{token}'"),
        Fault::NotInteger(token) => format!("expected an integer for {what}, found '{token}'"),
        Fault::NegativeLength(n) => format!("list length {n} is negative in {what}"),
    };
    ReadError::Syntax {
        format: PLY,
        at,
        message,
    }
}

/// Reads the vertex element; returns whether it has a z coordinate.
fn read_vertices<B: Body>(body: &mut B, el: &Element, p: &mut Parsed) -> Result<bool, ReadError> {
    let slot_of = |name: &str| match name {
        "x" => Slot::Coord(0),
        "y" => Slot::Coord(1),
        "z" => Slot::Coord(2),
        _ => Slot::Skip,
    };
    let slots: Vec<Slot> = el.props.iter().map(|p| slot_of(&p.name)).collect();
    for (c, axis) in ["x", "y"].into_iter().enumerate() {
        if !slots.contains(&Slot::Coord(c)) {
            return Err(ReadError::Syntax {
                format: PLY,
                at: Location::Line(el.line),
                message: format!("element 'vertex' has no scalar property '{axis}'"),
            });
        }
    }
    p.positions.reserve(el.count);
    read_elements(body, el, &slots, |item, at| {
        if item.xyz.iter().all(|c| c.is_finite()) {
            p.positions.push(Point3::from_array(item.xyz));
            Ok(())
        } else {
            Err(ReadError::NonFinite { format: PLY, at })
        }
    })?;
    Ok(slots.contains(&Slot::Coord(2)))
}

/// How a list element adds its index list to the parse.
type PushList = fn(&mut Parsed, &[i64], Location) -> Result<(), ReadError>;

/// Reads an element whose meaning is one vertex-index list (`face`, `tristrips`,
/// `range_grid`); the list property is the first of the accepted names.
fn read_lists<B: Body>(
    body: &mut B,
    el: &Element,
    p: &mut Parsed,
    push: PushList,
) -> Result<(), ReadError> {
    const NAMES: [&str; 3] = ["vertex_indices", "vertex_index", "vertex_ind"];
    let list = el
        .props
        .iter()
        .position(|p| matches!(p.kind, PropKind::List { .. }) && NAMES.contains(&p.name.as_str()))
        .ok_or_else(|| ReadError::Syntax {
            format: PLY,
            at: Location::Line(el.line),
            message: format!("element '{}' has no vertex_indices list property", el.name),
        })?;
    let mut slots = vec![Slot::Skip; el.props.len()];
    slots[list] = Slot::Indices;
    read_elements(body, el, &slots, |item, at| push(p, &item.list, at))
}

/// Checks a vertex index against the header's vertex count.
fn vertex_index(p: &Parsed, index: i64, at: Location) -> Result<u32, ReadError> {
    u32::try_from(index)
        .ok()
        .filter(|&i| (i as usize) < p.vertex_count)
        .ok_or(ReadError::IndexOutOfRange {
            format: PLY,
            at,
            index,
            count: p.vertex_count,
        })
}

fn push_face(p: &mut Parsed, list: &[i64], at: Location) -> Result<(), ReadError> {
    if list.len() < 3 {
        return Err(ReadError::Syntax {
            format: PLY,
            at,
            message: format!("face has {} vertices, needs 3", list.len()),
        });
    }
    for &i in list {
        let v = vertex_index(p, i, at)?;
        p.face_indices.push(v);
    }
    p.face_starts.push(p.face_indices.len());
    Ok(())
}

/// A triangle strip: -1 starts a new strip; every other triangle is flipped so that all keep
/// the first one's winding; triangles with a repeated vertex (strip joins) are dropped.
fn push_strip(p: &mut Parsed, list: &[i64], at: Location) -> Result<(), ReadError> {
    for strip in list.split(|&i| i == -1) {
        let strip = strip
            .iter()
            .map(|&i| vertex_index(p, i, at))
            .collect::<Result<Vec<u32>, _>>()?;
        for (j, w) in strip.windows(3).enumerate() {
            let [a, b, c] = if j % 2 == 0 {
                [w[0], w[1], w[2]]
            } else {
                [w[1], w[0], w[2]]
            };
            if a != b && b != c && a != c {
                p.face_indices.extend_from_slice(&[a, b, c]);
                p.face_starts.push(p.face_indices.len());
            }
        }
    }
    Ok(())
}

/// A range-grid cell: an empty list is an unmeasured cell, otherwise the first index is the
/// point the cell measured.
fn push_grid_cell(p: &mut Parsed, list: &[i64], at: Location) -> Result<(), ReadError> {
    let cell = match list.first() {
        Some(&i) => Some(vertex_index(p, i, at)?),
        None => None,
    };
    p.grid_cells.push(cell);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ascii(elements: &str, body: &str) -> Vec<u8> {
        format!("ply\nformat ascii 1.0\ncomment test\n{elements}end_header\n{body}").into_bytes()
    }

    const TRI: &str = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";

    #[test]
    fn skips_unknown_elements_and_list_properties() {
        let src = ascii(
            &format!(
                "element junk 2\nproperty list uint short a\nproperty double b\n{TRI}\
                 element face 1\nproperty uchar flags\nproperty list uchar int vertex_indices\n\
                 property list int float uv\n"
            ),
            "2 1 2 0.5\n0 9\n0 0 0\n1 0 0\n0 1 0\n7 3 0 1 2 2 0.5 0.5\n",
        );
        let f = read(&src).unwrap();
        assert_eq!(f.mesh.num_vertices(), 3);
        assert_eq!(f.mesh.face(0), &[0, 1, 2]);
        assert_eq!(f.dimension, 3);
    }

    #[test]
    fn tristrips_restart_flip_and_drop_degenerates() {
        let src = ascii(
            "element vertex 5\nproperty float x\nproperty float y\n\
             element tristrips 1\nproperty list int int vertex_indices\n",
            "0 0\n1 0\n0 1\n1 1\n2 2\n9 0 1 2 3 -1 2 3 3 4\n",
        );
        let f = read(&src).unwrap();
        assert_eq!(f.mesh.triangles(), vec![[0, 1, 2], [2, 1, 3]]);
        assert_eq!(f.dimension, 2);
    }

    #[test]
    fn errors_say_what_and_where() {
        let e = read(&ascii(TRI, "0 0 0\n1 x 0\n0 1 0\n")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "PLY line 10: expected a number for property 'y' of vertex 1 (of 3), found 'x'"
        );
        let e = read(&ascii(TRI, "0 0 0\n1 0 x\n0 1 0\n")).unwrap_err();
        assert!(e.to_string().starts_with("PLY line 10: "), "{e}");
        let e = read(&ascii(TRI, "0 0 0\n1 0 0\n")).unwrap_err();
        assert!(matches!(e, ReadError::Truncated { .. }), "{e}");
        // One bad face after three good vertices: (list length type, face line, error).
        for (count, face, message) in [
            (
                "uchar",
                "3 0 1 3",
                "PLY line 14: vertex index 3 is out of range (the file has 3 vertices)",
            ),
            (
                "char",
                "-3 0 1 2",
                "PLY line 14: list length -3 is negative in property 'vertex_indices' of face 0 (of 1)",
            ),
        ] {
            let src = ascii(
                &format!("{TRI}element face 1\nproperty list {count} int vertex_indices\n"),
                &format!("0 0 0\n1 0 0\n0 1 0\n{face}\n"),
            );
            assert_eq!(read(&src).unwrap_err().to_string(), message);
        }
        let e = read(&ascii(TRI, "0 0 0\n1 inf 0\n0 1 0\n")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "PLY line 10: coordinate is not a finite number"
        );
    }

    #[test]
    fn tightest_ascii_body_without_final_newline() {
        let src = ascii(
            "element vertex 2\nproperty float x\nproperty float y\n",
            "1 2\n3 4",
        );
        assert_eq!(read(&src).unwrap().mesh.num_vertices(), 2);
        let short = ascii(
            "element vertex 2\nproperty float x\nproperty float y\n",
            "1 2\n3",
        );
        assert!(matches!(read(&short), Err(ReadError::Truncated { .. })));
    }

    #[test]
    fn absurd_counts_fail_before_reserving() {
        let src = b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n\
            property float x\nproperty float y\nend_header\n\0\0\0\0";
        let e = read(src).unwrap_err();
        assert!(matches!(e, ReadError::Truncated { .. }), "{e}");
        assert!(e.to_string().contains("4000000000"), "{e}");
    }

    #[test]
    fn big_endian_binary() {
        let mut src = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\n\
            property float y\nproperty short z\nelement face 1\n\
            property list uchar uint vertex_indices\nend_header\n"
            .to_vec();
        for (x, y, z) in [(0.0f64, 0.0f32, 0i16), (1.0, 0.0, 0), (0.0, 1.0, -2)] {
            src.extend(x.to_be_bytes());
            src.extend(y.to_be_bytes());
            src.extend(z.to_be_bytes());
        }
        src.push(3);
        for i in [0u32, 1, 2] {
            src.extend(i.to_be_bytes());
        }
        let f = read(&src).unwrap();
        assert_eq!(f.mesh.positions()[2], Point3::new(0.0, 1.0, -2.0));
        assert_eq!(f.mesh.face(0), &[0, 1, 2]);
        let e = read(&src[..src.len() - 2]).unwrap_err();
        assert!(e.to_string().contains("byte"), "{e}");
    }
}
