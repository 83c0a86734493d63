//! Point Cloud Library PCD (versions 0.5 to 0.7): a text header, then the points as text rows
//! (`DATA ascii`), packed little-endian records (`DATA binary`) or LZF-compressed columns
//! (`DATA binary_compressed`).
//!
//! The fields `x`, `y` and `z` give the points (`z` missing: a 2D file); every other field
//! (colour, intensity, normals, ring, time, …) is skipped by its declared size and count. PCL
//! marks invalid points with NaN coordinates: they are left out. An organised cloud
//! (`HEIGHT` > 1, e.g. from a depth camera) is a `WIDTH × HEIGHT` image of points, and keeps it
//! as a [`RangeGrid`] with its NaN points as empty cells. `VIEWPOINT` (the sensor pose) is not
//! applied to the points, as PCL does not apply it either.

use super::text::{coordinate, lines, parse_f64, parse_i64, show, tokens};
use super::{Format, LoadedFile, Location, RangeGrid, ReadError};
use crate::geom::Point3;
use crate::mesh::PolyMesh;

const PCD: Format = Format::Pcd;

/// How many output bytes one input byte of LZF can give at most: a three-byte back reference
/// copies up to 264 bytes.
const LZF_MAX_RATIO: usize = 88;

/// Whether the start of a file is a PCD header: a `# .PCD` comment line, or `VERSION` followed
/// (after comments) by `FIELDS` or `COLUMNS`.
pub fn looks_like(head: &[u8]) -> bool {
    let mut keys = lines(head)
        .map(|(_, l)| l.trim_ascii())
        .filter(|l| !l.is_empty())
        .take(4);
    let Some(first) = keys.next() else {
        return false;
    };
    if first.starts_with(b"# .PCD") {
        return true;
    }
    let mut keywords = std::iter::once(first)
        .chain(keys)
        .filter(|l| !l.starts_with(b"#"))
        .filter_map(|l| tokens(l).next());
    matches!(
        (keywords.next(), keywords.next()),
        (Some(b"VERSION"), Some(b"FIELDS" | b"COLUMNS"))
    )
}

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Float,
    Signed,
    Unsigned,
}

struct Field {
    name: String,
    size: usize,
    kind: Kind,
    count: usize,
}

#[derive(Clone, Copy, PartialEq)]
enum Data {
    Ascii,
    Binary,
    Compressed,
}

struct Header {
    fields: Vec<Field>,
    width: Option<usize>,
    height: usize,
    points: usize,
    data: Data,
    /// Line of the `POINTS` (or `WIDTH`) keyword, for count errors.
    points_line: usize,
    /// Where the body starts: byte offset and line number.
    body: usize,
    body_line: usize,
}

fn syntax(line: usize, message: String) -> ReadError {
    ReadError::Syntax {
        format: PCD,
        at: Location::Line(line),
        message,
    }
}

fn count(tok: &[u8], line: usize, what: &str) -> Result<usize, ReadError> {
    parse_i64(tok)
        .and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| {
            syntax(
                line,
                format!("{what}: expected an integer ≥ 0, found '{}'", show(tok)),
            )
        })
}

