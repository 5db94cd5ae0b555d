//! Reading numbers and lines from large text files fast, with the same results as the
//! standard library.
//!
//! - [`Lines`] streams a file in 4 MB chunks and hands out its lines (without the line
//!   end) with their 1-based numbers; memory stays a chunk whatever the file's size.
//! - [`real`] reads a decimal real. Matrix files print a fixed number of significant
//!   digits (CalculiX: 14, `%20.13e`); such a number is `m * 10^e` with `m < 2^53` and
//!   `|e| <= 22`, where one multiplication or division of two exact doubles is correctly
//!   rounded (Clinger's fast path), so the result is the closest double, as the standard
//!   parser gives, at a fraction of its cost. Anything else goes to the standard parser.

use std::io::Read;

use crate::fe::FeError;

/// Exact powers of ten as doubles (10^22 is the largest one that is exact).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Whether `c` separates tokens (blank or tab; a carriage return before the line end).
pub fn is_blank(c: u8) -> bool {
    c == b' ' || c == b'\t' || c == b'\r'
}

/// A non-negative decimal integer of at most 18 digits, nothing else (a leading `+` is
/// accepted).
pub fn uint(t: &[u8]) -> Option<u64> {
    let t = t.strip_prefix(b"+").unwrap_or(t);
    if t.is_empty() || t.len() > 18 {
        return None;
    }
    let mut v = 0u64;
    for &c in t {
        let d = c.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        v = v * 10 + u64::from(d);
    }
    Some(v)
}

/// A finite decimal real (`2.5`, `-1.25e+05`, `3E-2`, `.5`), correctly rounded; `None`
/// for anything else (including `inf` and `nan`).
pub fn real(t: &[u8]) -> Option<f64> {
    fast_real(t).or_else(|| {
        let v: f64 = std::str::from_utf8(t).ok()?.parse().ok()?;
        // The standard parser also takes `inf`, `nan` and `infinity`: not matrix terms.
        v.is_finite().then_some(v)
    })
}

/// Clinger's fast path: sign, up to 19 digits with one optional point, an optional
/// exponent; `None` when the digits or the scale are out of its exact range.
fn fast_real(t: &[u8]) -> Option<f64> {
    let (neg, mut k) = match t.first()? {
        b'-' => (true, 1),
        b'+' => (false, 1),
        _ => (false, 0),
    };
    let mut m = 0u64;
    let (mut digits, mut scale, mut point, mut any) = (0u32, 0i32, false, false);
    while k < t.len() {
        let c = t[k];
        if c.is_ascii_digit() {
            any = true;
            if m != 0 || c != b'0' {
                digits += 1;
                if digits > 19 {
                    return None;
                }
            }
            m = m * 10 + u64::from(c - b'0');
            if point {
                scale -= 1;
            }
        } else if c == b'.' && !point {
            point = true;
        } else {
            break;
        }
        k += 1;
    }
    if !any {
        return None;
    }
    if k < t.len() {
        if t[k] != b'e' && t[k] != b'E' {
            return None;
        }
        k += 1;
        let (eneg, start) = match t.get(k) {
            Some(b'-') => (true, k + 1),
            Some(b'+') => (false, k + 1),
            _ => (false, k),
        };
        let e = uint(&t[start..]).filter(|&e| e < 1000)? as i32;
        scale += if eneg { -e } else { e };
    }
    if m >= 1 << 53 || scale.unsigned_abs() > 22 {
        return None;
    }
    let v = m as f64;
    let v = if scale >= 0 {
        v * POW10[scale as usize]
    } else {
        v / POW10[(-scale) as usize]
    };
    Some(if neg { -v } else { v })
}

/// The blank-separated tokens of `line`, each with its first column (1-based): at most
/// `N`, and the total count (which may be larger).
pub fn tokens<const N: usize>(line: &[u8]) -> ([(&[u8], usize); N], usize) {
    let mut out = [(&[][..], 0usize); N];
    let (mut count, mut k) = (0, 0);
    while k < line.len() {
        if is_blank(line[k]) {
            k += 1;
            continue;
        }
        let start = k;
        while k < line.len() && !is_blank(line[k]) {
            k += 1;
        }
        if count < N {
            out[count] = (&line[start..k], start + 1);
        }
        count += 1;
    }
    (out, count)
}

/// The columns (1-based, inclusive) of a token found by [`tokens`].
pub fn cols(tok: (&[u8], usize)) -> Option<(usize, usize)> {
    Some((tok.1, tok.1 + tok.0.len().max(1) - 1))
}

