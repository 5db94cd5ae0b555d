//! Nastran bulk-data cards: fixed small field (8 columns), fixed large field (16 columns,
//! `NAME*` and `*` continuations) and free field (commas), read from a stream one card
//! at a time.
//!
//! A card is a first line and its continuations; its data fields (field 2 on) are
//! concatenated over the lines, 8 per small-field line and 4 per large-field line, so a
//! card means the same in every layout. Fixed fields are cut by column, never by blanks:
//! a punched value may touch the field before it. Columns 73-80 (continuation mark or
//! sequence number) are not data. A line continues the card before it when it starts
//! with `+`, `*` or `,`, or when its field 1 is blank. `$` starts a comment; blank lines
//! are skipped; `ENDDATA` ends the deck. Free-field values are taken at full length.

use std::io::BufRead;

use super::error::FeError;
use super::fields::{Field, Lines, find_byte, trim};
use fxbody::fxb::fields::is_blank;

/// Where one field of the current card lies in the card's bytes.
#[derive(Debug, Clone, Copy)]
struct Span {
    start: usize,
    end: usize,
    line: usize,
    col: usize,
    width: usize,
}

/// One card: its name (field 1, trimmed, without the large-field `*`), first line and
/// data fields.
pub struct Card<'d> {
    /// Card name as written (case kept).
    pub name: &'d [u8],
    /// 1-based line of the card's first line.
    pub line: usize,
    buf: &'d [u8],
    spans: &'d [Span],
}

impl<'d> Card<'d> {
    /// Whether the card is `name` (case-insensitive).
    pub fn is(&self, name: &str) -> bool {
        self.name.eq_ignore_ascii_case(name.as_bytes())
    }

    /// The number of data fields (a multiple of the fields per line).
    pub fn len(&self) -> usize {
        self.spans.len()
    }

    /// Data field `k` (0 is field 2 of the first line); blank when the card has fewer.
    pub fn field(&self, k: usize) -> Field<'d> {
        match self.spans.get(k) {
            Some(s) => Field {
                text: &self.buf[s.start..s.end],
                line: s.line,
                col: s.col,
                width: s.width,
            },
            None => Field::missing(self.line),
        }
    }
}

/// How a physical line is laid out.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Layout {
    Small,
    Large,
    Free,
}

/// The cards of a bulk-data stream, one at a time.
pub struct Deck<'f, R> {
    lines: Lines<R>,
    file: &'f str,
    done: bool,
    /// The current card's lines, concatenated; a look-ahead line that starts the next
    /// card may follow them.
    buf: Vec<u8>,
    /// The look-ahead line: its number and where it starts in `buf`.
    ahead: Option<(usize, usize)>,
    /// The current card's fields.
    spans: Vec<Span>,
}

