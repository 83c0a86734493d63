//! The PLY header: encoding, elements with their typed properties, and range-grid size.

use crate::io::text::{parse_i64, show, tokens};
use crate::io::{Format, Location, ReadError};

/// How the body is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// Size in bytes in a binary body.
    pub fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

/// A property's type: one scalar, or a list with a count type and an item type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PropKind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

/// A property of an element.
#[derive(Clone, Debug)]
pub struct Property {
    pub name: String,
    pub kind: PropKind,
}

/// An element declaration: `count` items, each made of `props` in order.
#[derive(Clone, Debug)]
pub struct Element {
    pub name: String,
    pub count: usize,
    pub props: Vec<Property>,
    /// Header line of the declaration, for error messages.
    pub line: usize,
}

/// A parsed header.
#[derive(Clone, Debug)]
pub struct Header {
    pub encoding: Encoding,
    pub elements: Vec<Element>,
    /// `obj_info num_cols N` (Cyberware range scans).
    pub num_cols: Option<usize>,
    /// `obj_info num_rows N`.
    pub num_rows: Option<usize>,
    /// Byte offset of the first body byte.
    pub body_offset: usize,
    /// Line number of the first body line (ASCII bodies).
    pub body_line: usize,
}

impl Header {
    /// The first element with this name.
    pub fn element(&self, name: &str) -> Option<&Element> {
        self.elements.iter().find(|e| e.name == name)
    }
}

fn error(line: usize, message: String) -> ReadError {
    ReadError::Syntax {
        format: Format::Ply,
        at: Location::Line(line),
        message,
    }
}

/// Header lines with their number and the byte offset just past each line's `\n`.
fn header_lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8], usize)> {
    let mut pos = 0;
    let mut line_no = 0;
    std::iter::from_fn(move || {
        if pos >= bytes.len() {
            return None;
        }
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |k| pos + k);
        let line = &bytes[pos..end];
        pos = (end + 1).min(bytes.len());
        line_no += 1;
        Some((line_no, line.strip_suffix(b"\r").unwrap_or(line), pos))
    })
}

pub fn parse(bytes: &[u8]) -> Result<Header, ReadError> {
    let mut lines = header_lines(bytes);
    match lines.next() {
        Some((_, b"ply", _)) => {}
        _ => return Err(error(1, "the file does not start with 'ply'".into())),
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let (mut num_cols, mut num_rows) = (None, None);
    let mut last_line = 1;
    for (line_no, line, next) in lines {
        last_line = line_no;
        let mut toks = tokens(line);
        match toks.next() {
            Some(b"end_header") => {
                let encoding = encoding
                    .ok_or_else(|| error(line_no, "end_header before any format line".into()))?;
                return Ok(Header {
                    encoding,
                    elements,
                    num_cols,
                    num_rows,
                    body_offset: next,
                    body_line: line_no + 1,
                });
            }
            Some(b"format") => encoding = Some(parse_format(toks.next(), line_no)?),
            Some(b"element") => elements.push(parse_element(toks, line_no)?),
            Some(b"property") => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| error(line_no, "property before any element".into()))?;
                el.props.push(parse_property(toks, line_no)?);
            }
            Some(b"obj_info") => match (toks.next(), toks.next().and_then(parse_i64)) {
                (Some(b"num_cols"), Some(n)) => num_cols = usize::try_from(n).ok(),
                (Some(b"num_rows"), Some(n)) => num_rows = usize::try_from(n).ok(),
                _ => {}
            },
            Some(b"comment") | None => {}
            Some(other) => {
                return Err(error(
                    line_no,
                    format!("unknown header keyword '{}'", show(other)),
                ))
            }
        }
    }
    Err(error(last_line, "the header has no end_header line".into()))
}

fn parse_format(token: Option<&[u8]>, line_no: usize) -> Result<Encoding, ReadError> {
    match token {
        Some(b"ascii") => Ok(Encoding::Ascii),
        Some(b"binary_little_endian") => Ok(Encoding::BinaryLittleEndian),
        Some(b"binary_big_endian") => Ok(Encoding::BinaryBigEndian),
        Some(t) => Err(error(line_no, format!("unknown format '{}'", show(t)))),
        None => Err(error(line_no, "format line has no format".into())),
    }
}

fn parse_element<'a>(
    mut toks: impl Iterator<Item = &'a [u8]>,
    line_no: usize,
) -> Result<Element, ReadError> {
    let (Some(name), Some(count)) = (toks.next(), toks.next()) else {
        return Err(error(line_no, "expected 'element NAME COUNT'".into()));
    };
    let count = std::str::from_utf8(count)
        .ok()
        .and_then(|c| c.parse::<u64>().ok())
        .and_then(|c| usize::try_from(c).ok())
        .ok_or_else(|| error(line_no, format!("bad element count '{}'", show(count))))?;
    Ok(Element {
        name: String::from_utf8_lossy(name).into_owned(),
        count,
        props: Vec::new(),
        line: line_no,
    })
}

fn parse_property<'a>(
    mut toks: impl Iterator<Item = &'a [u8]>,
    line_no: usize,
) -> Result<Property, ReadError> {
    let scalar = |t: Option<&[u8]>| {
        let t = t.ok_or_else(|| error(line_no, "property line is incomplete".into()))?;
        Scalar::parse(t).ok_or_else(|| error(line_no, format!("unknown type '{}'", show(t))))
    };
    let first = toks.next();
    let kind = if first == Some(b"list") {
        let count = scalar(toks.next())?;
        if matches!(count, Scalar::F32 | Scalar::F64) {
            return Err(error(
                line_no,
                "a list count must have an integer type".into(),
            ));
        }
        PropKind::List {
            count,
            item: scalar(toks.next())?,
        }
    } else {
        PropKind::Scalar(scalar(first)?)
    };
    let name = toks
        .next()
        .ok_or_else(|| error(line_no, "property has no name".into()))?;
    Ok(Property {
        name: String::from_utf8_lossy(name).into_owned(),
        kind,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_cyberware_header() {
        let h = parse(
            b"ply\r\nformat binary_big_endian 1.0\r\nobj_info num_cols 4\r\nobj_info num_rows 2\r\n\
              element vertex 2\r\nproperty float x\r\nelement range_grid 8\r\n\
              property list uchar int vertex_indices\r\nend_header\r\nBODY",
        )
        .unwrap();
        assert_eq!(h.encoding, Encoding::BinaryBigEndian);
        assert_eq!((h.num_cols, h.num_rows), (Some(4), Some(2)));
        assert_eq!(h.elements[1].count, 8);
        assert_eq!(
            h.elements[1].props[0].kind,
            PropKind::List {
                count: Scalar::U8,
                item: Scalar::I32
            }
        );
        assert_eq!(h.body_line, 10);
    }

    #[test]
    fn header_errors_name_the_line() {
        let e = parse(b"ply\nformat ascii 1.0\nelement vertex 3\nproperty floaty x\n").unwrap_err();
        assert_eq!(e.to_string(), "PLY line 4: unknown type 'floaty'");
        let e = parse(b"ply\nformat ascii 1.0\nelement vertex -3\n").unwrap_err();
        assert_eq!(e.to_string(), "PLY line 3: bad element count '-3'");
        let e = parse(b"ply\nformat ascii 1.0\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "PLY line 2: the header has no end_header line"
        );
        assert!(parse(b"plx\n").is_err());
    }
}
