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

use super::{Format, LoadedFile, Location, ReadError};
use crate::geom::Point3;
use crate::mesh::PolyMesh;
use std::io::Cursor;

/// The smallest public header (LAS 1.0–1.2).
const HEADER_MIN: usize = 227;
/// Bytes of a VLR header.
const VLR_HEADER: usize = 54;
/// The minimum record length of point formats 0–10.
const RECORD_MIN: [usize; 11] = [20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67];
/// At least one bit of compressed data per point: bounds the point count a LAZ header may claim.
const LAZ_POINTS_PER_BYTE: usize = 8;

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
    header_size: usize,
    offset: usize,
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

/// The data of the `laszip encoded` VLR (record 22204), and its offset.
fn laszip_vlr<'a>(bytes: &'a [u8], h: &Header) -> Result<(&'a [u8], usize), ReadError> {
    let mut at = h.header_size;
    for _ in 0..h.vlr_count {
        let Some(head) = bytes
            .get(at..at + VLR_HEADER)
            .filter(|_| at + VLR_HEADER <= h.offset)
        else {
            break;
        };
        let user = &head[2..18];
        let record = u16_at(head, 18);
        let len = usize::from(u16_at(head, 20));
        let data_at = at + VLR_HEADER;
        let Some(data) = bytes.get(data_at..data_at + len) else {
            return Err(ReadError::Truncated {
                format: Format::Laz,
                at: Location::Byte(at),
                message: format!("a VLR of {len} bytes runs past the end of the file"),
            });
        };
        if user.starts_with(b"laszip encoded") && record == 22204 {
            return Ok((data, data_at));
        }
        at = data_at + len;
    }
    Err(syntax(
        Format::Laz,
        104,
        "the point format is marked compressed but the file has no LASzip VLR".into(),
    ))
}

fn laz_error(at: usize, e: impl std::fmt::Display) -> ReadError {
    syntax(Format::Laz, at, format!("LASzip: {e}"))
}

fn read_laz(bytes: &[u8], h: &Header) -> Result<Vec<Point3>, ReadError> {
    let (vlr_data, vlr_at) = laszip_vlr(bytes, h)?;
    let vlr = laz::LazVlr::from_buffer(vlr_data).map_err(|e| laz_error(vlr_at, e))?;
    let items = usize::try_from(vlr.items_size()).unwrap_or(usize::MAX);
    if items != h.record_len {
        return Err(syntax(
            Format::Laz,
            vlr_at,
            format!(
                "the LASzip items take {items} bytes per point, the header gives {}",
                h.record_len
            ),
        ));
    }
    let compressed = bytes.len() - h.offset;
    if h.points > compressed.saturating_mul(LAZ_POINTS_PER_BYTE) {
        return Err(ReadError::Truncated {
            format: Format::Laz,
            at: Location::Byte(107),
            message: format!(
                "the header declares {} points, more than {compressed} bytes of LASzip data can hold",
                h.points
            ),
        });
    }
    let compressor = u16_at(vlr_data, 0);
    if compressor >= 2 {
        check_chunks(bytes, h, &vlr, compressor == 3)?;
    }
    let mut cursor = Cursor::new(bytes);
    cursor.set_position(h.offset as u64);
    let mut dec = laz::LasZipDecompressor::new(cursor, vlr).map_err(|e| laz_error(h.offset, e))?;
    let mut rec = vec![0u8; h.record_len];
    let mut out = Vec::with_capacity(h.points.min(compressed));
    for i in 0..h.points {
        if let Err(e) = dec.decompress_one(&mut rec) {
            let at = usize::try_from(dec.get_mut().position()).unwrap_or(usize::MAX);
            return Err(ReadError::Truncated {
                format: Format::Laz,
                at: Location::Byte(at.min(bytes.len())),
                message: format!("point {i} of {}: {e}", h.points),
            });
        }
        out.push(point(&rec, h, h.offset)?);
    }
    Ok(out)
}

/// Checks the chunk table and, for LAS 1.4's layered chunks, every layer size, against the
/// bytes, before the decompressor allocates by them.
fn check_chunks(
    bytes: &[u8],
    h: &Header,
    vlr: &laz::LazVlr,
    layered: bool,
) -> Result<(), ReadError> {
    let data = h.offset;
    let stated = le::<8>(bytes, data).map(i64::from_le_bytes);
    // A writer that could not seek back leaves -1 and repeats the offset in the last 8 bytes.
    let table = match stated {
        Some(t) if t > data as i64 => Some(t),
        _ => bytes
            .len()
            .checked_sub(8)
            .and_then(|end| le::<8>(bytes, end))
            .map(i64::from_le_bytes)
            .filter(|&t| t > data as i64),
    };
    let Some(table) = table.and_then(|t| usize::try_from(t).ok()) else {
        if layered {
            return Err(syntax(
                Format::Laz,
                data,
                "the LAS 1.4 LAZ file has no chunk table".into(),
            ));
        }
        return Ok(());
    };
    let Some(count) = le::<4>(bytes, table + 4).map(u32::from_le_bytes) else {
        if layered {
            return Err(ReadError::Truncated {
                format: Format::Laz,
                at: Location::Byte(table),
                message: "the chunk table is past the end of the file".into(),
            });
        }
        return Ok(());
    };
    // Every chunk starts with one whole point.
    let room = table.saturating_sub(data + 8) / h.record_len.max(1);
    if count as usize > room {
        return Err(syntax(
            Format::Laz,
            table + 4,
            format!("the chunk table declares {count} chunks, the compressed points have room for {room}"),
        ));
    }
    if !layered {
        return Ok(());
    }
    let mut cursor = Cursor::new(bytes);
    cursor.set_position(data as u64);
    let chunks =
        laz::laszip::ChunkTable::read_from(&mut cursor, vlr).map_err(|e| laz_error(table, e))?;
    let layers: usize = vlr
        .items()
        .iter()
        .map(|item| match item.item_type() {
            laz::LazItemType::Point14 => 9,
            laz::LazItemType::RGBNIR14 => 2,
            laz::LazItemType::Byte14(n) => usize::from(n),
            _ => 1,
        })
        .sum();
    let mut start = data + 8;
    for (k, chunk) in chunks.as_ref().iter().enumerate() {
        let size = usize::try_from(chunk.byte_count).unwrap_or(usize::MAX);
        // The first point raw, a u32 point count, then one u32 size per layer.
        let sizes_at = start + h.record_len + 4;
        let mut total = 0usize;
        for l in 0..layers {
            let Some(s) = le::<4>(bytes, sizes_at + 4 * l).map(u32::from_le_bytes) else {
                return Err(ReadError::Truncated {
                    format: Format::Laz,
                    at: Location::Byte(sizes_at),
                    message: format!("chunk {k}: the layer sizes run past the end of the file"),
                });
            };
            total = total.saturating_add(s as usize);
        }
        if total > size || start.saturating_add(size) > bytes.len() {
            return Err(syntax(
                Format::Laz,
                sizes_at,
                format!("chunk {k}: its layers or its {size} bytes do not fit in the file"),
            ));
        }
        start += size;
    }
    Ok(())
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