impl<'f, R: BufRead> Deck<'f, R> {
    /// The cards of `reader`, which reads file `file` (for messages).
    pub fn new(reader: R, file: &'f str) -> Deck<'f, R> {
        Deck {
            lines: Lines::new(reader, file),
            file,
            done: false,
            buf: Vec::new(),
            ahead: None,
            spans: Vec::new(),
        }
    }

    /// Append the next line that is not a comment or blank to `buf` (`$` comments cut);
    /// its number and start, or `None` at the end or at `ENDDATA`.
    fn read_line(&mut self) -> Result<Option<(usize, usize)>, FeError> {
        while !self.done {
            let start = self.buf.len();
            let Some(no) = self.lines.append_line(&mut self.buf)? else {
                self.done = true;
                break;
            };
            if let Some(cut) = find_byte(&self.buf[start..], b'$') {
                self.buf.truncate(start + cut);
            }
            let l = &self.buf[start..];
            if !l.iter().any(|&c| !is_blank(c)) {
                self.buf.truncate(start);
                continue;
            }
            if l.len() >= 7
                && trim(l)
                    .get(..7)
                    .is_some_and(|w| w.eq_ignore_ascii_case(b"ENDDATA"))
            {
                self.buf.truncate(start);
                self.done = true;
                break;
            }
            return Ok(Some((no, start)));
        }
        Ok(None)
    }

    /// The next card whose name `want` accepts. Cards not wanted are skipped without
    /// looking at their fields.
    pub fn next_card(&mut self, want: impl Fn(&[u8]) -> bool) -> Result<Option<Card<'_>>, FeError> {
        loop {
            let no = match self.ahead.take() {
                Some((no, start)) => {
                    self.buf.drain(..start);
                    no
                }
                None => {
                    self.buf.clear();
                    match self.read_line()? {
                        Some((no, _)) => no,
                        None => return Ok(None),
                    }
                }
            };
            // A continuation of a card not wanted (or a stray one): skip.
            if is_continuation(&self.buf) {
                continue;
            }
            let (layout, name) = head_of(&self.buf);
            if !want(&self.buf[name.0..name.1]) {
                continue;
            }
            self.spans.clear();
            split(&self.buf, 0, no, layout, self.file, &mut self.spans)?;
            while let Some((cl, start)) = self.read_line()? {
                let l = &self.buf[start..];
                if !is_continuation(l) {
                    self.ahead = Some((cl, start));
                    break;
                }
                let (layout, _) = head_of(l);
                split(l, start, cl, layout, self.file, &mut self.spans)?;
            }
            let end = self.ahead.map_or(self.buf.len(), |a| a.1);
            return Ok(Some(Card {
                name: &self.buf[name.0..name.1],
                line: no,
                buf: &self.buf[..end],
                spans: &self.spans,
            }));
        }
    }
}

/// Whether a line continues the card before it.
fn is_continuation(l: &[u8]) -> bool {
    match l.first() {
        Some(b'+' | b'*' | b',') => true,
        _ => {
            let f1 = &l[..l.len().min(8)];
            f1.iter().all(|&c| is_blank(c)) && find_byte(l, b',').is_none()
        }
    }
}

/// The range of `part` (a sub-slice of `whole`) in `whole`.
fn range_in(whole: &[u8], part: &[u8]) -> (usize, usize) {
    let start = part.as_ptr() as usize - whole.as_ptr() as usize;
    (start, start + part.len())
}

/// The layout of a line and where its card name is (field 1 trimmed, `*` removed).
fn head_of(l: &[u8]) -> (Layout, (usize, usize)) {
    let (layout, f1) = match find_byte(l, b',') {
        Some(c) => (Layout::Free, trim(&l[..c])),
        None => {
            let f1 = trim(&l[..l.len().min(8)]);
            let layout = if f1.first() == Some(&b'*') || f1.last() == Some(&b'*') {
                Layout::Large
            } else {
                Layout::Small
            };
            (layout, f1)
        }
    };
    let name = if f1.first() == Some(&b'*') {
        &f1[..0]
    } else {
        trim(f1.strip_suffix(b"*").unwrap_or(f1))
    };
    (layout, range_in(l, name))
}

/// Append the data fields of one line (field 2 on), which starts at `base` in the
/// card's bytes, to `out`.
fn split(
    l: &[u8],
    base: usize,
    line: usize,
    layout: Layout,
    file: &str,
    out: &mut Vec<Span>,
) -> Result<(), FeError> {
    match layout {
        Layout::Free => {
            let first = find_byte(l, b',').unwrap_or(0);
            let f1 = trim(&l[..first]);
            let per_line = if f1.ends_with(b"*") || f1.starts_with(b"*") {
                4
            } else {
                8
            };
            let mut col = 0;
            let mut k = 0;
            for tok in l.split(|&c| c == b',') {
                let start = col;
                col += tok.len() + 1;
                if k == 0 {
                    k += 1;
                    continue;
                }
                if k > per_line {
                    // Field 10 (small) or 6 (large): a continuation mark, not data.
                    if k == per_line + 1 && (trim(tok).is_empty() || is_mark(tok)) {
                        k += 1;
                        continue;
                    }
                    return Err(FeError::syntax(
                        file,
                        line,
                        Some((start + 1, start + tok.len().max(1))),
                        tok,
                        "a field",
                        format!(
                            "at most {per_line} data fields on a free-field line \
                             (then an optional continuation mark)"
                        ),
                    ));
                }
                out.push(Span {
                    start: base + start,
                    end: base + start + tok.len(),
                    line,
                    col: start + 1,
                    width: tok.len(),
                });
                k += 1;
            }
            // Pad to the full line so later lines land on the right fields.
            while k <= per_line {
                out.push(Span {
                    start: base + l.len(),
                    end: base + l.len(),
                    line,
                    col: l.len() + 1,
                    width: 0,
                });
                k += 1;
            }
        }
        Layout::Small | Layout::Large => {
            if let Some(t) = find_byte(&l[..l.len().min(72)], b'\t') {
                return Err(FeError::syntax(
                    file,
                    line,
                    Some((t + 1, t + 1)),
                    b"<tab>",
                    "a fixed-field character",
                    "blanks (a tab's width in a fixed-field card is ambiguous): \
                     replace tabs with blanks or write the card with commas",
                ));
            }
            let width = if layout == Layout::Small { 8 } else { 16 };
            let mut col = 8;
            while col < 72 {
                out.push(Span {
                    start: base + col.min(l.len()),
                    end: base + (col + width).min(l.len()),
                    line,
                    col: col + 1,
                    width,
                });
                col += width;
            }
        }
    }
    Ok(())
}

