//! A bounds-checked reader over the bytes of an MSH file: whitespace-separated ASCII tokens,
//! lines, and binary values of either endianness. Every read checks the remaining length and
//! reports errors with the file and a [`Location`] (line for ASCII files, byte offset for
//! binary ones); nothing here can panic or allocate more than the input justifies.

use std::path::Path;

use crate::error::{Location, MeshError};

/// Longest token quoted back in an error message.
const MAX_TOKEN_ECHO: usize = 40;

pub(crate) struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    file: &'a Path,
    /// Binary file: locations are byte offsets.
    pub binary: bool,
    /// Binary values are big-endian.
    pub big_endian: bool,
    /// Size in bytes of a binary `size_t` (4 or 8; MSH 4.1).
    pub size_t: usize,
}

fn is_ws(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | b'\x0b' | b'\x0c')
}

impl<'a> Cursor<'a> {
    pub fn new(data: &'a [u8], file: &'a Path) -> Self {
        Cursor {
            data,
            pos: 0,
            file,
            binary: false,
            big_endian: false,
            size_t: 8,
        }
    }

    pub fn file(&self) -> &'a Path {
        self.file
    }

    pub fn pos(&self) -> usize {
        self.pos
    }

    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    /// The location of byte `pos`, as the file kind reports it.
    pub fn location_at(&self, pos: usize) -> Location {
        if self.binary {
            Location::Byte(pos)
        } else {
            let end = pos.min(self.data.len());
            Location::Line(1 + self.data[..end].iter().filter(|&&b| b == b'\n').count())
        }
    }

    pub fn truncated(&self, what: &str) -> MeshError {
        MeshError::Truncated {
            file: self.file.to_path_buf(),
            location: self.location_at(self.pos.min(self.data.len())),
            what: what.to_string(),
        }
    }

    pub fn malformed_at(&self, pos: usize, message: impl Into<String>) -> MeshError {
        MeshError::Malformed {
            file: self.file.to_path_buf(),
            location: self.location_at(pos),
            message: message.into(),
        }
    }

    fn bad_number(&self, pos: usize, what: &str, token: &[u8]) -> MeshError {
        let mut text =
            String::from_utf8_lossy(&token[..token.len().min(MAX_TOKEN_ECHO)]).into_owned();
        if token.len() > MAX_TOKEN_ECHO {
            text.push_str("...");
        }
        MeshError::BadNumber {
            file: self.file.to_path_buf(),
            location: self.location_at(pos),
            what: what.to_string(),
            token: text,
        }
    }

    // ---------------------------------------------------------------- ASCII

    pub fn skip_ws(&mut self) {
        while self.pos < self.data.len() && is_ws(self.data[self.pos]) {
            self.pos += 1;
        }
    }

    pub fn at_eof_after_ws(&mut self) -> bool {
        self.skip_ws();
        self.pos >= self.data.len()
    }

    /// The next whitespace-separated token and its start offset.
    pub fn token(&mut self, what: &str) -> Result<(&'a [u8], usize), MeshError> {
        self.skip_ws();
        let start = self.pos;
        while self.pos < self.data.len() && !is_ws(self.data[self.pos]) {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.truncated(what));
        }
        Ok((&self.data[start..self.pos], start))
    }

    /// An integer token in `i32` range.
    pub fn int32(&mut self, what: &str) -> Result<i32, MeshError> {
        let (tok, start) = self.token(what)?;
        parse_int(tok)
            .and_then(|v| i32::try_from(v).ok())
            .ok_or_else(|| self.bad_number(start, what, tok))
    }

    /// A non-negative integer token (an id).
    pub fn id(&mut self, what: &str) -> Result<u64, MeshError> {
        let (tok, start) = self.token(what)?;
        parse_int(tok)
            .and_then(|v| u64::try_from(v).ok())
            .ok_or_else(|| self.bad_number(start, what, tok))
    }

    /// A non-negative count token, checked against the rest of the file: each item needs at
    /// least `min_bytes` more bytes.
    pub fn count(&mut self, what: &str, min_bytes: usize) -> Result<usize, MeshError> {
        let (tok, start) = self.token(what)?;
        let n = parse_int(tok)
            .and_then(|v| usize::try_from(v).ok())
            .ok_or_else(|| self.bad_number(start, what, tok))?;
        self.check_count(n, min_bytes, what)?;
        Ok(n)
    }

    /// A finite floating-point token.
    pub fn float(&mut self, what: &str) -> Result<f64, MeshError> {
        let (tok, start) = self.token(what)?;
        std::str::from_utf8(tok)
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .filter(|v| v.is_finite())
            .ok_or_else(|| self.bad_number(start, what, tok))
    }

    /// The rest of the current line (without `\r\n`) and its start; `None` at end of file.
    pub fn line(&mut self) -> Option<(&'a [u8], usize)> {
        if self.pos >= self.data.len() {
            return None;
        }
        let start = self.pos;
        let end = match self.data[start..].iter().position(|&b| b == b'\n') {
            Some(k) => {
                self.pos = start + k + 1;
                start + k
            }
            None => {
                self.pos = self.data.len();
                self.data.len()
            }
        };
        let mut line = &self.data[start..end];
        while let Some((&last, rest)) = line.split_last() {
            if last == b'\r' {
                line = rest;
            } else {
                break;
            }
        }
        Some((line, start))
    }

    /// The next non-blank line (trimmed) and its start. It must end with `\n`: a last line
    /// without one means the file was cut.
    pub fn data_line(&mut self, what: &str) -> Result<(&'a [u8], usize), MeshError> {
        self.skip_ws();
        let start = self.pos;
        match self.data[start..].iter().position(|&b| b == b'\n') {
            Some(k) => {
                self.pos = start + k + 1;
                Ok((trim(&self.data[start..start + k]), start))
            }
            None => {
                self.pos = self.data.len();
                Err(self.truncated(what))
            }
        }
    }

    /// Parses `tok` (found at `pos`) as a non-negative id.
    pub fn id_in(&self, tok: &[u8], pos: usize, what: &str) -> Result<u64, MeshError> {
        parse_int(tok)
            .and_then(|v| u64::try_from(v).ok())
            .ok_or_else(|| self.bad_number(pos, what, tok))
    }

    /// Parses `tok` (found at `pos`) as an `i32`.
    pub fn i32_in(&self, tok: &[u8], pos: usize, what: &str) -> Result<i32, MeshError> {
        parse_int(tok)
            .and_then(|v| i32::try_from(v).ok())
            .ok_or_else(|| self.bad_number(pos, what, tok))
    }

    /// Skips to just after the next `\n` (or to the end).
    pub fn skip_line_rest(&mut self) {
        let _ = self.line();
    }

    /// Skips whitespace, then reads the line `$End<name>`.
    pub fn expect_end(&mut self, name: &str) -> Result<(), MeshError> {
        self.skip_ws();
        let what = format!("$End{name}");
        let Some((line, start)) = self.line() else {
            return Err(self.truncated(&format!("{what} (the end of section ${name})")));
        };
        if trim(line) == what.as_bytes() {
            Ok(())
        } else {
            let found =
                String::from_utf8_lossy(&line[..line.len().min(MAX_TOKEN_ECHO)]).into_owned();
            Err(self.malformed_at(
                start,
                format!(
                    "expected {what}, found `{found}` (a count in ${name} does not match its data)"
                ),
            ))
        }
    }

    /// Skips an unknown section: to just after the line `$End<name>`.
    pub fn skip_section(&mut self, name: &str) -> Result<(), MeshError> {
        let needle = format!("$End{name}");
        let needle = needle.as_bytes();
        let hay = &self.data[self.pos..];
        match hay.windows(needle.len()).position(|w| w == needle) {
            Some(k) => {
                self.pos += k + needle.len();
                self.skip_line_rest();
                Ok(())
            }
            None => {
                self.pos = self.data.len();
                Err(self.truncated(&format!("section ${name} (no $End{name} found)")))
            }
        }
    }

    /// Errors if `n` items of at least `min_bytes` bytes each cannot fit in the rest of the file.
    pub fn check_count(&self, n: usize, min_bytes: usize, what: &str) -> Result<(), MeshError> {
        match n.checked_mul(min_bytes.max(1)) {
            Some(need) if need <= self.remaining() => Ok(()),
            _ => Err(self.truncated(&format!(
                "{what}: the count {n} needs more data than the {} bytes left",
                self.remaining()
            ))),
        }
    }

    // ---------------------------------------------------------------- binary

    pub fn bytes(&mut self, n: usize, what: &str) -> Result<&'a [u8], MeshError> {
        if n > self.remaining() {
            return Err(self.truncated(what));
        }
        let s = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], MeshError> {
        let s = self.bytes(N, what)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        if self.big_endian {
            a.reverse();
        }
        Ok(a)
    }

    pub fn bin_i32(&mut self, what: &str) -> Result<i32, MeshError> {
        Ok(i32::from_le_bytes(self.array::<4>(what)?))
    }

    /// A binary `int` that must be non-negative.
    pub fn bin_u32(&mut self, what: &str) -> Result<u64, MeshError> {
        let start = self.pos;
        let v = self.bin_i32(what)?;
        u64::try_from(v).map_err(|_| self.bad_number(start, what, v.to_string().as_bytes()))
    }

    pub fn bin_f64(&mut self, what: &str) -> Result<f64, MeshError> {
        let start = self.pos;
        let v = f64::from_le_bytes(self.array::<8>(what)?);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.bad_number(start, what, v.to_string().as_bytes()))
        }
    }

    /// A binary `size_t` of the header's data size.
    pub fn bin_size(&mut self, what: &str) -> Result<u64, MeshError> {
        if self.size_t == 4 {
            Ok(u64::from(u32::from_le_bytes(self.array::<4>(what)?)))
        } else {
            Ok(u64::from_le_bytes(self.array::<8>(what)?))
        }
    }

    /// A binary `size_t` used as a count, checked against the rest of the file.
    pub fn bin_count(&mut self, what: &str, min_bytes: usize) -> Result<usize, MeshError> {
        let start = self.pos;
        let v = self.bin_size(what)?;
        let n = usize::try_from(v)
            .map_err(|_| self.bad_number(start, what, v.to_string().as_bytes()))?;
        self.check_count(n, min_bytes, what)?;
        Ok(n)
    }
}

