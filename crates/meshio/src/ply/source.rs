//! Value sources for a PLY body: an ASCII token stream and a binary cursor (either byte order),
//! behind one trait so that the element readers are written once.

use super::header::Scalar;
use crate::text::{TokenStream, parse_f32, parse_f64, parse_i64};

/// A low-level read failure; the element reader adds the path and element to it.
#[derive(Debug)]
pub(crate) enum ReadError {
    /// ASCII: the data ended.
    Eof { line: usize },
    /// ASCII: a token is not a number of the property's type.
    Malformed {
        line: usize,
        token: String,
        expected: &'static str,
    },
    /// Binary: fewer than `needed` bytes at `offset`.
    Truncated { offset: u64, needed: u64, len: u64 },
}

/// Where PLY values come from.
pub(crate) trait Source {
    /// Reads a value of type `ty` as f32 (rounded once, from the file's own precision).
    fn f32(&mut self, ty: Scalar) -> Result<f32, ReadError>;
    /// Reads an integer of type `ty` (list counts, vertex indices).
    fn int(&mut self, ty: Scalar) -> Result<i64, ReadError>;
    /// Skips a value of type `ty`.
    fn skip(&mut self, ty: Scalar) -> Result<(), ReadError>;
    /// Checks that the rest of the data can hold `n` list items of type `item`, so that the
    /// list can be allocated (binary: an exact bound; ASCII: one character and one separator
    /// per item).
    fn check_list(&self, n: u64, item: Scalar) -> Result<(), ReadError>;
    /// Line (ASCII) of the next value, for error messages.
    fn line(&mut self) -> Option<usize>;
    /// Bytes left after the last value read that are not whitespace (trailing data).
    fn trailing_bytes(&self) -> usize;
}

/// ASCII body.
pub(crate) struct Ascii<'a> {
    tokens: TokenStream<'a>,
}

impl<'a> Ascii<'a> {
    pub(crate) fn new(body: &'a [u8], first_line: usize) -> Self {
        Self {
            tokens: TokenStream::new(body, first_line),
        }
    }

    #[inline]
    fn token(&mut self) -> Result<&'a [u8], ReadError> {
        let line = self.tokens.line();
        self.tokens.next_token().ok_or(ReadError::Eof { line })
    }

    fn malformed(&self, token: &[u8], expected: &'static str) -> ReadError {
        ReadError::Malformed {
            line: self.tokens.line(),
            token: crate::error::token_text(token),
            expected,
        }
    }
}

impl Source for Ascii<'_> {
    #[inline]
    fn f32(&mut self, ty: Scalar) -> Result<f32, ReadError> {
        let token = self.token()?;
        let value = match ty {
            Scalar::F32 => parse_f32(token),
            Scalar::F64 => parse_f64(token).map(|v| v as f32),
            _ => parse_i64(token).map(|v| v as f32),
        };
        value.ok_or_else(|| {
            self.malformed(
                token,
                if ty.is_integer() {
                    "an integer"
                } else {
                    "a number"
                },
            )
        })
    }

    #[inline]
    fn int(&mut self, _ty: Scalar) -> Result<i64, ReadError> {
        let token = self.token()?;
        parse_i64(token).ok_or_else(|| self.malformed(token, "an integer"))
    }

    #[inline]
    fn skip(&mut self, _ty: Scalar) -> Result<(), ReadError> {
        self.token().map(|_| ())
    }

    fn check_list(&self, n: u64, _item: Scalar) -> Result<(), ReadError> {
        // Each item is at least one character and one separator (the last may lack it).
        if n > (self.tokens.remaining().len() as u64).div_ceil(2) {
            return Err(ReadError::Eof {
                line: self.tokens.line(),
            });
        }
        Ok(())
    }

    fn line(&mut self) -> Option<usize> {
        Some(self.tokens.next_line())
    }

    fn trailing_bytes(&self) -> usize {
        self.tokens
            .remaining()
            .iter()
            .filter(|b| !b.is_ascii_whitespace())
            .count()
    }
}

/// Binary body; `BIG` selects big-endian.
pub(crate) struct Binary<'a, const BIG: bool> {
    data: &'a [u8],
    pos: usize,
    /// Offset of `data` in the file, for error messages.
    base: u64,
}

impl<'a, const BIG: bool> Binary<'a, BIG> {
    pub(crate) fn new(body: &'a [u8], base: usize) -> Self {
        Self {
            data: body,
            pos: 0,
            base: base as u64,
        }
    }

    #[inline]
    fn take<const N: usize>(&mut self) -> Result<[u8; N], ReadError> {
        match self.data.get(self.pos..self.pos + N) {
            Some(bytes) => {
                self.pos += N;
                // The slice has exactly N bytes.
                let mut out = [0u8; N];
                out.copy_from_slice(bytes);
                Ok(out)
            }
            None => Err(ReadError::Truncated {
                offset: self.base + self.pos as u64,
                needed: N as u64,
                len: self.base + self.data.len() as u64,
            }),
        }
    }

    #[inline]
    fn value(&mut self, ty: Scalar) -> Result<f64, ReadError> {
        macro_rules! read {
            ($t:ty, $n:literal) => {{
                let bytes = self.take::<$n>()?;
                if BIG {
                    <$t>::from_be_bytes(bytes)
                } else {
                    <$t>::from_le_bytes(bytes)
                }
            }};
        }
        Ok(match ty {
            Scalar::I8 => f64::from(read!(i8, 1)),
            Scalar::U8 => f64::from(read!(u8, 1)),
            Scalar::I16 => f64::from(read!(i16, 2)),
            Scalar::U16 => f64::from(read!(u16, 2)),
            Scalar::I32 => f64::from(read!(i32, 4)),
            Scalar::U32 => f64::from(read!(u32, 4)),
            Scalar::F32 => f64::from(read!(f32, 4)),
            Scalar::F64 => read!(f64, 8),
        })
    }
}

impl<const BIG: bool> Source for Binary<'_, BIG> {
    #[inline]
    fn f32(&mut self, ty: Scalar) -> Result<f32, ReadError> {
        // f32 → f64 → f32 is exact; f64 and integers are rounded once.
        self.value(ty).map(|v| v as f32)
    }

    #[inline]
    fn int(&mut self, ty: Scalar) -> Result<i64, ReadError> {
        // Integers up to 32 bits are exact in f64; float types are truncated, and the header
        // check only allows integer list types for indices.
        self.value(ty).map(|v| v as i64)
    }

    #[inline]
    fn skip(&mut self, ty: Scalar) -> Result<(), ReadError> {
        let n = ty.size();
        if self.pos + n > self.data.len() {
            return Err(ReadError::Truncated {
                offset: self.base + self.pos as u64,
                needed: n as u64,
                len: self.base + self.data.len() as u64,
            });
        }
        self.pos += n;
        Ok(())
    }

    fn check_list(&self, n: u64, item: Scalar) -> Result<(), ReadError> {
        let needed = n.saturating_mul(item.size() as u64);
        if needed > (self.data.len() - self.pos) as u64 {
            return Err(ReadError::Truncated {
                offset: self.base + self.pos as u64,
                needed,
                len: self.base + self.data.len() as u64,
            });
        }
        Ok(())
    }

    fn line(&mut self) -> Option<usize> {
        None
    }

    fn trailing_bytes(&self) -> usize {
        self.data.len() - self.pos
    }
}
