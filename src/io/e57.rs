//! ASTM E57 (terrestrial laser scanners), read with the `e57` crate.
//!
//! Every scan (`data3D` entry) is read with its pose applied, so the points of all scans are in
//! the file's common frame; spherical coordinates are converted to Cartesian ones; points
//! marked invalid (or only a direction) are left out. A structured scan (with `rowIndex` and
//! `columnIndex`) keeps its grid as a [`RangeGrid`] when the file has that one scan only (see
//! [`LoadedFile::scans`] for why several scans keep none), with its invalid points as empty
//! cells. E57 coordinates are metres by the standard.

use super::{Format, LoadedFile, Location, RangeGrid, ReadError};
use crate::geom::Point3;
use crate::mesh::PolyMesh;
use e57::{CartesianCoordinate, E57Reader};
use std::io::Cursor;

const E57: Format = Format::E57;

/// The fixed file header: signature, version, lengths and the page size.
const HEADER_LEN: usize = 48;

/// A grid may have at most this many cells per measured point; a sparser one (indices that
/// spread far beyond the points) is not kept, since its cells would cost more memory than the
/// points themselves and triangulate almost nothing.
const MAX_CELLS_PER_POINT: usize = 16;

/// At least one bit of point data per point: bounds the record count the XML may claim (E57
/// can pack a constant field into zero bits).
const MAX_POINTS_PER_BYTE: usize = 8;

fn invalid(at: Location, e: impl std::fmt::Display) -> ReadError {
    ReadError::Syntax {
        format: E57,
        at,
        message: e.to_string(),
    }
}

/// Checks the header's lengths against the file before the crate allocates by them.
fn check_header(bytes: &[u8]) -> Result<(), ReadError> {
    let Some(h) = bytes.get(..HEADER_LEN) else {
        return Err(ReadError::Truncated {
            format: E57,
            at: Location::Byte(bytes.len()),
            message: format!("the file header takes {HEADER_LEN} bytes"),
        });
    };
    let word = |at: usize| {
        let mut w = [0u8; 8];
        w.copy_from_slice(&h[at..at + 8]);
        u64::from_le_bytes(w)
    };
    let (physical, xml_offset, xml_len) = (word(16), word(24), word(32));
    let len = bytes.len() as u64;
    if physical > len {
        return Err(ReadError::Truncated {
            format: E57,
            at: Location::Byte(16),
            message: format!(
                "the header gives a file length of {physical} bytes, the file has {len}"
            ),
        });
    }
    if xml_offset >= len || xml_len > len {
        return Err(ReadError::Truncated {
            format: E57,
            at: Location::Byte(24),
            message: format!(
                "the XML section ({xml_len} bytes at {xml_offset}) lies past the end of the file"
            ),
        });
    }
    Ok(())
}

/// Row/column bounds of a scan's records while they are read.
struct GridBounds {
    min: (i64, i64),
    max: (i64, i64),
}

