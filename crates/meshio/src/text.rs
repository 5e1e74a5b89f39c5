//! Byte-level helpers for the text formats (ASCII PLY, OBJ): line and token splitting without
//! per-line allocation, and number parsing from byte slices.

/// True for the ASCII whitespace that separates tokens (space, tab, CR, VT, FF).
#[inline]
pub(crate) fn is_blank(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | b'\x0b' | b'\x0c')
}

/// Iterates over lines as `(1-based line number, bytes without "\n" or "\r\n")`.
/// A last line without a trailing newline is still yielded.
pub(crate) struct Lines<'a> {
    data: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Lines<'a> {
    /// Lines of `data`, numbered from `first_line`.
    pub(crate) fn new(data: &'a [u8], first_line: usize) -> Self {
        Self {
            data,
            pos: 0,
            line: first_line,
        }
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = (usize, &'a [u8]);

    fn next(&mut self) -> Option<Self::Item> {
        if self.pos >= self.data.len() {
            return None;
        }
        let rest = &self.data[self.pos..];
        let (line, advance) = match rest.iter().position(|&b| b == b'\n') {
            Some(end) => (&rest[..end], end + 1),
            None => (rest, rest.len()),
        };
        self.pos += advance;
        let number = self.line;
        self.line += 1;
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        Some((number, line))
    }
}

/// Iterates over the whitespace-separated tokens of one line.
pub(crate) fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|&b| is_blank(b)).filter(|t| !t.is_empty())
}

/// A token stream across lines that tracks the line number (ASCII PLY bodies, where a row may
/// in principle wrap).
pub(crate) struct TokenStream<'a> {
    data: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> TokenStream<'a> {
    /// Tokens of `data`, whose first byte is on line `first_line`.
    pub(crate) fn new(data: &'a [u8], first_line: usize) -> Self {
        Self {
            data,
            pos: 0,
            line: first_line,
        }
    }

    /// The next token, or `None` at the end of the data.
    #[inline]
    pub(crate) fn next_token(&mut self) -> Option<&'a [u8]> {
        let data = self.data;
        while self.pos < data.len() {
            match data[self.pos] {
                b'\n' => self.line += 1,
                b if is_blank(b) => {}
                _ => break,
            }
            self.pos += 1;
        }
        if self.pos >= data.len() {
            return None;
        }
        let start = self.pos;
        while self.pos < data.len() && !is_blank(data[self.pos]) && data[self.pos] != b'\n' {
            self.pos += 1;
        }
        Some(&data[start..self.pos])
    }

    /// Line number of the current position (the end of the last token read).
    pub(crate) fn line(&self) -> usize {
        self.line
    }

    /// Line number of the next token (skips whitespace first; `line()` at the end of data).
    pub(crate) fn next_line(&mut self) -> usize {
        while self.pos < self.data.len()
            && (is_blank(self.data[self.pos]) || self.data[self.pos] == b'\n')
        {
            if self.data[self.pos] == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        self.line
    }

    /// Bytes not consumed yet.
    pub(crate) fn remaining(&self) -> &'a [u8] {
        &self.data[self.pos..]
    }
}

/// Parses an f32 (correctly rounded; accepts `nan` and `inf`, which the caller rejects with a
/// [`NonFinite`](crate::MeshIoError::NonFinite) error naming the vertex).
#[inline]
pub(crate) fn parse_f32(token: &[u8]) -> Option<f32> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

/// Parses an f64 (see [`parse_f32`]).
#[inline]
pub(crate) fn parse_f64(token: &[u8]) -> Option<f64> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

/// Parses an unsigned decimal integer; `None` on any other byte or on overflow.
pub(crate) fn parse_u64(token: &[u8]) -> Option<u64> {
    if token.is_empty() {
        return None;
    }
    token.iter().try_fold(0u64, |acc, &b| {
        let digit = b.wrapping_sub(b'0');
        if digit > 9 {
            return None;
        }
        acc.checked_mul(10)?.checked_add(u64::from(digit))
    })
}

/// Parses a decimal integer with an optional sign; `None` on any other byte or on overflow.
#[inline]
pub(crate) fn parse_i64(token: &[u8]) -> Option<i64> {
    let (negative, digits) = match token.first()? {
        b'-' => (true, &token[1..]),
        b'+' => (false, &token[1..]),
        _ => (false, token),
    };
    if digits.is_empty() {
        return None;
    }
    let mut value: i64 = 0;
    for &b in digits {
        let digit = b.wrapping_sub(b'0');
        if digit > 9 {
            return None;
        }
        value = value.checked_mul(10)?.checked_add(i64::from(digit))?;
    }
    Some(if negative { -value } else { value })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_strip_crlf_and_keep_last_line_without_newline() {
        let lines: Vec<_> = Lines::new(b"a b\r\n\nc", 1).collect();
        assert_eq!(lines, vec![(1, &b"a b"[..]), (2, &b""[..]), (3, &b"c"[..])]);
    }

    #[test]
    fn token_stream_counts_lines() {
        let mut ts = TokenStream::new(b"1 2\r\n\n 3\n", 10);
        assert_eq!(ts.next_token(), Some(&b"1"[..]));
        assert_eq!(ts.next_token(), Some(&b"2"[..]));
        assert_eq!(ts.next_token(), Some(&b"3"[..]));
        assert_eq!(ts.line(), 12);
        assert_eq!(ts.next_token(), None);
    }

    #[test]
    fn integers_reject_garbage_and_overflow() {
        assert_eq!(parse_i64(b"-17"), Some(-17));
        assert_eq!(parse_i64(b"+3"), Some(3));
        assert_eq!(parse_i64(b"3.0"), None);
        assert_eq!(parse_i64(b"-"), None);
        assert_eq!(parse_i64(b"99999999999999999999"), None);
    }

    #[test]
    fn floats_round_correctly() {
        assert_eq!(parse_f32(b"-1.5e3"), Some(-1500.0));
        assert!(parse_f32(b"nan").is_some_and(f32::is_nan));
        assert_eq!(parse_f32(b"1e"), None);
    }
}
