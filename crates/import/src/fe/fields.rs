//! Fields of FE text files: Nastran's real syntax, integer fields, fixed-field columns,
//! and lines read one at a time from a stream (a 250 MB punch is never held whole).

use std::io::{BufRead, Read};

use super::error::FeError;
use fxbody::fxb::fields::{is_blank, parse_int, parse_real};

/// One data field of a card: its raw text, the line it is on and its first column
/// (1-based).
#[derive(Debug, Clone, Copy)]
pub struct Field<'a> {
    /// Raw text, blanks included (empty when the line ends before the field).
    pub text: &'a [u8],
    /// 1-based line.
    pub line: usize,
    /// First column, 1-based.
    pub col: usize,
    /// Width in columns (the layout's, even when the line is shorter).
    pub width: usize,
}

impl<'a> Field<'a> {
    /// The text without surrounding blanks.
    pub fn trimmed(&self) -> &'a [u8] {
        trim(self.text)
    }

    /// Whether the field holds nothing but blanks.
    pub fn is_blank(&self) -> bool {
        self.trimmed().is_empty()
    }

    /// First and last column (`None` for a field the card does not have).
    pub fn cols(&self) -> Option<(usize, usize)> {
        (self.col > 0).then(|| (self.col, self.col + self.width.max(1) - 1))
    }

    /// A field the card does not have (read as blank), placed on `line`.
    pub fn missing(line: usize) -> Field<'a> {
        Field {
            text: &[],
            line,
            col: 0,
            width: 0,
        }
    }

    /// The field as an integer, `None` if blank; an error naming the line and columns
    /// if it is not an integer.
    pub fn int(&self, file: &str, what: &'static str) -> Result<Option<i64>, FeError> {
        match field_int(self.text) {
            Ok(v) => Ok(v),
            Err(()) => Err(FeError::syntax(
                file,
                self.line,
                self.cols(),
                self.trimmed(),
                what,
                "an integer",
            )),
        }
    }

    /// The field as a Nastran real, `None` if blank.
    pub fn real(&self, file: &str, what: &'static str) -> Result<Option<f64>, FeError> {
        let t = self.trimmed();
        if t.is_empty() {
            return Ok(None);
        }
        nastran_real(t).map(Some).ok_or_else(|| {
            FeError::syntax(
                file,
                self.line,
                self.cols(),
                t,
                what,
                "a Nastran real with a decimal point, such as 1.5, -2.0E+08, 1.0D+03, \
                 1.0+3, 1.-5 or .5",
            )
        })
    }
}

/// An integer field in one pass: `None` when blank, `Err` unless it is blanks, an
/// optional sign and digits, and blanks (what [`parse_int`] reads once trimmed).
fn field_int(text: &[u8]) -> Result<Option<i64>, ()> {
    let mut k = 0;
    while k < text.len() && is_blank(text[k]) {
        k += 1;
    }
    let start = k;
    if k < text.len() && matches!(text[k], b'+' | b'-') {
        k += 1;
    }
    while k < text.len() && text[k].is_ascii_digit() {
        k += 1;
    }
    let end = k;
    while k < text.len() && is_blank(text[k]) {
        k += 1;
    }
    if k != text.len() {
        return Err(());
    }
    if start == end {
        return Ok(None);
    }
    parse_int(&text[start..end]).map(Some).ok_or(())
}

/// A real as Nastran reads it (blanks around it removed first): a decimal point is
/// required (`7` is an integer, not a real), the exponent may be written `E`, `D` or as a
/// bare sign (`1.0+3` is 1000, `1.-5` is 1e-5), and the value must be finite.
pub fn nastran_real(text: &[u8]) -> Option<f64> {
    let text = trim(text);
    // No exponent form holds a point, so a point anywhere is a point in the mantissa.
    if !text.contains(&b'.') {
        return None;
    }
    real(text)
}

/// A real as [`parse_real`] reads it (Fortran syntax, finite), taking the direct route
/// through Rust's parser when the text is in its syntax (digits, a point, an `E`
/// exponent with its letter: what punches and most writers print) and [`parse_real`]'s
/// normalisation only for the rest (`D` exponents, `1.0+3`). Both give the correctly
/// rounded value of the same text; the direct route reads a 4.5-million-term punch in a
/// third less time.
pub fn real(text: &[u8]) -> Option<f64> {
    let unsigned = match text.first() {
        Some(b'+' | b'-') => &text[1..],
        _ => text,
    };
    // After the sign, a digit or a point: Rust's `inf` and `nan` cannot start so, and
    // every other text Rust accepts is a Fortran real with the same value.
    if unsigned
        .first()
        .is_some_and(|&c| c.is_ascii_digit() || c == b'.')
        && let Some(v) = std::str::from_utf8(text)
            .ok()
            .and_then(|t| t.parse::<f64>().ok())
    {
        return v.is_finite().then_some(v);
    }
    parse_real(text)
}