fn parse_header(bytes: &[u8]) -> Result<Header, ReadError> {
    let mut names: Vec<String> = Vec::new();
    let mut sizes: Option<Vec<usize>> = None;
    let mut kinds: Option<Vec<Kind>> = None;
    let mut counts: Option<Vec<usize>> = None;
    let (mut width, mut height, mut points) = (None, 1, None);
    let mut points_line = 1;
    let mut offset = 0;
    for (line_no, line) in lines(bytes) {
        offset += line.len() + 1;
        let mut t = tokens(line);
        let Some(key) = t.next() else { continue };
        if key.starts_with(b"#") {
            continue;
        }
        let values: Vec<&[u8]> = t.collect();
        let ints = |what: &str| -> Result<Vec<usize>, ReadError> {
            values.iter().map(|v| count(v, line_no, what)).collect()
        };
        let one = |what: &str| -> Result<usize, ReadError> {
            match values.as_slice() {
                [v] => count(v, line_no, what),
                _ => Err(syntax(line_no, format!("{what}: expected one integer"))),
            }
        };
        match key {
            b"VERSION" | b"VIEWPOINT" => {}
            b"FIELDS" | b"COLUMNS" => {
                names = values
                    .iter()
                    .map(|v| String::from_utf8_lossy(v).into_owned())
                    .collect();
            }
            b"SIZE" => sizes = Some(ints("SIZE")?),
            b"COUNT" => counts = Some(ints("COUNT")?),
            b"TYPE" => {
                let k = values.iter().map(|v| match *v {
                    b"F" => Ok(Kind::Float),
                    b"I" => Ok(Kind::Signed),
                    b"U" => Ok(Kind::Unsigned),
                    other => Err(syntax(
                        line_no,
                        format!("TYPE: expected F, I or U, found '{}'", show(other)),
                    )),
                });
                kinds = Some(k.collect::<Result<_, _>>()?);
            }
            b"WIDTH" => {
                width = Some(one("WIDTH")?);
                points_line = line_no;
            }
            b"HEIGHT" => height = one("HEIGHT")?,
            b"POINTS" => {
                points = Some(one("POINTS")?);
                points_line = line_no;
            }
            b"DATA" => {
                let data = match values.as_slice() {
                    [b"ascii"] => Data::Ascii,
                    [b"binary"] => Data::Binary,
                    [b"binary_compressed"] => Data::Compressed,
                    _ => {
                        return Err(syntax(
                            line_no,
                            "DATA: expected ascii, binary or binary_compressed".into(),
                        ))
                    }
                };
                let n = names.len();
                let sizes = sizes.unwrap_or_else(|| vec![4; n]);
                let kinds = kinds.unwrap_or_else(|| vec![Kind::Float; n]);
                let counts = counts.unwrap_or_else(|| vec![1; n]);
                if sizes.len() != n || kinds.len() != n || counts.len() != n {
                    return Err(syntax(
                        line_no,
                        format!(
                            "the header gives {n} FIELDS but {} SIZE, {} TYPE and {} COUNT values",
                            sizes.len(),
                            kinds.len(),
                            counts.len()
                        ),
                    ));
                }
                let mut fields = Vec::with_capacity(n);
                for (((name, size), kind), count) in
                    names.into_iter().zip(sizes).zip(kinds).zip(counts)
                {
                    let ok = match kind {
                        Kind::Float => matches!(size, 4 | 8),
                        _ => matches!(size, 1 | 2 | 4 | 8),
                    };
                    if !ok {
                        return Err(syntax(
                            line_no,
                            format!("field '{name}' has an unsupported SIZE {size} for its TYPE"),
                        ));
                    }
                    fields.push(Field {
                        name,
                        size,
                        kind,
                        count,
                    });
                }
                let points = match (points, width) {
                    (Some(p), _) => p,
                    (None, Some(w)) => w.saturating_mul(height),
                    (None, None) => {
                        return Err(syntax(
                            line_no,
                            "the header gives neither POINTS nor WIDTH".into(),
                        ))
                    }
                };
                return Ok(Header {
                    fields,
                    width,
                    height,
                    points,
                    data,
                    points_line,
                    body: offset.min(bytes.len()),
                    body_line: line_no + 1,
                });
            }
            other => {
                return Err(syntax(
                    line_no,
                    format!("unknown header keyword '{}'", show(other)),
                ))
            }
        }
    }
    Err(ReadError::Truncated {
        format: PCD,
        at: Location::Byte(bytes.len()),
        message: "the header has no DATA line".into(),
    })
}

/// Where x, y and z are in a record: (byte offset, field) and the token index for ascii.
#[derive(Clone, Copy)]
struct Coord<'a> {
    field: &'a Field,
    byte: usize,
    token: usize,
    /// Byte offset of the field's column in decompressed binary_compressed data, per point.
    column: usize,
}

