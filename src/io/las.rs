//! ASPRS LAS 1.0–1.4 and LAZ (LASzip-compressed LAS).
//!
//! The public header gives the point data offset, the point format and record length, the point
//! count (64-bit in LAS 1.4) and the scale and offset of the coordinates; every point format
//! (0–10) starts its record with `X Y Z` as signed 32-bit integers, and a point is
//! `X · scale + offset`. The rest of the record (intensity, classification, time, colour, …) is
//! skipped. LAZ points are decompressed one at a time with the `laz` crate (sequentially: no
//! threads in the browser), after the chunk table and the LAS 1.4 layer sizes have been checked
//! against the file, so that no number in a damaged file makes it allocate more than the file
//! holds.

#[cfg(feature = "laz")]
mod laszip;
#[cfg(feature = "laz")]
use laszip::read_laz;

/// Without the `laz` feature a LAZ file is a typed error.
#[cfg(not(feature = "laz"))]
fn read_laz(_: &[u8], _: &Header) -> Result<Vec<Point3>, ReadError> {
    Err(super::not_built(Format::Laz, "laz"))
}

use super::{Format, LoadedFile, Location, ReadError};
use crate::geom::Point3;
use crate::mesh::PolyMesh;

/// The smallest public header (LAS 1.0–1.2).
const HEADER_MIN: usize = 227;
/// The minimum record length of point formats 0–10.
const RECORD_MIN: [usize; 11] = [20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67];

/// Whether the file starts with the LAS signature.
pub fn looks_like(bytes: &[u8]) -> bool {
    bytes.starts_with(b"LASF")
}

/// Whether the point format byte marks LASzip compression (bit 7 or 6 set).
pub fn is_compressed(bytes: &[u8]) -> bool {
    bytes.get(104).is_some_and(|b| b & 0xC0 != 0)
}

struct Header {
    format: Format,
    /// Where the VLRs start (LAZ looks for its VLR there).
    #[cfg_attr(not(feature = "laz"), allow(dead_code))]
    header_size: usize,
    offset: usize,
    #[cfg_attr(not(feature = "laz"), allow(dead_code))]
    vlr_count: usize,
    record_len: usize,
    points: usize,
    scale: [f64; 3],
    shift: [f64; 3],
}

fn le<const N: usize>(bytes: &[u8], at: usize) -> Option<[u8; N]> {
    bytes.get(at..at + N)?.try_into().ok()
}

fn u16_at(b: &[u8], at: usize) -> u16 {
    le::<2>(b, at).map_or(0, u16::from_le_bytes)
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    le::<4>(b, at).map_or(0, u32::from_le_bytes)
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    le::<8>(b, at).map_or(0, u64::from_le_bytes)
}

fn f64_at(b: &[u8], at: usize) -> f64 {
    le::<8>(b, at).map_or(f64::NAN, f64::from_le_bytes)
}

fn syntax(format: Format, at: usize, message: String) -> ReadError {
    ReadError::Syntax {
        format,
        at: Location::Byte(at),
        message,
    }
}

fn header(bytes: &[u8]) -> Result<Header, ReadError> {
    let format = if is_compressed(bytes) {
        Format::Laz
    } else {
        Format::Las
    };
    if bytes.len() < HEADER_MIN {
        return Err(ReadError::Truncated {
            format,
            at: Location::Byte(bytes.len()),
            message: format!("the public header takes at least {HEADER_MIN} bytes"),
        });
    }
    let (major, minor) = (bytes[24], bytes[25]);
    if major != 1 || minor > 4 {
        return Err(syntax(
            format,
            24,
            format!("unsupported LAS version {major}.{minor}"),
        ));
    }
    let header_size = usize::from(u16_at(bytes, 94));
    let offset = u32_at(bytes, 96) as usize;
    let point_format = bytes[104] & 0x3F;
    let record_len = usize::from(u16_at(bytes, 105));
    if header_size < HEADER_MIN || header_size > offset {
        return Err(syntax(
            format,
            94,
            format!("header size {header_size} is below {HEADER_MIN} or past the point data at {offset}"),
        ));
    }
    if offset > bytes.len() {
        return Err(ReadError::Truncated {
            format,
            at: Location::Byte(96),
            message: format!("the point data starts at byte {offset}, past the end of the file"),
        });
    }
    let Some(&min) = RECORD_MIN.get(usize::from(point_format)) else {
        return Err(syntax(
            format,
            104,
            format!("unknown point format {point_format}"),
        ));
    };
    if record_len < min {
        return Err(syntax(
            format,
            105,
            format!("point format {point_format} needs records of at least {min} bytes, the header gives {record_len}"),
        ));
    }
    let legacy = u64::from(u32_at(bytes, 107));
    let points = if minor >= 4 && header_size >= 375 && legacy == 0 {
        u64_at(bytes, 247)
    } else {
        legacy
    };
    let scale = [f64_at(bytes, 131), f64_at(bytes, 139), f64_at(bytes, 147)];
    let shift = [f64_at(bytes, 155), f64_at(bytes, 163), f64_at(bytes, 171)];
    if scale.iter().chain(&shift).any(|v| !v.is_finite()) || scale.contains(&0.0) {
        return Err(syntax(
            format,
            131,
            "the coordinate scale and offset must be finite and the scale non-zero".into(),
        ));
    }
    Ok(Header {
        format,
        header_size,
        offset,
        vlr_count: u32_at(bytes, 100) as usize,
        record_len,
        points: usize::try_from(points).unwrap_or(usize::MAX),
        scale,
        shift,
    })
}