/// A file's lines, streamed in chunks.
pub struct Lines<R> {
    reader: R,
    file: String,
    buf: Vec<u8>,
    /// Start of the unread part of `buf` and end of its valid bytes.
    pos: usize,
    end: usize,
    eof: bool,
    line: usize,
}

/// Chunk size: a few MB keeps the reads large and the memory small.
const CHUNK: usize = 4 << 20;

impl<R: Read> Lines<R> {
    /// Lines of `reader`, which reads `file` (named in errors).
    pub fn new(reader: R, file: &str) -> Lines<R> {
        Lines {
            reader,
            file: file.to_string(),
            buf: vec![0; CHUNK],
            pos: 0,
            end: 0,
            eof: false,
            line: 0,
        }
    }

    /// The next line (without `\n`) and its 1-based number; `None` at the end.
    pub fn next_line(&mut self) -> Result<Option<(usize, &[u8])>, FeError> {
        loop {
            if let Some(k) = memchr::memchr(b'\n', &self.buf[self.pos..self.end]) {
                let start = self.pos;
                self.pos += k + 1;
                self.line += 1;
                return Ok(Some((self.line, &self.buf[start..start + k])));
            }
            if self.eof {
                if self.pos < self.end {
                    let start = self.pos;
                    self.pos = self.end;
                    self.line += 1;
                    return Ok(Some((self.line, &self.buf[start..self.end])));
                }
                return Ok(None);
            }
            self.refill()?;
        }
    }

    /// Move the partial line to the front and read more after it (growing the buffer
    /// for a line longer than a chunk).
    fn refill(&mut self) -> Result<(), FeError> {
        self.buf.copy_within(self.pos..self.end, 0);
        self.end -= self.pos;
        self.pos = 0;
        if self.end == self.buf.len() {
            self.buf.resize(self.buf.len() * 2, 0);
        }
        loop {
            match self.reader.read(&mut self.buf[self.end..]) {
                Ok(0) => {
                    self.eof = true;
                    return Ok(());
                }
                Ok(k) => {
                    self.end += k;
                    return Ok(());
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(source) => {
                    return Err(FeError::Io {
                        file: self.file.clone(),
                        source,
                    });
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_are_the_standard_parsers_bits() {
        // A deterministic spread of CalculiX-style and other numbers.
        let mut rng = fxbody_testkit::Rng::new(0x9e37_79b9_7f4a_7c15);
        for _ in 0..200_000 {
            let x = rng.next_u64();
            let m = (x % 100_000_000_000_000) as f64 / 1e13 + 1.0;
            let e = (x >> 48) as i32 % 40 - 20;
            let s = if x & 1 == 0 { 1.0 } else { -1.0 };
            for text in [
                format!("{:.13e}", s * m * 10f64.powi(e)),
                format!("{}", s * m * 10f64.powi(e)),
                format!("{:.6E}", m),
            ] {
                let want: f64 = text.parse().unwrap();
                assert_eq!(
                    real(text.as_bytes()).unwrap().to_bits(),
                    want.to_bits(),
                    "{text}"
                );
            }
        }
        for t in [
            "0.0000000000000e+00",
            "-0.0",
            ".5",
            "5.",
            "1e22",
            "123456789012345678901",
        ] {
            let want: f64 = t.parse().unwrap();
            assert_eq!(real(t.as_bytes()).unwrap().to_bits(), want.to_bits(), "{t}");
        }
        for t in [
            "", "-", "e5", "1e", "1.2.3", "inf", "NaN", "1e400", "1x", "0x10",
        ] {
            assert_eq!(real(t.as_bytes()), None, "{t}");
        }
    }

    #[test]
    fn lines_across_chunks_and_without_a_final_end() {
        let mut text = Vec::new();
        for k in 0..500_000 {
            text.extend_from_slice(format!("{k} {k} 1.0\n").as_bytes());
        }
        text.extend_from_slice(b"last");
        let mut lines = Lines::new(text.as_slice(), "x");
        let mut count = 0;
        while let Some((ln, line)) = lines.next_line().unwrap() {
            count += 1;
            assert_eq!(ln, count);
            if ln == 500_001 {
                assert_eq!(line, b"last");
            } else {
                assert_eq!(line, format!("{0} {0} 1.0", ln - 1).as_bytes());
            }
        }
        assert_eq!(count, 500_001);
    }
}
