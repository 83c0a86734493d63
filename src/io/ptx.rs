//! Leica PTX: one or more gridded scans, each a header and then `rows × cols` point lines.
//!
//! The header of a scan is ten lines: the number of columns, the number of rows, the scanner's
//! registered position and its X, Y and Z axes (three numbers each), then a 4 × 4 pose written
//! for row vectors: `[x y z 1] · M` is the registered point (rotation in the upper 3 × 3,
//! translation in the last row). Each point line holds `x y z` in the scanner's frame, usually
//! followed by an intensity and sometimes by `r g b`; columns after `z` are ignored. The points
//! are listed column by column (each column one vertical sweep of the scanner), and a cell the
//! laser did not measure is written as `0 0 0`: it becomes an empty grid cell and no point, as
//! in a Cyberware range grid.

use super::text::{coordinate, parse_i64, show, tokens};
use super::{Format, LoadedFile, Location, RangeGrid, ReadError};
use crate::geom::Point3;
use crate::mesh::PolyMesh;

const PTX: Format = Format::Ptx;

/// The shortest a point line can be (`0 0 0` and its newline); bounds the cells a header may
/// declare against the bytes that follow.
const MIN_POINT_LINE: usize = 6;

/// The non-blank lines of a file, with their 1-based numbers, and how many bytes remain.
struct Lines<'a> {
    bytes: &'a [u8],
    /// Byte offset of the next line not yet returned.
    pos: usize,
    /// Number of the line starting at `pos`.
    line: usize,
    /// The number of the last line returned (0 before the first).
    last: usize,
}

