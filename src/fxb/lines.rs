//! The data lines of a `.fxb` text, read through a window of 1 MiB rather than
//! whole: a 100 MB body file is parsed as it is read, so its bytes never sit in memory
//! at once (on a virtual machine, touching 100 MB of fresh memory costs more than
//! parsing it). The text may come from a file or from bytes already in memory; both go
//! through the same window, so both read the same lines with the same numbers.

use std::io::{self, Read};
use std::ops::Range;

/// Bytes read into the window at a time (the window grows only for a longer line).
const WINDOW: usize = 1 << 20;

/// The data lines of a text: comments (`#` or `$` in column 1) and blank lines skipped,
/// `\r\n` read as `\n`, a last line without its line end read as a line.
pub struct Lines<'r> {
    input: &'r mut dyn Read,
    /// `buf[start..end]` is text not yet handed out; `buf[..start]` may still hold the
    /// line handed out last ([`Lines::unread`]).
    buf: Vec<u8>,
    start: usize,
    end: usize,
    /// Offset in the text of `buf[0]`.
    base: u64,
    /// The input has no more bytes.
    eof: bool,
    /// Length of the whole text (for progress and for "how much is left").
    total: u64,
    /// Lines read so far, comments and blank lines included (the last line's number).
    line_no: usize,
    /// Where the last data line handed out starts in `buf`, and its line number.
    last: Option<(usize, usize)>,
}

