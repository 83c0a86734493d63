//! Byte-level helpers shared by the text readers: line splitting and number parsing without
//! copying the file into a `String` (files may hold stray non-UTF-8 bytes in comments).

use super::{Format, Location, ReadError};
use crate::progress::{self, Phase};

/// Lines of `bytes` with their 1-based numbers, without the `\n` or `\r\n` terminator.
/// Reports the share of `bytes` read as [`Phase::Reading`] progress.
pub fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    let mut offset = 0;
    bytes
        .split(|&b| b == b'\n')
        .enumerate()
        .map(move |(i, line)| {
            offset += line.len() + 1;
            if i % progress::BATCH == 0 {
                progress::report_count(Phase::Reading, offset.min(bytes.len()), bytes.len());
            }
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
///
/// Plain decimals with at most 2⁵³ as digits and a power of ten within ±22 (nearly every
/// coordinate in a scan file) take an exact fast path; the rest go to the standard parser.
pub fn parse_f64(token: &[u8]) -> Option<f64> {
    fast_f64(token).or_else(|| std::str::from_utf8(token).ok()?.parse().ok())
}

/// Clinger's fast path: when the decimal digits `m` fit in 53 bits and `10^|e|` ≤ 10²², both
/// are exact doubles, so the one multiplication or division rounds correctly and the result
/// equals the standard parser's.
fn fast_f64(token: &[u8]) -> Option<f64> {
    const POW10: [f64; 23] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
        1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
    ];
    let (negative, mut rest) = split_sign(token);
    let mut mantissa: u64 = 0;
    let mut exp: i64 = 0;
    let mut digits = 0;
    let mut in_fraction = false;
    while let [b, tail @ ..] = rest {
        match b {
            b'0'..=b'9' => {
                mantissa = mantissa.checked_mul(10)?.checked_add(u64::from(b - b'0'))?;
                exp -= i64::from(in_fraction);
                digits += 1;
            }
            b'.' if !in_fraction => in_fraction = true,
            _ => break,
        }
        rest = tail;
    }
    if digits == 0 || mantissa > 1 << 53 {
        return None;
    }
    if let [b'e' | b'E', tail @ ..] = rest {
        exp += parse_i64(tail).filter(|e| e.abs() < 1000)?;
    } else if !rest.is_empty() {
        return None;
    }
    let m = mantissa as f64;
    let power = *POW10.get(usize::try_from(exp.unsigned_abs()).ok()?)?;
    let value = if exp >= 0 { m * power } else { m / power };
    Some(if negative { -value } else { value })
}

fn split_sign(token: &[u8]) -> (bool, &[u8]) {
    match token {
        [b'-', rest @ ..] => (true, rest),
        [b'+', rest @ ..] => (false, rest),
        _ => (false, token),
    }
}

/// The token as a decimal integer with an optional sign.
pub fn parse_i64(token: &[u8]) -> Option<i64> {
    let (negative, digits) = split_sign(token);
    if digits.is_empty() {
        return None;
    }
    // Accumulate downwards so that i64::MIN parses too.
    let mut value: i64 = 0;
    for &b in digits {
        let d = b.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        value = value.checked_mul(10)?.checked_sub(i64::from(d))?;
    }
    if negative {
        Some(value)
    } else {
        value.checked_neg()
    }
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
    fn integers_parse_like_std() {
        for t in [
            "0",
            "-1",
            "+7",
            "9223372036854775807",
            "-9223372036854775808",
        ] {
            assert_eq!(parse_i64(t.as_bytes()), t.parse().ok(), "{t}");
        }
        for t in ["", "-", "1.0", "9223372036854775808", "1 ", "x"] {
            assert_eq!(parse_i64(t.as_bytes()), None, "{t}");
        }
    }

    proptest::proptest! {
        #[test]
        fn floats_parse_like_std(
            digits in "[0-9]{0,20}",
            fraction in proptest::option::of("[0-9]{0,20}"),
            exp in proptest::option::of(-40i32..40),
            sign in "[-+]?",
        ) {
            let mut t = format!("{sign}{digits}");
            if let Some(f) = fraction {
                t += &format!(".{f}");
            }
            if let Some(e) = exp {
                t += &format!("e{e}");
            }
            let expected: Option<f64> = t.parse().ok();
            let got = parse_f64(t.as_bytes());
            proptest::prop_assert_eq!(got.map(f64::to_bits), expected.map(f64::to_bits), "{}", t);
        }
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
