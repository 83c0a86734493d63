//! Typed value readers over a PLY body: whitespace-separated ASCII tokens, or binary data in
//! either byte order. Both report faults without context; the element loop adds it.

use super::header::{Element, PropKind, Scalar};
use crate::io::text::{parse_f64, parse_i64, show};
use crate::io::Location;

/// Why a value could not be read.
#[derive(Debug)]
pub enum Fault {
    /// The body ended.
    End,
    /// An ASCII token that is not a number.
    NotNumber(String),
    /// A value that should be a count or index but is not a whole number in range.
    NotInteger(String),
    /// A list length below zero.
    NegativeLength(i64),
}

/// A reader of typed values from a PLY body.
pub trait Body {
    /// The next value of type `t`, converted to f64 (exact for every PLY type).
    fn value(&mut self, t: Scalar) -> Result<f64, Fault>;
    /// The next value of type `t` as an integer (a vertex index, possibly -1).
    fn integer(&mut self, t: Scalar) -> Result<i64, Fault>;
    /// Skips `n` values of type `t`.
    fn skip(&mut self, t: Scalar, n: usize) -> Result<(), Fault>;
    /// Where the next value starts.
    fn at(&mut self) -> Location;
    /// Where the value last read, or tried, starts: the place to blame for a fault.
    fn fault_at(&self) -> Location;
    /// Bytes left in the body.
    fn remaining(&self) -> usize;
    /// The fewest bytes one item of `el` can take, so that a header count can be checked
    /// against [`Body::remaining`] before anything is reserved.
    fn min_item_size(&self, el: &Element) -> usize;

    /// The next list length: a non-negative integer.
    fn length(&mut self, t: Scalar) -> Result<usize, Fault> {
        let n = self.integer(t)?;
        usize::try_from(n).map_err(|_| Fault::NegativeLength(n))
    }
}

/// An ASCII body: values are whitespace-separated tokens; line breaks are counted for
/// locations but otherwise treated as any other space, as tolerant PLY readers do.
pub struct Ascii<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
    token_line: usize,
}

impl<'a> Ascii<'a> {
    /// `bytes` is the body; `line` is the file line it starts on.
    pub fn new(bytes: &'a [u8], line: usize) -> Ascii<'a> {
        Ascii {
            bytes,
            pos: 0,
            line,
            token_line: line,
        }
    }

    fn skip_space(&mut self) {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            self.line += usize::from(b == b'\n');
            self.pos += 1;
        }
    }

    fn token(&mut self) -> Result<&'a [u8], Fault> {
        self.skip_space();
        self.token_line = self.line;
        let start = self.pos;
        let len = self.bytes[start..]
            .iter()
            .position(|b| b.is_ascii_whitespace())
            .unwrap_or(self.bytes.len() - start);
        if len == 0 {
            return Err(Fault::End);
        }
        self.pos += len;
        Ok(&self.bytes[start..start + len])
    }
}

impl Body for Ascii<'_> {
    fn value(&mut self, _: Scalar) -> Result<f64, Fault> {
        let t = self.token()?;
        parse_f64(t).ok_or_else(|| Fault::NotNumber(show(t)))
    }

    fn integer(&mut self, _: Scalar) -> Result<i64, Fault> {
        let t = self.token()?;
        parse_i64(t).ok_or_else(|| Fault::NotInteger(show(t)))
    }

    fn skip(&mut self, _: Scalar, n: usize) -> Result<(), Fault> {
        for _ in 0..n {
            self.token()?;
        }
        Ok(())
    }

    fn at(&mut self) -> Location {
        self.skip_space();
        Location::Line(self.line)
    }

    fn fault_at(&self) -> Location {
        Location::Line(self.token_line)
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    /// Every property takes at least one character and one separator (except the very last
    /// one in the file, which the room check allows for).
    fn min_item_size(&self, el: &Element) -> usize {
        2 * el.props.len()
    }
}

/// A binary body; `BIG` selects big-endian byte order. Locations are absolute file offsets.
pub struct Binary<'a, const BIG: bool> {
    bytes: &'a [u8],
    pos: usize,
    last: usize,
}

impl<'a, const BIG: bool> Binary<'a, BIG> {
    /// `bytes` is the whole file; the body starts at `start`.
    pub fn new(bytes: &'a [u8], start: usize) -> Binary<'a, BIG> {
        Binary {
            bytes,
            pos: start,
            last: start,
        }
    }

    fn take<const N: usize>(&mut self) -> Result<[u8; N], Fault> {
        self.last = self.pos;
        let chunk = self
            .bytes
            .get(self.pos..self.pos.saturating_add(N))
            .and_then(|s| <[u8; N]>::try_from(s).ok())
            .ok_or(Fault::End)?;
        self.pos += N;
        Ok(chunk)
    }
}

macro_rules! decode {
    ($self:ident, $ty:ty, $n:literal) => {{
        let b = $self.take::<$n>()?;
        if BIG {
            <$ty>::from_be_bytes(b)
        } else {
            <$ty>::from_le_bytes(b)
        }
    }};
}

impl<const BIG: bool> Binary<'_, BIG> {
    /// Decodes a value of an integer type; `None` (nothing read) for the float types. Both
    /// `value` and `integer` read the integer types alike.
    fn whole(&mut self, t: Scalar) -> Result<Option<i64>, Fault> {
        Ok(Some(match t {
            Scalar::I8 => i64::from(decode!(self, i8, 1)),
            Scalar::U8 => i64::from(decode!(self, u8, 1)),
            Scalar::I16 => i64::from(decode!(self, i16, 2)),
            Scalar::U16 => i64::from(decode!(self, u16, 2)),
            Scalar::I32 => i64::from(decode!(self, i32, 4)),
            Scalar::U32 => i64::from(decode!(self, u32, 4)),
            Scalar::F32 | Scalar::F64 => return Ok(None),
        }))
    }
}

impl<const BIG: bool> Body for Binary<'_, BIG> {
    fn value(&mut self, t: Scalar) -> Result<f64, Fault> {
        if let Some(n) = self.whole(t)? {
            // PLY's integer types are at most 32 bits: an f64 holds them exactly.
            return Ok(n as f64);
        }
        Ok(match t {
            Scalar::F32 => f64::from(decode!(self, f32, 4)),
            _ => decode!(self, f64, 8),
        })
    }

    fn integer(&mut self, t: Scalar) -> Result<i64, Fault> {
        if let Some(n) = self.whole(t)? {
            return Ok(n);
        }
        let v = self.value(t)?;
        // Float-typed indices are whole numbers well inside i64 or they are wrong.
        if v.fract() == 0.0 && v.abs() < 9.0e15 {
            Ok(v as i64)
        } else {
            Err(Fault::NotInteger(v.to_string()))
        }
    }

    fn skip(&mut self, t: Scalar, n: usize) -> Result<(), Fault> {
        self.last = self.pos;
        let end = n
            .checked_mul(t.size())
            .and_then(|len| self.pos.checked_add(len))
            .filter(|&end| end <= self.bytes.len())
            .ok_or(Fault::End)?;
        self.pos = end;
        Ok(())
    }

    fn at(&mut self) -> Location {
        Location::Byte(self.pos)
    }

    fn fault_at(&self) -> Location {
        Location::Byte(self.last)
    }

    fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    fn min_item_size(&self, el: &Element) -> usize {
        el.props
            .iter()
            .map(|p| match p.kind {
                PropKind::Scalar(t) => t.size(),
                PropKind::List { count, .. } => count.size(),
            })
            .sum()
    }
}
