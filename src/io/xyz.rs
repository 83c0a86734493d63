//! Plain point text: XYZ, CSV and PTS. One point per line, fields separated by whitespace,
//! commas or semicolons; leading non-numeric lines are a header; `#` and `//` lines are
//! comments; a line holding one integer is a PTS point count and is skipped; columns beyond
//! x, y, z (intensity, colour, normals) are ignored; a PTS count must match the number of point
//! lines that follow it (up to the next count line or the end). Files with two numeric columns are 2D
//! points (z = 0). In a line separated by semicolons a comma is a decimal comma (`1,5;2,5`),
//! as spreadsheets in many locales write CSV.

use super::text::{coordinate, lines, parse_f64, parse_i64, show};
use super::{Format, LoadedFile, Location, ReadError};
use crate::geom::Point3;
use crate::mesh::PolyMesh;
use std::borrow::Cow;

const XYZ: Format = Format::Xyz;

/// The fields of a line, without surrounding quotes.
fn fields(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    let comma_separates = !line.contains(&b';');
    line.split(move |&b| b.is_ascii_whitespace() || b == b';' || (comma_separates && b == b','))
        .filter(|f| !f.is_empty())
        .map(|f| f.strip_prefix(b"\"").unwrap_or(f))
        .map(|f| f.strip_suffix(b"\"").unwrap_or(f))
}

/// A field with a decimal comma turned into a point (fields only keep commas in
/// semicolon-separated lines).
fn decimal_point(field: &[u8]) -> Cow<'_, [u8]> {
    if field.contains(&b',') {
        Cow::Owned(
            field
                .iter()
                .map(|&b| if b == b',' { b'.' } else { b })
                .collect(),
        )
    } else {
        Cow::Borrowed(field)
    }
}

/// How many leading fields (at most three) are numbers: 2 or 3 for a point line.
pub fn numeric_fields(line: &[u8]) -> usize {
    fields(line)
        .take(3)
        .take_while(|f| parse_f64(&decimal_point(f)).is_some())
        .count()
}

fn is_comment(line: &[u8]) -> bool {
    let t = line.trim_ascii_start();
    t.starts_with(b"#") || t.starts_with(b"//")
}

/// The count of a PTS count line (a line holding one integer), if `line` is one.
fn count_line(line: &[u8]) -> Option<i64> {
    let mut f = fields(line);
    match (f.next(), f.next()) {
        (Some(n), None) => parse_i64(n),
        _ => None,
    }
}

/// A PTS block's count (its line and value) against the points read since.
fn check_count(declared: Option<(usize, i64)>, read: usize) -> Result<(), ReadError> {
    let Some((line, n)) = declared else {
        return Ok(());
    };
    if i64::try_from(read).ok() == Some(n) {
        return Ok(());
    }
    let message = format!("the PTS count line says {n} points, {read} follow it");
    Err(if i64::try_from(read).is_ok_and(|r| r < n) {
        ReadError::Truncated {
            format: XYZ,
            at: Location::Line(line),
            message,
        }
    } else {
        ReadError::Syntax {
            format: XYZ,
            at: Location::Line(line),
            message,
        }
    })
}

pub fn read(bytes: &[u8]) -> Result<LoadedFile, ReadError> {
    let mut positions = Vec::new();
    let mut columns = 0;
    let mut declared = None;
    let mut since = 0;
    for (line_no, line) in lines(bytes) {
        if let Some(n) = count_line(line) {
            check_count(declared, since)?;
            declared = Some((line_no, n));
            since = 0;
            continue;
        }
        if is_comment(line) || fields(line).next().is_none() {
            continue;
        }
        if columns == 0 {
            columns = numeric_fields(line);
            if columns < 2 {
                columns = 0; // still in the header
                continue;
            }
        }
        positions.push(point(line, line_no, columns)?);
        since += 1;
    }
    check_count(declared, since)?;
    let mesh = PolyMesh::from_points(positions)?;
    Ok(LoadedFile {
        dimension: if columns == 2 { 2 } else { 3 },
        ..LoadedFile::from_mesh(XYZ, mesh)
    })
}

fn point(line: &[u8], line_no: usize, columns: usize) -> Result<Point3, ReadError> {
    let at = Location::Line(line_no);
    let mut xyz = [0.0; 3];
    let mut f = fields(line);
    for (k, c) in xyz.iter_mut().take(columns).enumerate() {
        let t = f.next().ok_or_else(|| ReadError::Syntax {
            format: XYZ,
            at,
            message: format!("expected {columns} numbers, found {k}"),
        })?;
        *c = field_coordinate(t, at)?;
    }
    Ok(Point3::from_array(xyz))
}

/// A coordinate field, read with [`decimal_point`]; errors quote the field as written.
fn field_coordinate(field: &[u8], at: Location) -> Result<f64, ReadError> {
    match decimal_point(field) {
        Cow::Borrowed(f) => coordinate(f, XYZ, at),
        Cow::Owned(f) => coordinate(&f, XYZ, at).map_err(|e| match e {
            ReadError::Syntax { .. } => ReadError::Syntax {
                format: XYZ,
                at,
                message: format!("expected a number, found '{}'", show(field)),
            },
            other => other,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_with_header_and_extra_columns() {
        let f = read(b"x;y;z;i\n# c\n1;2;3;9\n\"4\",\"5\",\"6\"\n").unwrap();
        assert_eq!(f.mesh.positions()[1], Point3::new(4.0, 5.0, 6.0));
        assert_eq!(f.dimension, 3);
    }

    #[test]
    fn semicolons_with_decimal_commas() {
        let f = read(b"x;y;z\n1,5;-2,25;3\n").unwrap();
        assert_eq!(f.mesh.positions()[0], Point3::new(1.5, -2.25, 3.0));
        let e = read(b"1;2;3\n1,5,1;2;3\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "XYZ line 2: expected a number, found '1,5,1'"
        );
    }

    #[test]
    fn pts_count_lines_and_2d_files() {
        let f = read(b"2\n1 2 3 10 255 0 0\n4 5 6 10 0 255 0\n").unwrap();
        assert_eq!(f.mesh.num_vertices(), 2);
        // Blocks, each with its count (Cyclone writes one per scan).
        let f = read(b"1\n1 2 3 -5\n2\n1 2 3 -5\n4 5 6 7\n").unwrap();
        assert_eq!(f.mesh.num_vertices(), 3);
        let e = read(b"3\n1 2 3 10\n4 5 6 10\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "XYZ line 1: file ends early: the PTS count line says 3 points, 2 follow it"
        );
        let e = read(b"1\n1 2 3 10\n4 5 6 10\n").unwrap_err();
        assert!(
            matches!(
                e,
                ReadError::Syntax {
                    at: Location::Line(1),
                    ..
                }
            ),
            "{e}"
        );
        let f = read(b"0.5 1\n2 3\n").unwrap();
        assert_eq!(f.dimension, 2);
        assert_eq!(f.mesh.positions()[1], Point3::new(2.0, 3.0, 0.0));
    }

    #[test]
    fn errors_name_the_line() {
        let e = read(b"x y z\n1 2 3\n4 five 6\n").unwrap_err();
        assert_eq!(e.to_string(), "XYZ line 3: expected a number, found 'five'");
        let e = read(b"1 2 3\n4\n5 6\n").unwrap_err();
        assert_eq!(e.to_string(), "XYZ line 3: expected 3 numbers, found 2");
        let e = read(b"1 2 3\n1 2 NaN\n").unwrap_err();
        assert!(matches!(
            e,
            ReadError::NonFinite {
                at: Location::Line(2),
                ..
            }
        ));
    }
}
