//! Byte-level helpers shared by the text readers: line splitting and number parsing without
//! copying the file into a `String` (files may hold stray non-UTF-8 bytes in comments).

use super::{Format, Location, ReadError};

/// Lines of `bytes` with their 1-based numbers, without the `\n` or `\r\n` terminator.
pub fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    bytes.split(|&b| b == b'\n').enumerate().map(|(i, line)| {
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        (i + 1, line)
    })
}

/// Whitespace-separated tokens of one line.
pub fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
}

/// The token as a float (any of Rust's float spellings, including `inf` and `nan`).
pub fn parse_f64(token: &[u8]) -> Option<f64> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

/// The token as an integer.
pub fn parse_i64(token: &[u8]) -> Option<i64> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

/// A token for an error message: lossy UTF-8, cut to a readable length.
pub fn show(token: &[u8]) -> String {
    const MAX: usize = 40;
    let s = String::from_utf8_lossy(&token[..token.len().min(MAX)]).into_owned();
    if token.len() > MAX {
        s + "…"
    } else {
        s
    }
}

/// Parses a finite coordinate, or says why not.
pub fn coordinate(token: &[u8], format: Format, at: Location) -> Result<f64, ReadError> {
    let value = parse_f64(token).ok_or_else(|| ReadError::Syntax {
        format,
        at,
        message: format!("expected a number, found '{}'", show(token)),
    })?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ReadError::NonFinite { format, at })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_strip_crlf_and_count_from_one() {
        let v: Vec<_> = lines(b"a\r\nb\nc").collect();
        assert_eq!(v, vec![(1, &b"a"[..]), (2, &b"b"[..]), (3, &b"c"[..])]);
    }

    #[test]
    fn coordinate_rejects_text_and_infinity() {
        let at = Location::Line(4);
        assert_eq!(coordinate(b"1.5e1", Format::Xyz, at), Ok(15.0));
        assert!(matches!(
            coordinate(b"x1", Format::Xyz, at),
            Err(ReadError::Syntax { .. })
        ));
        assert!(matches!(
            coordinate(b"inf", Format::Xyz, at),
            Err(ReadError::NonFinite { .. })
        ));
    }
}