fn is_mark(tok: &[u8]) -> bool {
    matches!(trim(tok).first(), Some(b'+' | b'*'))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe::fields::nastran_real;

    fn cards(text: &str) -> Vec<(String, usize, Vec<String>)> {
        let mut deck = Deck::new(text.as_bytes(), "t.bdf");
        let mut out = Vec::new();
        while let Some(card) = deck.next_card(|n| n != b"SKIP").unwrap() {
            let f = (0..card.len())
                .map(|k| String::from_utf8_lossy(card.field(k).trimmed()).into_owned())
                .collect();
            out.push((
                String::from_utf8_lossy(card.name).into_owned(),
                card.line,
                f,
            ));
        }
        out
    }

    #[test]
    fn the_three_layouts_give_the_same_fields() {
        let small = "GRID          12       01.0000002.0000003.000000       0\n";
        let large = "GRID*                 12               0        1.000000        2.000000\n\
                     *               3.000000               0\n";
        let free = "GRID,12,0,1.0,2.0,3.0,0\n";
        for t in [small, large, free] {
            let c = cards(t);
            assert_eq!(c.len(), 1, "{t}");
            assert_eq!(c[0].0, "GRID");
            let x: Vec<f64> = c[0].2[2..5]
                .iter()
                .map(|s| nastran_real(s.as_bytes()).unwrap())
                .collect();
            assert_eq!(x, vec![1.0, 2.0, 3.0], "{t}");
            assert_eq!(c[0].2[0], "12");
            assert_eq!(c[0].2[5], "0");
        }
    }

    #[test]
    fn continuations_comments_and_skipped_cards() {
        let text = "$ comment\nSKIP    1       2\n+       3       4\nDMIG    K       0\n\
                    +       5\n\n        6\nENDDATA\nDMIG    AFTER\n";
        let c = cards(text);
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].0, "DMIG");
        assert_eq!(c[0].1, 4);
        assert_eq!(c[0].2.len(), 24);
        assert_eq!(c[0].2[0], "K");
        assert_eq!(c[0].2[8], "5");
        assert_eq!(c[0].2[16], "6");
    }

    #[test]
    fn fields_know_their_columns() {
        let text = "DMIG*   KAAX                          21               1\n\
                    *                     21               1-2.261491337E+08\n";
        let mut deck = Deck::new(text.as_bytes(), "p.pch");
        let card = deck.next_card(|_| true).unwrap().unwrap();
        let f = card.field(6);
        assert_eq!(f.line, 2);
        assert_eq!(f.cols(), Some((41, 56)));
        assert_eq!(f.real("p.pch", "a value").unwrap(), Some(-2.261491337e8));
        assert_eq!(card.field(99).cols(), None);
        let e = Field {
            text: b"   1.2.3",
            line: 9,
            col: 41,
            width: 16,
        }
        .real("p.pch", "a real")
        .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("p.pch:9: cols 41-56: cannot read '1.2.3' as a real: expected"),
            "{e}"
        );
    }
}