pub fn read(bytes: &[u8]) -> Result<LoadedFile, ReadError> {
    check_header(bytes)?;
    let mut reader =
        E57Reader::new(Cursor::new(bytes)).map_err(|e| invalid(Location::Byte(0), e))?;
    let clouds = reader.pointclouds();
    let max_points = bytes.len().saturating_mul(MAX_POINTS_PER_BYTE);
    let mut positions: Vec<Point3> = Vec::new();
    let mut grid = None;
    for (k, pc) in clouds.iter().enumerate() {
        let at = Location::Item("scan", k);
        if !pc.has_cartesian() && !pc.has_spherical() {
            return Err(ReadError::Unsupported {
                format: E57,
                at,
                message: "the scan has neither Cartesian nor spherical coordinates".into(),
            });
        }
        let records = usize::try_from(pc.records).unwrap_or(usize::MAX);
        if records > max_points.saturating_sub(positions.len()) {
            return Err(invalid(
                at,
                format!("the scan declares {records} points, more than the file can hold"),
            ));
        }
        let structured = clouds.len() == 1 && pc.has_row_column();
        let mut cells: Vec<(i64, i64, u32)> = Vec::new();
        let mut bounds = GridBounds {
            min: (i64::MAX, i64::MAX),
            max: (i64::MIN, i64::MIN),
        };
        let start = positions.len();
        let points = reader.pointcloud_simple(pc).map_err(|e| invalid(at, e))?;
        for (i, p) in points.enumerate() {
            if i >= records {
                break;
            }
            let p = p.map_err(|e| invalid(at, format!("point {i}: {e}")))?;
            if structured {
                bounds.min = (bounds.min.0.min(p.row), bounds.min.1.min(p.column));
                bounds.max = (bounds.max.0.max(p.row), bounds.max.1.max(p.column));
            }
            let CartesianCoordinate::Valid { x, y, z } = p.cartesian else {
                continue;
            };
            let q = Point3::new(x, y, z);
            if !q.is_finite() {
                return Err(ReadError::NonFinite { format: E57, at });
            }
            let index =
                u32::try_from(positions.len()).map_err(|_| invalid(at, "more than 2³² points"))?;
            if structured {
                cells.push((p.row, p.column, index));
            }
            positions.push(q);
        }
        if structured {
            grid = build_grid(&bounds, &cells, positions.len() - start);
        }
    }
    let mesh = PolyMesh::from_points(positions)?;
    Ok(LoadedFile {
        range_grid: grid,
        scans: Some(clouds.len()),
        unit_to_metres: Some(1.0),
        ..LoadedFile::from_mesh(E57, mesh)
    })
}

/// The scan's grid: columns and rows spanning the indices seen, cells holding the points.
/// `None` when no index was seen, or when the grid would exceed [`MAX_CELLS_PER_POINT`].
fn build_grid(b: &GridBounds, cells: &[(i64, i64, u32)], points: usize) -> Option<RangeGrid> {
    let rows = usize::try_from(b.max.0.checked_sub(b.min.0)?.checked_add(1)?).ok()?;
    let cols = usize::try_from(b.max.1.checked_sub(b.min.1)?.checked_add(1)?).ok()?;
    let n = rows.checked_mul(cols)?;
    if n > points.max(1).saturating_mul(MAX_CELLS_PER_POINT) {
        return None;
    }
    let mut grid = vec![None; n];
    for &(r, c, index) in cells {
        let (r, c) = ((r - b.min.0) as usize, (c - b.min.1) as usize);
        let cell = grid.get_mut(r * cols + c)?;
        if cell.is_some() {
            // Two points in one cell (several returns): not a range image.
            return None;
        }
        *cell = Some(index);
    }
    RangeGrid::try_new(cols, rows, grid)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_lengths_are_checked_first() {
        let mut h = b"ASTM-E57".to_vec();
        h.resize(HEADER_LEN, 0);
        h[32..40].copy_from_slice(&u64::MAX.to_le_bytes());
        let e = read(&h).unwrap_err();
        assert!(
            matches!(
                e,
                ReadError::Truncated {
                    at: Location::Byte(24),
                    ..
                }
            ),
            "{e}"
        );
        assert!(matches!(
            read(b"ASTM-E57"),
            Err(ReadError::Truncated { .. })
        ));
    }

    #[test]
    fn grids_need_distinct_cells_and_enough_points() {
        let b = GridBounds {
            min: (0, 0),
            max: (1, 2),
        };
        let g = build_grid(&b, &[(0, 0, 0), (1, 2, 1)], 2).unwrap();
        assert_eq!((g.cols(), g.rows(), g.cell(2, 1)), (3, 2, Some(1)));
        assert!(build_grid(&b, &[(0, 0, 0), (0, 0, 1)], 2).is_none());
        let wide = GridBounds {
            min: (0, 0),
            max: (0, 1000),
        };
        assert!(build_grid(&wide, &[(0, 0, 0)], 1).is_none());
    }
}