/// The first position of `b` in `hay`, eight bytes at a time (reading a large punch
/// spends most of its time finding line ends; a byte-by-byte search took twice as long).
pub fn find_byte(hay: &[u8], b: u8) -> Option<usize> {
    const LO: u64 = 0x0101_0101_0101_0101;
    const HI: u64 = 0x8080_8080_8080_8080;
    let pattern = LO * u64::from(b);
    let mut chunks = hay.chunks_exact(8);
    let mut offset = 0;
    for c in &mut chunks {
        let mut word = [0u8; 8];
        word.copy_from_slice(c);
        let w = u64::from_le_bytes(word) ^ pattern;
        // A zero byte of w is a match; the lowest flagged byte is always a true one.
        let z = w.wrapping_sub(LO) & !w & HI;
        if z != 0 {
            return Some(offset + (z.trailing_zeros() / 8) as usize);
        }
        offset += 8;
    }
    chunks
        .remainder()
        .iter()
        .position(|&c| c == b)
        .map(|p| offset + p)
}

/// `text` without leading and trailing blanks.
pub fn trim(text: &[u8]) -> &[u8] {
    let a = text
        .iter()
        .position(|&c| !is_blank(c))
        .unwrap_or(text.len());
    let b = text
        .iter()
        .rposition(|&c| !is_blank(c))
        .map_or(a, |p| p + 1);
    &text[a..b]
}

/// The longest line a reader accepts (bytes, line end included).
pub const MAX_LINE: usize = 1 << 20;

/// Lines of a stream, numbered from 1, read one at a time into a reused buffer, without
/// their line ending (`\n` or `\r\n`).
pub struct Lines<R> {
    reader: R,
    buf: Vec<u8>,
    no: usize,
    file: String,
}

impl<R: BufRead> Lines<R> {
    /// The lines of `reader`, which reads file `file` (for messages).
    pub fn new(reader: R, file: &str) -> Lines<R> {
        Lines {
            reader,
            buf: Vec::with_capacity(128),
            no: 0,
            file: file.to_string(),
        }
    }

    /// The next line and its number, `None` at the end; a line longer than
    /// [`MAX_LINE`] bytes is refused (a binary file read by mistake would otherwise be
    /// taken in whole as one line).
    pub fn next_line(&mut self) -> Result<Option<(usize, &[u8])>, FeError> {
        let mut buf = std::mem::take(&mut self.buf);
        buf.clear();
        let no = self.append_line(&mut buf);
        self.buf = buf;
        Ok(no?.map(|no| (no, &self.buf[..])))
    }

    /// Append the next line (without its line end) to `out`; its number, `None` at the
    /// end. Lets a caller gather a card's lines in one buffer without copying them twice.
    pub fn append_line(&mut self, out: &mut Vec<u8>) -> Result<Option<usize>, FeError> {
        let start = out.len();
        let n = (&mut self.reader)
            .take(MAX_LINE as u64 + 1)
            .read_until(b'\n', out)
            .map_err(|source| FeError::Io {
                file: self.file.clone(),
                source,
            })?;
        if n == 0 {
            return Ok(None);
        }
        self.no += 1;
        if n > MAX_LINE {
            return Err(FeError::invalid(
                &self.file,
                self.no,
                format!(
                    "a line longer than {MAX_LINE} bytes: expected a text file of \
                     matrix terms, cards or coordinates"
                ),
            ));
        }
        if out.last() == Some(&b'\n') {
            out.pop();
        }
        if out.len() > start && out.last() == Some(&b'\r') {
            out.pop();
        }
        Ok(Some(self.no))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn find_byte_finds_the_first_match_anywhere() {
        let hay: Vec<u8> = (0..40u8).map(|k| b'a' + k % 7).collect();
        for needle in [b'a', b'c', b'g', b'z', 0x80, 0x81] {
            for start in 0..hay.len() {
                let h = &hay[start..];
                assert_eq!(
                    find_byte(h, needle),
                    h.iter().position(|&c| c == needle),
                    "{needle} from {start}"
                );
            }
        }
        assert_eq!(find_byte(b"\x81\x80\x01x", 0x80), Some(1));
        assert_eq!(
            find_byte(b"\x00\x01\x00\x01\x00\x01\x00\x01\x01", 0x01),
            Some(1)
        );
    }

    #[test]
    fn nastran_reals() {
        for (t, v) in [
            ("1.0D+03", 1e3),
            ("1.0+3", 1e3),
            (".5", 0.5),
            ("1.-5", 1e-5),
            ("-2.261491337E+08", -2.261491337e8),
            ("  7.  ", 7.0),
            ("-.5-2", -0.005),
            ("1.5d-1", 0.15),
        ] {
            assert_eq!(nastran_real(t.as_bytes()), Some(v), "{t}");
        }
        for t in [
            "7", "1E5", "1.2.3", "", ".", "1.0E", "1.0 E+3", "nan", "1.0E999",
        ] {
            assert_eq!(nastran_real(t.as_bytes()), None, "{t}");
        }
    }
}