pub fn read(bytes: &[u8]) -> Result<LoadedFile, ReadError> {
    let h = parse_header(bytes)?;
    let mut coords: [Option<Coord>; 3] = [None; 3];
    let (mut byte, mut token, mut column) = (0usize, 0usize, 0usize);
    for f in &h.fields {
        let k = match f.name.as_str() {
            "x" => Some(0),
            "y" => Some(1),
            "z" => Some(2),
            _ => None,
        };
        if let Some(k) = k {
            if f.count > 0 {
                coords[k] = Some(Coord {
                    field: f,
                    byte,
                    token,
                    column,
                });
            }
        }
        let width = f.size.saturating_mul(f.count);
        byte = byte.saturating_add(width);
        token = token.saturating_add(f.count);
        column = column.saturating_add(width.saturating_mul(h.points));
    }
    let record = byte;
    let (Some(x), Some(y)) = (coords[0], coords[1]) else {
        return Err(syntax(
            h.body_line.saturating_sub(1),
            "the FIELDS have no x and y".into(),
        ));
    };
    let xyz = [x, y, coords[2].unwrap_or(x)];
    let has_z = coords[2].is_some();
    let mut points: Vec<Option<Point3>> = Vec::new();
    let rest = &bytes[h.body..];
    match h.data {
        Data::Ascii => read_ascii(rest, &h, xyz, has_z, &mut points)?,
        Data::Binary => {
            check_room(h.points.saturating_mul(record), rest.len(), &h)?;
            points.reserve(h.points);
            for i in 0..h.points {
                let at = i * record;
                points.push(binary_point(
                    &rest[at..at + record],
                    xyz,
                    has_z,
                    h.body + at,
                )?);
            }
        }
        Data::Compressed => {
            let data = decompress(rest, h.points.saturating_mul(record), &h)?;
            points.reserve(h.points);
            for i in 0..h.points {
                let value = |c: Coord| {
                    let at = c.column + i * c.field.size * c.field.count;
                    decode(&data[at..at + c.field.size], c.field)
                };
                let p = [
                    value(xyz[0]),
                    value(xyz[1]),
                    if has_z { value(xyz[2]) } else { 0.0 },
                ];
                points.push(valid(p, Location::Byte(h.body))?);
            }
        }
    }
    finish(points, &h, has_z)
}

fn check_room(needed: usize, remaining: usize, h: &Header) -> Result<(), ReadError> {
    if needed <= remaining {
        return Ok(());
    }
    Err(ReadError::Truncated {
        format: PCD,
        at: Location::Byte(h.body + remaining),
        message: format!(
            "the header (line {}) declares {} points, which need {needed} bytes, but only \
             {remaining} follow it",
            h.points_line, h.points
        ),
    })
}

fn read_ascii(
    rest: &[u8],
    h: &Header,
    xyz: [Coord; 3],
    has_z: bool,
    points: &mut Vec<Option<Point3>>,
) -> Result<(), ReadError> {
    // Each point line takes at least two bytes ("0\n").
    check_room(h.points.saturating_mul(2).saturating_sub(1), rest.len(), h)?;
    points.reserve(h.points);
    let mut rows = lines(rest).filter(|(_, l)| !l.trim_ascii().is_empty());
    for i in 0..h.points {
        let Some((n, line)) = rows.next() else {
            return Err(ReadError::Truncated {
                format: PCD,
                at: Location::Line(h.points_line),
                message: format!(
                    "the file has {i} of the {} points the header declares",
                    h.points
                ),
            });
        };
        let line_no = h.body_line + n - 1;
        let at = Location::Line(line_no);
        let t: Vec<&[u8]> = tokens(line).collect();
        let mut p = [0.0; 3];
        for (k, c) in xyz.iter().enumerate().take(if has_z { 3 } else { 2 }) {
            let tok = t.get(c.token).ok_or_else(|| {
                syntax(
                    line_no,
                    format!(
                        "expected at least {} values, found {}",
                        c.token + 1,
                        t.len()
                    ),
                )
            })?;
            p[k] = match parse_f64(tok) {
                Some(v) if v.is_nan() => f64::NAN,
                _ => coordinate(tok, PCD, at)?,
            };
        }
        points.push(valid(p, at)?);
    }
    Ok(())
}

