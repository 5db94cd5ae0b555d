//! Nastran bulk-data cards: fixed small field (8 columns), fixed large field (16 columns,
//! `NAME*` and `*` continuations) and free field (commas), and Nastran's real syntax.
//!
//! A card is a first line and its continuations; its data fields (field 2 on) are
//! concatenated over the lines, 8 per small-field line and 4 per large-field line, so a
//! card means the same in every layout. Fixed fields are cut by column, never by blanks:
//! a punched value may touch the field before it. Columns 73-80 (continuation mark or
//! sequence number) are not data. A line continues the card before it when it starts
//! with `+`, `*` or `,`, or when its field 1 is blank. `$` starts a comment; blank lines
//! are skipped; `ENDDATA` ends the deck.

use super::error::FeError;
use crate::fxb::fields::{is_blank, parse_int, parse_real};

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

    /// First and last column.
    pub fn cols(&self) -> Option<(usize, usize)> {
        Some((self.col, self.col + self.width.max(1) - 1))
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

/// The first line of a card: its name (field 1, trimmed, without the large-field `*`)
/// and line.
#[derive(Debug, Clone, Copy)]
pub struct Head<'a> {
    /// Card name as written (case kept).
    pub name: &'a [u8],
    /// 1-based line of the card's first line.
    pub line: usize,
}

impl Head<'_> {
    /// Whether the card is `name` (case-insensitive).
    pub fn is(&self, name: &str) -> bool {
        self.name.eq_ignore_ascii_case(name.as_bytes())
    }
}

/// The cards of a bulk-data text, one at a time.
pub struct Deck<'a> {
    text: &'a [u8],
    pos: usize,
    line: usize,
    file: &'a str,
    /// A line already read that starts the next card.
    pending: Option<(usize, &'a [u8])>,
    done: bool,
}

/// How a physical line is laid out.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Layout {
    Small,
    Large,
    Free,
}

impl<'a> Deck<'a> {
    /// The cards of `text`, read from file `file` (for messages).
    pub fn new(text: &'a [u8], file: &'a str) -> Deck<'a> {
        Deck {
            text,
            pos: 0,
            line: 0,
            file,
            pending: None,
            done: false,
        }
    }

    /// The next line that is not a comment or blank, with its number; `$` comments cut.
    fn next_line(&mut self) -> Option<(usize, &'a [u8])> {
        if let Some(p) = self.pending.take() {
            return Some(p);
        }
        while !self.done && self.pos < self.text.len() {
            let rest = &self.text[self.pos..];
            let end = find_byte(rest, b'\n').unwrap_or(rest.len());
            self.pos += end + 1;
            self.line += 1;
            let mut l = &rest[..end];
            if let Some(cut) = find_byte(l, b'$') {
                l = &l[..cut];
            }
            if !l.iter().any(|&c| !is_blank(c)) {
                continue;
            }
            if let Some(s) = l.strip_suffix(b"\r") {
                l = s;
            }
            if l.len() >= 7
                && trim(l)
                    .get(..7)
                    .is_some_and(|w| w.eq_ignore_ascii_case(b"ENDDATA"))
            {
                self.done = true;
                return None;
            }
            return Some((self.line, l));
        }
        None
    }

    /// The next card whose name `want` accepts, its data fields in `fields` (cleared
    /// first). Cards not wanted are skipped without looking at their fields.
    pub fn next_card(
        &mut self,
        want: impl Fn(&[u8]) -> bool,
        fields: &mut Vec<Field<'a>>,
    ) -> Result<Option<Head<'a>>, FeError> {
        fields.clear();
        loop {
            let Some((ln, l)) = self.next_line() else {
                return Ok(None);
            };
            if is_continuation(l) {
                // A continuation of a card not wanted (or a stray one): skip.
                continue;
            }
            let (layout, name) = head_of(l);
            if !want(name) {
                continue;
            }
            split(l, ln, layout, self.file, fields)?;
            while let Some((cl, c)) = self.next_line() {
                if !is_continuation(c) {
                    self.pending = Some((cl, c));
                    break;
                }
                let (layout, _) = head_of(c);
                split(c, cl, layout, self.file, fields)?;
            }
            return Ok(Some(Head { name, line: ln }));
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

/// The layout of a line and its card name (field 1 trimmed, `*` removed).
fn head_of(l: &[u8]) -> (Layout, &[u8]) {
    if let Some(c) = find_byte(l, b',') {
        let f1 = trim(&l[..c]);
        return match f1.strip_suffix(b"*") {
            Some(n) => (Layout::Free, trim(n)),
            None => (Layout::Free, f1),
        };
    }
    let f1 = trim(&l[..l.len().min(8)]);
    if f1.first() == Some(&b'*') {
        return (Layout::Large, &[]);
    }
    match f1.strip_suffix(b"*") {
        Some(n) => (Layout::Large, trim(n)),
        None => (Layout::Small, f1),
    }
}

/// Append the data fields of one line (field 2 on) to `out`.
fn split<'a>(
    l: &'a [u8],
    line: usize,
    layout: Layout,
    file: &str,
    out: &mut Vec<Field<'a>>,
) -> Result<(), FeError> {
    match layout {
        Layout::Free => {
            let mut col = 0;
            let large = {
                let c = l.iter().position(|&c| c == b',').unwrap_or(0);
                trim(&l[..c]).ends_with(b"*") || trim(&l[..c]).starts_with(b"*")
            };
            let per_line = if large { 4 } else { 8 };
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
                out.push(Field {
                    text: tok,
                    line,
                    col: start + 1,
                    width: tok.len(),
                });
                k += 1;
            }
            // Pad to the full line so later lines land on the right fields.
            while k <= per_line {
                out.push(Field {
                    text: &[],
                    line,
                    col: col + 1,
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
                let a = col.min(l.len());
                let b = (col + width).min(l.len());
                out.push(Field {
                    text: &l[a..b],
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

    fn cards(text: &str) -> Vec<(String, usize, Vec<String>)> {
        let mut deck = Deck::new(text.as_bytes(), "t.bdf");
        let mut out = Vec::new();
        let mut fields = Vec::new();
        while let Some(h) = deck.next_card(|n| n != b"SKIP", &mut fields).unwrap() {
            let f = fields
                .iter()
                .map(|f| String::from_utf8_lossy(f.trimmed()).into_owned())
                .collect();
            out.push((String::from_utf8_lossy(h.name).into_owned(), h.line, f));
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
        let mut f = Vec::new();
        deck.next_card(|_| true, &mut f).unwrap().unwrap();
        assert_eq!(f[6].line, 2);
        assert_eq!(f[6].cols(), Some((41, 56)));
        assert_eq!(f[6].real("p.pch", "a value").unwrap(), Some(-2.261491337e8));
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