pub fn read(bytes: &[u8]) -> Result<LoadedFile, ReadError> {
    let h = header(bytes)?;
    let positions = if h.format == Format::Laz {
        read_laz(bytes, &h)?
    } else {
        read_las(bytes, &h)?
    };
    let mesh = PolyMesh::from_points(positions)?;
    Ok(LoadedFile {
        scans: Some(1),
        ..LoadedFile::from_mesh(h.format, mesh)
    })
}

/// A record's coordinates, scaled and offset; non-finite results are an error.
fn point(rec: &[u8], h: &Header, at: usize) -> Result<Point3, ReadError> {
    let c = |k: usize| {
        let raw = le::<4>(rec, 4 * k).map_or(0, i32::from_le_bytes);
        f64::from(raw) * h.scale[k] + h.shift[k]
    };
    let p = Point3::new(c(0), c(1), c(2));
    if p.is_finite() {
        Ok(p)
    } else {
        Err(ReadError::NonFinite {
            format: h.format,
            at: Location::Byte(at),
        })
    }
}

fn read_las(bytes: &[u8], h: &Header) -> Result<Vec<Point3>, ReadError> {
    let body = &bytes[h.offset..];
    let needed = h.points.saturating_mul(h.record_len);
    if needed > body.len() {
        let whole = body.len() / h.record_len;
        return Err(ReadError::Truncated {
            format: Format::Las,
            at: Location::Byte(h.offset + whole * h.record_len),
            message: format!(
                "the header declares {} points of {} bytes, the file holds {whole}",
                h.points, h.record_len
            ),
        });
    }
    body.chunks_exact(h.record_len)
        .take(h.points)
        .enumerate()
        .map(|(i, rec)| point(rec, h, h.offset + i * h.record_len))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn las(points: &[[i32; 3]], declared: u32) -> Vec<u8> {
        let mut b = vec![0u8; HEADER_MIN];
        b[..4].copy_from_slice(b"LASF");
        b[24] = 1;
        b[25] = 2;
        b[94..96].copy_from_slice(&(HEADER_MIN as u16).to_le_bytes());
        b[96..100].copy_from_slice(&(HEADER_MIN as u32).to_le_bytes());
        b[104] = 0;
        b[105..107].copy_from_slice(&20u16.to_le_bytes());
        b[107..111].copy_from_slice(&declared.to_le_bytes());
        for (k, s) in [0.01f64, 0.01, 0.001].iter().enumerate() {
            b[131 + 8 * k..139 + 8 * k].copy_from_slice(&s.to_le_bytes());
        }
        b[155..163].copy_from_slice(&100.0f64.to_le_bytes());
        for p in points {
            for c in p {
                b.extend(c.to_le_bytes());
            }
            b.extend([0u8; 8]);
        }
        b
    }

    #[test]
    fn scale_and_offset_are_applied() {
        let f = read(&las(&[[1, 2, 3], [-100, 0, 5000]], 2)).unwrap();
        assert_eq!(f.format, Format::Las);
        let p = f.mesh.positions();
        assert!((p[0] - Point3::new(100.01, 0.02, 0.003)).length() < 1e-12);
        assert!((p[1] - Point3::new(99.0, 0.0, 5.0)).length() < 1e-12);
    }

    #[test]
    fn short_files_and_huge_counts_fail_with_the_offset() {
        let e = read(&las(&[[1, 2, 3]], 2)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "LAS byte 247: file ends early: the header declares 2 points of 20 bytes, the file holds 1"
        );
        let e = read(&las(&[[1, 2, 3]], u32::MAX)).unwrap_err();
        assert!(matches!(e, ReadError::Truncated { .. }), "{e}");
        let mut b = las(&[[1, 2, 3]], 1);
        b[104] = 0x83;
        assert!(matches!(read(&b), Err(ReadError::Syntax { .. })));
    }
}