/// A point, `None` for PCL's NaN marker of an invalid point; infinite values are an error.
fn valid(p: [f64; 3], at: Location) -> Result<Option<Point3>, ReadError> {
    if p.iter().any(|v| v.is_nan()) {
        return Ok(None);
    }
    if p.iter().any(|v| v.is_infinite()) {
        return Err(ReadError::NonFinite { format: PCD, at });
    }
    Ok(Some(Point3::from_array(p)))
}

fn binary_point(
    rec: &[u8],
    xyz: [Coord; 3],
    has_z: bool,
    offset: usize,
) -> Result<Option<Point3>, ReadError> {
    let v = |c: Coord| decode(&rec[c.byte..c.byte + c.field.size], c.field);
    let p = [v(xyz[0]), v(xyz[1]), if has_z { v(xyz[2]) } else { 0.0 }];
    valid(p, Location::Byte(offset))
}

/// A little-endian value of the field's type (`bytes.len() == field.size`).
fn decode(b: &[u8], f: &Field) -> f64 {
    let mut w = [0u8; 8];
    w[..b.len()].copy_from_slice(b);
    let u = u64::from_le_bytes(w);
    match (f.kind, f.size) {
        (Kind::Float, 4) => f64::from(f32::from_bits(u as u32)),
        (Kind::Float, _) => f64::from_bits(u),
        (Kind::Unsigned, _) => u as f64,
        (Kind::Signed, size) => {
            // Sign-extend from `size` bytes.
            let shift = 64 - 8 * size as u32;
            ((u << shift) as i64 >> shift) as f64
        }
    }
}