impl<'a> Lines<'a> {
    fn new(bytes: &'a [u8]) -> Lines<'a> {
        Lines {
            bytes,
            pos: 0,
            line: 1,
            last: 0,
        }
    }

    /// Skips blank lines; true when a non-blank line starts at `pos`.
    fn skip_blank(&mut self) -> bool {
        while self.pos < self.bytes.len() {
            let rest = &self.bytes[self.pos..];
            let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
            if !rest[..len].trim_ascii().is_empty() {
                return true;
            }
            self.pos += len + 1;
            self.line += 1;
        }
        false
    }

    fn next(&mut self) -> Option<(usize, &'a [u8])> {
        if !self.skip_blank() {
            return None;
        }
        let rest = &self.bytes[self.pos..];
        let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        let line = &rest[..len];
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        let n = self.line;
        self.pos += len + 1;
        self.line += 1;
        self.last = n;
        Some((n, line))
    }

    /// Bytes from the next non-blank line to the end (0 at the end).
    fn remaining(&mut self) -> usize {
        self.skip_blank();
        self.bytes.len().saturating_sub(self.pos)
    }

    fn at_end(&mut self) -> bool {
        !self.skip_blank()
    }
}

/// Whether `head` starts like a PTX file: two lines holding one positive integer each, then
/// four lines of three numbers and four of four (the ten-line scan header).
pub fn looks_like(head: &[u8]) -> bool {
    let mut it = Lines::new(head);
    let mut shape = Vec::with_capacity(10);
    for _ in 0..10 {
        let Some((_, line)) = it.next() else {
            return false;
        };
        let t: Vec<&[u8]> = tokens(line).collect();
        let numeric = t.iter().all(|f| super::text::parse_f64(f).is_some());
        if !numeric {
            return false;
        }
        shape.push(t.len());
    }
    let counts_ok = (0..2).all(|k| {
        let mut t = tokens(head_line(head, k));
        matches!(t.next().and_then(parse_i64), Some(n) if n > 0)
    });
    counts_ok && shape == [1, 1, 3, 3, 3, 3, 4, 4, 4, 4]
}

/// The k-th non-blank line of `head`.
fn head_line(head: &[u8], k: usize) -> &[u8] {
    let mut it = Lines::new(head);
    for _ in 0..k {
        it.next();
    }
    it.next().map_or(&[][..], |(_, l)| l)
}

/// One scan's grid while it is read: row-major cells.
struct ScanGrid {
    cols: usize,
    rows: usize,
    cells: Vec<Option<u32>>,
}

pub fn read(bytes: &[u8]) -> Result<LoadedFile, ReadError> {
    let mut lines = Lines::new(bytes);
    let mut positions = Vec::new();
    let mut scans = 0;
    let mut first_grid = None;
    while !lines.at_end() {
        let grid = read_scan(&mut lines, &mut positions, scans)?;
        if scans == 0 {
            first_grid = Some(grid);
        } else {
            first_grid = None;
        }
        scans += 1;
    }
    let range_grid = first_grid.and_then(|g| RangeGrid::try_new(g.cols, g.rows, g.cells));
    let mesh = PolyMesh::from_points(positions)?;
    Ok(LoadedFile {
        range_grid,
        scans: Some(scans),
        ..LoadedFile::from_mesh(PTX, mesh)
    })
}

/// Reads one scan (header and points), appending its measured points in world coordinates.
fn read_scan(
    lines: &mut Lines,
    positions: &mut Vec<Point3>,
    scan: usize,
) -> Result<ScanGrid, ReadError> {
    let (line_cols, cols) = count_line(lines, "the number of columns")?;
    let (_, rows) = count_line(lines, "the number of rows")?;
    for what in [
        "scanner position",
        "scanner X axis",
        "scanner Y axis",
        "scanner Z axis",
    ] {
        numbers::<3>(lines, what)?;
    }
    let mut m = [[0.0; 4]; 4];
    for (k, row) in m.iter_mut().enumerate() {
        *row = numbers::<4>(
            lines,
            ["pose row 1", "pose row 2", "pose row 3", "pose row 4"][k],
        )?;
    }
    let cells = cols
        .checked_mul(rows)
        .filter(|&n| n.saturating_mul(MIN_POINT_LINE).saturating_sub(1) <= lines.remaining());
    let Some(cells) = cells else {
        return Err(ReadError::Truncated {
            format: PTX,
            at: Location::Line(line_cols),
            message: format!(
                "scan {} declares {cols} × {rows} points, more than the {} remaining bytes can hold",
                scan + 1,
                lines.remaining()
            ),
        });
    };
    let mut grid = vec![None; cells];
    for i in 0..cells {
        let Some((line_no, line)) = lines.next() else {
            return Err(ReadError::Truncated {
                format: PTX,
                at: Location::Line(line_cols),
                message: format!(
                    "scan {} has {i} of its {cols} × {rows} point lines",
                    scan + 1
                ),
            });
        };
        let p = point(line, line_no)?;
        if p == [0.0; 3] {
            continue;
        }
        let index = u32::try_from(positions.len()).map_err(|_| ReadError::Syntax {
            format: PTX,
            at: Location::Line(line_no),
            message: "more than 2³² points".into(),
        })?;
        // Column by column: point i is row i % rows of column i / rows.
        let (col, row) = (i / rows, i % rows);
        grid[row * cols + col] = Some(index);
        positions.push(transform(&m, p));
    }
    Ok(ScanGrid {
        cols,
        rows,
        cells: grid,
    })
}

/// `[x y z 1] · M`, in f64.
fn transform(m: &[[f64; 4]; 4], p: [f64; 3]) -> Point3 {
    let c = |j: usize| p[0] * m[0][j] + p[1] * m[1][j] + p[2] * m[2][j] + m[3][j];
    Point3::new(c(0), c(1), c(2))
}

fn count_line(lines: &mut Lines, what: &str) -> Result<(usize, usize), ReadError> {
    let (line_no, line) = lines.next().ok_or_else(|| ReadError::Truncated {
        format: PTX,
        at: Location::Line(lines.last + 1),
        message: format!("expected {what}"),
    })?;
    let mut t = tokens(line);
    let value = match (t.next(), t.next()) {
        (Some(tok), None) => parse_i64(tok).and_then(|n| usize::try_from(n).ok()),
        _ => None,
    };
    value
        .map(|n| (line_no, n))
        .ok_or_else(|| ReadError::Syntax {
            format: PTX,
            at: Location::Line(line_no),
            message: format!("expected {what} (one integer ≥ 0), found '{}'", show(line)),
        })
}

fn numbers<const N: usize>(lines: &mut Lines, what: &str) -> Result<[f64; N], ReadError> {
    let (line_no, line) = lines.next().ok_or_else(|| ReadError::Truncated {
        format: PTX,
        at: Location::Line(lines.last + 1),
        message: format!("the scan header ends before the {what}"),
    })?;
    leading_numbers(line, line_no, |k| {
        format!("expected {N} numbers for the {what}, found {k}")
    })
}

fn point(line: &[u8], line_no: usize) -> Result<[f64; 3], ReadError> {
    leading_numbers(line, line_no, |k| {
        format!("expected a point 'x y z [intensity [r g b]]', found {k} numbers")
    })
}

/// The first `N` numbers of `line` (more may follow); `missing(k)` words the error when the
/// line has only k.
fn leading_numbers<const N: usize>(
    line: &[u8],
    line_no: usize,
    missing: impl Fn(usize) -> String,
) -> Result<[f64; N], ReadError> {
    let at = Location::Line(line_no);
    let mut out = [0.0; N];
    let mut t = tokens(line);
    for (k, v) in out.iter_mut().enumerate() {
        let tok = t.next().ok_or_else(|| ReadError::Syntax {
            format: PTX,
            at,
            message: missing(k),
        })?;
        *v = coordinate(tok, PTX, at)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str =
        "2\n3\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 1 0 0\n-1 0 0 0\n0 0 1 0\n10 20 30 1\n";

    #[test]
    fn column_major_grid_with_pose_and_missing_cells() {
        // Column 0: rows 0..3, then column 1; the cell (col 1, row 1) is missing.
        let text =
            format!("{HEADER}1 0 0 0.5\n2 0 0 0.5\n3 0 0 0.5\n4 0 0 0.5\n0 0 0 0.5\n6 0 0 0.5\n");
        let f = read(text.as_bytes()).unwrap();
        assert_eq!(f.mesh.num_vertices(), 5);
        assert_eq!(f.scans, Some(1));
        // [1 0 0 1] · M = row 0 + row 3 = (10, 21, 30).
        assert_eq!(f.mesh.positions()[0], Point3::new(10.0, 21.0, 30.0));
        let g = f.range_grid.unwrap();
        assert_eq!((g.cols(), g.rows()), (2, 3));
        assert_eq!(g.cell(0, 2), Some(2));
        assert_eq!(g.cell(1, 0), Some(3));
        assert_eq!(g.cell(1, 1), None);
        assert_eq!(g.cell(1, 2), Some(4));
        assert!(looks_like(text.as_bytes()));
        assert!(!looks_like(b"2\n1 2 3 4\n5 6 7 8\n"));
    }

    #[test]
    fn two_scans_keep_no_grid_and_errors_name_the_line() {
        let scan = format!("{HEADER}1 0 0\n2 0 0\n3 0 0\n4 0 0\n5 0 0\n6 0 0\n");
        let f = read(format!("{scan}\n{scan}").as_bytes()).unwrap();
        assert_eq!((f.mesh.num_vertices(), f.scans), (12, Some(2)));
        assert!(f.range_grid.is_none());
        let e = read(format!("{HEADER}1 0 0\n2 x 0\n3 0 0\n4 0 0\n5 0 0\n6 0 0\n").as_bytes())
            .unwrap_err();
        assert_eq!(e.to_string(), "PTX line 12: expected a number, found 'x'");
        let e = read(format!("{HEADER}1 0 0\n").as_bytes()).unwrap_err();
        assert!(
            matches!(
                e,
                ReadError::Truncated {
                    at: Location::Line(1),
                    ..
                }
            ),
            "{e}"
        );
        let e = read(b"4000000000\n4000000000\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n1 2 3\n").unwrap_err();
        assert!(matches!(e, ReadError::Truncated { .. }), "{e}");
    }
}