impl<'r> Lines<'r> {
    /// The lines of the `total` bytes `input` gives.
    pub fn new(input: &'r mut dyn Read, total: u64) -> Lines<'r> {
        Lines {
            input,
            buf: Vec::new(),
            start: 0,
            end: 0,
            base: 0,
            eof: false,
            total,
            line_no: 0,
            last: None,
        }
    }

    /// The next data line: its 1-based line number and where it is in the window
    /// ([`Lines::text`]); `None` at the end of the text. A failing read is the error.
    pub fn next_data(&mut self) -> io::Result<Option<(usize, Range<usize>)>> {
        loop {
            let Some(range) = self.next_line()? else {
                return Ok(None);
            };
            self.line_no += 1;
            let line = &self.buf[range.clone()];
            let comment = matches!(line.first(), Some(b'#' | b'$'));
            let blank = line.iter().all(|&c| super::fields::is_blank(c));
            if !comment && !blank {
                self.last = Some((range.start, self.line_no));
                return Ok(Some((self.line_no, range)));
            }
        }
    }

    /// The bytes of a line [`Lines::next_data`] handed out (valid until the next call).
    pub fn text(&self, range: Range<usize>) -> &[u8] {
        &self.buf[range]
    }

    /// Hand out the last data line again on the next call to [`Lines::next_data`] (with
    /// the same line number); nothing when no line was handed out.
    pub fn unread(&mut self) {
        if let Some((start, line_no)) = self.last.take() {
            self.start = start;
            self.line_no = line_no - 1;
        }
    }

    /// Offset in the text of the next byte not yet handed out.
    pub fn offset(&self) -> u64 {
        self.base + self.start as u64
    }

    /// Length of the whole text.
    pub fn total(&self) -> u64 {
        self.total
    }

    /// Bytes of the text not yet handed out.
    pub fn remaining(&self) -> u64 {
        self.total.saturating_sub(self.offset())
    }

    /// Lines read so far, comments and blank lines included.
    pub fn line_no(&self) -> usize {
        self.line_no
    }

    /// The next raw line (without its `\n` and a `\r` before it), `None` at the end.
    fn next_line(&mut self) -> io::Result<Option<Range<usize>>> {
        let mut searched = self.start;
        loop {
            if let Some(p) = memchr::memchr(b'\n', &self.buf[searched..self.end]) {
                let (a, nl) = (self.start, searched + p);
                self.start = nl + 1;
                return Ok(Some(a..strip_cr(&self.buf, a, nl)));
            }
            if self.eof {
                if self.start == self.end {
                    return Ok(None);
                }
                let (a, b) = (self.start, self.end);
                self.start = b;
                return Ok(Some(a..strip_cr(&self.buf, a, b)));
            }
            searched = self.end - self.start;
            self.refill()?;
        }
    }

    /// Move the text not yet handed out to the front of the window and read more after
    /// it (growing the window when a single line fills it).
    fn refill(&mut self) -> io::Result<()> {
        self.buf.copy_within(self.start..self.end, 0);
        self.base += self.start as u64;
        self.end -= self.start;
        self.start = 0;
        self.last = None;
        // A window no larger than the text (a small file allocates a few bytes, not a
        // MiB), doubled while one line fills it.
        let left = usize::try_from(self.total.saturating_sub(self.base)).unwrap_or(WINDOW);
        let want = WINDOW.min(left.saturating_add(1));
        if self.buf.len() < want {
            self.buf.resize(want, 0);
        } else if self.end == self.buf.len() {
            self.buf.resize(2 * self.buf.len().max(1), 0);
        }
        loop {
            match self.input.read(&mut self.buf[self.end..]) {
                Ok(0) => {
                    self.eof = true;
                    return Ok(());
                }
                Ok(n) => {
                    self.end += n;
                    return Ok(());
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
    }
}

/// The end of the line `buf[a..b]` without a trailing `\r`.
fn strip_cr(buf: &[u8], a: usize, b: usize) -> usize {
    if b > a && buf[b - 1] == b'\r' {
        b - 1
    } else {
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every data line, with its number, read through a reader that hands out a few
    /// bytes at a time (so lines straddle refills).
    fn lines(text: &[u8], step: usize) -> Vec<(usize, Vec<u8>)> {
        struct Trickle<'a>(&'a [u8], usize);
        impl Read for Trickle<'_> {
            fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
                let n = self.1.min(self.0.len()).min(out.len());
                out[..n].copy_from_slice(&self.0[..n]);
                self.0 = &self.0[n..];
                Ok(n)
            }
        }
        let mut input = Trickle(text, step);
        let mut l = Lines::new(&mut input, text.len() as u64);
        let mut out = Vec::new();
        while let Some((n, r)) = l.next_data().unwrap() {
            out.push((n, l.text(r).to_vec()));
        }
        assert_eq!(l.remaining(), 0);
        out
    }

    #[test]
    fn data_lines_with_their_numbers_however_the_bytes_arrive() {
        let text = b"# c\n  1 2\r\n\n$ x\n   \t\n3\r\n4";
        let want: Vec<(usize, Vec<u8>)> = vec![
            (2, b"  1 2".to_vec()),
            (6, b"3".to_vec()),
            (7, b"4".to_vec()),
        ];
        for step in [1, 2, 3, 7, 1000] {
            assert_eq!(lines(text, step), want, "step {step}");
        }
        assert!(lines(b"", 4).is_empty());
        assert_eq!(lines(b"\r", 4), vec![]);
        assert_eq!(lines(b"x\r", 1), vec![(1, b"x".to_vec())]);
    }

    #[test]
    fn a_line_longer_than_the_window_is_one_line() {
        let mut text = vec![b'7'; 3 * WINDOW + 5];
        text.extend_from_slice(b"\n8\n");
        let got = lines(&text, WINDOW / 3);
        assert_eq!(got.len(), 2);
        assert_eq!(got[0].1.len(), 3 * WINDOW + 5);
        assert_eq!(got[1], (2, b"8".to_vec()));
    }

    #[test]
    fn unread_hands_out_the_same_line_again() {
        let text = b"# head\n1 2\n3\n";
        let mut input: &[u8] = text;
        let mut l = Lines::new(&mut input, text.len() as u64);
        let (n, r) = l.next_data().unwrap().unwrap();
        assert_eq!((n, l.text(r)), (2, &b"1 2"[..]));
        l.unread();
        let (n, r) = l.next_data().unwrap().unwrap();
        assert_eq!((n, l.text(r)), (2, &b"1 2"[..]));
        let (n, r) = l.next_data().unwrap().unwrap();
        assert_eq!((n, l.text(r)), (3, &b"3"[..]));
        assert_eq!(l.offset(), text.len() as u64);
    }
}