/// The decompressed column data of `DATA binary_compressed`: two u32 sizes, then LZF.
fn decompress(rest: &[u8], expected: usize, h: &Header) -> Result<Vec<u8>, ReadError> {
    let word = |k: usize| -> Option<usize> {
        let b = rest.get(4 * k..4 * k + 4)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let (Some(compressed), Some(size)) = (word(0), word(1)) else {
        return Err(ReadError::Truncated {
            format: PCD,
            at: Location::Byte(h.body + rest.len()),
            message: "expected the compressed and uncompressed sizes".into(),
        });
    };
    if size != expected {
        return Err(ReadError::Syntax {
            format: PCD,
            at: Location::Byte(h.body + 4),
            message: format!(
                "the uncompressed size is {size} bytes, but {} points of the declared fields take \
                 {expected}",
                h.points
            ),
        });
    }
    let input = &rest[8..];
    if compressed > input.len() {
        return Err(ReadError::Truncated {
            format: PCD,
            at: Location::Byte(h.body + rest.len()),
            message: format!(
                "the compressed data is {compressed} bytes, but only {} follow",
                input.len()
            ),
        });
    }
    if size > compressed.saturating_mul(LZF_MAX_RATIO) {
        return Err(ReadError::Syntax {
            format: PCD,
            at: Location::Byte(h.body),
            message: format!("{compressed} bytes of LZF data cannot hold {size} bytes"),
        });
    }
    lzf_decompress(&input[..compressed], size).map_err(|(at, message)| ReadError::Syntax {
        format: PCD,
        at: Location::Byte(h.body + 8 + at),
        message,
    })
}

/// Decompresses LZF (liblzf's format) into exactly `size` bytes, or says at which input byte
/// it went wrong.
fn lzf_decompress(input: &[u8], size: usize) -> Result<Vec<u8>, (usize, String)> {
    let mut out = Vec::with_capacity(size);
    let mut ip = 0;
    while ip < input.len() {
        let at = ip;
        let ctrl = usize::from(input[ip]);
        ip += 1;
        if ctrl < 32 {
            let run = ctrl + 1;
            let lit = input
                .get(ip..ip + run)
                .ok_or((at, "LZF literal run past the end of the data".to_string()))?;
            if out.len() + run > size {
                return Err((at, "LZF data decompresses past the declared size".into()));
            }
            out.extend_from_slice(lit);
            ip += run;
        } else {
            let mut len = ctrl >> 5;
            if len == 7 {
                len += usize::from(
                    *input
                        .get(ip)
                        .ok_or((at, "LZF data ends in a back reference".to_string()))?,
                );
                ip += 1;
            }
            let low = usize::from(
                *input
                    .get(ip)
                    .ok_or((at, "LZF data ends in a back reference".to_string()))?,
            );
            ip += 1;
            let back = ((ctrl & 0x1f) << 8) + low + 1;
            let len = len + 2;
            let start = out.len().checked_sub(back).ok_or((
                at,
                "LZF back reference before the start of the data".to_string(),
            ))?;
            if out.len() + len > size {
                return Err((at, "LZF data decompresses past the declared size".into()));
            }
            for k in 0..len {
                let b = out[start + k];
                out.push(b);
            }
        }
    }
    if out.len() != size {
        return Err((
            input.len(),
            format!(
                "LZF data gives {} bytes, not the declared {size}",
                out.len()
            ),
        ));
    }
    Ok(out)
}

fn finish(points: Vec<Option<Point3>>, h: &Header, has_z: bool) -> Result<LoadedFile, ReadError> {
    let organised =
        h.height > 1 && h.width.map(|w| w.saturating_mul(h.height)) == Some(points.len());
    let mut positions = Vec::with_capacity(points.len());
    let mut cells = Vec::with_capacity(if organised { points.len() } else { 0 });
    for p in points {
        match p {
            Some(p) => {
                let index = u32::try_from(positions.len())
                    .map_err(|_| syntax(h.points_line, "more than 2³² points".into()))?;
                cells.push(Some(index));
                positions.push(p);
            }
            None => cells.push(None),
        }
    }
    let range_grid = if organised {
        h.width.and_then(|w| RangeGrid::try_new(w, h.height, cells))
    } else {
        None
    };
    let mesh = PolyMesh::from_points(positions)?;
    Ok(LoadedFile {
        range_grid,
        dimension: if has_z { 3 } else { 2 },
        ..LoadedFile::from_mesh(PCD, mesh)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lzf_round_trip_of_a_hand_made_stream() {
        // literal "abc", then a back reference of 5 bytes at distance 3 -> "abcabcab".
        let data = [2, b'a', b'b', b'c', (3 << 5), 2];
        assert_eq!(lzf_decompress(&data, 8).unwrap(), b"abcabcab");
        assert!(lzf_decompress(&data, 7).is_err());
        assert!(lzf_decompress(&[0x20, 5], 3).is_err());
        assert!(lzf_decompress(&[5, 1], 6).is_err());
    }

    #[test]
    fn ascii_binary_and_organised_clouds() {
        let f = read(b"# .PCD v0.7\nVERSION 0.7\nFIELDS x y z i\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3 9\n4 5 6 9\n").unwrap();
        assert_eq!(f.mesh.positions()[1], Point3::new(4.0, 5.0, 6.0));
        let mut bin = b"VERSION 0.7\nFIELDS rgb x y z\nSIZE 4 2 2 8\nTYPE U I I F\nWIDTH 2\nHEIGHT 2\nPOINTS 4\nDATA binary\n".to_vec();
        for (x, y, z) in [
            (-1i16, 2i16, 0.5f64),
            (3, 4, f64::NAN),
            (5, 6, 1.0),
            (7, 8, 2.0),
        ] {
            bin.extend([0u8; 4]);
            bin.extend(x.to_le_bytes());
            bin.extend(y.to_le_bytes());
            bin.extend(z.to_le_bytes());
        }
        let f = read(&bin).unwrap();
        assert_eq!(f.mesh.num_vertices(), 3);
        assert_eq!(f.mesh.positions()[0], Point3::new(-1.0, 2.0, 0.5));
        let g = f.range_grid.unwrap();
        assert_eq!(
            (g.cols(), g.rows(), g.cell(1, 0), g.cell(0, 1)),
            (2, 2, None, Some(1))
        );
        let e = read(&bin[..bin.len() - 1]).unwrap_err();
        assert!(matches!(e, ReadError::Truncated { .. }), "{e}");
        assert!(looks_like(b"VERSION .7\nFIELDS x y z\n"));
        assert!(!looks_like(b"1 2 3\n"));
    }
}
