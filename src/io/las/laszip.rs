//! LAZ: the LASzip-compressed points of a LAS file, decompressed one at a time with the `laz`
//! crate, after the chunk table and the LAS 1.4 layer sizes have been checked against the bytes.

use super::{le, point, syntax, u16_at, Header};
use crate::geom::Point3;
use crate::io::{Format, Location, ReadError};
use std::io::Cursor;

/// Bytes of a VLR header.
const VLR_HEADER: usize = 54;
/// At least one bit of compressed data per point: bounds the point count a LAZ header may claim.
const LAZ_POINTS_PER_BYTE: usize = 8;

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

pub(super) fn read_laz(bytes: &[u8], h: &Header) -> Result<Vec<Point3>, ReadError> {
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