/// Parses a decimal integer (optional sign).
pub(crate) fn parse_int(tok: &[u8]) -> Option<i64> {
    std::str::from_utf8(tok).ok()?.parse::<i64>().ok()
}

/// `line` without leading and trailing ASCII whitespace.
pub(crate) fn trim(line: &[u8]) -> &[u8] {
    let start = line.iter().position(|&b| !is_ws(b)).unwrap_or(line.len());
    let end = line
        .iter()
        .rposition(|&b| !is_ws(b))
        .map_or(start, |k| k + 1);
    &line[start..end.max(start)]
}

/// Splits a line into whitespace-separated tokens.
pub(crate) fn split_ws(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|&b| is_ws(b)).filter(|t| !t.is_empty())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_lines_and_locations() {
        let data = b"$A\n 12 -3 x\r\n4.5e1\n";
        let p = Path::new("t.msh");
        let mut c = Cursor::new(data, p);
        assert_eq!(c.line().unwrap().0, b"$A");
        assert_eq!(c.int32("n").unwrap(), 12);
        assert_eq!(c.int32("n").unwrap(), -3);
        let e = c.int32("n").unwrap_err();
        assert!(e.to_string().contains("t.msh:2"), "{e}");
        assert_eq!(c.float("x").unwrap(), 45.0);
        assert!(matches!(c.token("t"), Err(MeshError::Truncated { .. })));
        assert_eq!(trim(b"  ab \r"), b"ab");
        assert_eq!(trim(b"   "), b"");
    }

    #[test]
    fn binary_values_both_endians() {
        let p = Path::new("t.msh");
        let mut c = Cursor::new(&[1, 0, 0, 0, 0, 0, 0, 1], p);
        c.binary = true;
        assert_eq!(c.bin_i32("i").unwrap(), 1);
        c.big_endian = true;
        assert_eq!(c.bin_i32("i").unwrap(), 1);
        assert!(matches!(
            c.bin_i32("i"),
            Err(MeshError::Truncated {
                location: Location::Byte(8),
                ..
            })
        ));
    }
}
